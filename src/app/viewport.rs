//! The central view: the ray-cast image, mouse camera control, the node-box overlay, the heatmap
//! legend and the per-pixel read-out on hover. It reports its size and the mouse's camera moves
//! as actions; the app's reconciler renders what it would show.

use super::{Action, Actions, BvhscopeApp, MessageKind};
use crate::render::legend::fmt_value;
use crate::render::{Frame, Legend};
use egui::{Color32, PointerButton, Pos2, Rect, Sense, Stroke, Vec2};
use std::sync::Arc;

/// Largest image the viewport renders (pixels), so huge windows stay interactive.
const MAX_PIXELS: f32 = 2560.0 * 1440.0;

pub fn show(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let rect = ui.available_rect_before_wrap();
    let response = ui.allocate_rect(rect, Sense::click_and_drag());

    // Camera input.
    if response.dragged_by(PointerButton::Primary) {
        let d = response.drag_delta();
        out.push(Action::Orbit(d.x, d.y));
    } else if response.dragged_by(PointerButton::Secondary) || response.dragged_by(PointerButton::Middle) {
        let d = response.drag_delta();
        out.push(Action::Pan { dx: d.x, dy: d.y, height: rect.height() });
    }
    // A click (no drag) pins the ray of the pixel under it; a shift-click selects its hit's leaf.
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
                } else {
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

    // Render at the viewport's pixel size.
    let ppp = ui.ctx().pixels_per_point();
    let mut size = rect.size() * ppp;
    let area = size.x * size.y;
    if area > MAX_PIXELS {
        size *= (MAX_PIXELS / area).sqrt();
    }
    let pixels = (size.x.round().max(1.0) as u32, size.y.round().max(1.0) as u32);
    if rect != app.viewport_rect || pixels != app.viewport_pixels() {
        out.push(Action::Viewport { rect, pixels });
    }

    // The image, stretched to the viewport while a new size is on its way.
    let painter = ui.painter_at(rect);
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

    // Side by side: A and B over the image, as halves, a wipe, or their difference.
    let compared = app.compare_images(ui.ctx());
    if let Some(c) = &compared {
        draw_compare(app, ui, &painter, rect, c, out);
    }

    // The legend histogram's threshold: the pixels at or below it dimmed.
    if let Some(shown) = &app.shown {
        if let Some(mask) = app.threshold_mask(ui.ctx(), shown).filter(|_| compared.is_none()) {
            painter.image(mask.id(), rect, Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)), Color32::WHITE);
        }
    }
    // An imported tree's pixels whose hit differs from the linear scan's, in red.
    if let Some((mask, _)) = app.wrong_mask(ui.ctx()).filter(|_| compared.is_none()) {
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
        draw_replay(app, &painter, rect, shown);
        draw_selected_node(app, &painter, rect, shown);
        draw_pinned(app, &painter, rect, &shown.camera);
    }

    // Files dragged over the window.
    if ui.ctx().input(|i| !i.raw.hovered_files.is_empty()) {
        painter.rect_filled(rect, 0.0, Color32::from_black_alpha(160));
        painter.text(
            rect.center(),
            egui::Align2::CENTER_CENTER,
            "Drop a mesh or scene to open it, or a BVH dump to import it",
            egui::FontId::proportional(22.0),
            Color32::WHITE,
        );
    }

    messages(app, ui, rect, out);
    if let Some(shown) = &app.shown {
        let compare_legend = compared.as_ref().and_then(|c| match app.compare.mode {
            super::CompareMode::Difference => c.diff.as_ref().map(|d| d.2.clone()),
            _ => c.legend.clone(),
        });
        // The histogram is of the image's own values: not drawn for a side-by-side pair.
        if let Some(legend) = compare_legend.as_ref() {
            legend_area(app, ui, rect, legend, false, out);
        } else if let Some(legend) = shown.legend.as_ref() {
            legend_area(app, ui, rect, legend, true, out);
        }
        if let Some(pos) = response.hover_pos() {
            let frame = shown.frame.clone();
            response.on_hover_ui_at_pointer(|ui| pixel_readout(ui, &frame, rect, pos));
        }
    }
}

