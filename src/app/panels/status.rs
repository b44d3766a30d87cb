//! The status line: the newest message (errors until dismissed, notes for a few seconds) on the
//! left, then the resolution reached, rays per second, the last full frame and running jobs.
//! Messages live here, not over the image: over it they hid the image and Compare's A/B labels
//! until dismissed. The line is one row tall whatever it says, so a message coming or going never
//! changes the image's size (which would render it again).

use crate::app::state::{Action, Actions, BvhscopeApp, MessageKind};
use egui::Color32;

pub fn show(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
        for job in
            [&app.jobs.render, &app.jobs.build, &app.jobs.load, &app.jobs.import, &app.jobs.film, &app.jobs.grade]
                .into_iter()
                .flatten()
        {
            let fraction = job.control.fraction();
            if job.control.total() > 0 {
                ui.add(egui::ProgressBar::new(fraction).desired_width(120.0).show_percentage());
            } else {
                ui.spinner();
            }
            ui.label(&job.label);
            ui.separator();
        }
        match app.last_full_frame {
            Some(t) => ui.label(format!("last full frame {:.0} ms", t.as_secs_f64() * 1e3)),
            None => ui.label("no full frame yet"),
        };
        ui.separator();
        match &app.shown {
            Some(s) => {
                ui.label(format!("{:.1} MRays/s", s.rays_per_s / 1e6));
                ui.separator();
                let f = &s.frame;
                let (cols, rows) = f.grid_size();
                if f.stride() <= 1 {
                    ui.label(format!("full resolution {cols}×{rows}"));
                } else {
                    ui.label(format!("1/{} resolution ({cols}×{rows} traced)", f.stride()));
                }
            }
            None => {
                ui.label("no image yet");
            }
        }
        ui.with_layout(egui::Layout::left_to_right(egui::Align::Center), |ui| messages(app, ui, out));
    });
}

/// The newest message on one line (its whole text on hover; a click on it dismisses it), and the
/// earlier ones behind a button listing them.
fn messages(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let Some(newest) = app.messages.last() else { return };
    let earlier = app.messages.len() - 1;
    if earlier > 0 {
        ui.menu_button(format!("{earlier} earlier"), |ui| {
            ui.set_max_width(520.0);
            for (i, m) in app.messages.iter().enumerate().take(earlier).rev() {
                ui.horizontal_top(|ui| {
                    if ui.small_button("Dismiss").clicked() {
                        out.push(Action::Dismiss(i));
                    }
                    ui.add(egui::Label::new(egui::RichText::new(titled(m.kind, &m.text)).color(colour(m.kind))).wrap());
                });
            }
            ui.separator();
            if ui.button("Dismiss them").clicked() {
                out.push(Action::DismissEarlier(earlier));
                ui.close();
            }
        });
    }
    let i = app.messages.len() - 1;
    if ui.small_button("Dismiss").on_hover_text("Dismiss this message").clicked() {
        out.push(Action::Dismiss(i));
    }
    let text = egui::RichText::new(titled(newest.kind, &newest.text)).color(colour(newest.kind)).strong();
    let label = ui.add(egui::Label::new(text).truncate().sense(egui::Sense::click()));
    if label.on_hover_text(&newest.text).clicked() {
        out.push(Action::Dismiss(i));
    }
}

fn titled(kind: MessageKind, text: &str) -> String {
    let title = match kind {
        MessageKind::Error => "Error",
        MessageKind::Warning => "Warning",
        MessageKind::Info => "Note",
    };
    format!("{title}: {text}")
}

/// Readable on the status bar's dark and light backgrounds alike.
fn colour(kind: MessageKind) -> Color32 {
    match kind {
        MessageKind::Error => Color32::from_rgb(255, 110, 100),
        MessageKind::Warning => Color32::from_rgb(240, 190, 60),
        MessageKind::Info => Color32::from_rgb(120, 180, 255),
    }
}
