//! The heatmap legend as a part of the image tile: beside the image where the tile is wide,
//! below it where it is not (as the exported PNGs have it), never over it — floating over the
//! image it hid half of it when presenting. Title, colour bar with its ends, the per-pixel
//! histogram with the hottest-pixel buttons, and the frame's min / mean / max; folded, only the
//! colour bar and its ends. Real labels, so screen readers and UI tests read the numbers.

use crate::app::state::{Action, Actions, BvhscopeApp};
use crate::render::legend::fmt_value;
use crate::render::Legend;
use egui::{Color32, Pos2, Rect, Sense, Stroke, UiBuilder, Vec2};

/// The legend's width beside the image (points).
const SIDE_WIDTH: f32 = 240.0;
/// Its height below the image: at most this, and at most `BELOW_SHARE` of the tile.
const BELOW_HEIGHT: f32 = 112.0;
const BELOW_SHARE: f32 = 0.35;
/// Folded: the strip holding the colour bar, beside (its width) or below (its height).
const FOLDED_SIDE: f32 = 52.0;
const FOLDED_BELOW: f32 = 24.0;

/// Where the legend is in the image tile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    Beside,
    Below,
}

/// The image tile `tile` split into the image's part and the legend's: beside or below the
/// image, whichever leaves the larger image (of `aspect`, a scene's film letterboxed, or the
/// whole part when `None`). Folded, the legend keeps the place it has unfolded (it does not jump
/// from below to beside).
pub fn split(tile: Rect, folded: bool, aspect: Option<f32>) -> (Rect, Rect, Place) {
    let below_height = |folded: bool| if folded { FOLDED_BELOW } else { BELOW_HEIGHT.min(tile.height() * BELOW_SHARE) };
    let shown = |w: f32, h: f32| match aspect {
        Some(a) => (w.min(h * a)) * (w.min(h * a) / a),
        None => w * h,
    };
    let beside =
        shown(tile.width() - SIDE_WIDTH, tile.height()) > shown(tile.width(), tile.height() - below_height(false));
    if beside {
        let x = tile.max.x - if folded { FOLDED_SIDE } else { SIDE_WIDTH };
        (
            Rect::from_min_max(tile.min, Pos2::new(x, tile.max.y)),
            Rect::from_min_max(Pos2::new(x, tile.min.y), tile.max),
            Place::Beside,
        )
    } else {
        let y = tile.max.y - below_height(folded);
        (
            Rect::from_min_max(tile.min, Pos2::new(tile.max.x, y)),
            Rect::from_min_max(Pos2::new(tile.min.x, y), tile.max),
            Place::Below,
        )
    }
}

/// The legend in `rect` (from `split`); `histogram`: the image's own values (not a pair's).
pub fn show(
    app: &BvhscopeApp,
    ui: &mut egui::Ui,
    rect: Rect,
    place: Place,
    legend: &Legend,
    histogram: bool,
    out: &mut Actions,
) {
    ui.painter().rect_filled(rect, 0.0, ui.visuals().panel_fill);
    let inner = rect.shrink2(Vec2::new(6.0, 4.0));
    let mut child = ui.new_child(UiBuilder::new().id_salt("heatmap-legend").max_rect(inner));
    child.set_clip_rect(rect);
    let ui = &mut child;
    match (app.settings.legend_folded, place) {
        (true, Place::Beside) => folded_beside(ui, inner, legend, out),
        (true, Place::Below) => folded_below(ui, legend, out),
        (false, Place::Beside) => {
            egui::ScrollArea::vertical().id_salt("legend-beside").auto_shrink([false, false]).show(ui, |ui| {
                header(ui, legend, out);
                bar(ui, legend, ui.available_width());
                if histogram {
                    histogram_area(app, ui, legend, out);
                }
                summary(ui, legend);
            });
        }
        (false, Place::Below) => {
            egui::ScrollArea::vertical().id_salt("legend-below").auto_shrink([false, false]).show(ui, |ui| {
                // Two columns when there is a histogram to show beside the bar; else one.
                let columns = if histogram { 2 } else { 1 };
                ui.columns(columns, |cols| {
                    header(&mut cols[0], legend, out);
                    let w = cols[0].available_width();
                    bar(&mut cols[0], legend, w);
                    summary(&mut cols[0], legend);
                    if histogram {
                        histogram_area(app, &mut cols[1], legend, out);
                    }
                });
            });
        }
    }
}

