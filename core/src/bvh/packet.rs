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
//! box-tested and its hitting rays test the leaf's triangles four at a time
//! (`TriangleIntersector::intersect4`, bit for bit the single-ray test), so every ray gets the hit
//! it would get alone (the same distance; between triangles hit at exactly the same distance either
//! may be reported).
//!
//! Packets are for the renderer's uncounted views of primary rays (`bvhscope render` of normals or
//! depth): heatmaps, and the app, which always counts for its hover read-out, trace single rays.
//! Incoherent rays defeat both shortcuts (bunny, 1M rays: 0.5 against 0.9 MRays/s), so they are
//! traced one by one. The 4-wide BVH traces packets the same way (`wide/packet.rs`), with the
//! groups, frustum and leaf tests of this file. Earlier, packets were 2×2 blocks traced with all
//! four lanes tested at every node; 8×8 ranged packets are 1.3× faster on the bunny's primary
//! frame (`PACKET=1 cargo run --release --example profile_trace -- binary primary`).

use super::node::{Bvh, TRAVERSAL_STACK_SIZE};
use super::simd::{max_keep, min_keep};
use super::stack::TraversalStack;
use super::{Hit, TraceOptions};
use crate::geometry::{Aabb, MollerTrumbore, Ray, TriangleHit, TriangleIntersector, TriangleTest, Watertight};
use std::mem::MaybeUninit;
use wide::f32x4;

/// Four rays of a packet in SIMD form (lane k = ray k), for one slab test of a box against all
/// four. Padding lanes (past the packet's end) repeat the last ray with `t_max = -inf`, so boxes
/// nearly always miss them (a box can still pass one whose ray starts inside it with
/// `t_min = -inf`); `Packet::leaf` masks them out.
pub(super) struct Group {
    org: [f32x4; 3],
    inv: [f32x4; 3],
    /// Per axis, all-ones lanes where the direction is negative (the far plane is `min`).
    neg: [f32x4; 3],
    t_min: f32x4,
    /// The rays' current `t_max` (the nearest hit so far).
    t_max: f32x4,
}

impl Group {
    /// Rays `base..base + 4` of `rays`; lanes past the end repeat the last ray (its padding).
    #[inline(always)]
    fn new(rays: &[Ray], base: usize) -> Self {
        let last = rays.len() - 1;
        let ray = |k: usize| &rays[(base + k).min(last)];
        let lanes = |f: &dyn Fn(&Ray) -> f32| f32x4::from([f(ray(0)), f(ray(1)), f(ray(2)), f(ray(3))]);
        let inv = [lanes(&|r| r.inv_dir().x), lanes(&|r| r.inv_dir().y), lanes(&|r| r.inv_dir().z)];
        // The scalar slab test picks planes by `is_sign_negative`; `< 0` agrees for every valid
        // ray (a -0 component gives -inf; an invalid ray has t_max = -inf and misses anyway).
        let sign = |v: f32x4| v.simd_lt(f32x4::ZERO);
        Group {
            org: [lanes(&|r| r.origin().x), lanes(&|r| r.origin().y), lanes(&|r| r.origin().z)],
            neg: [sign(inv[0]), sign(inv[1]), sign(inv[2])],
            inv,
            t_min: lanes(&|r| r.t_min),
            t_max: Self::t_max_of(rays, base),
        }
    }

    #[inline(always)]
    fn t_max_of(rays: &[Ray], base: usize) -> f32x4 {
        let lane = |k: usize| rays.get(base + k).map_or(f32::NEG_INFINITY, |r| r.t_max);
        f32x4::from([lane(0), lane(1), lane(2), lane(3)])
    }

