//! The central view: the ray-cast image, mouse camera control, the node-box overlay, the heatmap
//! legend beside or below the image (`legend.rs`) and the per-pixel read-out on hover. Nothing
//! but what the image shows draws over it: messages are in the status bar. It reports its size
//! and the mouse's camera moves as actions; the app's reconciler renders what it would show.

use super::{explain_overlay, legend};
use crate::app::state::{overlay, Action, Actions, BvhscopeApp, Shown};
use crate::app::views::compare::CompareImages;
use crate::render::{Frame, PairView};
use egui::{Color32, PointerButton, Pos2, Rect, Sense, Stroke, Vec2};
use std::sync::Arc;

/// Largest image the viewport renders (pixels), so huge windows stay interactive.
const MAX_PIXELS: f32 = 2560.0 * 1440.0;

/// Where the image goes in the viewport `full` and the size it is rendered at: the whole viewport
/// at its pixel size, or, for a scene's film, the largest rectangle of the film's aspect centred
/// in it (letterboxed) at the film's size.
fn image_area(app: &BvhscopeApp, full: Rect, ppp: f32) -> (Rect, (u32, u32)) {
    let (rect, mut size) = match app.film() {
        Some((w, h)) => {
            let aspect = w as f32 / h as f32;
            let fit = if full.width() / full.height().max(1.0) > aspect {
                Vec2::new(full.height() * aspect, full.height())
            } else {
                Vec2::new(full.width(), full.width() / aspect)
            };
            (Rect::from_center_size(full.center(), fit), Vec2::new(w as f32, h as f32))
        }
        None => (full, full.size() * ppp),
    };
    let area = size.x * size.y;
    if area > MAX_PIXELS {
        size *= (MAX_PIXELS / area).sqrt();
    }
    (rect, (size.x.round().max(1.0) as u32, size.y.round().max(1.0) as u32))
}

pub fn show(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let tile = ui.available_rect_before_wrap();
    // A heatmap's legend takes its part of the tile (chosen by the view, not by the frame on
    // screen, so the image's size does not change when the frame arrives).
    let (full, legend_at) = if app.settings.view.is_heatmap() {
        let aspect = app.film().map(|(w, h)| w as f32 / h as f32);
        let (image, legend, place) = legend::split(tile, app.settings.legend_folded, aspect);
        (image, Some((legend, place)))
    } else {
        (tile, None)
    };
    let response = ui.allocate_rect(full, Sense::click_and_drag());
    // The image's rectangle: the viewport, or the film letterboxed in it.
    let (rect, pixels) = image_area(app, full, ui.ctx().pixels_per_point());
    pointer_input(app, ui, &response, rect, out);
    if full != app.viewport_rect || rect != app.image_rect || pixels != app.viewport_pixels() {
        out.push(Action::Viewport { rect: full, image: rect, pixels });
    }
    // Drawing over the image is clipped to it.
    let painter = ui.painter_at(rect);
    let around = ui.painter_at(full);
    draw_image(app, ui, &painter, &around, rect);

    // Side by side: A and B over the image, as halves, a wipe, or their difference.
    let compared = app.compare_images(ui.ctx());
    if let Some(c) = &compared {
        draw_compare(app, ui, &painter, rect, c, out);
    }
    draw_overlays(app, ui, &painter, rect, compared.is_none());
    // Files dragged over the window.
    if ui.ctx().input(|i| !i.raw.hovered_files.is_empty()) {
        around.rect_filled(full, 0.0, Color32::from_black_alpha(160));
        around.text(
            full.center(),
            egui::Align2::CENTER_CENTER,
            "Drop a mesh or scene to open it, or a BVH dump to import it",
            egui::FontId::proportional(22.0),
            Color32::WHITE,
        );
    }

    if let (Some(shown), Some((at, place))) = (&app.shown, legend_at) {
        let compare_legend = compared.as_ref().and_then(|c| match app.compare.mode {
            PairView::Difference => c.diff.as_ref().map(|d| d.2.clone()),
            _ => c.legend.clone(),
        });
        // The histogram is of the image's own values: not drawn for a side-by-side pair.
        if let Some(l) = compare_legend.as_ref() {
            legend::show(app, ui, at, place, l, false, out);
        } else if let Some(l) = shown.legend.as_ref() {
            legend::show(app, ui, at, place, l, true, out);
        }
    }
    if let Some(shown) = &app.shown {
        if let Some(pos) = response.hover_pos() {
            let frame = shown.frame.clone();
            response.on_hover_ui_at_pointer(|ui| pixel_readout(ui, &frame, rect, pos));
        }
    }
}

