//! The wide BVHs' walk, written once for four and eight children: one SIMD slab test for the child
//! boxes of a node (a `geometry::slab::SlabKernel`: four lanes, or eight with AVX2 or AVX-512 where
//! the CPU has it, chosen per tree from `crate::cpu`), hit children visited nearest first. The common cases take few
//! branches: one child hit is entered directly, two are ordered by one comparison; only three or
//! more hits are sorted (on the stack). Leaves travel through the same path as nodes, as child
//! references (`ChildRef`; the loop layout of Embree's BVH4 traversal, Wald et al., "Embree: A
//! Kernel Framework for Efficient CPU Ray Tracing", SIGGRAPH 2014). What happens at a leaf is the
//! caller's closure. Counters: a node visit counts once, its box tests count per valid child (so
//! wide and binary heatmaps measure the same work). A child pushed on the stack is prefetched
//! into the cache: incoherent rays wait on memory, and by the time it is popped its node has
//! arrived (BENCHMARKS.md, sixth round).

use crate::bvh::accel::{Accelerator, Hit, TraceOptions};
use crate::bvh::counters::{NodeId, TraversalStats};
use crate::bvh::stack::TraversalStack;
use crate::bvh::traverse::{test_triangles, test_triangles_grouped, Groups4, LeafGroups};
use crate::bvh::wide::node::WideNode;
use crate::bvh::wide::wide_bvh::{ChildRef, WideBvh};
use crate::cpu::Simd;
use crate::geometry::slab::{widen, Scalar, Simd4, SlabKernel};
use crate::geometry::{Ray, TriangleIntersector};

/// The fixed part of the stack: at most W − 1 pushes per level of a tree built by bvhscope (the
/// build bounds the depth by `TRAVERSAL_STACK_SIZE`); a deeper imported tree spills onto the heap.
pub(super) const STACK: usize = 3 * crate::bvh::TRAVERSAL_STACK_SIZE + 4;
const STACK8: usize = 7 * crate::bvh::TRAVERSAL_STACK_SIZE + 8;