    /// Lanes whose ray hits the box `[lo, hi]` (per axis, splatted) within [t_min, t_max]. The
    /// arithmetic is the scalar slab test's, lane by lane.
    #[inline(always)]
    fn hit(&self, lo: [f32; 3], hi: [f32; 3]) -> u32 {
        let mut enter = self.t_min;
        let mut exit = self.t_max;
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

    /// `hit` for a packet whose rays all share the direction's sign on every axis: the near and
    /// far planes per axis are chosen once for all lanes (the same values `hit` selects, so the
    /// same result), which saves the per-lane selects, a third of the test.
    #[inline(always)]
    fn hit_planes(&self, near: [f32; 3], far: [f32; 3]) -> u32 {
        let mut enter = self.t_min;
        let mut exit = self.t_max;
        for axis in 0..3 {
            let t_near = (f32x4::splat(near[axis]) - self.org[axis]) * self.inv[axis];
            let t_far = (f32x4::splat(far[axis]) - self.org[axis]) * self.inv[axis];
            enter = max_keep(t_near, enter);
            exit = min_keep(t_far, exit);
        }
        enter.simd_le(exit).to_bitmask()
    }
}

/// Most rays in one packet: an 8×8 pixel tile.
pub const PACKET: usize = 64;
/// Side of the square pixel block a packet covers.
pub const PACKET_SIDE: u32 = 8;
pub(super) const GROUPS: usize = PACKET / 4;

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
pub(super) struct Frustum {
    valid: bool,
    org_lo: [f32; 3],
    org_hi: [f32; 3],
    inv_lo: [f32; 3],
    inv_hi: [f32; 3],
    neg: [bool; 3],
    t_min: f32,
}

impl Frustum {
    /// A frustum that rejects nothing.
    const OFF: Frustum = Frustum {
        valid: false,
        org_lo: [0.0; 3],
        org_hi: [0.0; 3],
        inv_lo: [0.0; 3],
        inv_hi: [0.0; 3],
        neg: [false; 3],
        t_min: 0.0,
    };

    /// The bounds of the rays in `groups` (padding lanes repeat a ray, so they change nothing).
    #[inline(always)]
    fn new(groups: &[Group]) -> Self {
        let inf = f32x4::splat(f32::INFINITY);
        let (mut org_lo, mut org_hi) = ([inf; 3], [-inf; 3]);
        let (mut inv_lo, mut inv_hi) = ([inf; 3], [-inf; 3]);
        let mut t_min = inf;
        // |x| < inf is false for infinities and NaNs; min and max skip NaNs, so a ray with one
        // must switch the test off here.
        let is_finite = |v: f32x4| v.abs().simd_lt(inf);
        let mut finite = f32x4::ZERO.simd_eq(f32x4::ZERO);
        for g in groups {
            for axis in 0..3 {
                let (o, i) = (g.org[axis], g.inv[axis]);
                finite &= is_finite(o) & is_finite(i);
                (org_lo[axis], org_hi[axis]) = (org_lo[axis].min(o), org_hi[axis].max(o));
                (inv_lo[axis], inv_hi[axis]) = (inv_lo[axis].min(i), inv_hi[axis].max(i));
            }
            t_min = t_min.min(g.t_min);
        }
        let low = |v: f32x4| v.to_array().into_iter().fold(f32::INFINITY, f32::min);
        let high = |v: f32x4| v.to_array().into_iter().fold(f32::NEG_INFINITY, f32::max);
        let inv_lo = inv_lo.map(low);
        let inv_hi = inv_hi.map(high);
        // One sign per axis, no zero or infinite component, finite origins.
        let one_sign = (0..3).all(|a| inv_lo[a] > 0.0 || inv_hi[a] < 0.0);
        Frustum {
            valid: !groups.is_empty() && one_sign && finite.all(),
            org_lo: org_lo.map(low),
            org_hi: org_hi.map(high),
            neg: std::array::from_fn(|a| inv_hi[a] < 0.0),
            inv_lo,
            inv_hi,
            t_min: low(t_min),
        }
    }