/// A and B over the viewport: each the left or right part of its image, split at the middle or at
/// the wipe line (dragged), or the difference image; each side labelled with its build.
fn draw_compare(
    app: &BvhscopeApp,
    ui: &egui::Ui,
    painter: &egui::Painter,
    rect: Rect,
    c: &super::compare_view::CompareImages,
    out: &mut Actions,
) {
    use super::CompareMode;
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
        CompareMode::Difference => match &c.diff {
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
            let split = if mode == CompareMode::Wipe { app.compare.wipe } else { 0.5 };
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
            if mode == CompareMode::Wipe {
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

/// Most frontier boxes the replay draws (past this, only the newest split's).
const MAX_FRONTIER_BOXES: usize = 4000;

/// A build replay's image: the frontier's boxes (its nodes acting as leaves) and the newest
/// split's two children in the selected node's colours.
fn draw_replay(app: &BvhscopeApp, painter: &egui::Painter, rect: Rect, shown: &super::Shown) {
    use super::overlay::{box_lines, lines_mesh};
    let (Some(p), Some(r)) = (&shown.partial, &app.replay.replay) else { return };
    if !Arc::ptr_eq(&p.tree, &r.tree) {
        return;
    }
    let mut lines = Vec::new();
    if p.splits < MAX_FRONTIER_BOXES {
        for n in p.frontier() {
            box_lines(
                &p.tree.nodes[n as usize].bounds().corners(),
                Color32::from_rgba_premultiplied(120, 120, 130, 120),
                1.0,
                &mut lines,
            );
        }
    }
    // LBVH: the Morton curve through the centroids in leaf order, a colour per frontier node.
    if let Some(m) = &app.replay.morton {
        morton_lines(m, p, &r.hierarchy, &mut lines);
    }
    let camera = &shown.camera;
    if let Some(&newest) = p.splits.checked_sub(1).and_then(|i| r.order.get(i)) {
        let l = p.tree.nodes[newest as usize].index as usize;
        for (c, color) in [(l, NODE_COLORS.left), (l + 1, NODE_COLORS.right)] {
            box_lines(&p.tree.nodes[c].bounds().corners(), color, 2.0, &mut lines);
        }
        // The plane the strategy cut it at.
        if let Some((_, Some(m), _)) = app.replay.newest.as_ref().filter(|(n, _, _)| *n == newest) {
            draw_plane(painter, rect, camera, &p.tree.nodes[newest as usize].bounds(), m, &mut lines);
        }
    }
    let near = (camera.position - camera.look_at).length() * 1e-4;
    painter.add(egui::Shape::Mesh(Arc::new(lines_mesh(&lines, camera, rect, near))));
}

/// Most segments of the Morton curve drawn (a bigger frontier is drawn through every k-th node).
const MAX_MORTON_SEGMENTS: usize = 20_000;

/// The Morton curve of an LBVH tree at the replay's resolution: the frontier nodes in leaf order
/// (which is Morton order), each at the mean centroid of its triangles, joined in that order and
/// coloured from its start (blue) to its end (yellow). After one split it is two points, after
/// seven the eight octant-like cells in Z order, and it refines as the tree is split.
fn morton_lines(
    m: &crate::bvh::lbvh::MortonOrder,
    p: &crate::bvh::replay::PartialBvh,
    h: &crate::bvh::inspect::Hierarchy,
    out: &mut Vec<super::overlay::Line3>,
) {
    let mut pieces: Vec<(u32, u32)> =
        p.frontier().iter().map(|&n| (h.first[n as usize], h.count[n as usize])).collect();
    pieces.sort_unstable();
    let step = pieces.len().div_ceil(MAX_MORTON_SEGMENTS).max(1);
    let points: Vec<glam::Vec3> = pieces.iter().step_by(step).map(|&(f, c)| m.mean(f, c)).collect();
    let n = points.len().saturating_sub(1).max(1) as f32;
    for (k, w) in points.windows(2).enumerate() {
        let t = k as f32 / n;
        let color = Color32::from_rgb((40.0 + 210.0 * t) as u8, (120.0 + 100.0 * t) as u8, (250.0 - 200.0 * t) as u8);
        out.push(super::overlay::Line3 { a: w[0], b: w[1], color, width: 3.0 });
    }
}

/// The node of the binary tree whose drawn box has an edge under `pos` (the overlay's boxes are
/// the current layout's; a wide child's box is its binary node's, so it is found by its bounds).
fn drawn_box_node(app: &BvhscopeApp, rect: Rect, shown: &super::Shown, pos: Pos2) -> Option<u32> {
    if !app.settings.show_boxes {
        return None;
    }
    let e = app.nodes.current(Some(&shown.bvh))?;
    let boxes = app.overlay_boxes()?;
    let i = super::overlay::box_near(&boxes, &shown.camera, rect, pos, 5.0)?;
    let corners = boxes[i].corners;
    e.tree.nodes.iter().position(|n| n.bounds().corners() == corners).map(|n| n as u32)
}

/// The selected node of the Tree and Node windows: the rest of the image dimmed (a mask over the
/// frame: pixels whose hit is not one of its triangles), its box, its children's boxes in their
/// own colours, and the plane the builder split it at as a translucent quad.
fn draw_selected_node(app: &BvhscopeApp, painter: &egui::Painter, rect: Rect, shown: &super::Shown) {
    use super::overlay::{box_lines, lines_mesh};
    let Some(node) = app.nodes.selected.filter(|_| app.nodes.window) else { return };
    let Some(e) = app.nodes.current(Some(&shown.bvh)) else { return };
    let Some(n) = e.tree.nodes.get(node as usize) else { return };
    if let Some(mask) = app.node_mask(painter.ctx(), shown, e, node) {
        painter.image(mask.id(), rect, Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)), Color32::WHITE);
    }
    let camera = &shown.camera;
    let mut lines = Vec::new();
    if !n.is_leaf() {
        for (child, color) in [(n.index, NODE_COLORS.left), (n.index + 1, NODE_COLORS.right)] {
            box_lines(&e.tree.nodes[child as usize].bounds().corners(), color, 1.5, &mut lines);
        }
    }
    box_lines(&n.bounds().corners(), NODE_COLORS.node, 2.5, &mut lines);
    // The split plane: where the tree's own strategy cut this node (its inspection's marker).
    let plane = app
        .nodes
        .inspection
        .as_ref()
        .filter(|i| i.node == node && !n.is_leaf())
        .and_then(|i| i.markers.iter().find(|(s, _)| *s == e.tree.params.strategy).and_then(|(_, m)| *m));
    if let Some(m) = plane {
        draw_plane(painter, rect, camera, &n.bounds(), &m, &mut lines);
    }
    let near = (camera.position - camera.look_at).length() * 1e-4;
    painter.add(egui::Shape::Mesh(Arc::new(lines_mesh(&lines, camera, rect, near))));
}

/// A split plane across a node's box: a translucent quad at the marker's position on its axis,
/// outlined (its outline added to `lines`).
fn draw_plane(
    painter: &egui::Painter,
    rect: Rect,
    camera: &crate::render::Camera,
    b: &crate::geometry::Aabb,
    m: &crate::bvh::inspect::Marker,
    lines: &mut Vec<super::overlay::Line3>,
) {
    use super::overlay::{project, Line3};
    let (a, (u, v)) = (m.axis as usize, [(1, 2), (0, 2), (0, 1)][m.axis as usize]);
    let corner = |cu: f32, cv: f32| {
        let mut p = glam::Vec3::ZERO;
        p[a] = m.position;
        p[u] = cu;
        p[v] = cv;
        p
    };
    let quad = [
        corner(b.min[u], b.min[v]),
        corner(b.max[u], b.min[v]),
        corner(b.max[u], b.max[v]),
        corner(b.min[u], b.max[v]),
    ];
    let pts: Option<Vec<Pos2>> = quad.iter().map(|&q| project(camera, rect, q)).collect();
    if let Some(pts) = pts {
        painter.add(egui::Shape::convex_polygon(pts, NODE_COLORS.plane, Stroke::new(1.0, NODE_COLORS.plane_edge)));
    }
    for k in 0..4 {
        lines.push(Line3 { a: quad[k], b: quad[(k + 1) % 4], color: NODE_COLORS.plane_edge, width: 1.0 });
    }
}

/// The colours of the selected node, its children and its split plane.
pub struct NodeColors {
    pub node: Color32,
    pub left: Color32,
    pub right: Color32,
    pub plane: Color32,
    pub plane_edge: Color32,
}

pub const NODE_COLORS: NodeColors = NodeColors {
    node: Color32::WHITE,
    left: Color32::from_rgb(80, 170, 255),
    right: Color32::from_rgb(255, 110, 200),
    plane: Color32::from_rgba_premultiplied(60, 50, 10, 60),
    plane_edge: Color32::from_rgb(250, 210, 80),
};

/// The colours a pinned ray's step is drawn in (the Ray window's legend names them).
pub struct RayColors {
    pub visited: Color32,
    pub skipped: Color32,
    pub tested_hit: Color32,
    pub tested_miss: Color32,
    pub current: Color32,
    pub triangle_hit: Color32,
    pub triangle_miss: Color32,
    pub hit_point: Color32,
}

pub const RAY_COLORS: RayColors = RayColors {
    visited: Color32::from_rgba_premultiplied(100, 100, 106, 90),
    skipped: Color32::from_rgb(240, 160, 60),
    tested_hit: Color32::from_rgb(80, 220, 230),
    tested_miss: Color32::from_rgb(150, 70, 70),
    current: Color32::from_rgb(250, 220, 60),
    triangle_hit: Color32::from_rgb(90, 230, 90),
    triangle_miss: Color32::from_rgb(235, 80, 70),
    hit_point: Color32::from_rgb(90, 230, 90),
};

/// The pinned rays over the image: every pinned ray as a line (the selected one brighter), and for
/// the selected one, at the step shown: the boxes already visited dimmed, the skipped ones orange,
/// the box tested at this step (cyan when hit), the current node yellow, the current leaf's
/// triangles outlined (green hit, red missed), and the closest hit so far marked. All in world
/// space, so orbiting shows the ray from the side.
fn draw_pinned(app: &BvhscopeApp, painter: &egui::Painter, rect: Rect, camera: &crate::render::Camera) {
    use super::overlay::{box_lines, lines_mesh, project, Line3};
    let rays = &app.pins;
    let Some(sel) = rays.current() else { return };
    let far = (camera.position - camera.look_at).length() * 2.0;
    let mut lines = Vec::new();
    for (i, r) in rays.pinned.iter().enumerate() {
        let (color, width) = if i == rays.selected { (Color32::WHITE, 2.0) } else { (Color32::from_gray(150), 1.0) };
        lines.push(Line3 { a: r.ray.origin(), b: r.end(far), color, width });
    }
    let pic = sel.picture(rays.step);
    let mut add_box = |at: (crate::bvh::TraceLevel, crate::bvh::NodeId), color: Color32, width: f32| {
        if let Some(c) = sel.bvh.node_corners(at.0, at.1) {
            box_lines(&c, color, width, &mut lines);
        }
    };
    for &v in &pic.visited {
        add_box(v, RAY_COLORS.visited, 1.0);
    }
    for &s in &pic.skipped {
        add_box(s, RAY_COLORS.skipped, 1.5);
    }
    if let Some((level, node, hit)) = pic.tested {
        let color = if hit { RAY_COLORS.tested_hit } else { RAY_COLORS.tested_miss };
        add_box((level, node), color, 1.5);
    }
    if let Some(cur) = pic.current {
        add_box(cur, RAY_COLORS.current, 2.5);
    }
    for &(tri, hit) in &pic.triangles {
        if let Some([a, b, c]) = sel.bvh.triangle_corners(tri) {
            let color = if hit { RAY_COLORS.triangle_hit } else { RAY_COLORS.triangle_miss };
            for (p, q) in [(a, b), (b, c), (c, a)] {
                lines.push(Line3 { a: p, b: q, color, width: 2.0 });
            }
        }
    }
    let near = (camera.position - camera.look_at).length() * 1e-4;
    painter.add(egui::Shape::Mesh(std::sync::Arc::new(lines_mesh(&lines, camera, rect, near))));
    if let Some(p) = pic.closest_t.and_then(|t| project(camera, rect, sel.ray.at(t))) {
        painter.circle(p, 5.0, RAY_COLORS.hit_point, Stroke::new(1.5, Color32::BLACK));
    }
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
            let c = frame.counters(x, y);
            for (name, v) in [
                ("Nodes visited", c.nodes_visited),
                ("Box tests", c.box_tests),
                ("Leaves visited", c.leaves_visited),
                ("Triangle tests", c.triangle_tests),
            ] {
                ui.label(name);
                ui.label(v.to_string());
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

/// The heatmap legend in the viewport's lower-left corner: title, colour bar with its ends, and
/// the frame's min / mean / max. Real labels, so screen readers and UI tests see the numbers.
/// Bins of the legend's histogram.
pub const HISTOGRAM_BINS: usize = 32;

fn legend_area(app: &BvhscopeApp, ui: &egui::Ui, rect: Rect, legend: &Legend, histogram: bool, out: &mut Actions) {
    egui::Area::new(ui.scope_id().with("heatmap-legend"))
        .fixed_pos(rect.left_bottom() + Vec2::new(12.0, -158.0))
        .order(egui::Order::Foreground)
        .show(ui.ctx(), |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.set_max_width(330.0);
                ui.label(egui::RichText::new(format!("Legend: {}", legend.title)).strong());
                let mut bar_x = 0.0..=0.0;
                ui.horizontal(|ui| {
                    ui.label(fmt_value(legend.range_min as f64));
                    let (bar, _) = ui.allocate_exact_size(Vec2::new(220.0, 14.0), Sense::hover());
                    bar_x = bar.x_range().min..=bar.x_range().max;
                    let steps = 110;
                    for i in 0..steps {
                        let t = i as f32 / (steps - 1) as f32;
                        let [r, g, b] = legend.colormap.map(t);
                        let x0 = bar.min.x + bar.width() * i as f32 / steps as f32;
                        let x1 = bar.min.x + bar.width() * (i + 1) as f32 / steps as f32;
                        ui.painter().rect_filled(
                            Rect::from_x_y_ranges(x0..=x1 + 0.5, bar.y_range()),
                            0.0,
                            Color32::from_rgb(r, g, b),
                        );
                    }
                    ui.painter().rect_stroke(bar, 0.0, Stroke::new(1.0, Color32::GRAY), egui::StrokeKind::Outside);
                    ui.label(fmt_value(legend.range_max as f64));
                });
                if histogram {
                    histogram_bars(app, ui, legend, bar_x, out);
                }
                ui.label(format!(
                    "min {}   mean {:.2}   max {}   (all traced rays)",
                    fmt_value(legend.min as f64),
                    legend.mean,
                    fmt_value(legend.max as f64)
                ));
            });
        });
}

