//! The menu bar: File (open, recent, built-in scene, export), View, Help; each menu scrolls when
//! taller than the window.

use crate::app::state::shortcuts::{shortcut_text as format_shortcut, SHORTCUTS};
use crate::app::state::{Action, Actions, BvhscopeApp};
use crate::render::View;

fn shortcut_text(ctx: &egui::Context, action: &Action) -> String {
    SHORTCUTS.iter().find(|(_, a, _)| a == action).map_or(String::new(), |(s, _, _)| format_shortcut(ctx, s))
}

/// A menu item that emits `action`, with the action's shortcut beside it.
fn item(ui: &mut egui::Ui, out: &mut Actions, text: &str, action: Action) {
    let shortcut = shortcut_text(ui.ctx(), &action);
    if ui.add(egui::Button::new(text).shortcut_text(shortcut)).clicked() {
        out.push(action);
    }
}

/// A menu (top-level or within one) whose body scrolls when it is taller than the room between
/// its top and the window's bottom. A popup that does not fit is cut off at the window's edge:
/// presenting at 720 px (480 points at 150 %), the View menu's last commands were out of reach.
fn menu(ui: &mut egui::Ui, title: &str, content: impl FnOnce(&mut egui::Ui)) {
    ui.menu_button(title, |ui| {
        // Below the body come the popup frame's margin and stroke, and a little air so the last
        // item does not touch the window's edge.
        let below =
            ui.spacing().menu_margin.bottomf() + ui.visuals().window_stroke().width + ui.spacing().item_spacing.y;
        let room = ui.ctx().content_rect().bottom() - ui.cursor().top() - below;
        // A solid bar, shown whenever the body scrolls: a floating one stays hidden until the
        // pointer is over it, and a menu cut short with no sign of more looks complete.
        ui.spacing_mut().scroll = egui::style::ScrollStyle::solid();
        // At least a few rows, even in a window too small to hold them.
        let room = room.max(3.0 * ui.spacing().interact_size.y);
        // The room as the least height too: the popup's first frame measures it at most 400
        // points tall, every later frame offers no more than that, and a body scrolling in
        // 400 points would scroll in a window with room for all of it.
        let mut body = egui::ScrollArea::vertical().max_height(room).min_scrolled_height(room);
        // A menu opens at its top, not where it was scrolled to the last time it was open: the
        // scroll offset is kept under the same id from one opening to the next.
        let pass = ui.ctx().cumulative_pass_nr();
        let seen = ui.scope_id().with("menu shown in pass");
        let last: Option<u64> = ui.data(|d| d.get_temp(seen));
        ui.data_mut(|d| d.insert_temp(seen, pass));
        if last.is_none_or(|l| l + 1 != pass) {
            body = body.vertical_scroll_offset(0.0);
        }
        body.show(ui, |ui| {
            // The bar takes its width from the items: without this their labels wrap ("SIMT
            // efficiency (32 / lanes)") where the menu could grow by the bar's width instead.
            ui.style_mut().wrap_mode = Some(egui::TextWrapMode::Extend);
            content(ui)
        });
    });
}

pub fn show(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    egui::MenuBar::new().ui(ui, |ui| {
        menu(ui, "File", |ui| file_menu(app, ui, out));
        menu(ui, "View", |ui| view_menu(app, ui, out));
        menu(ui, "Lesson", |ui| lesson_menu(app, ui, out));
        menu(ui, "Help", |ui| {
            let shortcut = shortcut_text(ui.ctx(), &Action::Help);
            if ui.add(egui::Button::new("Keyboard and mouse").shortcut_text(shortcut)).clicked() {
                out.push(Action::SetHelp(true));
            }
        });
        ui.separator();
        ui.label(egui::RichText::new(app.scene.title()).strong());
    });
}