    /// True when no ray of the packet can hit `b` before `t_far` (the farthest `t_max` of the
    /// packet). Each ray's slab distance `(plane - o) · inv` is a rounded expression monotonic in
    /// `o` and in `inv`, so its extremes over the ranges are at their corners: the bounds below
    /// contain every ray's own rounded value.
    #[inline(always)]
    pub(super) fn misses(&self, b: &Aabb, t_far: f32) -> bool {
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

impl Frustum {
    /// The four-box form of `misses` for a wide node's children (SoA planes `min[axis][slot]`):
    /// the mask of slots some ray of the packet may hit before `t_far`, all four when the test
    /// does not apply. The same bounds, one SIMD lane per box.
    #[inline(always)]
    pub(super) fn may_hit4(&self, min: &[[f32; 4]; 3], max: &[[f32; 4]; 3], t_far: f32) -> u32 {
        if !self.valid {
            return 0b1111;
        }
        let mut enter = f32x4::splat(self.t_min);
        let mut exit = f32x4::splat(t_far);
        for axis in 0..3 {
            let (near, far) = if self.neg[axis] { (max[axis], min[axis]) } else { (min[axis], max[axis]) };
            let (o_lo, o_hi) = (f32x4::splat(self.org_lo[axis]), f32x4::splat(self.org_hi[axis]));
            let (i0, i1) = (f32x4::splat(self.inv_lo[axis]), f32x4::splat(self.inv_hi[axis]));
            let corners = |plane: [f32; 4]| {
                let p = f32x4::from(plane);
                let (d0, d1) = (p - o_hi, p - o_lo);
                (d0 * i0, d0 * i1, d1 * i0, d1 * i1)
            };
            let n = corners(near);
            let f = corners(far);
            enter = enter.max(n.0.min(n.1).min(n.2.min(n.3)));
            exit = exit.min(f.0.max(f.1).max(f.2.max(f.3)));
        }
        // Rejected only when surely empty, as in `misses` (a NaN keeps the box).
        !enter.simd_gt(exit).to_bitmask() & 0b1111
    }
}

/// The packet's per-ray state: SIMD groups of four rays for the box tests, and each ray's
/// prepared triangle test and hit so far. The arrays are left uninitialised past what is
/// written (see `new_in`).
pub(super) struct Packet<'r, T: TriangleIntersector> {
    rays: &'r mut [Ray],
    /// The first `n_groups` are set.
    groups: [MaybeUninit<Group>; GROUPS],
    pub(super) n_groups: usize,
    /// Every ray's direction has the signs `neg` on the three axes (the common case for primary
    /// rays), so box tests pick planes once per box.
    one_sign: bool,
    neg: [bool; 3],
    pub(super) frustum: Frustum,
    /// Each group's triangle-test setup, made at its first leaf (bit g of `prepared_mask` set).
    prepared: [MaybeUninit<T::Prepared4>; GROUPS],
    prepared_mask: u64,
    /// Each ray's nearest hit so far (bit k of `hit_mask` set): leaf-order triangle and barycentrics.
    best: [MaybeUninit<(u32, TriangleHit)>; PACKET],
    hit_mask: u64,
}

impl<'r, T: TriangleIntersector> Packet<'r, T> {
    /// Set up the packet of `rays` in `slot`, in place: returning it by value would copy the
    /// whole state (kilobytes, most of it never written), which costs as much as tracing a packet
    /// that misses everything. The caller returns before this for an empty packet.
    #[inline(always)]
    pub(super) fn new_in<'s>(slot: &'s mut MaybeUninit<Self>, rays: &'r mut [Ray]) -> &'s mut Self {
        debug_assert!(rays.len() <= PACKET, "a packet holds at most {PACKET} rays");
        let n_groups = rays.len().div_ceil(4);
        // Every field, by name: a field added to `Packet` and not written below fails to compile
        // here instead of being left uninitialised.
        let _every_field = |p: &Self| {
            let Packet {
                rays: _,
                groups: _,
                n_groups: _,
                one_sign: _,
                neg: _,
                frustum: _,
                prepared: _,
                prepared_mask: _,
                best: _,
                hit_mask: _,
            } = p;
        };
        let p = slot.as_mut_ptr();
        // SAFETY: every field that is not a MaybeUninit array is written here through raw
        // pointers (no reference to uninitialised data is made) before the slot is taken as set.
        let packet = unsafe {
            use std::ptr::addr_of_mut;
            addr_of_mut!((*p).rays).write(rays);
            addr_of_mut!((*p).n_groups).write(n_groups);
            addr_of_mut!((*p).one_sign).write(false);
            addr_of_mut!((*p).neg).write([false; 3]);
            addr_of_mut!((*p).frustum).write(Frustum::OFF);
            addr_of_mut!((*p).prepared_mask).write(0);
            addr_of_mut!((*p).hit_mask).write(0);
            slot.assume_init_mut()
        };
        let (mut all_neg, mut any_neg) = ([f32x4::ZERO.simd_eq(f32x4::ZERO); 3], [f32x4::ZERO; 3]);
        for g in 0..n_groups {
            let group = packet.groups[g].write(Group::new(packet.rays, 4 * g));
            for axis in 0..3 {
                (all_neg[axis], any_neg[axis]) = (all_neg[axis] & group.neg[axis], any_neg[axis] | group.neg[axis]);
            }
        }
        packet.one_sign = (0..3).all(|a| all_neg[a].all() || !any_neg[a].any());
        packet.neg = all_neg.map(|m| m.all());
        packet.frustum = Frustum::new(packet.groups());
        packet
    }

