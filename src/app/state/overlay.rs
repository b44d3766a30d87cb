//! The node-box overlay: BVH boxes as wireframes over the ray-cast image, in the same pinhole
//! projection as the renderer. Edges are clipped against the near plane in camera space before
//! projection, so a box around or behind the camera draws correctly instead of wrapping around.
//! Optionally only what lies in front of the surface is drawn: each edge is cut into pieces a few
//! pixels long, and a piece is kept when its distance from the eye is no more than the distance
//! the ray of the pixel under it travelled to its hit (the depth test of a rasteriser, against
//! the ray-cast image).

use super::settings::BoxLevel;
use crate::bvh::two_level::placed_corners;
use crate::bvh::{SceneBvh, TreeView};
use crate::geometry::Aabb;
use crate::render::{Camera, Frame};
use egui::{Color32, Mesh, Pos2, Rect};
use glam::Vec3;

/// Corner pairs of the 12 box edges; corner k has x from bit 0, y from bit 1, z from bit 2.
const EDGES: [(usize, usize); 12] =
    [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)];

/// Projects world points into a screen rectangle as the camera sees them.
pub struct Projector {
    eye: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    /// Screen pixels per unit of x/z and y/z.
    sx: f32,
    sy: f32,
    center: Pos2,
    near: f32,
}

impl Projector {
    pub fn new(camera: &Camera, rect: Rect, near: f32) -> Self {
        let (forward, right, up) = camera.basis();
        let tan_v = (camera.vfov_deg.to_radians() * 0.5).tan();
        let tan_h = tan_v * camera.aspect();
        Self {
            eye: camera.position,
            right,
            up,
            forward,
            sx: rect.width() * 0.5 / tan_h,
            sy: rect.height() * 0.5 / tan_v,
            center: rect.center(),
            near,
        }
    }

    fn to_camera(&self, p: Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward))
    }

    fn to_screen(&self, c: Vec3) -> Pos2 {
        Pos2::new(self.center.x + c.x / c.z * self.sx, self.center.y - c.y / c.z * self.sy)
    }

    /// The screen segment of a world segment, clipped to the near plane; None if wholly behind it.
    #[cfg(test)]
    pub fn segment(&self, a: Vec3, b: Vec3) -> Option<(Pos2, Pos2)> {
        self.clip_segment(self.to_camera(a), self.to_camera(b)).map(|(a, b)| (self.to_screen(a), self.to_screen(b)))
    }

    /// A camera-space segment clipped to the near plane (camera space); None if wholly behind it.
    fn clip_segment(&self, mut a: Vec3, mut b: Vec3) -> Option<(Vec3, Vec3)> {
        if a.z < self.near && b.z < self.near {
            return None;
        }
        if a.z < self.near {
            a = a + (b - a) * ((self.near - a.z) / (b.z - a.z));
        } else if b.z < self.near {
            b = b + (a - b) * ((self.near - b.z) / (a.z - b.z));
        }
        Some((a, b))
    }

    /// The 12 edges of a box given by its corners (`Aabb::corners` order), clipped, in camera
    /// space (the eye at the origin, so a point's length is its distance from the eye).
    pub fn box_edges(&self, corners: &[Vec3; 8]) -> impl Iterator<Item = (Vec3, Vec3)> + '_ {
        let corners = corners.map(|c| self.to_camera(c));
        EDGES.iter().filter_map(move |&(i, j)| self.clip_segment(corners[i], corners[j]))
    }
}

/// The depth test of "only in front of the surface": the frame the overlay is drawn over, and
/// where it is on screen.
#[derive(Clone, Copy)]
pub struct DepthTest<'a> {
    pub frame: &'a Frame,
    pub rect: Rect,
}

impl DepthTest<'_> {
    /// Screen length of the pieces an edge is cut into for the test.
    const PIECE: f32 = 3.0;

    /// Whether a camera-space point drawn at `screen` lies in front of the surface there: no
    /// farther from the eye than the pixel's ray went (a miss is infinitely far; a point off the
    /// image is kept). The 0.1% allowance keeps box faces that lie on the surface.
    fn in_front(&self, point: Vec3, screen: Pos2) -> bool {
        let (f, r) = (self.frame, self.rect);
        let u = (screen.x - r.min.x) / r.width();
        let v = (screen.y - r.min.y) / r.height();
        if !(0.0..1.0).contains(&u) || !(0.0..1.0).contains(&v) {
            return true;
        }
        let (x, y) = ((u * f.width() as f32) as u32, (v * f.height() as f32) as u32);
        point.length() <= f.sample(x, y).t * 1.001
    }
}

