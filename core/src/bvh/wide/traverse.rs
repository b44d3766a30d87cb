//! Traversal of the 4-wide BVH: one SIMD slab test for all four child boxes of a node (the `wide`
//! crate: SSE on x86-64, NEON on aarch64, plain arrays elsewhere), hit children visited nearest
//! first. The common cases take few branches: one child hit is entered directly, two are ordered
//! by one comparison; only three or four hits are sorted (on the stack). Leaves travel through the
//! same path as nodes, as tagged references (the loop layout of Embree's BVH4 traversal, Wald et
//! al., "Embree: A Kernel Framework for Efficient CPU Ray Tracing", SIGGRAPH 2014). Counters: a
//! node visit counts once, its box tests count per valid child (so wide and binary heatmaps
//! measure the same work). A child pushed on the stack is prefetched into the cache: incoherent
//! rays wait on memory, and by the time it is popped its node has arrived (bunny, 1M incoherent
//! rays, one thread: median +9% over nine alternated pairs; primary rays unchanged).

use super::{WideBvh, WideNode, WIDTH};
use crate::bvh::stack::TraversalStack;
use crate::bvh::{Accelerator, Hit, TraceOptions, TraversalStats};
use crate::geometry::{MollerTrumbore, Ray, TriangleHit, TriangleIntersector, TriangleTest, Watertight};

const _: () = assert!(WIDTH == 4, "child references pack the slot into two bits");
use crate::bvh::simd::{max_keep, min_keep, prefetch};
use wide::f32x4;

/// Deepest stack a traversal can need: at most three pushes per level (the build bounds the depth
/// by `TRAVERSAL_STACK_SIZE`).
const STACK: usize = 3 * crate::bvh::TRAVERSAL_STACK_SIZE + 4;

/// The ray in SIMD form, with the near/far planes chosen per axis by direction sign.
struct SimdRay {
    org: [f32x4; 3],
    inv: [f32x4; 3],
    neg: [bool; 3],
}

impl SimdRay {
    fn new(ray: &Ray) -> Self {
        let (o, i) = (ray.origin(), ray.inv_dir());
        Self {
            org: [f32x4::splat(o.x), f32x4::splat(o.y), f32x4::splat(o.z)],
            inv: [f32x4::splat(i.x), f32x4::splat(i.y), f32x4::splat(i.z)],
            neg: [i.x.is_sign_negative(), i.y.is_sign_negative(), i.z.is_sign_negative()],
        }
    }

    /// Entry distances of the four child boxes and the mask of those hit within [t_min, t_max].
    #[inline(always)]
    fn hit(&self, n: &WideNode, t_min: f32, t_max: f32) -> ([f32; WIDTH], u32) {
        let mut enter = f32x4::splat(t_min);
        let mut exit = f32x4::splat(t_max);
        for axis in 0..3 {
            let (near, far) = if self.neg[axis] { (&n.max[axis], &n.min[axis]) } else { (&n.min[axis], &n.max[axis]) };
            let t0 = (f32x4::from(*near) - self.org[axis]) * self.inv[axis];
            let t1 = (f32x4::from(*far) - self.org[axis]) * self.inv[axis];
            enter = max_keep(t0, enter);
            exit = min_keep(t1, exit);
        }
        let mask = enter.simd_le(exit).to_bitmask() & n.valid as u32;
        (enter.to_array(), mask)
    }
}

/// A child reference: a wide node index, or `LEAF | (node·4 + slot)` for a leaf slot (its first
/// triangle and count are read from that node, which is still in cache when the leaf is reached).
const LEAF: u32 = 1 << 31;

impl WideBvh {
    #[inline(always)]
    fn child_ref(node: &WideNode, index: u32, slot: usize) -> u32 {
        if node.count[slot] > 0 {
            LEAF | (index << 2 | slot as u32)
        } else {
            node.child[slot]
        }
    }

