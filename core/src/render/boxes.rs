//! Node boxes drawn over an image, as line segments in its pixels: the app's overlay turns them
//! into egui shapes, `render --boxes` draws them into the PNG (`draw_segments`), so a view that
//! explains is fed by the same code that renders. The boxes are the nodes at a depth (for two
//! levels the top level's and/or each mesh BVH's placed by every instance), in the renderer's
//! pinhole projection. Edges are clipped against the near plane in camera space before
//! projection, so a box around or behind the camera draws correctly instead of wrapping around.
//! Optionally only what lies in front of the surface is kept: each edge is cut into pieces a few
//! pixels long, and a piece is kept when its distance from the eye is no more than the distance
//! the ray of the pixel under it travelled to its hit (the depth test of a rasteriser, against
//! the ray-cast frame).

#[cfg(test)]
mod boxes_tests;
mod raster;

pub use raster::{draw_segments, Segment};

use crate::bvh::two_level::placed_corners;
use crate::bvh::{SceneBvh, TreeStats, TreeView};
use crate::geometry::Aabb;
use crate::render::camera::Camera;
use crate::render::frame::Frame;
use glam::{Vec2, Vec3};

/// Corner pairs of the 12 box edges; corner k has x from bit 0, y from bit 1, z from bit 2
/// (`Aabb::corners` order).
pub const EDGES: [(usize, usize); 12] =
    [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)];

/// The depth of the top level's boxes over a two-level BVH unless one is chosen (the app's
/// default, which `render --boxes` follows).
pub const DEFAULT_TOP_DEPTH: u32 = 1;

/// Projects world points into an image of `size` (pixels, or the app's points; (0, 0) its top
/// left corner) as the camera sees them.
#[derive(Clone, Copy, Debug)]
pub struct Projector {
    eye: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    /// Image units per unit of x/z and y/z.
    scale: Vec2,
    center: Vec2,
    near: f32,
}

impl Projector {
    /// The projection of `camera` onto an image of `size`, its near plane `near` in front of the
    /// eye.
    pub fn new(camera: &Camera, size: Vec2, near: f32) -> Self {
        let (forward, right, up) = camera.basis();
        let tan_v = (camera.vfov_deg.to_radians() * 0.5).tan();
        let tan_h = tan_v * camera.aspect();
        Self {
            eye: camera.position,
            right,
            up,
            forward,
            scale: Vec2::new(size.x * 0.5 / tan_h, size.y * 0.5 / tan_v),
            center: size * 0.5,
            near,
        }
    }

    /// A world point in camera space: x right, y up, z along the view (the eye at the origin, so
    /// a point's length is its distance from the eye).
    pub fn to_camera(&self, p: Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward))
    }

    /// Where a camera-space point in front of the eye shows on the image.
    pub fn to_image(&self, c: Vec3) -> Vec2 {
        Vec2::new(self.center.x + c.x / c.z * self.scale.x, self.center.y - c.y / c.z * self.scale.y)
    }

    /// Where a world point shows, if it is in front of the eye.
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        let c = self.to_camera(p);
        (c.z > 0.0).then(|| self.to_image(c))
    }

    /// A camera-space segment clipped to the near plane; None if wholly behind it.
    pub fn clip(&self, mut a: Vec3, mut b: Vec3) -> Option<(Vec3, Vec3)> {
        if a.z < self.near && b.z < self.near {
            return None;
        }
        if a.z < self.near {
            a += (b - a) * ((self.near - a.z) / (b.z - a.z));
        } else if b.z < self.near {
            b += (a - b) * ((self.near - b.z) / (a.z - b.z));
        }
        Some((a, b))
    }

    /// The image segment of a world segment, clipped to the near plane; None if wholly behind it.
    pub fn segment(&self, a: Vec3, b: Vec3) -> Option<(Vec2, Vec2)> {
        self.clip(self.to_camera(a), self.to_camera(b)).map(|(a, b)| (self.to_image(a), self.to_image(b)))
    }

    /// The 12 edges of a box given by its corners (`Aabb::corners` order), clipped, in camera
    /// space.
    pub fn box_edges(&self, corners: &[Vec3; 8]) -> impl Iterator<Item = (Vec3, Vec3)> + '_ {
        let corners = corners.map(|c| self.to_camera(c));
        EDGES.iter().filter_map(move |&(i, j)| self.clip(corners[i], corners[j]))
    }
}