/// The File menu: open (a mesh, a lesson, a BVH, a grade report), export, save, quit.
fn file_menu(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    item(ui, out, "Open…", Action::Open);
    item(ui, out, "Open path…", Action::OpenPath);
    menu(ui, "Open recent", |ui| {
        if app.settings.recent_files.is_empty() {
            ui.weak("No recent files");
        }
        for path in app.settings.recent_files.clone() {
            if ui.button(path.display().to_string()).clicked() {
                out.push(Action::OpenFile(path));
            }
        }
    });
    if ui.button("Built-in scene").clicked() {
        out.push(Action::ShowBuiltin);
    }
    ui.separator();
    if ui
        .button("Open lesson…")
        .on_hover_text("A teacher's steps (a lesson file): PageDown or Right for the next")
        .clicked()
    {
        out.push(Action::OpenLesson);
    }
    if ui
        .button("Open BVH…")
        .on_hover_text("A BVH written by your own renderer (bvhscope-bvh: JSON, .json.gz or the text form; see the README) for this mesh: checked, then shown as \"imported\" in the strategy list")
        .clicked()
    {
        out.push(Action::OpenBvh);
    }
    if ui.button("Open BVH path…").on_hover_text("Type the dump's path").clicked() {
        out.push(Action::OpenBvhPath);
    }
    if ui
        .button("Open grade report…")
        .on_hover_text("A class's report from bvhscope grade (its grade.json): the students listed; choosing one shows their BVH against SAH binned")
        .clicked()
    {
        out.push(Action::OpenGradeReport);
    }
    if ui.button("Open grade report path…").on_hover_text("Type the path of grade.json or its folder").clicked() {
        out.push(Action::OpenGradeReportPath);
    }
    if ui
        .button("Export BVH…")
        .on_hover_text("The current tree in the bvhscope-bvh format (JSON; the text form when the name ends in .txt), as bvhscope export-bvh writes it")
        .clicked()
    {
        out.push(Action::ExportBvh);
    }
    ui.separator();
    item(ui, out, "Save view as PNG…", Action::SavePng);
    item(ui, out, "Export statistics as CSV…", Action::ExportStats);
    if ui.button("Export statistics as JSON…").clicked() {
        out.push(Action::ExportStatsJson);
    }
    let counts = if app.compare.on {
        ui.button("Export the pair's counts as CSV…").on_hover_text(
            "One row per pixel: x, y, A's value, B's value, B - A of the heatmap's metric (render --against … --difference)",
        )
    } else {
        ui.button("Export counts as CSV…").on_hover_text(
            "One row per pixel: x, y, nodes visited, box tests, leaves, triangle tests, hit triangle (-1: miss); the numbers the heatmaps colour",
        )
    };
    if counts.clicked() {
        out.push(Action::ExportCounts);
    }
    if ui
        .button("Save scene as…")
        .on_hover_text("The camera, the meshes and the BVH settings, as a scene file")
        .clicked()
    {
        out.push(Action::SaveScene);
    }
    if ui.button("Save to a typed path…").clicked() {
        out.push(Action::SavePngTyped);
    }
    ui.separator();
    if ui.button("Quit").clicked() {
        ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
    }
}