    /// Start loading a child that goes on the stack: the node, or a leaf's first triangle.
    #[inline(always)]
    fn prefetch_child(&self, node: &WideNode, slot: usize) {
        let i = node.child[slot] as usize;
        if node.count[slot] > 0 {
            if let Some(t) = self.tris.get(i) {
                prefetch(t);
            }
        } else if let Some(n) = self.nodes.get(i) {
            prefetch(n);
        }
    }

    fn closest<T: TriangleIntersector, const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        stats.box_tests(1);
        if self.prim_ids.is_empty() || self.root_bounds.intersect(ray).is_none() {
            return None;
        }
        let sray = SimdRay::new(ray);
        // The triangle test's per-ray setup waits for the first leaf: most rays that miss never
        // reach one.
        let mut prepared: Option<T::Prepared> = None;
        let mut best: Option<(usize, TriangleHit)> = None;
        let mut stack = TraversalStack::<STACK>::new();
        let mut cur = 0u32;
        'traversal: loop {
            // Descend through interior nodes until a leaf is reached or nothing is hit.
            while cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                stats.node_visited();
                stats.box_tests(node.valid.count_ones());
                let (enter, mask) = sray.hit(node, ray.t_min, ray.t_max);
                if mask == 0 {
                    // Nothing hit here: continue with the nearest useful entry of the stack.
                    match stack.pop_nearer(ray.t_max) {
                        Some(r) => {
                            cur = r;
                            continue 'traversal;
                        }
                        None => break 'traversal,
                    }
                }
                let s0 = mask.trailing_zeros() as usize;
                let rest = mask & (mask - 1);
                if rest == 0 {
                    cur = Self::child_ref(node, cur, s0);
                    continue;
                }
                let s1 = rest.trailing_zeros() as usize;
                let rest2 = rest & (rest - 1);
                if rest2 == 0 {
                    let (r0, r1) = (Self::child_ref(node, cur, s0), Self::child_ref(node, cur, s1));
                    if enter[s0] <= enter[s1] {
                        self.prefetch_child(node, s1);
                        stack.push((r1, enter[s1]));
                        cur = r0;
                    } else {
                        self.prefetch_child(node, s0);
                        stack.push((r0, enter[s0]));
                        cur = r1;
                    }
                    continue;
                }
                // Three or four children hit: push them all, nearest on top, and take it.
                let mut m = mask;
                let mut k = 0;
                while m != 0 {
                    let slot = m.trailing_zeros() as usize;
                    m &= m - 1;
                    let r = Self::child_ref(node, cur, slot);
                    self.prefetch_child(node, slot);
                    stack.push((r, enter[slot]));
                    k += 1;
                }
                stack.sort_top(k);
                cur = match stack.pop() {
                    Some((r, _)) => r,
                    None => break 'traversal,
                };
            }
            // A leaf.
            let (node, slot) = ((cur & !LEAF) >> 2, (cur & 3) as usize);
            let node = &self.nodes[node as usize];
            let (first, count) = (node.child[slot] as usize, node.count[slot] as usize);
            stats.leaf_visited();
            stats.triangle_tests(count as u32);
            for (i, tri) in self.tris[first..first + count].iter().enumerate() {
                if let Some(h) = T::intersect(prepared.get_or_insert_with(|| T::prepare(ray)), ray, tri) {
                    ray.t_max = h.t;
                    best = Some((first + i, h));
                    if ANY {
                        break 'traversal;
                    }
                }
            }
            match stack.pop_nearer(ray.t_max) {
                Some(r) => cur = r,
                None => break 'traversal,
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
        // Children are always taken nearest first here; `opts.order` applies to the binary layout.
        match opts.test {
            TriangleTest::Watertight => self.closest::<Watertight, ANY, S>(ray, stats),
            TriangleTest::MollerTrumbore => self.closest::<MollerTrumbore, ANY, S>(ray, stats),
        }
    }
}

impl Accelerator for WideBvh {
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