/// A box to draw: a node's box, as its eight world-space corners (an instance's transform makes
/// an axis-aligned box of the mesh a parallelepiped in the world).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverlayBox {
    /// Picks the colour.
    pub id: usize,
    pub corners: [Vec3; 8],
    /// A top-level box of a two-level BVH: drawn white and twice as thick.
    pub top: bool,
}

impl OverlayBox {
    pub fn world(id: usize, b: &Aabb) -> Self {
        Self { id, corners: b.corners(), top: false }
    }
}

/// The boxes to draw for a built BVH: a single BVH's at `depth`; for two levels the top level's at
/// `top_depth` and/or each mesh BVH's at `depth` placed by every instance, as `level` says.
pub fn boxes_of(bvh: &SceneBvh, level: BoxLevel, top_depth: u32, depth: u32, leaves_above: bool) -> Vec<OverlayBox> {
    let world = |top: bool| move |(id, b): (usize, Aabb)| OverlayBox { top, ..OverlayBox::world(id, &b) };
    let Some(t) = bvh.two_level() else {
        return bvh.tree().boxes_at_depth(depth, leaves_above).into_iter().map(world(false)).collect();
    };
    let mut v = Vec::new();
    if level.shows_bottom() {
        v.extend(t.bottom_boxes_at_depth(depth, leaves_above).into_iter().map(|b| OverlayBox {
            id: b.id,
            corners: placed_corners(&b.bounds, &b.to_world),
            top: false,
        }));
    }
    if level.shows_top() {
        v.extend(t.top.boxes_at_depth(top_depth, leaves_above).into_iter().map(world(true)));
    }
    v
}

/// A distinct, stable colour per node (golden-ratio hue steps).
pub fn node_color(node: usize) -> Color32 {
    let hue = (node as f32 * 0.618_034).fract();
    egui::ecolor::Hsva::new(hue, 0.85, 1.0, 1.0).into()
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
    let projector = Projector::new(camera, rect, near);
    let mut mesh = Mesh::default();
    for l in lines {
        if let Some((a, b)) = projector.clip_segment(projector.to_camera(l.a), projector.to_camera(l.b)) {
            add_segment(&mut mesh, projector.to_screen(a), projector.to_screen(b), l.width, l.color);
        }
    }
    mesh
}