/// A box to draw: a node's box, as its eight world-space corners (an instance's transform makes
/// an axis-aligned box of the mesh a parallelepiped in the world).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeBox {
    /// Picks the colour (`node_rgb`).
    pub id: usize,
    pub corners: [Vec3; 8],
    /// A top-level box of a two-level BVH: drawn white and twice as thick.
    pub top: bool,
}

impl NodeBox {
    pub fn world(id: usize, b: &Aabb) -> Self {
        Self { id, corners: b.corners(), top: false }
    }
}

/// Which boxes to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoxPick {
    /// The single BVH's depth, or each mesh BVH's (0: the root).
    pub depth: u32,
    /// Two levels: the top level's boxes at this depth (None: not drawn).
    pub top_depth: Option<u32>,
    /// Two levels: each mesh BVH's boxes at `depth`, placed by every instance.
    pub bottom: bool,
    /// Also the leaves shallower than the depth, which have no nodes at it.
    pub leaves_above: bool,
}

impl BoxPick {
    /// The app's defaults at `depth`: both levels, the top level at `DEFAULT_TOP_DEPTH` (or its
    /// deepest level if shallower), no leaves above.
    pub fn at(bvh: &SceneBvh, depth: u32) -> Self {
        let top_depth = max_depths(bvh).1.map_or(DEFAULT_TOP_DEPTH, |top| DEFAULT_TOP_DEPTH.min(top));
        Self { depth, top_depth: Some(top_depth), bottom: true, leaves_above: false }
    }
}

/// The deepest level of the boxes `BoxPick::depth` picks from (the single BVH's, else the deepest
/// of the mesh BVHs': the end of the app's depth slider), and of the top level (two levels).
pub fn max_depths(bvh: &SceneBvh) -> (u32, Option<u32>) {
    match bvh.two_level() {
        Some(t) => {
            let bottom = t.bottom.iter().map(|b| TreeStats::of(b).max_depth).max().unwrap_or(0);
            (bottom, Some(TreeStats::of(&t.top).max_depth))
        }
        None => (TreeStats::of(bvh.tree()).max_depth, None),
    }
}

/// The boxes of `bvh` that `pick` names: a single BVH's at its depth; for two levels the mesh
/// BVHs' boxes (placed by each instance) then the top level's.
pub fn boxes_at(bvh: &SceneBvh, pick: &BoxPick) -> Vec<NodeBox> {
    let world = |top: bool| move |(id, b): (usize, Aabb)| NodeBox { top, ..NodeBox::world(id, &b) };
    let Some(t) = bvh.two_level() else {
        return bvh.tree().boxes_at_depth(pick.depth, pick.leaves_above).into_iter().map(world(false)).collect();
    };
    let mut v = Vec::new();
    if pick.bottom {
        v.extend(t.bottom_boxes_at_depth(pick.depth, pick.leaves_above).into_iter().map(|b| NodeBox {
            id: b.id,
            corners: placed_corners(&b.bounds, &b.to_world),
            top: false,
        }));
    }
    if let Some(d) = pick.top_depth {
        v.extend(t.top.boxes_at_depth(d, pick.leaves_above).into_iter().map(world(true)));
    }
    v
}

/// A distinct, stable colour per node: golden-ratio hue steps at saturation 0.85 and value 1 in
/// linear light, in sRGB (the bytes egui's `Hsva::new(hue, 0.85, 1.0, 1.0)` makes).
pub fn node_rgb(node: usize) -> [u8; 3] {
    let h = (node as f32 * 0.618_034).fract();
    let (s, v) = (0.85f32, 1.0f32);
    let f = h * 6.0 - (h * 6.0).floor();
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - f * s), v * (1.0 - (1.0 - f) * s));
    let rgb = match (h * 6.0).floor() as i32 % 6 {
        0 => [v, t, p],
        1 => [q, v, p],
        2 => [p, v, t],
        3 => [p, q, v],
        4 => [t, p, v],
        _ => [v, p, q],
    };
    rgb.map(srgb_u8)
}