    /// The set groups.
    #[inline(always)]
    fn groups(&self) -> &[Group] {
        // SAFETY: `new_in` wrote the first `n_groups` slots; MaybeUninit<Group> has Group's layout.
        unsafe { std::slice::from_raw_parts(self.groups.as_ptr().cast::<Group>(), self.n_groups) }
    }

    #[inline(always)]
    fn groups_mut(&mut self) -> &mut [Group] {
        // SAFETY: as in `groups`.
        unsafe { std::slice::from_raw_parts_mut(self.groups.as_mut_ptr().cast::<Group>(), self.n_groups) }
    }

    /// The farthest `t_max` of any ray: nothing beyond it can matter to the packet.
    pub(super) fn t_far(&self) -> f32 {
        let far = self.groups().iter().fold(f32x4::splat(f32::NEG_INFINITY), |m, g| m.max(g.t_max));
        far.to_array().into_iter().fold(f32::NEG_INFINITY, f32::max)
    }

    #[inline(always)]
    pub(super) fn group_hits(&self, g: usize, lo: [f32; 3], hi: [f32; 3]) -> u32 {
        if self.one_sign {
            let pick = |axis: usize, near: bool| if self.neg[axis] == near { hi[axis] } else { lo[axis] };
            let near = [pick(0, true), pick(1, true), pick(2, true)];
            let far = [pick(0, false), pick(1, false), pick(2, false)];
            self.groups()[g].hit_planes(near, far)
        } else {
            self.groups()[g].hit(lo, hi)
        }
    }

    /// Test triangles `first..first + count` against the rays of group `g` in `mask`; true when
    /// one of them found a nearer hit.
    #[inline(always)]
    /// A leaf over `tris` (`first` is the index of `tris[0]` in leaf order) for every group from
    /// `from` whose rays hit its box `[lo, hi]`; true when one of them found a nearer hit.
    pub(super) fn leaf_groups(
        &mut self,
        from: usize,
        lo: [f32; 3],
        hi: [f32; 3],
        tris: &[[glam::Vec3; 3]],
        first: usize,
    ) -> bool {
        let mut found = false;
        for g in from..self.n_groups {
            let mask = self.group_hits(g, lo, hi);
            if mask != 0 {
                found |= self.leaf(g, mask, tris, first);
            }
        }
        found
    }

    fn leaf(&mut self, g: usize, mask: u32, tris: &[[glam::Vec3; 3]], first: usize) -> bool {
        // Only the lanes of real rays (the last group may have padding lanes).
        let mask = mask & ((1u32 << (self.rays.len() - 4 * g).min(4)) - 1);
        if self.prepared_mask & (1 << g) == 0 {
            self.prepared[g].write(T::prepare4(self.rays, 4 * g));
            self.prepared_mask |= 1 << g;
        }
        // SAFETY: bit g of `prepared_mask` is set only after slot g was written.
        let prepared = unsafe { self.prepared[g].assume_init_ref() };
        let (t_min, mut t_max) = (self.groups()[g].t_min, self.groups()[g].t_max);
        let mut found = false;
        for (i, tri) in tris.iter().enumerate() {
            let hits = T::intersect4(prepared, t_min, t_max, mask, tri);
            if hits.mask == 0 {
                continue;
            }
            let mut m = hits.mask;
            while m != 0 {
                let lane = m.trailing_zeros() as usize;
                m &= m - 1;
                let k = 4 * g + lane;
                let h = TriangleHit { t: hits.t[lane], u: hits.u[lane], v: hits.v[lane] };
                self.rays[k].t_max = h.t;
                self.best[k].write(((first + i) as u32, h));
                self.hit_mask |= 1 << k;
            }
            t_max = Group::t_max_of(self.rays, 4 * g);
            found = true;
        }
        if found {
            self.groups_mut()[g].t_max = t_max;
        }
        found
    }

