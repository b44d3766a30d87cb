//! Ray packets: up to 64 coherent rays (an 8×8 block of pixels) traced together through the
//! binary BVH with ranged traversal. Wald, Boulos & Shirley, "Ray Tracing Deformable Scenes Using
//! Dynamic Bounding Volume Hierarchies" (ACM TOG 26(1), 2007), §4: the packet walks the tree once,
//! and at each node only the rays from the first one that hits the node's box onwards stay active.
//!
//! Why it is fast for primary rays: near the top of the tree the first active rays hit nearly every
//! box the packet reaches, so a node costs one SIMD box test (four rays) for all 64. When that first
//! group misses, a conservative test of the whole packet (interval arithmetic over the rays'
//! origins and inverse directions, the paper's §4.2) rejects most boxes no ray reaches before the
//! other groups are tried one by one. At a leaf every group from the first active one is
//! box-tested and its hitting rays test the leaf's triangles with the single-ray test, so every ray
//! gets the hit it would get alone (the same distance; between triangles hit at exactly the same
//! distance either may be reported).
//!
//! Packets are for the renderer's uncounted views of primary rays (`bvhscope render` of normals or
//! depth): heatmaps, and the app, which always counts for its hover read-out, trace single rays.
//! Incoherent rays defeat both shortcuts (bunny, 1M rays: 0.5 against 0.9 MRays/s), so they are
//! traced one by one. The 4-wide BVH traces packets ray by ray (the trait's default): packets of
//! four rays over it (four child boxes × four rays per node) measured slower than its single rays.
//! Earlier, packets were 2×2 blocks traced with all four lanes tested at every node; 8×8 ranged
//! packets are 1.3× faster on the bunny's primary frame (`PACKET=1 cargo run --release --example profile_trace -- binary primary`).

use super::node::{Bvh, TRAVERSAL_STACK_SIZE};
use super::simd::{max_keep, min_keep};
use super::{Hit, TraceOptions};
use crate::geometry::{Aabb, MollerTrumbore, Ray, TriangleHit, TriangleIntersector, TriangleTest, Watertight};
use std::mem::MaybeUninit;
use wide::f32x4;

/// Four rays of a packet in SIMD form (lane k = ray k), for one slab test of a box against all
/// four. Padding lanes get `t_max = -inf` (in `Packet::t_max`), so every box misses them.
struct Group {
    org: [f32x4; 3],
    inv: [f32x4; 3],
    /// Per axis, all-ones lanes where the direction is negative (the far plane is `min`).
    neg: [f32x4; 3],
    t_min: f32x4,
}

impl Group {
    fn new(rays: &[Ray; 4]) -> Self {
        let lanes = |f: &dyn Fn(&Ray) -> f32| f32x4::from([f(&rays[0]), f(&rays[1]), f(&rays[2]), f(&rays[3])]);
        let inv = [lanes(&|r| r.inv_dir().x), lanes(&|r| r.inv_dir().y), lanes(&|r| r.inv_dir().z)];
        // The scalar slab test picks planes by `is_sign_negative`; `< 0` agrees for every valid
        // ray (a -0 component gives -inf; an invalid ray has t_max = -inf and misses anyway).
        let sign = |v: f32x4| v.simd_lt(f32x4::ZERO);
        Self {
            org: [lanes(&|r| r.origin().x), lanes(&|r| r.origin().y), lanes(&|r| r.origin().z)],
            neg: [sign(inv[0]), sign(inv[1]), sign(inv[2])],
            inv,
            t_min: lanes(&|r| r.t_min),
        }
    }