/// The distribution of the heatmap's per-pixel values under the colour bar, on its range; a click
/// or drag sets a threshold above which the image's pixels are highlighted (the rest dimmed).
fn histogram_bars(
    app: &BvhscopeApp,
    ui: &mut egui::Ui,
    legend: &Legend,
    x: std::ops::RangeInclusive<f32>,
    out: &mut Actions,
) {
    let Some(counts) = app.legend_histogram() else { return };
    // The bars sit under the colour bar, bin for bin.
    let (row, response) = ui
        .horizontal(|ui| {
            ui.add_space((*x.start() - ui.cursor().min.x).max(0.0));
            ui.allocate_exact_size(Vec2::new(x.end() - x.start(), 44.0), Sense::click_and_drag())
        })
        .inner;
    let bars = row;
    let painter = ui.painter_at(row);
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
        painter.line_segment([Pos2::new(px, row.min.y), Pos2::new(px, row.max.y)], Stroke::new(2.0, Color32::WHITE));
    }
    if let Some(pos) = response.interact_pointer_pos().filter(|_| response.clicked() || response.dragged()) {
        let t = legend.range_min + span * ((pos.x - bars.min.x) / bars.width()).clamp(0.0, 1.0);
        out.push(Action::SetThreshold(Some(t)));
    }
    if response.double_clicked() || response.secondary_clicked() {
        out.push(Action::SetThreshold(None));
    }
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "Histogram of the heatmap"));
    let above = app.threshold.map_or(String::new(), |t| format!(" Pixels above {}: highlighted.", fmt_value(t as f64)));
    ui.weak(format!("Pixels per value (square root scale). Click or drag to highlight the pixels above a value; double-click to clear.{above}"))
        .on_hover_text("The same bins as `bvhscope render --histogram 32`");
}