/// The pointer over the image: dragging orbits or pans, the wheel zooms, a click pins a ray or
/// selects a node.
fn pointer_input(app: &BvhscopeApp, ui: &egui::Ui, response: &egui::Response, rect: Rect, out: &mut Actions) {
    if response.dragged_by(PointerButton::Primary) {
        let d = response.drag_delta();
        out.push(Action::Orbit(d.x, d.y));
    } else if response.dragged_by(PointerButton::Secondary) || response.dragged_by(PointerButton::Middle) {
        let d = response.drag_delta();
        out.push(Action::Pan { dx: d.x, dy: d.y, height: rect.height() });
    }
    // A Ctrl-click (Cmd on a Mac), or a click while the Ray window is open (picking rays), pins
    // the ray of the pixel under it: a plain click elsewhere (dismissing a message, bringing the
    // window to the front) does nothing. A shift-click selects its hit's leaf.
    if response.clicked() {
        if let (Some(pos), Some(shown)) = (response.interact_pointer_pos(), &app.shown) {
            if let Some((x, y)) = pixel_at(&shown.frame, rect, pos) {
                if ui.input(|i| i.modifiers.shift) {
                    // A drawn box's edge under the pointer selects that box's node; elsewhere the
                    // pixel's leaf.
                    match drawn_box_node(app, rect, shown, pos) {
                        Some(n) => out.push(Action::SelectNode(n)),
                        None => out.push(Action::SelectPixelNode(x, y)),
                    }
                } else if ui.input(|i| i.modifiers.command) || app.ray_window || !app.pins.pinned.is_empty() {
                    out.push(Action::PinPixel(x, y));
                }
            }
        }
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            out.push(Action::Zoom(scroll));
        }
    }
}

/// The image, stretched to the viewport while a new size is on its way; the film's outline and
/// its size around it.
fn draw_image(app: &BvhscopeApp, ui: &mut egui::Ui, painter: &egui::Painter, around: &egui::Painter, rect: Rect) {
    if let Some((w, h)) = app.film() {
        around.rect_stroke(rect.expand(1.0), 0.0, Stroke::new(1.0, Color32::from_gray(110)), egui::StrokeKind::Outside);
        let text = egui::RichText::new(format!("film {w}×{h}")).small().color(Color32::from_gray(150));
        let at =
            Rect::from_min_max(rect.left_bottom() + Vec2::new(0.0, 2.0), rect.right_bottom() + Vec2::new(0.0, 18.0));
        ui.put(at, egui::Label::new(text))
            .on_hover_text("The scene's film: the image is its camera's size, letterboxed (View panel: Film)");
    }
    if let Some(shown) = &app.shown {
        // A coarse pass's image has a texel per traced pixel; its last row and column may cover
        // pixels past the frame's edge, which the uv range leaves out.
        let f = &shown.frame;
        let ((cols, rows), s) = (f.grid_size(), f.stride().max(1) as f32);
        let uv = Rect::from_min_max(
            Pos2::ZERO,
            Pos2::new(f.width() as f32 / (cols as f32 * s), f.height() as f32 / (rows as f32 * s)),
        );
        painter.image(shown.texture.id(), rect, uv, Color32::WHITE);
    } else {
        let busy = app.jobs.build.as_ref().map_or("Preparing…".to_string(), |b| format!("{}…", b.label));
        painter.text(rect.center(), egui::Align2::CENTER_CENTER, busy, egui::FontId::proportional(18.0), Color32::GRAY);
    }
}

