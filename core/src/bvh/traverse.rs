//! The binary BVH's walk, written once: ordered stack traversal with a fixed-size stack, near
//! child first (pbrt-v4 §7.3.5, "BVHAggregate::Intersect"). The mesh BVH (triangles at its leaves)
//! and the two-level BVH's top level (placements at its leaves) both walk with it; what happens at
//! a leaf is the caller's closure, and what is counted is the statistics sink's.
//!
//! At an interior node both children's boxes are tested; a child the ray misses, or enters beyond
//! the closest hit so far, is never visited. Of two hit children the near one is visited next and
//! the far one pushed with its entry distance, which is checked again when it is popped (the hit
//! found meanwhile may make it useless). Near is chosen by the handout's rule (direction sign on the
//! split axis) or by the entry distance, compiled as separate loops (`BY_DISTANCE`).

use super::node::{Bvh, BvhNode, TRAVERSAL_STACK_SIZE};
use super::stack::TraversalStack;
use crate::bvh::accel::{Accelerator, Hit, TraceOptions};
use crate::bvh::counters::{NodeId, TraversalStats};
use crate::geometry::slab::{widen, OneRay};
use crate::geometry::{Ray, TriangleHit, TriangleIntersector};
use std::ops::Range;

/// Which level of a hierarchy a walk is on, for the counters: a mesh's BVH, or the top level of a
/// two-level BVH, whose visits a sink may also count apart (`top_node_visited`).
pub(crate) trait Level {
    fn node_visited<S: TraversalStats>(stats: &mut S);
    fn box_tests<S: TraversalStats>(stats: &mut S, n: u32);
    fn leaf_visited<S: TraversalStats>(stats: &mut S);
}

/// A mesh's BVH: leaves hold triangles.
pub(crate) enum MeshLevel {}

impl Level for MeshLevel {
    #[inline(always)]
    fn node_visited<S: TraversalStats>(stats: &mut S) {
        stats.node_visited();
    }
    #[inline(always)]
    fn box_tests<S: TraversalStats>(stats: &mut S, n: u32) {
        stats.box_tests(n);
    }
    #[inline(always)]
    fn leaf_visited<S: TraversalStats>(stats: &mut S) {
        stats.leaf_visited();
    }
}

/// The top level of a two-level BVH: leaves hold placements (counted as instances entered).
pub(crate) enum TopLevelWalk {}

impl Level for TopLevelWalk {
    #[inline(always)]
    fn node_visited<S: TraversalStats>(stats: &mut S) {
        stats.top_node_visited();
    }
    #[inline(always)]
    fn box_tests<S: TraversalStats>(stats: &mut S, n: u32) {
        stats.top_box_tests(n);
    }
    #[inline(always)]
    fn leaf_visited<S: TraversalStats>(_: &mut S) {}
}

/// Walk `nodes` (node 0 the root) nearest first. `leaf(range, ray, stats)` is called for every
/// leaf reached, with the leaf's range of primitive slots; it may shrink `ray.t_max` (a nearer hit
/// prunes what is left) and returns true to stop the walk (an any-hit query that found one).
#[inline(always)]
pub(crate) fn walk<L: Level, const BY_DISTANCE: bool, S: TraversalStats>(
    nodes: &[BvhNode],
    ray: &mut Ray,
    stats: &mut S,
    leaf: impl FnMut(Range<usize>, &mut Ray, &mut S) -> bool,
) {
    walk_from::<L, BY_DISTANCE, S>(nodes, 0, ray, stats, leaf)
}