/// Ask the CPU to start loading `p` (a node or triangle the walk will probably visit soon) into
/// the cache. Incoherent rays spend much of their time waiting for memory, and a child pushed on
/// the stack is popped tens of nodes later. A hint only: it never changes a result.
#[inline(always)]
fn prefetch<T>(p: &T) {
    #[cfg(target_arch = "x86_64")]
    for line in (0..std::mem::size_of::<T>()).step_by(64) {
        // SAFETY: a prefetch never faults and reads nothing into the program; the address lies
        // inside `*p`, a live reference.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            _mm_prefetch::<_MM_HINT_T0>((p as *const T).cast::<i8>().add(line));
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

impl<const W: usize> WideBvh<W> {
    /// Start loading a child that goes on the stack: the node, or the first cache line of a leaf's
    /// data as the walk's test reads it (`leaves`, `per` floats a triangle: `walk_ray`).
    #[inline(always)]
    fn prefetch_child(&self, node: &WideNode<W>, slot: usize, leaves: &[f32], per: usize) {
        let i = node.child[slot] as usize;
        if node.count[slot] > 0 {
            if let Some(t) = leaves.get(per * i) {
                prefetch(t);
            }
        } else if let Some(n) = self.nodes.get(i) {
            prefetch(n);
        }
    }

    /// Walk the tree nearest child first. `leaf(first, count, ray, stats)` is called for every
    /// leaf reached (its triangles `first..first + count` in leaf order); it may shrink
    /// `ray.t_max` and returns true to stop the walk.
    /// `kernel` tests a node's child boxes; `N` is the stack's size (`STACK` for four children).
    /// `leaves` are the leaves' floats as `leaf` reads them, `per` a triangle, from which a
    /// pushed leaf is prefetched.
    #[inline(always)]
    pub(crate) fn walk_ray<S: TraversalStats, K: SlabKernel<W>, const N: usize>(
        &self,
        kernel: K,
        (leaves, per): (&[f32], usize),
        ray: &mut Ray,
        stats: &mut S,
        mut leaf: impl FnMut(usize, usize, &mut Ray, &mut S) -> bool,
    ) {
        stats.box_tests(1);
        if S::STEPS {
            stats.step_box(NodeId::Node(0), self.root_bounds.intersect(ray).filter(|_| !self.prim_ids.is_empty()));
        }
        if self.prim_ids.is_empty() || self.root_bounds.intersect(ray).is_none() {
            return;
        }
        let sray = kernel.prepare(ray);
        // The closest hit so far, widened: what boxes and stack entries are compared with.
        let mut limit = widen(ray.t_max);
        let t_min = ray.t_min;
        let mut stack = TraversalStack::<N>::new();
        let mut cur = ChildRef::ROOT;
        'traversal: loop {
            // Descend through interior nodes until a leaf is reached or nothing is hit.
            while !cur.is_leaf() {
                let index = cur.node();
                let node = &self.nodes[index as usize];
                if S::STEPS {
                    stats.step_enter(NodeId::Node(index));
                }
                stats.node_visited();
                stats.box_tests(node.valid.count_ones());
                let (enter, mask) = kernel.test(&sray, &node.boxes, node.valid as u32, t_min, limit);
                if S::STEPS {
                    self.report_boxes(stats, node, index, mask, &enter, ray, limit);
                }
                if mask == 0 {
                    // Nothing hit here: continue with the nearest useful entry of the stack.
                    match self.pop(&mut stack, limit, stats) {
                        Some(r) => {
                            cur = ChildRef::from_raw(r);
                            continue 'traversal;
                        }
                        None => break 'traversal,
                    }
                }
                let s0 = mask.trailing_zeros() as usize;
                let rest = mask & (mask - 1);
                if rest == 0 {
                    cur = ChildRef::of(node, index, s0);
                    continue;
                }
                let s1 = rest.trailing_zeros() as usize;
                let rest2 = rest & (rest - 1);
                if rest2 == 0 {
                    // Both references first: they do not wait for the comparison.
                    let (r0, r1) = (ChildRef::of(node, index, s0), ChildRef::of(node, index, s1));
                    if enter[s0] <= enter[s1] {
                        self.prefetch_child(node, s1, leaves, per);
                        stack.push((r1.raw(), enter[s1]));
                        cur = r0;
                    } else {
                        self.prefetch_child(node, s0, leaves, per);
                        stack.push((r0.raw(), enter[s0]));
                        cur = r1;
                    }
                    if S::STEPS {
                        report_stack::<S, W, N>(stats, &stack);
                    }
                    continue;
                }
                // Three or more children hit: push them all, nearest on top, and take it.
                let mut m = mask;
                let mut k = 0;
                while m != 0 {
                    let slot = m.trailing_zeros() as usize;
                    m &= m - 1;
                    self.prefetch_child(node, slot, leaves, per);
                    stack.push((ChildRef::of(node, index, slot).raw(), enter[slot]));
                    k += 1;
                }
                stack.sort_top(k);
                if S::STEPS {
                    report_stack::<S, W, N>(stats, &stack);
                }
                cur = match stack.pop() {
                    Some((r, _)) => ChildRef::from_raw(r),
                    None => break 'traversal,
                };
                if S::STEPS {
                    report_stack::<S, W, N>(stats, &stack);
                }
            }
            let (index, slot) = cur.leaf::<W>();
            let node = &self.nodes[index];
            stats.leaf_visited();
            if S::STEPS {
                stats.step_leaf(node_id::<W>(cur));
            }
            if leaf(node.child[slot] as usize, node.count[slot] as usize, ray, stats) {
                break 'traversal;
            }
            limit = widen(ray.t_max);
            match self.pop(&mut stack, limit, stats) {
                Some(r) => cur = ChildRef::from_raw(r),
                None => break 'traversal,
            }
        }
    }
}

impl<const W: usize> WideBvh<W> {
    /// `pop_nearer`, telling a tracing sink what it skips and what the stack then holds.
    #[inline(always)]
    fn pop<S: TraversalStats, const N: usize>(
        &self,
        stack: &mut TraversalStack<N>,
        limit: f32,
        stats: &mut S,
    ) -> Option<u32> {
        let next = stack.pop_nearer_or_skip(limit, |r, t| {
            if S::STEPS {
                stats.step_skip(node_id::<W>(ChildRef::from_raw(r)), t);
            }
        });
        if S::STEPS {
            report_stack::<S, W, N>(stats, stack);
        }
        next
    }

    /// Tell a tracing sink the box test of each valid child of `node` (number `index`): hit or
    /// not as the SIMD test found, with the entry it computed; the exit, which the SIMD test does
    /// not return, from the one-box test of the same slab module.
    #[allow(clippy::too_many_arguments)]
    fn report_boxes<S: TraversalStats>(
        &self,
        stats: &mut S,
        node: &WideNode<W>,
        index: u32,
        mask: u32,
        enter: &[f32; W],
        ray: &Ray,
        limit: f32,
    ) {
        for slot in node.slots() {
            let child = node_id::<W>(ChildRef::of(node, index, slot));
            let hit = mask & (1 << slot) != 0;
            let mut r = *ray;
            r.t_max = limit;
            let exit = node.boxes.bounds(slot).intersect(&r).map_or(enter[slot], |i| i.1);
            stats.step_box(child, hit.then_some((enter[slot], exit)));
        }
    }
}

/// The trace's name of a child reference.
fn node_id<const W: usize>(r: ChildRef) -> NodeId {
    if r.is_leaf() {
        let (node, slot) = r.leaf::<W>();
        NodeId::Leaf { node: node as u32, slot: slot as u8 }
    } else {
        NodeId::Node(r.node())
    }
}

/// Tell a tracing sink what the wide walk's stack holds.
fn report_stack<S: TraversalStats, const W: usize, const N: usize>(stats: &mut S, stack: &TraversalStack<N>) {
    let top: Vec<(NodeId, f32)> = stack
        .top(crate::bvh::counters::REPORTED_STACK)
        .iter()
        .map(|&(r, t)| (node_id::<W>(ChildRef::from_raw(r)), t))
        .collect();
    stats.step_stack(stack.len(), &top);
}

impl<const W: usize> WideBvh<W> {
    /// One ray's closest (or, with `ANY`, first) hit with box kernel `kernel`; leaves tested
    /// `groups` at a time in SIMD when `GROUPED` (four, or sixteen with AVX-512), one by one
    /// otherwise (the scalar path).
    #[inline(always)]
    fn trace_with<
        T: TriangleIntersector,
        const ANY: bool,
        S: TraversalStats,
        K: SlabKernel<W>,
        const N: usize,
        const GROUPED: bool,
    >(
        &self,
        kernel: K,
        groups: impl LeafGroups,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        let (mut prepared, mut best) = (None, None);
        // The leaves as the test reads them: their vertices coordinate by coordinate, or the
        // stored form of a test that asks for it (`TriangleIntersector::STORED`).
        let (leaf_floats, per) = match GROUPED && T::STORED {
            true => (self.stored_leaves(), crate::geometry::stored_triangle::STORED_FLOATS),
            false => (super::leaves::floats(&self.tris), 9),
        };
        // Inlined always: this closure is compiled without the AVX2 walk's features (it is defined
        // here, not in `trace_avx2`), and as a call it could not inline the AVX2 leaf test either,
        // which then cost a second call per leaf (seen in a profile).
        self.walk_ray::<S, K, N>(
            kernel,
            (leaf_floats, per),
            ray,
            stats,
            #[inline(always)]
            |first, count, ray, stats| {
                let ids = |i: usize| self.prim_ids[i];
                if GROUPED {
                    // The wide layouts' leaves, coordinate by coordinate (`leaves.rs`).
                    let coords = &leaf_floats[per * first..];
                    test_triangles_grouped::<T, ANY, S, _>(
                        groups,
                        coords,
                        count,
                        first,
                        ray,
                        stats,
                        &mut prepared,
                        &mut best,
                        ids,
                    )
                } else {
                    self.with_leaf(first, count, |tris| {
                        test_triangles::<T, ANY, S>(tris, first, ray, stats, &mut prepared, &mut best, ids)
                    })
                }
            },
        );
        best.map(|(i, h)| Hit { t: h.t, u: h.u, v: h.v, prim: self.prim_ids[i] })
    }
}

impl Accelerator for WideBvh {
    /// Children are always taken nearest first here; `BY_DISTANCE` applies to the binary layout.
    fn trace<T: TriangleIntersector, const BY_DISTANCE: bool, const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        match self.simd {
            Simd::Scalar => self.trace_with::<T, ANY, S, _, STACK, false>(Scalar, Groups4, ray, stats),
            // The leaves in SIMD passes, as the 8-wide walk's: the app's default layout gained
            // 1.12× on incoherent rays over one triangle at a time (BENCHMARKS.md, 2026-12-03).
            #[cfg(target_arch = "x86_64")]
            Simd::Avx2 | Simd::Avx512 => match crate::geometry::slab8::Avx2::detect() {
                // SAFETY: `detect` found AVX2 and FMA.
                Some(k) => unsafe { self.trace_avx2::<T, ANY, S, _, STACK>(k, Simd4, ray, stats) },
                None => self.trace_with::<T, ANY, S, _, STACK, true>(Simd4, Groups4, ray, stats),
            },
            _ => self.trace_with::<T, ANY, S, _, STACK, true>(Simd4, Groups4, ray, stats),
        }
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

impl<const W: usize> WideBvh<W> {
    /// The walk compiled for AVX2 (and the bit instructions that come with it: a loop over a
    /// mask's bits becomes POPCNT, not a multiply trick), so the box kernel's intrinsics (`boxes`:
    /// eight boxes in one AVX2 pass, or four in one VEX-encoded four-lane pass) and everything else
    /// in the walk are inlined as AVX code; leaves are tested eight triangles a pass (`triangle8`;
    /// up to four take the four-lane pass). FMA is enabled but never contracted into (Rust does not
    /// fuse `a * b + c`), so results stay those of the other kernels. `N` is the stack's size.
    ///
    /// # Safety
    /// The CPU must have these features: `kernel` proves it.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,popcnt,bmi1,bmi2,lzcnt")]
    unsafe fn trace_avx2<
        T: TriangleIntersector,
        const ANY: bool,
        S: TraversalStats,
        K: SlabKernel<W>,
        const N: usize,
    >(
        &self,
        kernel: crate::geometry::slab8::Avx2,
        boxes: K,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        let groups = crate::bvh::traverse::Groups8(kernel);
        self.trace_with::<T, ANY, S, _, N, true>(boxes, groups, ray, stats)
    }
}

impl WideBvh<8> {
    /// The walk compiled for AVX-512F/VL on top of the AVX2 set: the eight boxes tested with mask
    /// registers and planes picked by offsets (`avx512::slab8`), a leaf's triangles sixteen at a
    /// time in masked 256-bit passes (`avx512::leaf`). Nothing is fused; results are the other kernels'.
    ///
    /// # Safety
    /// The CPU must have these features: `kernel` proves it.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl,avx2,fma,popcnt,bmi1,bmi2,lzcnt")]
    unsafe fn trace_avx512<T: TriangleIntersector, const ANY: bool, S: TraversalStats>(
        &self,
        kernel: crate::geometry::avx512::Avx512,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        let groups = crate::bvh::traverse::Groups16(kernel);
        self.trace_with::<T, ANY, S, _, STACK8, true>(kernel, groups, ray, stats)
    }
}

impl Accelerator for WideBvh<8> {
    /// Children are always taken nearest first here; `BY_DISTANCE` applies to the binary layout.
    /// The box kernel is the tree's `simd` level, chosen once when it was built.
    fn trace<T: TriangleIntersector, const BY_DISTANCE: bool, const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        match self.simd {
            #[cfg(target_arch = "x86_64")]
            // Leaves of up to four triangles take the AVX2 walk (its four-lane pass): there the
            // AVX-512 one measured 1–8% slower (BENCHMARKS.md, "AVX-512"); it is for leaves of
            // eight and more (sixteen in two masked 256-bit passes: `avx512::leaf`).
            Simd::Avx512 if self.params.max_leaf_size > 4 => match crate::geometry::avx512::Avx512::detect() {
                // SAFETY: `detect` found AVX-512F/VL and the AVX2 set.
                Some(k) => unsafe { self.trace_avx512::<T, ANY, S>(k, ray, stats) },
                None => self.trace_with::<T, ANY, S, _, STACK8, true>(Simd4, Groups4, ray, stats),
            },
            #[cfg(target_arch = "x86_64")]
            Simd::Avx512 => match crate::geometry::slab8::Avx2::detect() {
                // SAFETY: `detect` found AVX2 and FMA.
                Some(k) => unsafe { self.trace_avx2::<T, ANY, S, _, STACK8>(k, k, ray, stats) },
                None => self.trace_with::<T, ANY, S, _, STACK8, true>(Simd4, Groups4, ray, stats),
            },
            #[cfg(target_arch = "x86_64")]
            Simd::Avx2 => match crate::geometry::slab8::Avx2::detect() {
                // SAFETY: `detect` found AVX2 and FMA.
                Some(k) => unsafe { self.trace_avx2::<T, ANY, S, _, STACK8>(k, k, ray, stats) },
                None => self.trace_with::<T, ANY, S, _, STACK8, true>(Simd4, Groups4, ray, stats),
            },
            Simd::Scalar => self.trace_with::<T, ANY, S, _, STACK8, false>(Scalar, Groups4, ray, stats),
            _ => self.trace_with::<T, ANY, S, _, STACK8, true>(Simd4, Groups4, ray, stats),
        }
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
