//! The brute-force reference: test every triangle. Slow, obviously right, and the yardstick for
//! the BVH's correctness tests and the CLI's speedup column.

use crate::bvh::accel::{Accelerator, Hit};
use crate::bvh::counters::TraversalStats;
use crate::geometry::{Ray, TriangleIntersector};
use crate::mesh::Mesh;
use glam::Vec3;

pub struct LinearScan {
    tris: Vec<[Vec3; 3]>,
}

impl LinearScan {
    pub fn new(mesh: &Mesh) -> Self {
        Self { tris: (0..mesh.triangle_count() as u32).map(|i| mesh.triangle(i)).collect() }
    }
}

impl Accelerator for LinearScan {
    /// Every triangle, in order (the near-child rule has nothing to order); an any-hit query
    /// stops at the first hit and counts the tests it made.
    fn trace<T: TriangleIntersector, const BY_DISTANCE: bool, const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        let (mut prepared, mut best) = (None, None);
        let id = |i: usize| i as u32;
        crate::bvh::traverse::test_triangles::<T, ANY, S>(&self.tris, 0, ray, stats, &mut prepared, &mut best, id);
        best.map(|(i, h)| Hit { t: h.t, u: h.u, v: h.v, prim: i as u32 })
    }
}