/// `walk` of the subtree under node `root` (its box tested first, as the root's is).
#[inline(always)]
pub(crate) fn walk_from<L: Level, const BY_DISTANCE: bool, S: TraversalStats>(
    nodes: &[BvhNode],
    root: usize,
    ray: &mut Ray,
    stats: &mut S,
    mut leaf: impl FnMut(Range<usize>, &mut Ray, &mut S) -> bool,
) {
    let inv_dir = ray.inv_dir();
    let slab_ray = OneRay::new(ray);
    // The closest hit so far, widened: what boxes and stack entries are compared with.
    let mut limit = widen(ray.t_max);
    // Which child is near under the handout's rule, per axis: a negative direction component
    // (including -0) means the right child (larger coordinates) is met first.
    let dir_neg = [inv_dir.x.is_sign_negative(), inv_dir.y.is_sign_negative(), inv_dir.z.is_sign_negative()];
    L::box_tests(stats, 1);
    let (t0, t1) = nodes[root].slab(&slab_ray, ray.t_min, limit);
    if S::STEPS {
        stats.step_box(NodeId::Node(root as u32), (t0 <= t1).then_some((t0, t1)));
    }
    if !(t0 <= t1) {
        return;
    }
    let mut stack = TraversalStack::<TRAVERSAL_STACK_SIZE>::new();
    let mut current = root;
    loop {
        let node = &nodes[current];
        L::node_visited(stats);
        if S::STEPS {
            stats.step_enter(NodeId::Node(current as u32));
        }
        if node.is_leaf() {
            L::leaf_visited(stats);
            if S::STEPS {
                stats.step_leaf(NodeId::Node(current as u32));
            }
            if leaf(node.prims(), ray, stats) {
                return;
            }
            limit = widen(ray.t_max);
        } else {
            let left = node.index as usize;
            L::box_tests(stats, 2);
            let (l0, l1) = nodes[left].slab(&slab_ray, ray.t_min, limit);
            let (r0, r1) = nodes[left + 1].slab(&slab_ray, ray.t_min, limit);
            if S::STEPS {
                stats.step_box(NodeId::Node(left as u32), (l0 <= l1).then_some((l0, l1)));
                stats.step_box(NodeId::Node(left as u32 + 1), (r0 <= r1).then_some((r0, r1)));
            }
            match (l0 <= l1, r0 <= r1) {
                (true, true) => {
                    let right_first = if BY_DISTANCE { r0 < l0 } else { dir_neg[node.axis as usize] };
                    let (near, far, far_t) = if right_first { (left + 1, left, l0) } else { (left, left + 1, r0) };
                    stack.push((far as u32, far_t));
                    if S::STEPS {
                        report_stack(stats, &stack);
                    }
                    current = near;
                    continue;
                }
                (true, false) => {
                    current = left;
                    continue;
                }
                (false, true) => {
                    current = left + 1;
                    continue;
                }
                (false, false) => {}
            }
        }
        // The next node that can still hold a hit nearer than the best so far.
        let next = stack.pop_nearer_or_skip(limit, |n, t| {
            if S::STEPS {
                stats.step_skip(NodeId::Node(n), t);
            }
        });
        if S::STEPS {
            report_stack(stats, &stack);
        }
        match next {
            Some(n) => current = n as usize,
            None => return,
        }
    }
}

/// Tell a tracing sink what the binary walk's stack holds.
fn report_stack<S: TraversalStats, const N: usize>(stats: &mut S, stack: &TraversalStack<N>) {
    let top: Vec<(NodeId, f32)> =
        stack.top(super::counters::REPORTED_STACK).iter().map(|&(n, t)| (NodeId::Node(n), t)).collect();
    stats.step_stack(stack.len(), &top);
}

/// Test a leaf's triangles `tris` (slot `first` onwards in leaf order) against the ray: each
/// nearer hit shrinks `ray.t_max` and is kept in `best`; an any-hit query stops at the first. The
/// triangle tests actually made are counted (an any-hit that stops early counts no more). The
/// triangle test's per-ray setup waits in `prepared` for the first leaf: most rays that miss never
/// reach one. `prim_of` names a slot's triangle for a trace. Shared by the binary and the wide walk
/// and the linear scan.
#[inline(always)]
pub(crate) fn test_triangles<T: TriangleIntersector, const ANY: bool, S: TraversalStats>(
    tris: &[[glam::Vec3; 3]],
    first: usize,
    ray: &mut Ray,
    stats: &mut S,
    prepared: &mut Option<T::Prepared>,
    best: &mut Option<(usize, crate::geometry::TriangleHit)>,
    prim_of: impl Fn(usize) -> u32,
) -> bool {
    for (k, tri) in tris.iter().enumerate() {
        let hit = T::intersect(prepared.get_or_insert_with(|| T::prepare(ray)), ray, tri);
        if S::STEPS {
            stats.step_triangle(prim_of(first + k), hit);
        }
        if let Some(h) = hit {
            ray.t_max = h.t;
            *best = Some((first + k, h));
            if ANY {
                stats.triangle_tests(k as u32 + 1);
                return true;
            }
        }
    }
    stats.triangle_tests(tris.len() as u32);
    false
}