/// The frame's min, mean and max on one line.
fn summary(ui: &mut egui::Ui, legend: &Legend) {
    let text = format!(
        "min {}   mean {:.2}   max {}",
        fmt_value(legend.min as f64),
        legend.mean,
        fmt_value(legend.max as f64)
    );
    ui.label(text).on_hover_text("Over all traced rays (the range above may be fixed)");
}

/// The title with the fold button, and the note.
fn header(ui: &mut egui::Ui, legend: &Legend, out: &mut Actions) {
    ui.horizontal_top(|ui| {
        if ui.small_button("Fold").on_hover_text("Fold the legend to its colour bar").clicked() {
            out.push(Action::FoldLegend(true));
        }
        ui.add(egui::Label::new(egui::RichText::new(format!("Legend: {}", legend.title)).strong()).wrap());
    });
    if !legend.note.is_empty() {
        ui.add(egui::Label::new(egui::RichText::new(&legend.note).weak()).wrap());
    }
}

/// The colour bar between its range's ends, `width` wide in all.
fn bar(ui: &mut egui::Ui, legend: &Legend, width: f32) {
    ui.horizontal(|ui| {
        let lo = ui.label(fmt_value(legend.range_min as f64));
        let hi_text = fmt_value(legend.range_max as f64);
        let hi_w = ui.fonts_mut(|f| {
            f.layout_no_wrap(hi_text.clone(), egui::TextStyle::Body.resolve(ui.style()), Color32::WHITE).size().x
        });
        let spacing = ui.spacing().item_spacing.x;
        let w = (width - lo.rect.width() - hi_w - 2.0 * spacing).max(20.0);
        let (r, _) = ui.allocate_exact_size(Vec2::new(w, 14.0), Sense::hover());
        paint_bar(ui.painter(), r, legend, false);
        ui.label(hi_text);
    });
}

/// The colour map across `r`: left to right, or bottom to top (`upright`).
fn paint_bar(painter: &egui::Painter, r: Rect, legend: &Legend, upright: bool) {
    let steps = 110;
    for i in 0..steps {
        let t = i as f32 / (steps - 1) as f32;
        let [red, g, b] = legend.colormap.map(t);
        let (a, z) = (i as f32 / steps as f32, (i + 1) as f32 / steps as f32);
        let cell = if upright {
            Rect::from_x_y_ranges(r.x_range(), r.max.y - r.height() * z - 0.5..=r.max.y - r.height() * a)
        } else {
            Rect::from_x_y_ranges(r.min.x + r.width() * a..=r.min.x + r.width() * z + 0.5, r.y_range())
        };
        painter.rect_filled(cell, 0.0, Color32::from_rgb(red, g, b));
    }
    painter.rect_stroke(r, 0.0, Stroke::new(1.0, Color32::GRAY), egui::StrokeKind::Outside);
}

/// Folded beside the image: the unfold button, the range's top, an upright bar, its bottom.
fn folded_beside(ui: &mut egui::Ui, inner: Rect, legend: &Legend, out: &mut Actions) {
    ui.vertical_centered(|ui| {
        let show = egui::Button::new("Show").small().wrap_mode(egui::TextWrapMode::Extend);
        if ui.add(show).on_hover_text("Show the legend: title, histogram, hottest pixel, min / mean / max").clicked() {
            out.push(Action::FoldLegend(false));
        }
        ui.small(fmt_value(legend.range_max as f64));
        let h = (inner.max.y - ui.cursor().min.y - 22.0).max(20.0);
        let (r, response) = ui.allocate_exact_size(Vec2::new(14.0, h), Sense::hover());
        paint_bar(ui.painter(), r, legend, true);
        response.on_hover_text(format!("Legend: {}", legend.title));
        ui.small(fmt_value(legend.range_min as f64));
    });
}

