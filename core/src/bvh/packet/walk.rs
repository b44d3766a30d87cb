//! The packet walk: 8×8 rays through one tree, lanes masked as they leave.

use crate::bvh::accel::{Hit, TraceOptions, PACKET};
use crate::bvh::node::{Bvh, TRAVERSAL_STACK_SIZE};
use crate::bvh::packet::lanes::{Four, PacketLanes};
use crate::bvh::packet::state::Packet;
use crate::bvh::stack::TraversalStack;
use crate::cpu::Simd;
use crate::geometry::slab_packet::RayInterval;
use crate::geometry::{Aabb, Ray, TriangleIntersector};
use glam::Vec3;
use std::mem::MaybeUninit;

/// Side of the square pixel block a packet covers.
pub const PACKET_SIDE: u32 = 8;

/// Groups of four rays in a packet.
pub(super) const GROUPS: usize = PACKET / 4;

/// Where ray `k` of a packet sits in its 8×8 block: Z-order (even bits of `k` give x, odd bits y),
/// so every four consecutive rays, the SIMD groups, are 2×2 pixels and a range of groups stays
/// compact on screen.
pub fn packet_position(k: u32) -> (u32, u32) {
    let bits = |b: u32| (b & 1) | (b >> 1 & 2) | (b >> 2 & 4);
    (bits(k), bits(k >> 1))
}

/// A BVH layout as the packet walk sees it: nodes whose children are boxes, up to eight, with their
/// planes in SoA order (`min[axis][slot]`), and child references (`u32`) the walk keeps on its
/// stack.
pub(crate) trait PacketTree {
    /// The kernels this tree's packets run: sixteen-ray groups where it is `Avx512`, else four.
    fn simd(&self) -> Simd;
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
    /// The binary tree keeps no kernel choice of its own: the process's (`Simd::chosen`).
    fn simd(&self) -> Simd {
        Simd::chosen()
    }
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
pub(super) const STACK: usize = 7 * TRAVERSAL_STACK_SIZE + 8;

/// The packet walk, written once for every layout (Wald, Boulos & Shirley 2007, §4). For each
/// child of a node the packet finds the first group of rays that hits its box, starting from
/// the node's own first group; children no group hits are dropped, the others are visited nearest
/// first along the packet's leading direction (their centres projected on it: for coherent rays
/// that is front to back; the order only affects speed, never the result). Most children are hit
/// by the node's first group; the others are first put to the packet's frustum, one SIMD test per
/// four boxes, then to the following groups one by one. At a leaf every group from its first one
/// tests the leaf's triangles with the group's triangle test (bit for bit the single-ray test), so
/// each ray gets the hit it would get alone. `kernel` makes and tests the packet's groups (`G` of them).
///
/// With `ANY` (any-hit queries: shadow and ambient-occlusion rays) a ray leaves the walk at its
/// first hit (`Packet::retire_hits`), and the walk ends once every ray has one.
#[inline(always)]
pub(super) fn walk<B: PacketTree, T: TriangleIntersector, K: PacketLanes<T>, const G: usize, const ANY: bool>(
    kernel: K,
    bvh: &B,
    rays: &mut [Ray],
    hits: &mut [Option<Hit>],
) {
    let lead = rays[0].dir();
    let mut slot = MaybeUninit::uninit();
    let packet = Packet::<T, K, G>::new_in(&mut slot, kernel, rays);
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
            // Groups of sixteen: the frustum first, for every child (`PacketLanes::FRUSTUM_FIRST`).
            let culled = K::FRUSTUM_FIRST && packet.frustum.is_valid();
            if culled {
                todo = bvh.may_hit(cur, todo, &packet.frustum, t_far);
            }
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
                if !culled {
                    missed &= bvh.may_hit(cur, missed, &packet.frustum, t_far);
                }
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
                if ANY && packet.retire_hits() {
                    break;
                }
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
pub(crate) fn closest_hits_packet<B: PacketTree>(
    bvh: &B,
    rays: &mut [Ray],
    hits: &mut [Option<Hit>],
    opts: TraceOptions,
) {
    packet::<B, false>(bvh, rays, hits, opts)
}

/// Whether each of up to `PACKET` coherent rays hits anything within its interval (`occluded[k]`
/// for `rays[k]`), the same as `any_hit` on each: the packet walk with any-hit queries.
pub(crate) fn any_hits_packet<B: PacketTree>(bvh: &B, rays: &[Ray], occluded: &mut [bool], opts: TraceOptions) {
    assert!(rays.len() <= PACKET && occluded.len() == rays.len(), "a packet holds at most {PACKET} rays");
    let Some(&first) = rays.first() else { return };
    let mut copy = [first; PACKET];
    copy[..rays.len()].copy_from_slice(rays);
    let mut hits = [None; PACKET];
    packet::<B, true>(bvh, &mut copy[..rays.len()], &mut hits[..rays.len()], opts);
    for (o, h) in occluded.iter_mut().zip(&hits) {
        *o = h.is_some();
    }
}

pub(super) fn packet<B: PacketTree, const ANY: bool>(
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
    crate::bvh::accel::dispatch!(opts, |T, _BY_DISTANCE| {
        #[cfg(target_arch = "x86_64")]
        if bvh.simd() == Simd::Avx512 {
            if let Some(k) = crate::geometry::avx512::Avx512::detect() {
                // SAFETY: `detect` found AVX-512F/VL and the AVX2 set.
                return unsafe { walk_avx512::<B, T, ANY>(k, bvh, rays, hits) };
            }
        }
        #[cfg(target_arch = "x86_64")]
        if bvh.simd() == Simd::Avx2 {
            if let Some(k) = crate::geometry::slab8::Avx2::detect() {
                // SAFETY: `detect` found AVX2, FMA and the bit instructions.
                return unsafe { walk_avx2::<B, T, ANY>(k, bvh, rays, hits) };
            }
        }
        walk::<B, T, _, GROUPS, ANY>(Four, bvh, rays, hits)
    })
}

/// The walk compiled for AVX2 with groups of eight rays (`geometry::packet8`): eight per packet.
///
/// # Safety
/// The CPU must have these features: `k` proves it.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,popcnt,bmi1,bmi2,lzcnt")]
pub(super) unsafe fn walk_avx2<B: PacketTree, T: TriangleIntersector, const ANY: bool>(
    k: crate::geometry::slab8::Avx2,
    bvh: &B,
    rays: &mut [Ray],
    hits: &mut [Option<Hit>],
) {
    walk::<B, T, _, { PACKET / 8 }, ANY>(crate::bvh::packet::lanes::Eight(k), bvh, rays, hits)
}

/// The walk compiled for AVX-512 with groups of sixteen rays (`avx512::packet`): four per packet.
///
/// # Safety
/// The CPU must have these features: `k` proves it.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx2,fma,popcnt,bmi1,bmi2,lzcnt")]
pub(super) unsafe fn walk_avx512<B: PacketTree, T: TriangleIntersector, const ANY: bool>(
    k: crate::geometry::avx512::Avx512,
    bvh: &B,
    rays: &mut [Ray],
    hits: &mut [Option<Hit>],
) {
    walk::<B, T, _, { PACKET / 16 }, ANY>(crate::bvh::packet::lanes::Sixteen(k), bvh, rays, hits)
}