/// How a leaf stored coordinate by coordinate (`wide::leaves`) is tested: `N` triangles per SIMD
/// pass: four with every kernel (`Groups4`), eight with AVX2 (`Groups8`), sixteen with AVX-512 (`Groups16`).
pub(crate) trait LeafGroups: Copy {
    const N: usize;
    /// One pass's hits (`Hits4`, `Hits16`).
    type Hits: Copy;
    /// Triangles `N·g..N·g + N` (those below `count`) against the ray.
    fn test<T: TriangleIntersector>(
        self,
        p: &T::Prepared,
        ray: &Ray,
        coords: &[f32],
        count: usize,
        g: usize,
    ) -> Self::Hits;
    /// The mask of the lanes hit.
    fn mask(h: &Self::Hits) -> u32;
    /// Lane k's hit (meaningful where its bit of the mask is set).
    fn lane(h: &Self::Hits, k: usize) -> TriangleHit;
}

/// Four triangles per pass (`TriangleIntersector::intersect_group_coords`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Groups4;

impl LeafGroups for Groups4 {
    const N: usize = 4;
    type Hits = crate::geometry::triangle::Hits4;
    #[inline(always)]
    fn test<T: TriangleIntersector>(
        self,
        p: &T::Prepared,
        ray: &Ray,
        coords: &[f32],
        count: usize,
        g: usize,
    ) -> crate::geometry::triangle::Hits4 {
        T::intersect_group_coords(p, ray, coords, count, g)
    }
    #[inline(always)]
    fn mask(h: &crate::geometry::triangle::Hits4) -> u32 {
        h.mask
    }
    #[inline(always)]
    fn lane(h: &crate::geometry::triangle::Hits4, k: usize) -> TriangleHit {
        TriangleHit { t: h.t[k], u: h.u[k], v: h.v[k] }
    }
}

/// Sixteen triangles per pass with AVX-512 (`TriangleIntersector::intersect_group16_coords`).
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Groups16(pub crate::geometry::avx512::Avx512);

#[cfg(target_arch = "x86_64")]
impl LeafGroups for Groups16 {
    const N: usize = 16;
    type Hits = crate::geometry::avx512::Hits16;
    #[inline(always)]
    fn test<T: TriangleIntersector>(
        self,
        p: &T::Prepared,
        ray: &Ray,
        coords: &[f32],
        count: usize,
        g: usize,
    ) -> crate::geometry::avx512::Hits16 {
        if count <= 4 {
            // A leaf of up to four: the four-lane pass, inlined into the walk, costs no more than
            // a masked AVX-512 one, and that one is a call (`watertight_leaf16`).
            let h = T::intersect_group_coords(p, ray, coords, count, 0);
            let mut hits = crate::geometry::avx512::Hits16 { mask: h.mask, ..crate::geometry::avx512::Hits16::NONE };
            hits.t[..4].copy_from_slice(&h.t);
            hits.u[..4].copy_from_slice(&h.u);
            hits.v[..4].copy_from_slice(&h.v);
            return hits;
        }
        T::intersect_group16_coords(self.0, p, ray, coords, count, g)
    }
    #[inline(always)]
    fn mask(h: &crate::geometry::avx512::Hits16) -> u32 {
        h.mask
    }
    #[inline(always)]
    fn lane(h: &crate::geometry::avx512::Hits16, k: usize) -> TriangleHit {
        TriangleHit { t: h.t[k], u: h.u[k], v: h.v[k] }
    }
}

/// Eight triangles per pass with AVX2 (`TriangleIntersector::intersect_group8_coords`).
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Groups8(pub crate::geometry::slab8::Avx2);

