//! The panels around the viewport; each reads and changes the app state, nothing more.

pub mod build;
pub mod compare;
pub mod grade;
pub mod imported;
pub mod menu;
pub mod node;
pub mod ray;
pub mod replay;
pub mod stats;
pub mod status;
pub mod tiles;
pub mod tree;
pub mod view;
pub mod windows;

/// Lay out a side panel's contents in the width the panel has now. A panel grows to fit what it
/// holds and egui remembers the larger width, so a wider figure (a "before" column, a long label)
/// used to narrow the viewport for good and change the camera's aspect. Here the contents scroll
/// vertically and wrap (or, past the edge, are clipped), and the panel reports exactly its own
/// width; only the user's drag of its edge resizes it.
pub fn fixed_width(ui: &mut egui::Ui, add_contents: impl FnOnce(&mut egui::Ui)) {
    let rect = ui.available_rect_before_wrap();
    let mut inner = ui.new_child(egui::UiBuilder::new().max_rect(rect).layout(*ui.layout()));
    inner.shrink_clip_rect(rect);
    egui::ScrollArea::vertical().auto_shrink([false, false]).show(&mut inner, |ui| {
        ui.set_max_width(rect.width());
        add_contents(ui)
    });
    ui.advance_cursor_after_rect(rect);
}

/// The widest a grid column of the statistics may be before its text wraps: `columns` share the
/// width (less the spacing between them).
pub fn grid_column_width(ui: &egui::Ui, columns: usize) -> f32 {
    let spacing = ui.spacing().item_spacing.x * columns.saturating_sub(1) as f32;
    ((ui.available_width() - spacing) / columns.max(1) as f32).max(40.0)
}

/// Every panel and window of a frame, laid out; what they ask for goes to `out`.
pub fn show_all(app: &mut super::BvhscopeApp, ui: &mut egui::Ui, out: &mut super::Actions) {
    let ctx = ui.ctx().clone();
    egui::Panel::top("menu").show(ui, |ui| menu::show(app, ui, out));
    egui::Panel::bottom("status").show(ui, |ui| status::show(app, ui));
    egui::CentralPanel::default().frame(egui::Frame::NONE).show(ui, |ui| tiles::show(app, ui, out));
    windows::show(app, &ctx, out);
}
