//! The node-box overlay: BVH boxes as wireframes over the ray-cast image. Which boxes, their
//! projection, near-plane clipping, colours and the "only in front of the surface" depth test are
//! the core's (`render::boxes`, which `render --boxes` draws into its PNG too); this module only
//! turns its segments into egui shapes over the viewport, and draws the explain view's lines in
//! the same projection.

use super::settings::BoxLevel;
use crate::bvh::SceneBvh;
use crate::render::boxes::{box_segments, boxes_at, BoxPick, Projector, EDGES};
use crate::render::{Camera, Frame};
use egui::{Color32, Mesh, Pos2, Rect};
use glam::{Vec2, Vec3};

/// A box to draw (the core's: its corners, its id for the colour, top level or not).
pub type OverlayBox = crate::render::boxes::NodeBox;

fn projector(camera: &Camera, rect: Rect, near: f32) -> Projector {
    Projector::new(camera, Vec2::new(rect.width(), rect.height()), near)
}

/// An image point of the core's projection over `rect` on screen.
fn on_screen(rect: Rect, p: Vec2) -> Pos2 {
    rect.min + egui::vec2(p.x, p.y)
}

/// The boxes to draw for a built BVH: a single BVH's at `depth`; for two levels the top level's at
/// `top_depth` and/or each mesh BVH's at `depth` placed by every instance, as `level` says.
pub fn boxes_of(bvh: &SceneBvh, level: BoxLevel, top_depth: u32, depth: u32, leaves_above: bool) -> Vec<OverlayBox> {
    let pick = BoxPick {
        depth,
        top_depth: level.shows_top().then_some(top_depth),
        bottom: level.shows_bottom(),
        leaves_above,
    };
    boxes_at(bvh, &pick)
}

/// Add the quad of a screen segment to the mesh.
fn add_segment(mesh: &mut Mesh, p: Pos2, q: Pos2, width: f32, color: Color32) {
    let d = q - p;
    let len = d.length();
    if !(len.is_finite()) || len < 1e-3 {
        return;
    }
    let n = egui::vec2(-d.y, d.x) / len * (width * 0.5);
    let base = mesh.vertices.len() as u32;
    for v in [p + n, p - n, q - n, q + n] {
        mesh.colored_vertex(v, color);
    }
    mesh.add_triangle(base, base + 1, base + 2);
    mesh.add_triangle(base, base + 2, base + 3);
}

/// A world-space line segment to draw over the image.
#[derive(Clone, Copy, Debug)]
pub struct Line3 {
    pub a: Vec3,
    pub b: Vec3,
    pub color: Color32,
    pub width: f32,
}

/// The 12 edges of a box (corners in `Aabb::corners` order) as lines.
pub fn box_lines(corners: &[Vec3; 8], color: Color32, width: f32, out: &mut Vec<Line3>) {
    out.extend(EDGES.iter().map(|&(i, j)| Line3 { a: corners[i], b: corners[j], color, width }));
}

/// Lines as one mesh of thin quads, in the camera's projection over `rect`, clipped to its near
/// plane (which is `near` in front of the eye).
pub fn lines_mesh(lines: &[Line3], camera: &Camera, rect: Rect, near: f32) -> Mesh {
    let projector = projector(camera, rect, near);
    let mut mesh = Mesh::default();
    for l in lines {
        if let Some((a, b)) = projector.segment(l.a, l.b) {
            add_segment(&mut mesh, on_screen(rect, a), on_screen(rect, b), l.width, l.color);
        }
    }
    mesh
}

/// Where a world point shows over `rect`, if it is in front of the camera.
pub fn project(camera: &Camera, rect: Rect, p: Vec3) -> Option<Pos2> {
    projector(camera, rect, 0.0).project(p).map(|p| on_screen(rect, p))
}

/// The box whose drawn edges pass nearest `pos` on screen, within `reach` points: its index in
/// `boxes` (edges behind the eye are skipped).
pub fn box_near(boxes: &[OverlayBox], camera: &Camera, rect: Rect, pos: Pos2, reach: f32) -> Option<usize> {
    let mut best: Option<(f32, usize)> = None;
    for (i, b) in boxes.iter().enumerate() {
        for &(a, c) in &EDGES {
            let (Some(p), Some(q)) = (project(camera, rect, b.corners[a]), project(camera, rect, b.corners[c])) else {
                continue;
            };
            // Distance from pos to the segment pq.
            let d = q - p;
            let t = ((pos - p).dot(d) / d.length_sq().max(1e-12)).clamp(0.0, 1.0);
            let dist = (p + d * t).distance(pos);
            if dist <= reach && best.is_none_or(|(bd, _)| dist < bd) {
                best = Some((dist, i));
            }
        }
    }
    best.map(|(_, i)| i)
}

