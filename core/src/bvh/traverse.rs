//! BVH traversal: closest hit and any hit, with a fixed-size stack, near child first.
//!
//! At an interior node both children's boxes are tested; a child the ray misses, or enters beyond
//! the closest hit so far, is never visited. Of two hit children the near one is visited next and
//! the far one pushed with its entry distance, which is checked again when it is popped (the hit
//! found meanwhile may make it useless). Near is chosen by the handout's rule (direction sign on the
//! split axis) or by the entry distance; both are compiled as separate loops (`BY_DISTANCE`), as are
//! the triangle test (`T`) and the statistics sink (`S`), so none of the choices costs a branch
//! per node. Layout and loop follow pbrt-v4 §7.3.5 ("BVHAggregate::Intersect").

use super::node::{Bvh, TRAVERSAL_STACK_SIZE};
use super::stack::TraversalStack;
use super::{Accelerator, Hit, TraceOptions, TraversalOrder, TraversalStats};
use crate::geometry::{MollerTrumbore, Ray, TriangleIntersector, TriangleTest, Watertight};

impl Bvh {
    fn closest<T: TriangleIntersector, const BY_DISTANCE: bool, const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        let nodes = &self.nodes[..];
        let (origin, inv_dir) = (ray.origin(), ray.inv_dir());
        // Which child is near under the handout's rule, per axis: a negative direction component
        // (including -0) means the right child (larger coordinates) is met first.
        let dir_neg = [inv_dir.x.is_sign_negative(), inv_dir.y.is_sign_negative(), inv_dir.z.is_sign_negative()];
        stats.box_tests(1);
        let (t0, t1) = nodes[0].bounds.slab(origin, inv_dir, ray.t_min, ray.t_max);
        if !(t0 <= t1) {
            return None;
        }
        // The triangle test's per-ray setup waits for the first leaf: most rays that miss never
        // reach one.
        let mut prepared: Option<T::Prepared> = None;
        let mut best: Option<(usize, crate::geometry::TriangleHit)> = None;
        let mut stack = TraversalStack::<TRAVERSAL_STACK_SIZE>::new();
        let mut current = 0usize;
        loop {
            let node = &nodes[current];
            stats.node_visited();
            if node.is_leaf() {
                stats.leaf_visited();
                stats.triangle_tests(node.count as u32);
                for i in node.prims() {
                    if let Some(h) = T::intersect(prepared.get_or_insert_with(|| T::prepare(ray)), ray, &self.tris[i]) {
                        ray.t_max = h.t;
                        best = Some((i, h));
                        if ANY {
                            break;
                        }
                    }
                }
                if ANY && best.is_some() {
                    break;
                }
            } else {
                let left = node.index as usize;
                stats.box_tests(2);
                let (l0, l1) = nodes[left].bounds.slab(origin, inv_dir, ray.t_min, ray.t_max);
                let (r0, r1) = nodes[left + 1].bounds.slab(origin, inv_dir, ray.t_min, ray.t_max);
                let hit_l = l0 <= l1;
                let hit_r = r0 <= r1;
                if hit_l && hit_r {
                    let right_first = if BY_DISTANCE { r0 < l0 } else { dir_neg[node.axis as usize] };
                    let (near, far, far_t) = if right_first { (left + 1, left, l0) } else { (left, left + 1, r0) };
                    stack.push((far as u32, far_t));
                    current = near;
                    continue;
                } else if hit_l {
                    current = left;
                    continue;
                } else if hit_r {
                    current = left + 1;
                    continue;
                }
            }
            // The next node that can still hold a hit nearer than the best so far.
            match stack.pop_nearer(ray.t_max) {
                Some(n) => current = n as usize,
                None => break,
            }
        }
        best.map(|(i, h)| Hit { t: h.t, u: h.u, v: h.v, prim: self.prim_ids[i] })
    }

    fn dispatch<const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut Ray,
        opts: TraceOptions,
        stats: &mut S,
    ) -> Option<Hit> {
        use TraversalOrder::*;
        match (opts.test, opts.order) {
            (TriangleTest::Watertight, EntryDistance) => self.closest::<Watertight, true, ANY, S>(ray, stats),
            (TriangleTest::Watertight, SplitAxisSign) => self.closest::<Watertight, false, ANY, S>(ray, stats),
            (TriangleTest::MollerTrumbore, EntryDistance) => self.closest::<MollerTrumbore, true, ANY, S>(ray, stats),
            (TriangleTest::MollerTrumbore, SplitAxisSign) => self.closest::<MollerTrumbore, false, ANY, S>(ray, stats),
        }
    }
}

impl Accelerator for Bvh {
    fn closest_hit<S: TraversalStats>(&self, ray: &mut Ray, opts: TraceOptions, stats: &mut S) -> Option<Hit> {
        self.dispatch::<false, S>(ray, opts, stats)
    }

    fn any_hit<S: TraversalStats>(&self, ray: &Ray, opts: TraceOptions, stats: &mut S) -> bool {
        let mut r = *ray;
        self.dispatch::<true, S>(&mut r, opts, stats).is_some()
    }

    fn traces_packets(&self) -> bool {
        true
    }

    fn closest_hits(&self, rays: &mut [Ray], hits: &mut [Option<Hit>], opts: TraceOptions) {
        crate::bvh::packet::closest_hits_packet(self, rays, hits, opts)
    }
}
