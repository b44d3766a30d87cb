//! The menu bar: File (open, recent, built-in scene, export), View, Help.

use crate::app::shortcuts::{shortcut_text as format_shortcut, Action, SHORTCUTS};
use crate::app::{BvhscopeApp, PathWindow, Pick};
use crate::render::View;

fn shortcut_text(ctx: &egui::Context, action: Action) -> String {
    SHORTCUTS.iter().find(|(_, a, _)| *a == action).map_or(String::new(), |(s, _, _)| format_shortcut(ctx, s))
}

fn item(ui: &mut egui::Ui, text: &str, action: Action) -> bool {
    let shortcut = shortcut_text(ui.ctx(), action);
    ui.add(egui::Button::new(text).shortcut_text(shortcut)).clicked()
}

pub fn show(app: &mut BvhscopeApp, ui: &mut egui::Ui) {
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| {
            if item(ui, "Open…", Action::Open) {
                app.act(Action::Open);
            }
            if item(ui, "Open path…", Action::OpenPath) {
                app.act(Action::OpenPath);
            }
            ui.menu_button("Open recent", |ui| {
                if app.settings.recent_files.is_empty() {
                    ui.weak("No recent files");
                }
                for path in app.settings.recent_files.clone() {
                    if ui.button(path.display().to_string()).clicked() {
                        app.open(path);
                    }
                }
            });
            if ui.button("Built-in scene").clicked() {
                app.show_builtin();
            }
            ui.separator();
            if item(ui, "Save view as PNG…", Action::SavePng) {
                app.act(Action::SavePng);
            }
            if item(ui, "Export statistics as CSV…", Action::ExportStats) {
                app.act(Action::ExportStats);
            }
            if ui.button("Export statistics as JSON…").clicked() {
                let name = crate::app::export::default_name(app, "json");
                app.jobs.pick_file(Pick::SaveStatsJson, &name);
            }
            if ui
                .button("Save scene as…")
                .on_hover_text("The camera, the meshes and the BVH settings, as a scene file")
                .clicked()
            {
                let name = format!("{}.json", app.scene.title().trim_end_matches(".obj").trim_end_matches(".json"));
                app.jobs.pick_file(Pick::SaveScene, &name);
            }
            if ui.button("Save to a typed path…").clicked() {
                let name = crate::app::export::default_name(app, "png");
                app.path_window = Some(PathWindow::new(Pick::SavePng, name, None));
            }
            ui.separator();
            if ui.button("Quit").clicked() {
                ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
            }
        });
        ui.menu_button("View", |ui| {
            for (i, v) in View::ALL.iter().enumerate() {
                let shortcut = shortcut_text(ui.ctx(), Action::View(i));
                if ui
                    .add(egui::Button::selectable(app.settings.view == *v, v.label()).shortcut_text(shortcut))
                    .clicked()
                {
                    app.settings.view = *v;
                }
            }
            ui.separator();
            if item(ui, "Frame the mesh", Action::FrameMesh) {
                app.frame_mesh();
            }
            if item(ui, "Reset camera", Action::ResetView) {
                app.reset_view();
            }
            if item(ui, "Node boxes", Action::ToggleBoxes) {
                app.act(Action::ToggleBoxes);
            }
        });
        ui.menu_button("Help", |ui| {
            if item(ui, "Keyboard and mouse", Action::Help) {
                app.show_help = true;
            }
        });
        ui.separator();
        ui.label(egui::RichText::new(app.scene.title()).strong());
    });
}
