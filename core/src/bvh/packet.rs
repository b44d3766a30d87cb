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
//! Incoherent rays defeat both shortcuts (they are slower in packets than alone, BENCHMARKS.md,
//! "Seventh round"), so they are traced one by one. Both layouts trace packets with the one walk
//! of this file (`walk`), over the children of their nodes as `PacketTree` presents them: the
//! binary BVH's two children, the wide BVH's four. Earlier, packets were 2×2 blocks traced with all four lanes tested at every node;
//! 8×8 ranged packets replaced them (BENCHMARKS.md, "Seventh round").

use super::node::{Bvh, TRAVERSAL_STACK_SIZE};
use super::stack::TraversalStack;
use super::{Hit, TraceOptions};
use crate::geometry::slab_packet::{RayGroup, RayInterval};
use crate::geometry::{Aabb, Ray, TriangleHit, TriangleIntersector};
use glam::Vec3;
use std::mem::MaybeUninit;
use wide::f32x4;

pub use super::accel::PACKET;
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

/// The packet's per-ray state: SIMD groups of four rays for the box tests, and each ray's
/// prepared triangle test and hit so far. The arrays are left uninitialised past what is
/// written (see `new_in`).
pub(super) struct Packet<'r, T: TriangleIntersector> {
    rays: &'r mut [Ray],
    /// The first `n_groups` are set.
    groups: [MaybeUninit<RayGroup>; GROUPS],
    pub(super) n_groups: usize,
    /// Every ray's direction has the signs `neg` on the three axes (the common case for primary
    /// rays), so box tests pick planes once per box.
    one_sign: bool,
    neg: [bool; 3],
    pub(super) frustum: RayInterval,
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
            addr_of_mut!((*p).frustum).write(RayInterval::OFF);
            addr_of_mut!((*p).prepared_mask).write(0);
            addr_of_mut!((*p).hit_mask).write(0);
            slot.assume_init_mut()
        };
        let (mut all_neg, mut any_neg) = ([f32x4::ZERO.simd_eq(f32x4::ZERO); 3], [f32x4::ZERO; 3]);
        for g in 0..n_groups {
            let group = packet.groups[g].write(RayGroup::new(packet.rays, 4 * g));
            for axis in 0..3 {
                (all_neg[axis], any_neg[axis]) = (all_neg[axis] & group.neg[axis], any_neg[axis] | group.neg[axis]);
            }
        }
        packet.one_sign = (0..3).all(|a| all_neg[a].all() || !any_neg[a].any());
        packet.neg = [all_neg[0].all(), all_neg[1].all(), all_neg[2].all()];
        packet.frustum = RayInterval::new(packet.groups());
        packet
    }

    /// The set groups.
    #[inline(always)]
    fn groups(&self) -> &[RayGroup] {
        // SAFETY: `new_in` wrote the first `n_groups` slots; MaybeUninit<RayGroup> has Group's layout.
        unsafe { std::slice::from_raw_parts(self.groups.as_ptr().cast::<RayGroup>(), self.n_groups) }
    }

    #[inline(always)]
    fn groups_mut(&mut self) -> &mut [RayGroup] {
        // SAFETY: as in `groups`.
        unsafe { std::slice::from_raw_parts_mut(self.groups.as_mut_ptr().cast::<RayGroup>(), self.n_groups) }
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

    /// A leaf over `tris` (`first` is the index of `tris[0]` in leaf order) for every group from
    /// `from` whose rays hit its box `[lo, hi]`; true when one of them found a nearer hit.
    #[inline(always)]
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

    /// Test triangles `tris` (the first at `first` in leaf order) against the rays of group `g`
    /// in `mask`; true when one of them found a nearer hit.
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
            t_max = RayGroup::t_max_of(self.rays, 4 * g);
            found = true;
        }
        if found {
            self.groups_mut()[g].set_t_max(t_max);
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

/// A BVH layout as the packet walk sees it: nodes whose children are boxes, up to eight, with their
/// planes in SoA order (`min[axis][slot]`), and child references (`u32`) the walk keeps on its
/// stack.
pub(super) trait PacketTree {
    fn prim_ids(&self) -> &[u32];
    /// `f` of the triangles `start..start + count` of a leaf, in leaf order.
    fn with_leaf<R>(&self, start: usize, count: usize, f: impl FnOnce(&[[glam::Vec3; 3]]) -> R) -> R;
    fn root_bounds(&self) -> Aabb;
    fn root(&self) -> u32;
    fn is_leaf(&self, r: u32) -> bool;
    /// The valid child slots of interior node `r`.
    fn slots(&self, r: u32) -> u32;
    /// Slot `slot`'s box, as its planes.
    fn slot_planes(&self, r: u32, slot: usize) -> ([f32; 3], [f32; 3]);
    /// Per slot, where its box's centre lies along `lead` (twice that, in fact: the order is all
    /// that counts).
    fn keys(&self, r: u32, lead: Vec3) -> [f32; 8];
    /// The slots of `missed` whose boxes some ray of the packet may still hit before `t_far`
    /// (the packet's interval test, `RayInterval`).
    fn may_hit(&self, r: u32, missed: u32, frustum: &RayInterval, t_far: f32) -> u32;
    /// The reference of slot `slot` of interior node `r`.
    fn child(&self, r: u32, slot: usize) -> u32;
    /// A leaf's box, and its triangles `first..first + count` in leaf order.
    fn leaf(&self, r: u32) -> ([f32; 3], [f32; 3], usize, usize);
}

impl PacketTree for Bvh {
    fn prim_ids(&self) -> &[u32] {
        &self.prim_ids
    }
    #[inline(always)]
    fn with_leaf<R>(&self, start: usize, count: usize, f: impl FnOnce(&[[glam::Vec3; 3]]) -> R) -> R {
        f(&self.tris[start..start + count])
    }
    fn root_bounds(&self) -> Aabb {
        self.root_bounds()
    }
    fn root(&self) -> u32 {
        0
    }
    #[inline(always)]
    fn is_leaf(&self, r: u32) -> bool {
        self.nodes[r as usize].is_leaf()
    }
    #[inline(always)]
    fn slots(&self, _: u32) -> u32 {
        0b11
    }
    #[inline(always)]
    fn slot_planes(&self, r: u32, slot: usize) -> ([f32; 3], [f32; 3]) {
        let n = &self.nodes[(self.nodes[r as usize].index as usize) + slot];
        (n.lo, n.hi)
    }
    #[inline(always)]
    fn keys(&self, r: u32, lead: Vec3) -> [f32; 8] {
        let key = |s: usize| {
            let (lo, hi) = self.slot_planes(r, s);
            (Vec3::from_array(lo) + Vec3::from_array(hi)).dot(lead)
        };
        [key(0), key(1), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    }
    #[inline(always)]
    fn may_hit(&self, r: u32, missed: u32, frustum: &RayInterval, t_far: f32) -> u32 {
        let mut m = 0;
        for s in 0..2 {
            if missed & (1 << s) != 0 {
                let (lo, hi) = self.slot_planes(r, s);
                m |= (!frustum.misses(&Aabb::new(Vec3::from_array(lo), Vec3::from_array(hi)), t_far) as u32) << s;
            }
        }
        m
    }
    #[inline(always)]
    fn child(&self, r: u32, slot: usize) -> u32 {
        self.nodes[r as usize].index + slot as u32
    }
    #[inline(always)]
    fn leaf(&self, r: u32) -> ([f32; 3], [f32; 3], usize, usize) {
        let n = &self.nodes[r as usize];
        (n.lo, n.hi, n.index as usize, n.count as usize)
    }
}

/// The fixed part of a packet walk's stack: at most seven pushes per level of an 8-wide tree built
/// by bvhscope (the build bounds the depth by `TRAVERSAL_STACK_SIZE`; a deeper imported tree
/// spills onto the heap). Not initialised: its size costs nothing.
const STACK: usize = 7 * TRAVERSAL_STACK_SIZE + 8;

/// The packet walk, written once for every layout (Wald, Boulos & Shirley 2007, §4). For each
/// child of a node the packet finds the first group of four rays that hits its box, starting from
/// the node's own first group; children no group hits are dropped, the others are visited nearest
/// first along the packet's leading direction (their centres projected on it: for coherent rays
/// that is front to back; the order only affects speed, never the result). Most children are hit
/// by the node's first group; the others are first put to the packet's frustum, one SIMD test per
/// four boxes, then to the following groups one by one. At a leaf every group from its first one
/// tests the leaf's triangles with the four-ray triangle test (bit for bit the single-ray test), so
/// each ray gets the hit it would get alone.
fn walk<B: PacketTree, T: TriangleIntersector>(bvh: &B, rays: &mut [Ray], hits: &mut [Option<Hit>]) {
    let lead = rays[0].dir();
    let mut slot = MaybeUninit::uninit();
    let packet = Packet::<T>::new_in(&mut slot, rays);
    let mut t_far = packet.t_far();
    // The root's first group: the rays before it miss the whole tree.
    let (lo, hi) = bvh.root_bounds().planes();
    let Some(root_group) = (0..packet.n_groups).find(|&g| packet.group_hits(g, lo, hi) != 0) else {
        return;
    };
    // (child reference, first group that may hit it).
    let mut stack = TraversalStack::<STACK, (u32, u8)>::new();
    let (mut cur, mut first) = (bvh.root(), root_group);
    loop {
        if !bvh.is_leaf(cur) {
            let key = bvh.keys(cur, lead);
            // The hit children as (key, reference, first group), kept sorted far to near.
            let mut hit = [(0f32, 0u32, 0u8); 8];
            let mut n = 0;
            let mut add = |s: usize, g: usize| {
                let mut j = n;
                while j > 0 && hit[j - 1].0 < key[s] {
                    hit[j] = hit[j - 1];
                    j -= 1;
                }
                hit[j] = (key[s], bvh.child(cur, s), g as u8);
                n += 1;
            };
            let mut missed = 0u32;
            let mut todo = bvh.slots(cur);
            while todo != 0 {
                let s = todo.trailing_zeros() as usize;
                todo &= todo - 1;
                let (lo, hi) = bvh.slot_planes(cur, s);
                if packet.group_hits(first, lo, hi) != 0 {
                    add(s, first);
                } else {
                    missed |= 1 << s;
                }
            }
            if missed != 0 && first + 1 < packet.n_groups {
                missed &= bvh.may_hit(cur, missed, &packet.frustum, t_far);
                while missed != 0 {
                    let s = missed.trailing_zeros() as usize;
                    missed &= missed - 1;
                    let (lo, hi) = bvh.slot_planes(cur, s);
                    let mut g = first + 1;
                    while g < packet.n_groups && packet.group_hits(g, lo, hi) == 0 {
                        g += 1;
                    }
                    if g < packet.n_groups {
                        add(s, g);
                    }
                }
            }
            if n > 0 {
                for &(_, r, g) in &hit[..n - 1] {
                    stack.push((r, g));
                }
                (cur, first) = (hit[n - 1].1, hit[n - 1].2 as usize);
                continue;
            }
        } else {
            let (lo, hi, start, count) = bvh.leaf(cur);
            if bvh.with_leaf(start, count, |tris| packet.leaf_groups(first, lo, hi, tris, start)) {
                t_far = packet.t_far();
            }
        }
        let Some((r, g)) = stack.pop() else { break };
        (cur, first) = (r, g as usize);
    }
    packet.finish(bvh.prim_ids(), hits);
}

/// Closest hits of up to `PACKET` coherent rays (an 8×8 pixel block, best in the order of
/// `packet_position`), the same as `closest_hit` on each.
pub(super) fn closest_hits_packet<B: PacketTree>(
    bvh: &B,
    rays: &mut [Ray],
    hits: &mut [Option<Hit>],
    opts: TraceOptions,
) {
    assert!(rays.len() <= PACKET && hits.len() == rays.len(), "a packet holds at most {PACKET} rays");
    hits.fill(None);
    if rays.is_empty() || bvh.prim_ids().is_empty() {
        return;
    }
    // The packet's order is its own (the lead ray's), whatever `opts.order` says.
    super::accel::dispatch!(opts, |T, _BY_DISTANCE| walk::<B, T>(bvh, rays, hits))
}

#[cfg(test)]
#[path = "packet_tests.rs"]
mod tests;