/// Folded below the image: the unfold button and the bar between its ends, on one line.
fn folded_below(ui: &mut egui::Ui, legend: &Legend, out: &mut Actions) {
    ui.horizontal(|ui| {
        if ui
            .small_button("Show the legend")
            .on_hover_text("Show the legend: title, histogram, hottest pixel, min / mean / max")
            .clicked()
        {
            out.push(Action::FoldLegend(false));
        }
        ui.label(&legend.title);
        let w = ui.available_width();
        bar(ui, legend, w);
    });
}

/// The histogram under the bar, with its hint and the hottest-pixel buttons.
fn histogram_area(app: &BvhscopeApp, ui: &mut egui::Ui, legend: &Legend, out: &mut Actions) {
    histogram_bars(app, ui, legend, out);
    ui.horizontal_wrapped(|ui| {
        let hint = "Pixels per value (square root scale), the same bins as `bvhscope render --histogram 32`. Click or drag to highlight the pixels above a value; double-click to clear.";
        match app.threshold {
            Some(t) => ui.weak(format!("above {}: highlighted", fmt_value(t as f64))),
            None => ui.weak("click: highlight above"),
        }
        .on_hover_text(hint);
        if ui
            .small_button("Hottest pixel")
            .on_hover_text("Pin the ray with the most work in this heatmap in the Ray window (bvhscope trace --hottest 1)")
            .clicked()
        {
            out.push(Action::Hottest { next: false });
        }
        let next = ui.add_enabled(app.hottest.is_some(), egui::Button::new("Next").small());
        if next.on_hover_text("The pixel with the next most work (bvhscope trace --hottest K)").clicked() {
            out.push(Action::Hottest { next: true });
        }
    });
}

/// The distribution of the heatmap's per-pixel values on its range, across the available width;
/// a click or drag sets a threshold above which the image's pixels are highlighted (the rest
/// dimmed).
fn histogram_bars(app: &BvhscopeApp, ui: &mut egui::Ui, legend: &Legend, out: &mut Actions) {
    let Some(counts) = app.legend_histogram() else { return };
    let (bars, response) = ui.allocate_exact_size(Vec2::new(ui.available_width(), 40.0), Sense::click_and_drag());
    let painter = ui.painter_at(bars);
    let top = counts.iter().copied().max().unwrap_or(1).max(1) as f32;
    let w = bars.width() / counts.len() as f32;
    for (i, &c) in counts.iter().enumerate() {
        // A square root keeps the rare high values visible beside the crowd at the low end.
        let h = bars.height() * (c as f32 / top).sqrt();
        let x0 = bars.min.x + w * i as f32;
        let [r, g, b] = legend.colormap.map((i as f32 + 0.5) / counts.len() as f32);
        painter.rect_filled(
            Rect::from_min_max(Pos2::new(x0, bars.max.y - h), Pos2::new(x0 + w - 0.5, bars.max.y)),
            0.0,
            Color32::from_rgb(r, g, b),
        );
    }
    let span = legend.range_max - legend.range_min;
    if let Some(t) = app.threshold {
        let px = bars.min.x + bars.width() * ((t - legend.range_min) / span.max(1e-20)).clamp(0.0, 1.0);
        painter.line_segment([Pos2::new(px, bars.min.y), Pos2::new(px, bars.max.y)], Stroke::new(2.0, Color32::WHITE));
    }
    if let Some(pos) = response.interact_pointer_pos().filter(|_| response.clicked() || response.dragged()) {
        let t = legend.range_min + span * ((pos.x - bars.min.x) / bars.width()).clamp(0.0, 1.0);
        out.push(Action::SetThreshold(Some(t)));
    }
    if response.double_clicked() || response.secondary_clicked() {
        out.push(Action::SetThreshold(None));
    }
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "Histogram of the heatmap"));
}
