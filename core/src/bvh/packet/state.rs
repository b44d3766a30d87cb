//! A packet's per-ray state during the walk: its SIMD groups of rays (`G` groups of `K::N` rays:
//! sixteen of four, or four of sixteen with AVX-512) for the box tests, each group's prepared
//! triangle test, and each ray's hit so far.

use super::lanes::PacketLanes;
use crate::bvh::accel::{Hit, PACKET};
use crate::geometry::slab_packet::RayInterval;
use crate::geometry::{Ray, TriangleHit, TriangleIntersector};
use std::mem::MaybeUninit;

/// The arrays are left uninitialised past what is written (see `new_in`).
pub(super) struct Packet<'r, T: TriangleIntersector, K: PacketLanes<T>, const G: usize> {
    kernel: K,
    rays: &'r mut [Ray],
    /// The first `n_groups` are set.
    groups: [MaybeUninit<K::Group>; G],
    pub(super) n_groups: usize,
    /// Every ray's direction has the signs `neg` on the three axes (the common case for primary
    /// rays), so box tests pick planes once per box.
    one_sign: bool,
    neg: [bool; 3],
    pub(super) frustum: RayInterval,
    /// Each group's triangle-test setup, made at its first leaf (bit g of `prepared_mask` set).
    prepared: [MaybeUninit<K::Prepared>; G],
    prepared_mask: u64,
    /// Each ray's nearest hit so far (bit k of `hit_mask` set): leaf-order triangle and barycentrics.
    best: [MaybeUninit<(u32, TriangleHit)>; PACKET],
    hit_mask: u64,
    /// Any-hit walks: the rays that have left the walk with their hit (`retire_hits`).
    retired: u64,
}

impl<'r, T: TriangleIntersector, K: PacketLanes<T>, const G: usize> Packet<'r, T, K, G> {
    /// Set up the packet of `rays` in `slot`, in place: returning it by value would copy the
    /// whole state (kilobytes, most of it never written), which costs as much as tracing a packet
    /// that misses everything. The caller returns before this for an empty packet.
    #[inline(always)]
    pub(super) fn new_in<'s>(slot: &'s mut MaybeUninit<Self>, kernel: K, rays: &'r mut [Ray]) -> &'s mut Self {
        debug_assert!(rays.len() <= PACKET && G * K::N == PACKET, "a packet holds at most {PACKET} rays");
        let n_groups = rays.len().div_ceil(K::N);
        // Every field, by name: a field added to `Packet` and not written below fails to compile
        // here instead of being left uninitialised.
        let _every_field = |p: &Self| {
            let Packet {
                kernel: _,
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
                retired: _,
            } = p;
        };
        let p = slot.as_mut_ptr();
        // SAFETY: every field that is not a MaybeUninit array is written here through raw
        // pointers (no reference to uninitialised data is made) before the slot is taken as set.
        let packet = unsafe {
            use std::ptr::addr_of_mut;
            addr_of_mut!((*p).kernel).write(kernel);
            addr_of_mut!((*p).rays).write(rays);
            addr_of_mut!((*p).n_groups).write(n_groups);
            addr_of_mut!((*p).one_sign).write(false);
            addr_of_mut!((*p).neg).write([false; 3]);
            addr_of_mut!((*p).frustum).write(RayInterval::OFF);
            addr_of_mut!((*p).prepared_mask).write(0);
            addr_of_mut!((*p).hit_mask).write(0);
            addr_of_mut!((*p).retired).write(0);
            slot.assume_init_mut()
        };
        for g in 0..n_groups {
            packet.groups[g].write(kernel.group(packet.rays, K::N * g));
        }
        (packet.one_sign, packet.neg) = kernel.signs(packet.groups());
        packet.frustum = kernel.frustum(packet.groups());
        packet
    }

    /// The set groups.
    #[inline(always)]
    fn groups(&self) -> &[K::Group] {
        // SAFETY: `new_in` wrote the first `n_groups` slots; MaybeUninit<X> has X's layout.
        unsafe { std::slice::from_raw_parts(self.groups.as_ptr().cast::<K::Group>(), self.n_groups) }
    }

    /// The farthest `t_max` of any ray: nothing beyond it can matter to the packet.
    pub(super) fn t_far(&self) -> f32 {
        self.kernel.t_far(self.groups())
    }

    #[inline(always)]
    pub(super) fn group_hits(&self, g: usize, lo: [f32; 3], hi: [f32; 3]) -> u32 {
        let group = &self.groups()[g];
        if self.one_sign {
            let pick = |axis: usize, near: bool| if self.neg[axis] == near { hi[axis] } else { lo[axis] };
            let near = [pick(0, true), pick(1, true), pick(2, true)];
            let far = [pick(0, false), pick(1, false), pick(2, false)];
            self.kernel.hit_planes(group, near, far)
        } else {
            self.kernel.hit(group, lo, hi)
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
    /// in `mask` (`PacketLanes::leaf`); true when one of them found a nearer hit.
    fn leaf(&mut self, g: usize, mask: u32, tris: &[[glam::Vec3; 3]], first: usize) -> bool {
        let (n, kernel) = (K::N, self.kernel);
        // Only the lanes of real rays (the last group may have padding lanes).
        let mask = mask & ((1u32 << (self.rays.len() - n * g).min(n)) - 1);
        if self.prepared_mask & (1 << g) == 0 {
            self.prepared[g].write(kernel.prepare(self.rays, n * g));
            self.prepared_mask |= 1 << g;
        }
        // SAFETY: bit g of `prepared_mask` is set only after slot g was written; `new_in` wrote
        // group g (g < n_groups).
        let (prepared, group) = unsafe { (self.prepared[g].assume_init_ref(), self.groups[g].assume_init_mut()) };
        let (best, hit_mask) = (&mut self.best, &mut self.hit_mask);
        kernel.leaf(prepared, group, mask, tris, self.rays, n * g, |lane, i, h| {
            let k = n * g + lane;
            best[k].write(((first + i) as u32, h));
            *hit_mask |= 1 << k;
        })
    }

    /// Any-hit walks: every ray that found a hit since the last call leaves the walk (its `t_max`
    /// becomes −∞, as a padding lane's, so none of its box or triangle tests passes again) and its
    /// group takes that. True when every ray of the packet has a hit: the walk can stop.
    pub(super) fn retire_hits(&mut self) -> bool {
        let mut new = self.hit_mask & !self.retired;
        self.retired |= new;
        let (n, kernel) = (K::N, self.kernel);
        let mut touched = 0u64;
        while new != 0 {
            let k = new.trailing_zeros() as usize;
            new &= new - 1;
            self.rays[k].t_max = f32::NEG_INFINITY;
            touched |= 1 << (k / n);
        }
        while touched != 0 {
            let g = touched.trailing_zeros() as usize;
            touched &= touched - 1;
            // SAFETY: a ray of group g hit, so g < n_groups: `new_in` wrote it.
            kernel.refresh(unsafe { self.groups[g].assume_init_mut() }, self.rays, n * g);
        }
        self.retired.count_ones() as usize == self.rays.len()
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