/// The View menu: the views, the camera, the explain windows, presenting and the layout.
fn view_menu(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    for (i, v) in View::ALL.iter().enumerate() {
        let shortcut = shortcut_text(ui.ctx(), &Action::View(i));
        if ui.add(egui::Button::selectable(app.settings.view == *v, v.label()).shortcut_text(shortcut)).clicked() {
            out.push(Action::View(i));
        }
    }
    ui.separator();
    item(ui, out, "Frame the mesh", Action::FrameMesh);
    item(ui, out, "Reset camera", Action::ResetView);
    item(ui, out, "Node boxes", Action::ToggleBoxes);
    if ui.button("Trace a ray…").on_hover_text("The Ray window: click a pixel to pin its ray, or type a ray").clicked()
    {
        out.push(Action::ShowRayWindow);
    }
    if ui
        .button("Tree and node…")
        .on_hover_text("The Tree and Node windows: the hierarchy, and why a node was split where it was")
        .clicked()
    {
        out.push(Action::ShowTree(true));
    }
    if ui.button("Replay the build…").on_hover_text("The Replay window: the tree after each split, traced").clicked()
    {
        out.push(Action::ShowReplay(true));
    }
    if ui
        .add_enabled(app.import.tree.is_some(), egui::Button::new("Imported BVH…"))
        .on_hover_text("The checker's findings of the imported BVH")
        .on_disabled_hover_text("No BVH is imported: File › Open BVH…")
        .clicked()
    {
        out.push(Action::ShowImported(true));
    }
    if ui
        .add_enabled(app.grade.report.is_some(), egui::Button::new("Grade report…"))
        .on_hover_text("The class of the grade report opened")
        .on_disabled_hover_text("No grade report is open: File › Open grade report…")
        .clicked()
    {
        out.push(Action::ShowGrade(true));
    }
    if ui
        .button("Compare side by side…")
        .on_hover_text("B, another strategy's build, next to A on the same camera and scale")
        .clicked()
    {
        out.push(Action::Compare(true));
    }
    ui.separator();
    let mut present = app.settings.present;
    let f5 = shortcut_text(ui.ctx(), &Action::TogglePresent);
    if ui
        .checkbox(&mut present, format!("Present ({f5})"))
        .on_hover_text("For a room: everything at 150 % or more (text of 18 px and up), the Node view's plots half its tile tall, every figure written out")
        .changed()
    {
        out.push(Action::Present(present));
    }
    ui.horizontal(|ui| {
        ui.label(format!("Size {:.0} %", 100.0 * app.settings.zoom()));
        if ui.small_button("−").on_hover_text(shortcut_text(ui.ctx(), &Action::UiScaleBy(-1))).clicked() {
            out.push(Action::UiScaleBy(-1));
        }
        if ui.small_button("+").on_hover_text(shortcut_text(ui.ctx(), &Action::UiScaleBy(1))).clicked() {
            out.push(Action::UiScaleBy(1));
        }
        if ui.small_button("100 %").clicked() {
            out.push(Action::UiScale(1.0));
        }
    });
    if ui
        .button("Reset the layout")
        .on_hover_text("The image, the panels and the views where a fresh start puts them")
        .clicked()
    {
        out.push(Action::ResetLayout);
    }
}

/// The Lesson menu: open, step, record (each step only what changed), save, close.
fn lesson_menu(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let open = app.lesson.is_some();
    let steps = app.lesson.as_ref().map_or(0, |l| l.len());
    if ui.button("New lesson").on_hover_text("No steps yet: set up a view, then add it as a step").clicked() {
        out.push(Action::NewLesson);
    }
    if ui.button("Open lesson…").clicked() {
        out.push(Action::OpenLesson);
    }
    if ui.button("Open lesson path…").on_hover_text("Type the lesson file's path").clicked() {
        out.push(Action::OpenLessonPath);
    }
    ui.separator();
    let add = ui.add_enabled(open, egui::Button::new("Add this view as a step"));
    if add.on_hover_text("What the app shows now, after the step on screen (only what changed is kept)").clicked() {
        out.push(Action::AddStep);
    }
    let replace = ui.add_enabled(steps > 0, egui::Button::new("Replace this step"));
    if replace.on_hover_text("The step on screen shows what the app shows now (its text kept)").clicked() {
        out.push(Action::ReplaceStep);
    }
    if let Some(l) = &app.lesson {
        let mut editing = l.editing;
        if ui.checkbox(&mut editing, "Edit the text").changed() {
            out.push(Action::LessonEditing(editing));
        }
    }
    ui.separator();
    if ui.add_enabled(steps > 0, egui::Button::new("Previous step").shortcut_text("PageUp")).clicked() {
        out.push(Action::LessonPrevious);
    }
    if ui.add_enabled(steps > 0, egui::Button::new("Next step").shortcut_text("PageDown")).clicked() {
        out.push(Action::LessonNext);
    }
    ui.separator();
    if ui.add_enabled(steps > 0, egui::Button::new("Save lesson…")).clicked() {
        out.push(Action::SaveLesson);
    }
    if ui.add_enabled(open, egui::Button::new("Close lesson")).clicked() {
        out.push(Action::CloseLesson);
    }
}
