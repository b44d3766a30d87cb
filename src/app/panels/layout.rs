//! Laying out a panel's contents: a fixed width that scrolls, the statistics' grid columns.

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
