//! Floating windows: Help (shortcuts), and the path field used when no file dialog is available.

use crate::app::shortcuts::{shortcut_text, MOUSE, SHORTCUTS};
use crate::app::{Action, Actions, BvhscopeApp, Pick};
use std::path::PathBuf;

pub fn show(app: &BvhscopeApp, ctx: &egui::Context, out: &mut Actions) {
    let mut open = app.show_help;
    egui::Window::new("Help").open(&mut open).resizable(false).show(ctx, |ui| {
        ui.heading("Keyboard");
        egui::Grid::new("keys").num_columns(2).striped(true).show(ui, |ui| {
            for (shortcut, _, what) in SHORTCUTS {
                ui.monospace(shortcut_text(ctx, shortcut));
                ui.label(*what);
                ui.end_row();
            }
        });
        ui.heading("Mouse");
        egui::Grid::new("mouse").num_columns(2).striped(true).show(ui, |ui| {
            for (input, what) in MOUSE {
                ui.monospace(*input);
                ui.label(*what);
                ui.end_row();
            }
        });
    });
    if open != app.show_help {
        out.push(Action::SetHelp(open));
    }

    let Some(window) = &app.path_window else { return };
    let mut text = window.text.clone();
    let title = match window.pick {
        Pick::Open => "Open a mesh",
        Pick::SavePng => "Save the view as PNG",
        Pick::SaveStatsCsv => "Export statistics (CSV)",
        Pick::SaveStatsJson => "Export statistics (JSON)",
        Pick::SaveScene => "Save the scene",
        Pick::SaveCounts => "Export counts (CSV)",
        Pick::OpenBvh => "Import a BVH dump for this mesh",
        Pick::SaveBvh => "Export the BVH as a dump",
        Pick::SaveAnimation => "Export the replay as an animation (.gif or .png)",
        Pick::OpenGradeReport => "Open a grade report (its grade.json or its folder)",
    };
    let mut keep = true;
    let mut chosen = None;
    egui::Window::new(title).collapsible(false).resizable(false).show(ctx, |ui| {
        if let Some(note) = &window.note {
            ui.label(note);
        }
        let label = ui.label("Path");
        let edit = ui.add(egui::TextEdit::singleline(&mut text).desired_width(420.0)).labelled_by(label.id);
        // The field takes the keyboard when the window opens: what is typed goes into it, and
        // while it has focus no single-key shortcut fires (`shortcuts::pressed`).
        if window.focus {
            edit.request_focus();
            out.push(Action::PathFocused);
        }
        let enter = edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
        if (edit.has_focus() || edit.lost_focus()) && ui.input(|i| i.key_pressed(egui::Key::Escape)) {
            keep = false;
        }
        ui.horizontal(|ui| {
            let verb = match window.pick {
                Pick::Open | Pick::OpenGradeReport => "Open",
                Pick::OpenBvh => "Import",
                _ => "Save",
            };
            if (ui.button(verb).clicked() || enter) && !text.trim().is_empty() {
                chosen = Some((window.pick, PathBuf::from(text.trim())));
            }
            if ui.button("Cancel").clicked() {
                keep = false;
            }
        });
    });
    if let Some((pick, path)) = chosen {
        out.push(Action::Picked(pick, path));
    } else if !keep {
        out.push(Action::ClosePathWindow);
    } else if text != window.text {
        out.push(Action::PathText(text));
    }
}