/// Over the image: the threshold's dimming and the imported tree's wrong pixels (not over a
/// side-by-side pair), the node boxes, and the explain views' marks.
fn draw_overlays(app: &BvhscopeApp, ui: &egui::Ui, painter: &egui::Painter, rect: Rect, single: bool) {
    // The legend histogram's threshold: the pixels at or below it dimmed.
    if let Some(shown) = &app.shown {
        if let Some(mask) = app.threshold_mask(ui.ctx(), shown).filter(|_| single) {
            painter.image(mask.id(), rect, Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)), Color32::WHITE);
        }
    }
    // An imported tree's pixels whose hit differs from the linear scan's, in red.
    if let Some((mask, _)) = app.wrong_mask(ui.ctx()).filter(|_| single) {
        painter.image(mask.id(), rect, Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)), Color32::WHITE);
    }

    // Node boxes, in the camera of the image they are drawn over.
    if app.settings.show_boxes {
        if let (Some(boxes), Some(camera)) = (app.overlay_boxes(), app.shown.as_ref().map(|s| s.camera)) {
            let depth = app.settings.boxes_in_front.then(|| app.shown.as_ref().map(|s| s.frame.clone())).flatten();
            let mesh = app.overlay_mesh(boxes, camera, rect, depth);
            painter.add(egui::Shape::Mesh(mesh));
        }
    }

    if let Some(shown) = &app.shown {
        explain_overlay::draw_replay(app, painter, rect, shown);
        explain_overlay::draw_selected_node(app, painter, rect, shown);
        explain_overlay::draw_pinned(app, painter, rect, &shown.camera);
    }
}

/// A and B over the viewport: each the left or right part of its image, split at the middle or at
/// the wipe line (dragged), or the difference image; each side labelled with its build.
fn draw_compare(
    app: &BvhscopeApp,
    ui: &egui::Ui,
    painter: &egui::Painter,
    rect: Rect,
    c: &CompareImages,
    out: &mut Actions,
) {
    let label = |p: Pos2, align: egui::Align2, text: String| {
        let g = painter.layout_no_wrap(text, egui::FontId::proportional(14.0), Color32::WHITE);
        let r = align.anchor_size(p, g.size()).expand(4.0);
        painter.rect_filled(r, 3.0, Color32::from_black_alpha(170));
        painter.galley(r.min + Vec2::splat(4.0), g, Color32::WHITE);
    };
    let b_label = app.compare.b.as_ref().map_or(String::new(), |b| b.bvh.label());
    let a_label = app.shown.as_ref().map_or(String::new(), |s| s.build_label.clone());
    let full = Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
    match app.compare.mode {
        PairView::Difference => match &c.diff {
            Some((tex, _, _)) => {
                painter.image(tex.id(), rect, full, Color32::WHITE);
                label(
                    rect.left_top() + Vec2::new(8.0, 8.0),
                    egui::Align2::LEFT_TOP,
                    format!("B - A: {b_label} minus {a_label}"),
                );
            }
            None => label(
                rect.center_top() + Vec2::new(0.0, 8.0),
                egui::Align2::CENTER_TOP,
                "The difference is of heatmaps: choose a heatmap view".into(),
            ),
        },
        mode => {
            let split = if mode == PairView::Wipe { app.compare.wipe } else { 0.5 };
            let x = rect.left() + rect.width() * split;
            let (left, right) = (
                Rect::from_min_max(rect.min, Pos2::new(x, rect.max.y)),
                Rect::from_min_max(Pos2::new(x, rect.min.y), rect.max),
            );
            painter.image(c.a.id(), left, Rect::from_min_max(Pos2::ZERO, Pos2::new(split, 1.0)), Color32::WHITE);
            painter.image(
                c.b.id(),
                right,
                Rect::from_min_max(Pos2::new(split, 0.0), Pos2::new(1.0, 1.0)),
                Color32::WHITE,
            );
            painter.line_segment(
                [Pos2::new(x, rect.top()), Pos2::new(x, rect.bottom())],
                Stroke::new(2.0, Color32::WHITE),
            );
            label(rect.left_top() + Vec2::new(8.0, 8.0), egui::Align2::LEFT_TOP, format!("A: {a_label}"));
            label(rect.right_top() + Vec2::new(-8.0, 8.0), egui::Align2::RIGHT_TOP, format!("B: {b_label}"));
            if mode == PairView::Wipe {
                // The line's handle: drag it (over the image a drag orbits).
                let handle = Rect::from_center_size(Pos2::new(x, rect.center().y), Vec2::new(14.0, rect.height()));
                let r = ui.interact(handle, ui.scope_id().with("compare-wipe"), Sense::drag());
                r.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Splitter, true, "Wipe line"));
                if r.hovered() || r.dragged() {
                    ui.ctx().set_cursor_icon(egui::CursorIcon::ResizeHorizontal);
                }
                if let Some(p) = r.interact_pointer_pos().filter(|_| r.dragged()) {
                    out.push(Action::Wipe((p.x - rect.left()) / rect.width()));
                }
            }
        }
    }
}

