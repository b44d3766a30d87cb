//! What the viewport draws over the image to explain the tree: the build replay's frontier (and
//! an LBVH's Morton curve), the selected node with its children and split plane, and the pinned
//! rays step by step. All in world space through `overlay`'s projection, so orbiting shows them
//! from the side.

use crate::app::state::{BvhscopeApp, Shown};
use egui::{Color32, Pos2, Rect, Stroke};
use std::sync::Arc;

/// Most frontier boxes the replay draws (past this, only the newest split's).
const MAX_FRONTIER_BOXES: usize = 4000;

/// Most segments of the Morton curve drawn (a bigger frontier is drawn through every k-th node).
const MAX_MORTON_SEGMENTS: usize = 20_000;

/// A build replay's image: the frontier's boxes (its nodes acting as leaves) and the newest
/// split's two children in the selected node's colours.
pub(super) fn draw_replay(app: &BvhscopeApp, painter: &egui::Painter, rect: Rect, shown: &Shown) {
    use crate::app::state::overlay::{box_lines, lines_mesh};
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

/// The Morton curve of an LBVH tree at the replay's resolution: the frontier nodes in leaf order
/// (which is Morton order), each at the mean centroid of its triangles, joined in that order and
/// coloured from its start (blue) to its end (yellow). After one split it is two points, after
/// seven the eight octant-like cells in Z order, and it refines as the tree is split.
fn morton_lines(
    m: &crate::bvh::morton::MortonOrder,
    p: &crate::explain::replay::PartialBvh,
    h: &crate::bvh::Hierarchy,
    out: &mut Vec<crate::app::state::overlay::Line3>,
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
        out.push(crate::app::state::overlay::Line3 { a: w[0], b: w[1], color, width: 3.0 });
    }
}

/// The selected node of the Tree and Node windows: the rest of the image dimmed (a mask over the
/// frame: pixels whose hit is not one of its triangles), its box, its children's boxes in their
/// own colours, and the plane the builder split it at as a translucent quad.
pub(super) fn draw_selected_node(app: &BvhscopeApp, painter: &egui::Painter, rect: Rect, shown: &Shown) {
    use crate::app::state::overlay::{box_lines, lines_mesh};
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
    m: &crate::explain::inspect::Marker,
    lines: &mut Vec<crate::app::state::overlay::Line3>,
) {
    use crate::app::state::overlay::{project, Line3};
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
pub(super) fn draw_pinned(app: &BvhscopeApp, painter: &egui::Painter, rect: Rect, camera: &crate::render::Camera) {
    use crate::app::state::overlay::{box_lines, lines_mesh, project, Line3};
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
