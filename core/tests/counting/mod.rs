//! What the exact-count tests share: the rays' options, the midpoint tree of hand-placed
//! triangles, and running one ray both ways (closest and any hit).
#![allow(dead_code)]

use bvhscope_core::bvh::{Accelerator, BuildParams, RayCounters, Strategy, TraceOptions, TraversalOrder};
use bvhscope_core::geometry::{Ray, TriangleTest};
use bvhscope_core::mesh::Mesh;
use glam::Vec3;

pub const ORDERS: [TraversalOrder; 2] = [TraversalOrder::SplitAxisSign, TraversalOrder::EntryDistance];
pub const TESTS: [TriangleTest; 3] = TriangleTest::ALL;

/// Midpoint splits, one triangle per leaf: the tree follows from the centroids alone.
pub fn params() -> BuildParams {
    BuildParams { strategy: Strategy::Midpoint, max_leaf_size: 1, ..BuildParams::default() }
}

/// A triangle in the plane z = `z` with its centroid at (`x`, 0, `z`): corners (x ∓ 0.5, -0.5) and
/// (x, 1), so its box is x ± 0.5, y -0.5..1.
pub fn tri_at(positions: &mut Vec<Vec3>, x: f32, z: f32) -> [u32; 3] {
    let i = positions.len() as u32;
    positions.extend([Vec3::new(x - 0.5, -0.5, z), Vec3::new(x + 0.5, -0.5, z), Vec3::new(x, 1.0, z)]);
    [i, i + 1, i + 2]
}

pub fn counts(n: u32, b: u32, l: u32, t: u32) -> RayCounters {
    RayCounters { nodes_visited: n, box_tests: b, leaves_visited: l, triangle_tests: t, ..RayCounters::ZERO }
}

/// The closest hit's triangle and counters, and the any-hit answer and counters.
pub fn run(accel: &impl Accelerator, ray: &Ray, opts: TraceOptions) -> (Option<u32>, RayCounters, bool, RayCounters) {
    let (mut closest, mut any) = (RayCounters::ZERO, RayCounters::ZERO);
    let hit = accel.closest_hit(&mut ray.clone(), opts, &mut closest).map(|h| h.prim);
    let found = accel.any_hit(ray, opts, &mut any);
    (hit, closest, found, any)
}

/// Four triangles in a row along x (centroids x = 0, 2, 4, 6, all in z = 0), facing the rays.
///
/// Binary tree (midpoint of the centroids on x, the widest axis): root splits at 3 into A = {0, 2}
/// and B = {4, 6}; A at 1 into leaves T0 | T1, B at 5 into T2 | T3. Seven nodes, depth 2.
/// Wide tree: the root takes A and B, then opens B (the two have equal area; the later one wins
/// the tie), then A: one node with the four leaves as its children.
pub fn row() -> Mesh {
    let mut p = Vec::new();
    let tris = [0.0, 2.0, 4.0, 6.0].map(|x| tri_at(&mut p, x, 0.0)).to_vec();
    Mesh::from_triangles("row", p, tris)
}

/// Two triangles whose boxes overlap along the split axis, at different depths: TL (centroid
/// x = -1) wide, x -3..1, in z = -1.5; TR (centroid x = 1) small, x 0.5..1.5, in z = 0. The
/// centroids spread 2 in x and 1.5 in z, so the root splits on x: left TL, right TR.
pub fn overlapping() -> Mesh {
    let p = vec![
        Vec3::new(-3.0, -0.5, -1.5),
        Vec3::new(1.0, -0.5, -1.5),
        Vec3::new(-1.0, 1.0, -1.5),
        Vec3::new(0.5, -0.5, 0.0),
        Vec3::new(1.5, -0.5, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
    ];
    Mesh::from_triangles("overlapping", p, vec![[0, 1, 2], [3, 4, 5]])
}