/// Errors (until dismissed) and notes (for a few seconds) across the top of the viewport. Each
/// wraps inside the viewport, however long (a scene's note can be a paragraph), with its Dismiss
/// button below the text, so the button stays on screen.
fn messages(app: &BvhscopeApp, ui: &egui::Ui, rect: Rect, out: &mut Actions) {
    if app.messages.is_empty() {
        return;
    }
    let mut dismiss = None;
    let margin = 8.0;
    let width = (rect.width() - 24.0 - 2.0 * margin).max(60.0);
    egui::Area::new(ui.scope_id().with("messages"))
        .fixed_pos(rect.left_top() + Vec2::new(12.0, 12.0))
        .order(egui::Order::Foreground)
        .constrain_to(rect)
        .show(ui.ctx(), |ui| {
            ui.set_max_width(width + 2.0 * margin);
            for (i, m) in app.messages.iter().enumerate() {
                let (fill, title) = match m.kind {
                    MessageKind::Error => (Color32::from_rgb(110, 24, 24), "Error"),
                    MessageKind::Warning => (Color32::from_rgb(110, 80, 10), "Warning"),
                    MessageKind::Info => (Color32::from_rgb(24, 60, 100), "Note"),
                };
                egui::Frame::new().fill(fill).inner_margin(margin).corner_radius(4.0).show(ui, |ui| {
                    ui.set_max_width(width);
                    let text = egui::RichText::new(format!("{title}: {}", m.text)).color(Color32::WHITE);
                    ui.add(egui::Label::new(text).wrap());
                    if ui.small_button("Dismiss").clicked() {
                        dismiss = Some(i);
                    }
                });
            }
        });
    out.extend(dismiss.map(Action::Dismiss));
}
