//! The CWBVH walk on the CPU, step for step what shaders/cwbvh.wgsl does, with core's own slab and
//! watertight tests: the reference the GPU's counts are tested against, and the source of CPU
//! per-ray counts for the warp view (`crate::warp`).
//!
//! The walk (Ylitie et al. 2017, §4): at a node, all eight child boxes are tested; the hit leaf
//! children's triangles are tested at once, nearest octant first; the hit interior children form a
//! group (a bit mask over the slots, in the ray's octant order) whose first child is entered and
//! whose rest goes on the stack as one entry. A popped group is entered without a distance test
//! (the paper keeps no distances), and its next child's boxes are tested against the closest hit.
//!
//! Counts, consistent with core's wide layouts (`bvh::wide`): one box test for the root's box, a
//! node visit per wide node entered with one box test per valid child slot, a leaf visit per leaf
//! child whose triangles are tested, and every triangle tested.

use super::Cwbvh;
use bvhscope_core::bvh::{Hit, RayCounters};
use bvhscope_core::geometry::slab::{widen, OneRay};
use bvhscope_core::geometry::{
    MollerTrumbore, MollerTrumboreStored, Ray, TriangleIntersector, TriangleTest, Watertight,
};

impl Cwbvh {
    /// The octant of `ray`'s direction: bit k set when its reciprocal is negative on axis k (-0
    /// included), as the GPU finds it. Child slot s is visited in the order of s ^ octant.
    pub fn octant(ray: &Ray) -> u32 {
        let inv = ray.inv_dir();
        (inv.x.is_sign_negative() as u32)
            | (inv.y.is_sign_negative() as u32) << 1
            | (inv.z.is_sign_negative() as u32) << 2
    }

    /// The closest hit of `ray` (its `t_max` shrunk to it) and the walk's counts, with the
    /// triangle test `test` (the GPU's `TEST` switch).
    pub fn trace_cpu(&self, ray: &mut Ray, test: TriangleTest) -> (Option<Hit>, RayCounters) {
        match test {
            TriangleTest::Watertight => self.walk_cpu::<Watertight>(ray),
            TriangleTest::MollerTrumbore => self.walk_cpu::<MollerTrumbore>(ray),
            TriangleTest::MollerTrumboreStored => self.walk_cpu::<MollerTrumboreStored>(ray),
        }
    }

    /// The closest hit of `ray` (its `t_max` shrunk to it) and the walk's counts.
    fn walk_cpu<T: TriangleIntersector>(&self, ray: &mut Ray) -> (Option<Hit>, RayCounters) {
        let mut c = RayCounters::default();
        let slab = OneRay::new(ray);
        let mut limit = widen(ray.t_max);
        c.box_tests += 1;
        let (lo, hi) = self.root_bounds.planes();
        let (t0, t1) = slab.one_box(&lo, &hi, ray.t_min, limit);
        if !(t0 <= t1) || self.prim_ids.is_empty() {
            return (None, c);
        }
        let oct = Self::octant(ray);
        let shear = T::prepare(ray);
        let mut best: Option<(usize, bvhscope_core::geometry::TriangleHit)> = None;
        let mut stack: Vec<(u32, u32, u32)> = Vec::new(); // (child base, interior bits by key, imask)
        let mut cur = 0usize;
        loop {
            let n = &self.nodes[cur];
            c.nodes_visited += 1;
            c.box_tests += n.valid().count_ones();
            let (mut inner, mut leaves) = (0u32, 0u32);
            for s in 0..8 {
                if n.meta[s] == 0 {
                    continue;
                }
                let (lo, hi) = n.child_box(s);
                let (t0, t1) = slab.one_box(&lo, &hi, ray.t_min, limit);
                if t0 <= t1 {
                    let key = s as u32 ^ oct;
                    if n.is_interior(s) {
                        inner |= 1 << key;
                    } else {
                        leaves |= 1 << key;
                    }
                }
            }
            while leaves != 0 {
                let s = (leaves.trailing_zeros() ^ oct) as usize;
                leaves &= leaves - 1;
                let [first, count] = self.leaves[n.leaf(s) as usize];
                c.leaves_visited += 1;
                for i in first as usize..(first + count) as usize {
                    if let Some(h) = T::intersect(&shear, ray, &self.tris[i]) {
                        ray.t_max = h.t;
                        best = Some((i, h));
                    }
                }
                c.triangle_tests += count;
                limit = widen(ray.t_max);
            }
            let (base, mut bits, imask) = if inner != 0 {
                (n.child_base, inner, n.imask as u32)
            } else {
                match stack.pop() {
                    Some(g) => g,
                    None => break,
                }
            };
            let s = bits.trailing_zeros() ^ oct;
            bits &= bits - 1;
            cur = (base + (imask & ((1u32 << s) - 1)).count_ones()) as usize;
            if bits != 0 {
                stack.push((base, bits, imask));
            }
        }
        (best.map(|(i, h)| Hit { t: h.t, u: h.u, v: h.v, prim: self.prim_ids[i] }), c)
    }
}
