//! Floating windows: Help (shortcuts), and the path field used when no file dialog is available.

use crate::app::jobs::Pick;
use crate::app::state::shortcuts::{shortcut_text, LESSON_HELP, MOUSE, SHORTCUTS};
use crate::app::state::{Action, Actions, BvhscopeApp};
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
            for (keys, what) in LESSON_HELP {
                ui.monospace(*keys);
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
    // A short title (the window is as wide as its path field: a long title was cut off), and what
    // the file must be on a line of its own.
    let (title, what) = match window.pick {
        Pick::Open => ("Open a mesh", "A mesh (.obj) or a scene (.json)"),
        Pick::SavePng => ("Save the view", "As a PNG image (.png)"),
        Pick::SaveStatsCsv => ("Export statistics", "As CSV (.csv)"),
        Pick::SaveStatsJson => ("Export statistics", "As JSON (.json)"),
        Pick::SaveScene => ("Save the scene", "As a bvhscope scene file (.json)"),
        Pick::SaveCounts => ("Export counts", "Per pixel, as CSV (.csv)"),
        Pick::OpenBvh => ("Import a BVH", "A bvhscope-bvh dump for this mesh (.json, .json.gz or .txt)"),
        Pick::SaveBvh => ("Export the BVH", "As a bvhscope-bvh dump (.json, .json.gz or .txt)"),
        Pick::SaveAnimation => ("Export the replay", "As an animation (.gif or .png)"),
        Pick::OpenGradeReport => ("Open a grade report", "Its grade.json, or its folder"),
        Pick::OpenLesson => ("Open a lesson", "A lesson file (.json): a teacher's steps"),
        Pick::SaveLesson => ("Save the lesson", "As a lesson file (.json)"),
    };
    let mut keep = true;
    let mut chosen = None;
    egui::Window::new(title).collapsible(false).resizable(false).show(ctx, |ui| {
        if let Some(note) = &window.note {
            ui.label(note);
        }
        ui.label(what);
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
                Pick::Open | Pick::OpenGradeReport | Pick::OpenLesson => "Open",
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