/// All boxes as one mesh of thin quads (the core's segments, `box_segments`): far cheaper for
/// egui than 12 line shapes per box, which keeps 10,000 boxes smooth. With `depth` (the frame
/// shown over `rect`), only the parts in front of its surface ("Only in front of the surface");
/// egui clips what lies outside the viewport.
pub fn boxes_mesh(boxes: &[OverlayBox], camera: &Camera, rect: Rect, width: f32, depth: Option<&Frame>) -> Mesh {
    let size = Vec2::new(rect.width(), rect.height());
    let mut mesh = Mesh::default();
    for s in box_segments(boxes, camera, size, width, depth) {
        let [r, g, b] = s.rgb;
        add_segment(&mut mesh, on_screen(rect, s.a), on_screen(rect, s.b), s.width, Color32::from_rgb(r, g, b));
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;

    fn camera() -> Camera {
        Camera {
            position: Vec3::new(0.0, 0.0, 5.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            vfov_deg: 90.0,
            width: 200,
            height: 100,
        }
    }

    /// A shift-click on a drawn box's edge picks that box: the nearest edge within reach wins.
    #[test]
    fn the_box_whose_edge_is_under_the_pointer_is_found() {
        let (cam, rect) = (camera(), Rect::from_min_size(Pos2::ZERO, egui::vec2(200.0, 100.0)));
        let a = OverlayBox::world(0, &Aabb::new(Vec3::new(-2.0, -1.0, -1.0), Vec3::new(-1.0, 1.0, 1.0)));
        let b = OverlayBox::world(1, &Aabb::new(Vec3::new(1.0, -1.0, -1.0), Vec3::new(2.0, 1.0, 1.0)));
        let boxes = [a, b];
        let on_b = project(&cam, rect, Vec3::new(1.5, 1.0, 1.0)).unwrap(); // the middle of a front edge of b
        assert_eq!(box_near(&boxes, &cam, rect, on_b, 3.0), Some(1));
        assert_eq!(box_near(&boxes, &cam, rect, on_b + egui::vec2(0.0, 2.0), 3.0), Some(1), "within reach");
        let centre = project(&cam, rect, Vec3::ZERO).unwrap();
        assert_eq!(box_near(&boxes, &cam, rect, centre, 3.0), None, "between the boxes, no edge near");
    }

    fn rect() -> Rect {
        Rect::from_min_size(Pos2::ZERO, egui::vec2(200.0, 100.0))
    }

    /// The core's colours are the bytes egui's hue steps made when the overlay picked them itself.
    #[test]
    fn node_colours_are_egui_s_hues() {
        for id in 0..2000 {
            let hue = (id as f32 * 0.618_034).fract();
            let egui: Color32 = egui::ecolor::Hsva::new(hue, 0.85, 1.0, 1.0).into();
            let [r, g, b] = crate::render::boxes::node_rgb(id);
            assert_eq!(Color32::from_rgb(r, g, b), egui, "node {id}");
        }
    }

    #[test]
    fn mesh_has_one_quad_per_visible_edge() {
        let boxes = vec![
            OverlayBox::world(1, &Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))),
            OverlayBox::world(2, &Aabb::new(Vec3::splat(-0.5), Vec3::splat(0.5))),
        ];
        let m = boxes_mesh(&boxes, &camera(), rect(), 1.0, None);
        // Both boxes lie wholly in front of the camera and inside the view; the edges along the
        // view axis are off-centre, so they project to real segments too: 2 × 12 quads.
        assert_eq!(m.vertices.len(), 24 * 4);
        assert_eq!(m.indices.len(), 24 * 6);
        // A box behind the camera adds nothing.
        let behind = vec![OverlayBox::world(3, &Aabb::new(Vec3::new(-1.0, -1.0, 6.0), Vec3::new(1.0, 1.0, 8.0)))];
        assert_eq!(boxes_mesh(&behind, &camera(), rect(), 1.0, None).vertices.len(), 0);
    }

    /// The total screen length of the quads of a mesh (each quad's long side).
    fn drawn_length(m: &Mesh) -> f32 {
        m.vertices.chunks(4).map(|q| (q[2].pos - q[1].pos).length()).sum()
    }

    #[test]
    fn only_the_parts_in_front_of_the_surface_are_drawn_when_asked() {
        use crate::bvh::{AnyBvh, BuildParams};
        use crate::render::{render, RenderSettings};
        // A wall at z = 0 facing the camera (at z = 5), and two boxes: one in front of the wall,
        // one behind it, both within the view.
        let wall = crate::mesh::Mesh {
            positions: vec![
                Vec3::new(-9.0, -9.0, 0.0),
                Vec3::new(9.0, -9.0, 0.0),
                Vec3::new(9.0, 9.0, 0.0),
                Vec3::new(-9.0, 9.0, 0.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            ..Default::default()
        };
        let cam = camera();
        let frame = render(&AnyBvh::build(&wall, &BuildParams::default()), &wall, &cam, &RenderSettings::default());
        let front = vec![OverlayBox::world(1, &Aabb::new(Vec3::new(-1.0, -1.0, 1.0), Vec3::new(1.0, 1.0, 2.0)))];
        let behind = vec![OverlayBox::world(2, &Aabb::new(Vec3::new(-1.0, -1.0, -3.0), Vec3::new(1.0, 1.0, -2.0)))];
        let across = vec![OverlayBox::world(3, &Aabb::new(Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1.0, 1.0, 1.0)))];
        let all = |b: &[OverlayBox]| drawn_length(&boxes_mesh(b, &cam, rect(), 1.0, None));
        let shown = |b: &[OverlayBox]| drawn_length(&boxes_mesh(b, &cam, rect(), 1.0, Some(&frame)));
        assert!((shown(&front) - all(&front)).abs() < 0.01 * all(&front), "a box in front is drawn whole");
        assert_eq!(shown(&behind), 0.0, "a box behind the wall is hidden");
        // A box through the wall: its front face and the front halves of its side edges.
        let (a, s) = (all(&across), shown(&across));
        assert!(s > 0.3 * a && s < 0.8 * a, "part of a box through the wall: {s} of {a}");
    }
}