/// Linear [0, 1] to sRGB 0–255, as egui rounds it.
fn srgb_u8(l: f32) -> u8 {
    if l <= 0.0 {
        0
    } else if l <= 0.003_130_8 {
        (3294.6 * l + 0.5) as u8
    } else if l <= 1.0 {
        (269.025 * l.powf(1.0 / 2.4) - 14.025 + 0.5) as u8
    } else {
        255
    }
}

/// The colour of top-level boxes.
pub const TOP_RGB: [u8; 3] = [255, 255, 255];

/// Screen length of the pieces an edge is cut into for the depth test.
const PIECE: f32 = 3.0;

/// Whether a camera-space point drawn at `at` on an image of `size` lies in front of the surface
/// of `frame` there: no farther from the eye than the pixel's ray went (a miss is infinitely far;
/// a point off the image is kept). The 0.1% allowance keeps box faces that lie on the surface.
fn in_front(frame: &Frame, size: Vec2, point: Vec3, at: Vec2) -> bool {
    let (u, v) = (at.x / size.x, at.y / size.y);
    if !(0.0..1.0).contains(&u) || !(0.0..1.0).contains(&v) {
        return true;
    }
    let (x, y) = ((u * frame.width() as f32) as u32, (v * frame.height() as f32) as u32);
    point.length() <= frame.sample(x, y).t * 1.001
}

/// The segments of `boxes` seen by `camera` on an image of `size`: 12 edges a box, clipped to a
/// near plane just in front of the eye, each in its node's colour `width` wide (top-level boxes
/// white and twice as wide). Edges far outside the image are dropped. With `depth` (the frame
/// the image shows), only the pieces in front of its surface.
pub fn box_segments(boxes: &[NodeBox], camera: &Camera, size: Vec2, width: f32, depth: Option<&Frame>) -> Vec<Segment> {
    let extent =
        boxes.iter().flat_map(|b| b.corners).fold(Aabb::EMPTY, |acc, c| acc.grow(c)).extent().length().max(1e-6);
    let near = (extent * 1e-4).max((camera.position - camera.look_at).length() * 1e-4);
    let projector = Projector::new(camera, size, near);
    let margin = size.x.max(size.y);
    let (lo, hi) = (Vec2::splat(-margin), size + margin);
    let inside = |p: Vec2| p.cmpge(lo).all() && p.cmple(hi).all();
    let mut out = Vec::new();
    for b in boxes {
        let (rgb, width) = if b.top { (TOP_RGB, width * 2.0) } else { (node_rgb(b.id), width) };
        let mut push = |a: Vec2, b: Vec2| out.push(Segment { a, b, rgb, width });
        for (a, c) in projector.box_edges(&b.corners) {
            let (p, q) = (projector.to_image(a), projector.to_image(c));
            // Segments far outside the image are dropped; the drawing clips the rest.
            let (min, max) = (p.min(q), p.max(q));
            let overlaps = min.cmple(size).all() && max.cmpge(Vec2::ZERO).all();
            if !inside(p) && !inside(q) && !overlaps {
                continue;
            }
            let Some(frame) = depth else {
                push(p, q);
                continue;
            };
            // Pieces along the edge, interpolated in camera space (an image-space step is not a
            // fixed step in depth); each kept or dropped by its middle, runs merged into one.
            let pieces = ((q - p).length() / PIECE).ceil().clamp(1.0, 512.0) as usize;
            let at = |k: f32| a + (c - a) * (k / pieces as f32);
            let mut run: Option<Vec2> = None;
            for k in 0..pieces {
                let mid = at(k as f32 + 0.5);
                let visible = in_front(frame, size, mid, projector.to_image(mid));
                match (visible, run) {
                    (true, None) => run = Some(projector.to_image(at(k as f32))),
                    (false, Some(start)) => {
                        push(start, projector.to_image(at(k as f32)));
                        run = None;
                    }
                    _ => {}
                }
            }
            if let Some(start) = run {
                push(start, q);
            }
        }
    }
    out
}