#[cfg(target_arch = "x86_64")]
impl LeafGroups for Groups8 {
    const N: usize = 8;
    type Hits = crate::geometry::triangle8::Hits8;
    #[inline(always)]
    fn test<T: TriangleIntersector>(
        self,
        p: &T::Prepared,
        ray: &Ray,
        coords: &[f32],
        count: usize,
        g: usize,
    ) -> crate::geometry::triangle8::Hits8 {
        T::intersect_group8_coords(self.0, p, ray, coords, count, g)
    }
    #[inline(always)]
    fn mask(h: &crate::geometry::triangle8::Hits8) -> u32 {
        h.mask
    }
    #[inline(always)]
    fn lane(h: &crate::geometry::triangle8::Hits8, k: usize) -> TriangleHit {
        TriangleHit { t: h.t[k], u: h.u[k], v: h.v[k] }
    }
}

/// `test_triangles` `L::N` triangles at a time, each group in one SIMD pass. The lanes are then
/// taken in order against the closest hit so far, as the one-by-one loop takes them, so the same
/// hits are reported and the same closest hit kept, bit for bit. Counts are the one-by-one loop's
/// too, so that no count depends on the CPU: every triangle of the leaf for a closest hit; for an
/// any-hit query, the triangles up to the one that hit (the SIMD pass computed the rest of its
/// group, unused). The `count` triangles come from the 8-wide layout's leaf storage: `coords` are
/// the floats from the leaf's first one on, coordinate by coordinate (`wide::leaves`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn test_triangles_grouped<T: TriangleIntersector, const ANY: bool, S: TraversalStats, L: LeafGroups>(
    groups: L,
    coords: &[f32],
    count: usize,
    first: usize,
    ray: &mut Ray,
    stats: &mut S,
    prepared: &mut Option<T::Prepared>,
    best: &mut Option<(usize, TriangleHit)>,
    prim_of: impl Fn(usize) -> u32,
) -> bool {
    let p = *prepared.get_or_insert_with(|| T::prepare(ray));
    for g in 0..count.div_ceil(L::N) {
        let hits = groups.test::<T>(&p, ray, coords, count, g);
        let mask = L::mask(&hits);
        if mask == 0 && !S::STEPS {
            continue;
        }
        // The lanes to take: every one of the group where each step is reported, else only those
        // hit (a lane missed then changes nothing: a leaf of sixteen with one hit takes one turn).
        let lanes = ((1u64 << (count - L::N * g).min(L::N)) - 1) as u32;
        let mut todo = if S::STEPS { lanes } else { mask & lanes };
        while todo != 0 {
            let k = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let hit = (mask & (1 << k) != 0).then(|| L::lane(&hits, k)).filter(|h| h.t < ray.t_max);
            let i = first + L::N * g + k;
            if S::STEPS {
                stats.step_triangle(prim_of(i), hit);
            }
            if let Some(h) = hit {
                ray.t_max = h.t;
                *best = Some((i, h));
                if ANY {
                    stats.triangle_tests((L::N * g + k + 1) as u32);
                    return true;
                }
            }
        }
    }
    stats.triangle_tests(count as u32);
    false
}

impl Accelerator for Bvh {
    fn trace<T: TriangleIntersector, const BY_DISTANCE: bool, const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        let (mut prepared, mut best) = (None, None);
        walk::<MeshLevel, BY_DISTANCE, S>(&self.nodes, ray, stats, |range, ray, stats| {
            let first = range.start;
            let ids = |i: usize| self.prim_ids[i];
            test_triangles::<T, ANY, S>(&self.tris[range], first, ray, stats, &mut prepared, &mut best, ids)
        });
        best.map(|(i, h)| Hit { t: h.t, u: h.u, v: h.v, prim: self.prim_ids[i] })
    }

    fn traces_packets(&self) -> bool {
        true
    }

    fn closest_hits(&self, rays: &mut [Ray], hits: &mut [Option<Hit>], opts: TraceOptions) {
        crate::bvh::packet::walk::closest_hits_packet(self, rays, hits, opts)
    }

    fn any_hits(&self, rays: &[Ray], occluded: &mut [bool], opts: TraceOptions) {
        crate::bvh::packet::walk::any_hits_packet(self, rays, occluded, opts)
    }
}
