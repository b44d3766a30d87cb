//! The brute-force reference: test every triangle. Slow, obviously right, and the yardstick for
//! the BVH's correctness tests and the CLI's speedup column.

use super::{Accelerator, Hit, TraceOptions, TraversalStats};
use crate::geometry::{MollerTrumbore, Ray, TriangleIntersector, TriangleTest, Watertight};
use crate::mesh::Mesh;
use glam::Vec3;

pub struct LinearScan {
    tris: Vec<[Vec3; 3]>,
}

impl LinearScan {
    pub fn new(mesh: &Mesh) -> Self {
        Self { tris: (0..mesh.triangle_count() as u32).map(|i| mesh.triangle(i)).collect() }
    }

    fn closest<T: TriangleIntersector, S: TraversalStats>(&self, ray: &mut Ray, stats: &mut S) -> Option<Hit> {
        let p = T::prepare(ray);
        let mut best = None;
        stats.triangle_tests(self.tris.len() as u32);
        for (i, tri) in self.tris.iter().enumerate() {
            if let Some(h) = T::intersect(&p, ray, tri) {
                ray.t_max = h.t;
                best = Some(Hit { t: h.t, u: h.u, v: h.v, prim: i as u32 });
            }
        }
        best
    }

    fn any<T: TriangleIntersector, S: TraversalStats>(&self, ray: &Ray, stats: &mut S) -> bool {
        let p = T::prepare(ray);
        for (i, tri) in self.tris.iter().enumerate() {
            if T::intersect(&p, ray, tri).is_some() {
                stats.triangle_tests(i as u32 + 1);
                return true;
            }
        }
        stats.triangle_tests(self.tris.len() as u32);
        false
    }
}

impl Accelerator for LinearScan {
    fn closest_hit<S: TraversalStats>(&self, ray: &mut Ray, opts: TraceOptions, stats: &mut S) -> Option<Hit> {
        match opts.test {
            TriangleTest::Watertight => self.closest::<Watertight, S>(ray, stats),
            TriangleTest::MollerTrumbore => self.closest::<MollerTrumbore, S>(ray, stats),
        }
    }

    fn any_hit<S: TraversalStats>(&self, ray: &Ray, opts: TraceOptions, stats: &mut S) -> bool {
        match opts.test {
            TriangleTest::Watertight => self.any::<Watertight, S>(ray, stats),
            TriangleTest::MollerTrumbore => self.any::<MollerTrumbore, S>(ray, stats),
        }
    }
}