    /// Lanes whose ray hits the box `[lo, hi]` (per axis, splatted) within [t_min, t_max]. The
    /// arithmetic is the scalar slab test's, lane by lane.
    #[inline(always)]
    fn hit(&self, lo: [f32; 3], hi: [f32; 3], t_max: f32x4) -> u32 {
        let mut enter = self.t_min;
        let mut exit = t_max;
        for axis in 0..3 {
            let ta = (f32x4::splat(lo[axis]) - self.org[axis]) * self.inv[axis];
            let tb = (f32x4::splat(hi[axis]) - self.org[axis]) * self.inv[axis];
            let near = self.neg[axis].bitselect(tb, ta);
            let far = self.neg[axis].bitselect(ta, tb);
            enter = max_keep(near, enter);
            exit = min_keep(far, exit);
        }
        enter.simd_le(exit).to_bitmask()
    }
}

/// Most rays in one packet: an 8×8 pixel tile.
pub const PACKET: usize = 64;
/// Side of the square pixel block a packet covers.
pub const PACKET_SIDE: u32 = 8;
const GROUPS: usize = PACKET / 4;

/// Where ray `k` of a packet sits in its 8×8 block: Z-order (even bits of `k` give x, odd bits y),
/// so every four consecutive rays, the SIMD groups, are 2×2 pixels and a range of groups stays
/// compact on screen.
pub fn packet_position(k: u32) -> (u32, u32) {
    let bits = |b: u32| (b & 1) | (b >> 1 & 2) | (b >> 2 & 4);
    (bits(k), bits(k >> 1))
}

/// A conservative bound of the packet's rays: where they start and the range of their inverse
/// directions per axis. Valid only when every ray's direction has the same sign on each axis and
/// no component is zero (then each ray's near plane of a box is the same one, and the bounds on
/// its slab distances follow from the corners of the ranges).
struct Frustum {
    valid: bool,
    org_lo: [f32; 3],
    org_hi: [f32; 3],
    inv_lo: [f32; 3],
    inv_hi: [f32; 3],
    neg: [bool; 3],
    t_min: f32,
}