/// The node of the binary tree whose drawn box has an edge under `pos` (the overlay's boxes are
/// the current layout's; a wide child's box is its binary node's, so it is found by its bounds).
fn drawn_box_node(app: &BvhscopeApp, rect: Rect, shown: &Shown, pos: Pos2) -> Option<u32> {
    if !app.settings.show_boxes {
        return None;
    }
    let e = app.nodes.current(Some(&shown.bvh))?;
    let boxes = app.overlay_boxes()?;
    let i = overlay::box_near(&boxes, &shown.camera, rect, pos, 5.0)?;
    let corners = boxes[i].corners;
    e.tree.nodes.iter().position(|n| n.bounds().corners() == corners).map(|n| n as u32)
}

/// The frame pixel under a screen position.
fn pixel_at(frame: &Frame, rect: Rect, pos: Pos2) -> Option<(u32, u32)> {
    let u = (pos.x - rect.min.x) / rect.width();
    let v = (pos.y - rect.min.y) / rect.height();
    if !(0.0..1.0).contains(&u) || !(0.0..1.0).contains(&v) {
        return None;
    }
    Some(((u * frame.width() as f32) as u32, (v * frame.height() as f32) as u32))
}

fn pixel_readout(ui: &mut egui::Ui, frame: &Arc<Frame>, rect: Rect, pos: Pos2) {
    let Some((x, y)) = pixel_at(frame, rect, pos) else { return };
    let s = frame.sample(x, y);
    egui::Grid::new("pixel-readout").num_columns(2).show(ui, |ui| {
        ui.label("Pixel");
        ui.label(format!("{x}, {y}"));
        ui.end_row();
        ui.label("Hit");
        if s.is_hit() {
            ui.label(format!("triangle {} at t = {:.4}", s.prim, s.t));
        } else {
            ui.label("nothing");
        }
        ui.end_row();
        if frame.counted() {
            // A frame of secondary rays: its counts are the sums over the pixel's rays (the
            // heatmap shows their mean), and the camera ray's own follow.
            let (kind, per_hit) = frame.ray_kind();
            let rays = if kind.is_secondary() && s.is_hit() {
                format!(" ({per_hit} {} rays)", kind.name())
            } else {
                String::new()
            };
            let c = frame.counters(x, y);
            for (name, v) in [
                ("Nodes visited", c.nodes_visited),
                ("Box tests", c.box_tests),
                ("Leaves visited", c.leaves_visited),
                ("Triangle tests", c.triangle_tests),
            ] {
                ui.label(name);
                ui.label(format!("{v}{rays}"));
                ui.end_row();
            }
            if kind.is_secondary() {
                let p = frame.primary_counters(x, y);
                ui.label("Camera ray");
                ui.label(format!("{} nodes, {} triangle tests", p.nodes_visited, p.triangle_tests));
                ui.end_row();
            }
        }
        if frame.stride() > 1 {
            ui.label("");
            ui.weak(format!("coarse pass: traced pixel of a {0}×{0} block", frame.stride()));
            ui.end_row();
        }
    });
}
