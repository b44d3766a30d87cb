//! The panels around the viewport, the viewport itself (with its overlays), the windows and the
//! docked tiles that hold them; each reads the app's state and emits actions, nothing more.

pub mod build;
pub mod compare;
mod explain_overlay;
pub mod grade;
pub mod imported;
mod layout;
mod legend;
pub mod lesson;
pub mod menu;
pub mod node;
pub mod ray;
pub mod replay;
pub mod stats;
pub mod status;
pub mod tiles;
pub mod tree;
pub mod view;
mod viewport;
pub mod windows;

use crate::app::state::{Actions, BvhscopeApp};

/// Every panel and window of a frame, laid out; what they ask for goes to `out`.
pub fn show_all(app: &mut BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let ctx = ui.ctx().clone();
    egui::Panel::top("menu").show(ui, |ui| menu::show(app, ui, out));
    egui::Panel::bottom("status").show(ui, |ui| status::show(app, ui, out));
    // The lesson's band, above the status line: a strip of its own, never over the image.
    if let Some(l) = &app.lesson {
        let height = lesson::height(ui, l);
        let frame = egui::Frame::side_top_panel(ui.style()).inner_margin(lesson::FRAME_MARGIN);
        let band = egui::Panel::bottom("lesson").resizable(false).frame(frame).exact_size(height);
        band.show(ui, |ui| lesson::show(app, ui, out));
    }
    egui::CentralPanel::default().frame(egui::Frame::NONE).show(ui, |ui| tiles::show(app, ui, out));
    windows::show(app, &ctx, out);
}