impl Frustum {
    #[inline(always)]
    fn new(rays: &[Ray]) -> Self {
        use glam::Vec3;
        let first = rays.first().map_or(Vec3::ONE, |r| r.inv_dir());
        let (mut org_lo, mut org_hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let (mut inv_lo, mut inv_hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let mut t_min = f32::INFINITY;
        let mut finite = true;
        for r in rays {
            let (o, inv) = (r.origin(), r.inv_dir());
            // min and max skip NaNs: a ray with one must switch the test off.
            finite &= o.is_finite() & inv.is_finite();
            (org_lo, org_hi) = (org_lo.min(o), org_hi.max(o));
            (inv_lo, inv_hi) = (inv_lo.min(inv), inv_hi.max(inv));
            t_min = t_min.min(r.t_min);
        }
        // One sign per axis, no zero or infinite component, finite origins.
        let one_sign = (inv_lo.cmpgt(Vec3::ZERO) | inv_hi.cmplt(Vec3::ZERO)).all();
        Frustum {
            valid: !rays.is_empty() && one_sign && finite,
            org_lo: org_lo.to_array(),
            org_hi: org_hi.to_array(),
            inv_lo: inv_lo.to_array(),
            inv_hi: inv_hi.to_array(),
            neg: first.cmplt(Vec3::ZERO).into(),
            t_min,
        }
    }

    /// True when no ray of the packet can hit `b` before `t_far` (the farthest `t_max` of the
    /// packet). Each ray's slab distance `(plane - o) · inv` is a rounded expression monotonic in
    /// `o` and in `inv`, so its extremes over the ranges are at their corners: the bounds below
    /// contain every ray's own rounded value.
    #[inline(always)]
    fn misses(&self, b: &Aabb, t_far: f32) -> bool {
        if !self.valid {
            return false;
        }
        let mut enter = self.t_min;
        let mut exit = t_far;
        for axis in 0..3 {
            let (near, far) = if self.neg[axis] { (b.max[axis], b.min[axis]) } else { (b.min[axis], b.max[axis]) };
            let corners = |plane: f32| {
                let (d0, d1) = (plane - self.org_hi[axis], plane - self.org_lo[axis]);
                let (i0, i1) = (self.inv_lo[axis], self.inv_hi[axis]);
                [d0 * i0, d0 * i1, d1 * i0, d1 * i1]
            };
            let n = corners(near);
            let f = corners(far);
            enter = enter.max(n[0].min(n[1]).min(n[2]).min(n[3]));
            exit = exit.min(f[0].max(f[1]).max(f[2]).max(f[3]));
        }
        enter > exit
    }
}

/// The packet's per-ray state: SIMD groups of four rays for the box tests, and each ray's
/// prepared triangle test and hit so far.
struct Packet<'r, T: TriangleIntersector> {
    rays: &'r mut [Ray],
    groups: [Group; GROUPS],
    /// Per group, the rays' current `t_max` (`-inf` on the padding lanes of the last group).
    t_max: [f32x4; GROUPS],
    n_groups: usize,
    /// Each ray's triangle-test setup, made at its first leaf (bit k of `prepared_mask` set) —
    /// not initialised up front: clearing 64 slots per packet costs more than most packets' work.
    prepared: [MaybeUninit<T::Prepared>; PACKET],
    prepared_mask: u64,
    /// Each ray's nearest hit so far (bit k of `hit_mask` set): leaf-order triangle and barycentrics.
    best: [MaybeUninit<(u32, TriangleHit)>; PACKET],
    hit_mask: u64,
}

impl<'r, T: TriangleIntersector> Packet<'r, T> {
    #[inline(always)]
    fn new(rays: &'r mut [Ray]) -> Self {
        let n = rays.len();
        let n_groups = n.div_ceil(4);
        // Padding lanes repeat the last ray; their t_max of -inf makes them miss every box. (The
        // caller returns before this for an empty packet.)
        let groups = std::array::from_fn(|g| Group::new(&std::array::from_fn(|k| rays[(4 * g + k).min(n - 1)])));
        let mut packet = Packet {
            rays,
            groups,
            t_max: [f32x4::splat(f32::NEG_INFINITY); GROUPS],
            n_groups,
            prepared: [const { MaybeUninit::uninit() }; PACKET],
            prepared_mask: 0,
            best: [const { MaybeUninit::uninit() }; PACKET],
            hit_mask: 0,
        };
        for g in 0..n_groups {
            packet.update_t_max(g);
        }
        packet
    }

    fn update_t_max(&mut self, g: usize) {
        let n = self.rays.len();
        self.t_max[g] = f32x4::from(std::array::from_fn::<f32, 4, _>(|k| {
            let i = 4 * g + k;
            if i < n {
                self.rays[i].t_max
            } else {
                f32::NEG_INFINITY
            }
        }));
    }

    /// The farthest `t_max` of any ray: nothing beyond it can matter to the packet.
    fn t_far(&self) -> f32 {
        self.rays.iter().fold(f32::NEG_INFINITY, |m, r| m.max(r.t_max))
    }

    #[inline(always)]
    fn group_hits(&self, g: usize, lo: [f32; 3], hi: [f32; 3]) -> u32 {
        self.groups[g].hit(lo, hi, self.t_max[g])
    }