    /// Each ray's closest hit, with the mesh's triangle index (`prim_ids` maps leaf order to it).
    pub(super) fn finish(&self, prim_ids: &[u32], hits: &mut [Option<Hit>]) {
        let mut m = self.hit_mask;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            // SAFETY: bit k of `hit_mask` is set only after slot k was written.
            let (i, h) = unsafe { self.best[k].assume_init() };
            hits[k] = Some(Hit { t: h.t, u: h.u, v: h.v, prim: prim_ids[i as usize] });
        }
    }
}

impl PacketWalk for Bvh {
    fn has_no_triangles(&self) -> bool {
        self.prim_ids.is_empty()
    }

    fn walk<T: TriangleIntersector>(&self, rays: &mut [Ray], hits: &mut [Option<Hit>]) {
        // Near child by the first ray's direction on the split axis (the rays are coherent; the
        // order only affects speed, not the result).
        let lead = rays[0].inv_dir();
        let dir_neg = [lead.x.is_sign_negative(), lead.y.is_sign_negative(), lead.z.is_sign_negative()];
        let mut slot = MaybeUninit::uninit();
        let packet = Packet::<T>::new_in(&mut slot, rays);
        let mut t_far = packet.t_far();
        let nodes = &self.nodes[..];
        // (node, first group that may hit it); one push per level of the depth-bounded tree.
        let mut stack = TraversalStack::<TRAVERSAL_STACK_SIZE, (u32, u8)>::new();
        let (mut current, mut first) = (0usize, 0usize);
        loop {
            let node = &nodes[current];
            let (lo, hi) = (node.bounds.min.to_array(), node.bounds.max.to_array());
            // The first group with a ray that hits the box; rays before it have missed an
            // ancestor, so they cannot hit anything below.
            let mut g = first;
            let mut mask = packet.group_hits(g, lo, hi);
            if mask == 0 && !packet.frustum.misses(&node.bounds, t_far) {
                while g + 1 < packet.n_groups && mask == 0 {
                    g += 1;
                    mask = packet.group_hits(g, lo, hi);
                }
            }
            if mask != 0 {
                if !node.is_leaf() {
                    let left = node.index as usize;
                    let (near, far) = if dir_neg[node.axis as usize] { (left + 1, left) } else { (left, left + 1) };
                    stack.push((far as u32, g as u8));
                    (current, first) = (near, g);
                    continue;
                }
                let (start, count) = (node.index as usize, node.count as usize);
                if packet.leaf_groups(g, lo, hi, &self.tris[start..start + count], start) {
                    t_far = packet.t_far();
                }
            }
            let Some((node, group)) = stack.pop() else { break };
            (current, first) = (node as usize, group as usize);
        }
        packet.finish(&self.prim_ids, hits);
    }
}

/// A BVH layout that traces packets: its ranged walk over one packet. `closest_hits_packet` does
/// the rest for every layout.
pub(super) trait PacketWalk {
    /// True when there is nothing to hit.
    fn has_no_triangles(&self) -> bool;
    /// Trace `rays` (1 to `PACKET` of them) as one packet; `hits` are cleared.
    fn walk<T: TriangleIntersector>(&self, rays: &mut [Ray], hits: &mut [Option<Hit>]);
}

/// Closest hits of up to `PACKET` coherent rays (an 8×8 pixel block, best in the order of
/// `packet_position`), the same as `closest_hit` on each.
pub(super) fn closest_hits_packet<B: PacketWalk>(
    bvh: &B,
    rays: &mut [Ray],
    hits: &mut [Option<Hit>],
    opts: TraceOptions,
) {
    assert!(rays.len() <= PACKET && hits.len() == rays.len(), "a packet holds at most {PACKET} rays");
    hits.fill(None);
    if rays.is_empty() || bvh.has_no_triangles() {
        return;
    }
    match opts.test {
        TriangleTest::Watertight => bvh.walk::<Watertight>(rays, hits),
        TriangleTest::MollerTrumbore => bvh.walk::<MollerTrumbore>(rays, hits),
    }
}

#[cfg(test)]
#[path = "packet_tests.rs"]
mod tests;