/// Where a world point shows over `rect`, if it is in front of the camera.
pub fn project(camera: &Camera, rect: Rect, p: Vec3) -> Option<Pos2> {
    let projector = Projector::new(camera, rect, 0.0);
    let c = projector.to_camera(p);
    (c.z > 0.0).then(|| projector.to_screen(c))
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

/// All boxes as one mesh of thin quads: far cheaper for egui than 12 line shapes per box, which
/// keeps 10,000 boxes smooth. With `depth`, only the parts in front of the surface.
pub fn boxes_mesh(boxes: &[OverlayBox], camera: &Camera, rect: Rect, width: f32, depth: Option<DepthTest>) -> Mesh {
    let extent =
        boxes.iter().flat_map(|b| b.corners).fold(Aabb::EMPTY, |acc, c| acc.grow(c)).extent().length().max(1e-6);
    let near = (extent * 1e-4).max((camera.position - camera.look_at).length() * 1e-4);
    let projector = Projector::new(camera, rect, near);
    let clip = rect.expand(rect.width().max(rect.height()));
    let mut mesh = Mesh::default();
    for b in boxes {
        let (color, width) = if b.top { (Color32::WHITE, width * 2.0) } else { (node_color(b.id), width) };
        for (a, c) in projector.box_edges(&b.corners) {
            let (p, q) = (projector.to_screen(a), projector.to_screen(c));
            // Segments far outside the view are dropped; egui clips the rest to the viewport.
            if !clip.contains(p) && !clip.contains(q) && !Rect::from_two_pos(p, q).intersects(rect) {
                continue;
            }
            let Some(test) = depth else {
                add_segment(&mut mesh, p, q, width, color);
                continue;
            };
            // Pieces along the edge, interpolated in camera space (a screen-space step is not a
            // fixed step in depth); each kept or dropped by its middle, runs merged into a quad.
            let pieces = ((q - p).length() / DepthTest::PIECE).ceil().clamp(1.0, 512.0) as usize;
            let at = |k: f32| a + (c - a) * (k / pieces as f32);
            let mut run: Option<Pos2> = None;
            for k in 0..pieces {
                let mid = at(k as f32 + 0.5);
                let visible = test.in_front(mid, projector.to_screen(mid));
                match (visible, run) {
                    (true, None) => run = Some(projector.to_screen(at(k as f32))),
                    (false, Some(start)) => {
                        add_segment(&mut mesh, start, projector.to_screen(at(k as f32)), width, color);
                        run = None;
                    }
                    _ => {}
                }
            }
            if let Some(start) = run {
                add_segment(&mut mesh, start, q, width, color);
            }
        }
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn points_project_like_the_renderer() {
        let p = Projector::new(&camera(), rect(), 0.01);
        // The look-at point is the centre; with a 90° vertical fov, y = z·tan(45°) is the top edge.
        let (a, _) = p.segment(Vec3::ZERO, Vec3::ZERO).unwrap();
        assert_eq!(a, Pos2::new(100.0, 50.0));
        let (top, _) = p.segment(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO).unwrap();
        assert!((top.y - 0.0).abs() < 1e-3, "{top:?}");
        // And the renderer's ray through that screen point heads towards the world point.
        let g = camera().ray_gen();
        let dir = g.ray(150.0, 25.0).dir();
        let world = Vec3::new(0.0, 0.0, 5.0) + dir * (5.0 / -dir.z);
        let (s, _) = p.segment(world, world).unwrap();
        assert!((s - Pos2::new(150.0, 25.0)).length() < 1e-2, "{s:?}");
    }

    #[test]
    fn edges_behind_the_camera_are_dropped_and_crossing_ones_clipped() {
        let p = Projector::new(&camera(), rect(), 0.01);
        assert!(p.segment(Vec3::new(0.0, 0.0, 6.0), Vec3::new(1.0, 0.0, 9.0)).is_none());
        let (a, b) = p.segment(Vec3::new(1.0, 0.0, 10.0), Vec3::new(1.0, 0.0, 0.0)).expect("part is visible");
        assert!(a.x.is_finite() && b.x.is_finite());
        // x/z = 1/5 with tan(h/2) = 2 (aspect 2, 90° vertical): 100 + 0.2 / 2 * 100 = 110.
        assert!((b.x - 110.0).abs() < 1e-3, "the visible end projects normally: {b:?}");
        // A box around the camera still yields finite, clipped edges.
        let around = Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
        let edges: Vec<_> = p.box_edges(&around.corners()).collect();
        assert!(!edges.is_empty() && edges.len() < 12);
        assert!(edges.iter().all(|(a, b)| a.x.is_finite() && a.y.is_finite() && b.x.is_finite() && b.y.is_finite()));
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
        assert_ne!(node_color(1), node_color(2));
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
        let test = DepthTest { frame: &frame, rect: rect() };
        let front = vec![OverlayBox::world(1, &Aabb::new(Vec3::new(-1.0, -1.0, 1.0), Vec3::new(1.0, 1.0, 2.0)))];
        let behind = vec![OverlayBox::world(2, &Aabb::new(Vec3::new(-1.0, -1.0, -3.0), Vec3::new(1.0, 1.0, -2.0)))];
        let across = vec![OverlayBox::world(3, &Aabb::new(Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1.0, 1.0, 1.0)))];
        let all = |b: &[OverlayBox]| drawn_length(&boxes_mesh(b, &cam, rect(), 1.0, None));
        let shown = |b: &[OverlayBox]| drawn_length(&boxes_mesh(b, &cam, rect(), 1.0, Some(test)));
        assert!((shown(&front) - all(&front)).abs() < 0.01 * all(&front), "a box in front is drawn whole");
        assert_eq!(shown(&behind), 0.0, "a box behind the wall is hidden");
        // A box through the wall: its front face and the front halves of its side edges.
        let (a, s) = (all(&across), shown(&across));
        assert!(s > 0.3 * a && s < 0.8 * a, "part of a box through the wall: {s} of {a}");
    }
}