    /// Test triangles `first..first + count` against the rays of group `g` in `mask`; true when
    /// one of them found a nearer hit.
    #[inline(always)]
    fn leaf(&mut self, g: usize, mask: u32, tris: &[[glam::Vec3; 3]], first: usize, count: usize) -> bool {
        let mut found = false;
        for (i, tri) in tris[first..first + count].iter().enumerate() {
            let mut m = mask;
            while m != 0 {
                let k = 4 * g + m.trailing_zeros() as usize;
                m &= m - 1;
                let ray = &mut self.rays[k];
                if self.prepared_mask & (1 << k) == 0 {
                    self.prepared[k].write(T::prepare(ray));
                    self.prepared_mask |= 1 << k;
                }
                // SAFETY: bit k of `prepared_mask` is set only after slot k was written.
                let prepared = unsafe { self.prepared[k].assume_init_ref() };
                if let Some(h) = T::intersect(prepared, ray, tri) {
                    ray.t_max = h.t;
                    self.best[k].write(((first + i) as u32, h));
                    self.hit_mask |= 1 << k;
                    found = true;
                }
            }
        }
        if found {
            self.update_t_max(g);
        }
        found
    }
}

impl Bvh {
    fn closest_packet<T: TriangleIntersector>(&self, rays: &mut [Ray], hits: &mut [Option<Hit>]) {
        assert!(rays.len() <= PACKET && hits.len() == rays.len(), "a packet holds at most {PACKET} rays");
        hits.fill(None);
        if rays.is_empty() || self.prim_ids.is_empty() {
            return;
        }
        let frustum = Frustum::new(rays);
        // Near child by the first ray's direction on the split axis (the rays are coherent; the
        // order only affects speed, not the result).
        let lead = rays[0].inv_dir();
        let dir_neg = [lead.x.is_sign_negative(), lead.y.is_sign_negative(), lead.z.is_sign_negative()];
        let mut packet = Packet::<T>::new(rays);
        let mut t_far = packet.t_far();
        let nodes = &self.nodes[..];
        // (node, first group that may hit it); one push per level of the depth-bounded tree.
        let mut stack = [(0u32, 0u8); TRAVERSAL_STACK_SIZE];
        let mut len = 0usize;
        let (mut current, mut first) = (0usize, 0usize);
        loop {
            let node = &nodes[current];
            let (lo, hi) = (node.bounds.min.to_array(), node.bounds.max.to_array());
            // The first group with a ray that hits the box; rays before it have missed an
            // ancestor, so they cannot hit anything below.
            let mut g = first;
            let mut mask = packet.group_hits(g, lo, hi);
            if mask == 0 && !frustum.misses(&node.bounds, t_far) {
                while g + 1 < packet.n_groups && mask == 0 {
                    g += 1;
                    mask = packet.group_hits(g, lo, hi);
                }
            }
            if mask != 0 {
                if !node.is_leaf() {
                    let left = node.index as usize;
                    let (near, far) = if dir_neg[node.axis as usize] { (left + 1, left) } else { (left, left + 1) };
                    stack[len] = (far as u32, g as u8);
                    len += 1;
                    (current, first) = (near, g);
                    continue;
                }
                let (start, count) = (node.index as usize, node.count as usize);
                let mut found = packet.leaf(g, mask, &self.tris, start, count);
                for h in g + 1..packet.n_groups {
                    let m = packet.group_hits(h, lo, hi);
                    if m != 0 {
                        found |= packet.leaf(h, m, &self.tris, start, count);
                    }
                }
                if found {
                    t_far = packet.t_far();
                }
            }
            if len == 0 {
                break;
            }
            len -= 1;
            (current, first) = (stack[len].0 as usize, stack[len].1 as usize);
        }
        let mut m = packet.hit_mask;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            // SAFETY: bit k of `hit_mask` is set only after slot k was written.
            let (i, h) = unsafe { packet.best[k].assume_init() };
            hits[k] = Some(Hit { t: h.t, u: h.u, v: h.v, prim: self.prim_ids[i as usize] });
        }
    }

    /// Closest hits of up to `PACKET` coherent rays (an 8×8 pixel block, best in the order of
    /// `packet_position`), the same as `closest_hit` on each.
    pub(crate) fn closest_hits_packet(&self, rays: &mut [Ray], hits: &mut [Option<Hit>], opts: TraceOptions) {
        match opts.test {
            TriangleTest::Watertight => self.closest_packet::<Watertight>(rays, hits),
            TriangleTest::MollerTrumbore => self.closest_packet::<MollerTrumbore>(rays, hits),
        }
    }
}

#[cfg(test)]
#[path = "packet_tests.rs"]
mod tests;
