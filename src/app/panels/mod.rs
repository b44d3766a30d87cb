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
    // The side panels keep the width they have (the user's, remembered by egui's memory):
    // their contents wrap, scroll or clip inside it and never widen them, so the viewport,
    // and with it the camera's aspect, stays as it is when the figures change.
    egui::Panel::left("controls").resizable(true).default_size(290.0).size_range(200.0..=640.0).show(ui, |ui| {
        fixed_width(ui, |ui| {
            build::show(app, ui, out);
            ui.separator();
            view::show(app, ui, out);
        })
    });
    egui::Panel::right("statistics")
        .resizable(true)
        .default_size(340.0)
        .size_range(220.0..=720.0)
        .show(ui, |ui| fixed_width(ui, |ui| stats::show(app, ui, out)));
    egui::CentralPanel::default()
        .frame(egui::Frame::NONE.fill(egui::Color32::from_gray(12)))
        .show(ui, |ui| super::viewport::show(app, ui, out));
    windows::show(app, &ctx, out);
    ray::show(app, &ctx, out);
    tree::show(app, &ctx, out);
    node::show(app, &ctx, out);
    replay::show(app, &ctx, out);
    compare::show(app, &ctx, out);
    imported::show(app, &ctx, out);
    grade::show(app, &ctx, out);
}
