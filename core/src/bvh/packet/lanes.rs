//! The SIMD groups a packet is cut into, as the packet walk uses them: four rays per group on every
//! CPU (`Four`: `slab_packet::RayGroup` and `TriangleIntersector::intersect4`), eight with AVX2
//! (`Eight`: `geometry::packet8`), sixteen with AVX-512 (`Sixteen`: `avx512::packet`). Each group
//! tests a box or a triangle for all its rays in one pass, lane by lane the single-ray arithmetic,
//! so a packet finds what single rays find whichever runs; the walk (`super::walk`) is written
//! once for all three.

use crate::geometry::slab_packet::{RayGroup, RayInterval};
use crate::geometry::triangle::Hits4;
use crate::geometry::{Ray, TriangleHit, TriangleIntersector};
use glam::Vec3;
use wide::f32x4;

/// One kind of group: how it is made from a packet's rays and what it tests.
pub(crate) trait PacketLanes<T: TriangleIntersector>: Copy {
    /// Rays per group.
    const N: usize;
    /// Whether the walk puts every child to the packet's frustum before its first group (one
    /// test for the packet instead of a group pass per child: worth it where a group pass is
    /// dear), or only the children that group misses.
    const FRUSTUM_FIRST: bool;
    type Group;
    /// The triangle test's per-group setup, made at the group's first leaf.
    type Prepared: Copy;
    type Hits;
    /// Rays `base..base + N` (lanes past the end repeat the last ray with `t_max = -inf`).
    fn group(self, rays: &[Ray], base: usize) -> Self::Group;
    /// The lanes whose ray hits `[lo, hi]` within its interval.
    fn hit(self, g: &Self::Group, lo: [f32; 3], hi: [f32; 3]) -> u32;
    /// `hit` with the near and far planes already chosen (every ray has the packet's signs).
    fn hit_planes(self, g: &Self::Group, near: [f32; 3], far: [f32; 3]) -> u32;
    /// Take the rays' `t_max` again after hits.
    fn refresh(self, g: &mut Self::Group, rays: &[Ray], base: usize);
    /// Whether every ray of `groups` has the same direction sign on each axis, and the signs
    /// (true: negative).
    fn signs(self, groups: &[Self::Group]) -> (bool, [bool; 3]);
    /// The farthest `t_max` of any ray of `groups`.
    fn t_far(self, groups: &[Self::Group]) -> f32;
    /// The packet's frustum (`RayInterval`).
    fn frustum(self, groups: &[Self::Group]) -> RayInterval;
    fn prepare(self, rays: &[Ray], base: usize) -> Self::Prepared;
    /// `tri` against the rays of `g` in `lanes`, each within its interval.
    fn intersect(self, p: &Self::Prepared, g: &Self::Group, lanes: u32, tri: &[Vec3; 3]) -> Self::Hits;
    fn mask(h: &Self::Hits) -> u32;
    /// Lane k's hit (meaningful where its bit of the mask is set).
    fn lane(h: &Self::Hits, k: usize) -> TriangleHit;
    /// A leaf for group `g` (rays `base..base + N` of `rays`): `leaf_loop`.
    #[allow(clippy::too_many_arguments)]
    fn leaf(
        self,
        p: &Self::Prepared,
        g: &mut Self::Group,
        lanes: u32,
        tris: &[[Vec3; 3]],
        rays: &mut [Ray],
        base: usize,
        record: impl FnMut(usize, usize, TriangleHit),
    ) -> bool {
        leaf_loop::<T, Self>(self, p, g, lanes, tris, rays, base, record)
    }
}

/// Each triangle of `tris` in order against the rays of group `g` in `lanes`: a ray that hits
/// takes the hit's distance as its `t_max` and `record(ray in the group, triangle, hit)` is told;
/// after a triangle that hit, the group takes its rays' new `t_max` before the next one is tested.
/// True when some ray found a nearer hit.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn leaf_loop<T: TriangleIntersector, K: PacketLanes<T>>(
    kernel: K,
    p: &K::Prepared,
    g: &mut K::Group,
    lanes: u32,
    tris: &[[Vec3; 3]],
    rays: &mut [Ray],
    base: usize,
    mut record: impl FnMut(usize, usize, TriangleHit),
) -> bool {
    let mut found = false;
    for (i, tri) in tris.iter().enumerate() {
        let hits = kernel.intersect(p, g, lanes, tri);
        let mut m = K::mask(&hits);
        if m == 0 {
            continue;
        }
        while m != 0 {
            let lane = m.trailing_zeros() as usize;
            m &= m - 1;
            let h = K::lane(&hits, lane);
            rays[base + lane].t_max = h.t;
            record(lane, i, h);
        }
        kernel.refresh(g, rays, base);
        found = true;
    }
    found
}

/// Groups of four rays (`wide::f32x4`: SSE on x86-64, NEON on aarch64).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Four;

impl<T: TriangleIntersector> PacketLanes<T> for Four {
    const N: usize = 4;
    const FRUSTUM_FIRST: bool = false;
    type Group = RayGroup;
    type Prepared = T::Prepared4;
    type Hits = Hits4;

    #[inline(always)]
    fn group(self, rays: &[Ray], base: usize) -> RayGroup {
        RayGroup::new(rays, base)
    }
    #[inline(always)]
    fn hit(self, g: &RayGroup, lo: [f32; 3], hi: [f32; 3]) -> u32 {
        g.hit(lo, hi)
    }
    #[inline(always)]
    fn hit_planes(self, g: &RayGroup, near: [f32; 3], far: [f32; 3]) -> u32 {
        g.hit_planes(near, far)
    }
    #[inline(always)]
    fn refresh(self, g: &mut RayGroup, rays: &[Ray], base: usize) {
        g.set_t_max(RayGroup::t_max_of(rays, base));
    }
    #[inline(always)]
    fn signs(self, groups: &[RayGroup]) -> (bool, [bool; 3]) {
        // Lane masks combined over the groups, reduced once at the end.
        let (mut all_neg, mut any_neg) = ([f32x4::ZERO.simd_eq(f32x4::ZERO); 3], [f32x4::ZERO; 3]);
        for group in groups {
            for axis in 0..3 {
                (all_neg[axis], any_neg[axis]) = (all_neg[axis] & group.neg[axis], any_neg[axis] | group.neg[axis]);
            }
        }
        let one_sign = (0..3).all(|a| all_neg[a].all() || !any_neg[a].any());
        (one_sign, [all_neg[0].all(), all_neg[1].all(), all_neg[2].all()])
    }
    #[inline(always)]
    fn t_far(self, groups: &[RayGroup]) -> f32 {
        let far = groups.iter().fold(f32x4::splat(f32::NEG_INFINITY), |m, g| m.max(g.t_max));
        far.to_array().into_iter().fold(f32::NEG_INFINITY, f32::max)
    }
    #[inline(always)]
    fn frustum(self, groups: &[RayGroup]) -> RayInterval {
        RayInterval::new(groups)
    }
    #[inline(always)]
    fn prepare(self, rays: &[Ray], base: usize) -> T::Prepared4 {
        T::prepare4(rays, base)
    }
    #[inline(always)]
    fn intersect(self, p: &T::Prepared4, g: &RayGroup, lanes: u32, tri: &[Vec3; 3]) -> Hits4 {
        T::intersect4(p, g.t_min, g.t_max, lanes, tri)
    }
    #[inline(always)]
    fn mask(h: &Hits4) -> u32 {
        h.mask
    }
    #[inline(always)]
    fn lane(h: &Hits4, k: usize) -> TriangleHit {
        TriangleHit { t: h.t[k], u: h.u[k], v: h.v[k] }
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use eight::Eight;

#[cfg(target_arch = "x86_64")]
mod eight {
    use super::*;
    use crate::geometry::packet8::{interval8, RayGroup8};
    use crate::geometry::slab8::Avx2;
    use crate::geometry::triangle8::Hits8;

    /// Groups of eight rays in AVX2 registers (`geometry::packet8`), where the CPU has them.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct Eight(pub Avx2);

    // SAFETY (every `unsafe` below): the kernels are compiled for AVX2 and FMA
    // (`#[target_feature]`), and `self.0` proves the CPU has them.
    impl<T: TriangleIntersector> PacketLanes<T> for Eight {
        const N: usize = 8;
        // Measured both ways (bunny and beast, leaves of 8, AVX2): the frustum first was 4 %
        // faster on the bunny's primary packets and 15 % slower on the beast's.
        const FRUSTUM_FIRST: bool = false;
        type Group = RayGroup8;
        type Prepared = T::Prepared8;
        type Hits = Hits8;

        #[inline(always)]
        fn group(self, rays: &[Ray], base: usize) -> RayGroup8 {
            unsafe { RayGroup8::new(self.0, rays, base) }
        }
        #[inline(always)]
        fn hit(self, g: &RayGroup8, lo: [f32; 3], hi: [f32; 3]) -> u32 {
            unsafe { g.hit(self.0, lo, hi) }
        }
        #[inline(always)]
        fn hit_planes(self, g: &RayGroup8, near: [f32; 3], far: [f32; 3]) -> u32 {
            unsafe { g.hit_planes(self.0, near, far) }
        }
        #[inline(always)]
        fn refresh(self, g: &mut RayGroup8, rays: &[Ray], base: usize) {
            unsafe { g.refresh(self.0, rays, base) };
        }
        #[inline(always)]
        fn signs(self, groups: &[RayGroup8]) -> (bool, [bool; 3]) {
            let (mut all_neg, mut any_neg) = ([u8::MAX; 3], [0u8; 3]);
            for group in groups {
                for axis in 0..3 {
                    (all_neg[axis], any_neg[axis]) = (all_neg[axis] & group.neg[axis], any_neg[axis] | group.neg[axis]);
                }
            }
            let one_sign = (0..3).all(|a| all_neg[a] == u8::MAX || any_neg[a] == 0);
            (one_sign, all_neg.map(|m| m == u8::MAX))
        }
        #[inline(always)]
        fn t_far(self, groups: &[RayGroup8]) -> f32 {
            groups.iter().map(|g| unsafe { g.t_far(self.0) }).fold(f32::NEG_INFINITY, f32::max)
        }
        #[inline(always)]
        fn frustum(self, groups: &[RayGroup8]) -> RayInterval {
            unsafe { interval8(self.0, groups) }
        }
        #[inline(always)]
        fn prepare(self, rays: &[Ray], base: usize) -> T::Prepared8 {
            T::prepare8(self.0, rays, base)
        }
        #[inline(always)]
        fn intersect(self, p: &T::Prepared8, g: &RayGroup8, lanes: u32, tri: &[Vec3; 3]) -> Hits8 {
            T::intersect8(self.0, p, g.t_min, g.t_max, lanes, tri)
        }
        #[inline(always)]
        fn mask(h: &Hits8) -> u32 {
            h.mask
        }
        #[inline(always)]
        fn lane(h: &Hits8, k: usize) -> TriangleHit {
            TriangleHit { t: h.t[k], u: h.u[k], v: h.v[k] }
        }
        #[inline(always)]
        fn leaf(
            self,
            p: &T::Prepared8,
            g: &mut RayGroup8,
            lanes: u32,
            tris: &[[Vec3; 3]],
            rays: &mut [Ray],
            base: usize,
            record: impl FnMut(usize, usize, TriangleHit),
        ) -> bool {
            unsafe { leaf8::<T, _>(self, p, g, lanes, tris, rays, base, record) }
        }
    }

    /// `leaf_loop` compiled for AVX2, so that the triangle test inlines into the loop over the
    /// leaf's triangles (the packet walk calls it from a closure, which has no target features).
    ///
    /// # Safety
    /// The CPU has AVX2 and FMA (`k.0` proves it).
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn leaf8<T: TriangleIntersector, F: FnMut(usize, usize, TriangleHit)>(
        k: Eight,
        p: &T::Prepared8,
        g: &mut RayGroup8,
        lanes: u32,
        tris: &[[Vec3; 3]],
        rays: &mut [Ray],
        base: usize,
        record: F,
    ) -> bool {
        leaf_loop::<T, Eight>(k, p, g, lanes, tris, rays, base, record)
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use sixteen::Sixteen;

#[cfg(target_arch = "x86_64")]
mod sixteen {
    use super::*;
    use crate::geometry::avx512::packet::{interval16, RayGroup16};
    use crate::geometry::avx512::{Avx512, Hits16};

    /// Groups of sixteen rays in AVX-512 registers (`avx512::packet`), where the CPU has them.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct Sixteen(pub Avx512);

    // SAFETY (every `unsafe` below): the kernels are compiled for AVX-512 (`#[target_feature]`),
    // and `self.0` proves the CPU has it.
    impl<T: TriangleIntersector> PacketLanes<T> for Sixteen {
        const N: usize = 16;
        const FRUSTUM_FIRST: bool = true;
        type Group = RayGroup16;
        type Prepared = T::Prepared16;
        type Hits = Hits16;

        #[inline(always)]
        fn group(self, rays: &[Ray], base: usize) -> RayGroup16 {
            unsafe { RayGroup16::new(self.0, rays, base) }
        }
        #[inline(always)]
        fn hit(self, g: &RayGroup16, lo: [f32; 3], hi: [f32; 3]) -> u32 {
            unsafe { g.hit(self.0, lo, hi) }
        }
        #[inline(always)]
        fn hit_planes(self, g: &RayGroup16, near: [f32; 3], far: [f32; 3]) -> u32 {
            unsafe { g.hit_planes(self.0, near, far) }
        }
        #[inline(always)]
        fn refresh(self, g: &mut RayGroup16, rays: &[Ray], base: usize) {
            unsafe { g.refresh(self.0, rays, base) };
        }
        #[inline(always)]
        fn signs(self, groups: &[RayGroup16]) -> (bool, [bool; 3]) {
            let (mut all_neg, mut any_neg) = ([u16::MAX; 3], [0u16; 3]);
            for group in groups {
                for axis in 0..3 {
                    (all_neg[axis], any_neg[axis]) = (all_neg[axis] & group.neg[axis], any_neg[axis] | group.neg[axis]);
                }
            }
            let one_sign = (0..3).all(|a| all_neg[a] == u16::MAX || any_neg[a] == 0);
            (one_sign, all_neg.map(|m| m == u16::MAX))
        }
        #[inline(always)]
        fn t_far(self, groups: &[RayGroup16]) -> f32 {
            groups.iter().map(|g| unsafe { g.t_far(self.0) }).fold(f32::NEG_INFINITY, f32::max)
        }
        #[inline(always)]
        fn frustum(self, groups: &[RayGroup16]) -> RayInterval {
            unsafe { interval16(self.0, groups) }
        }
        #[inline(always)]
        fn prepare(self, rays: &[Ray], base: usize) -> T::Prepared16 {
            T::prepare16(self.0, rays, base)
        }
        #[inline(always)]
        fn intersect(self, p: &T::Prepared16, g: &RayGroup16, lanes: u32, tri: &[Vec3; 3]) -> Hits16 {
            T::intersect16(self.0, p, g.t_min, g.t_max, lanes, tri)
        }
        #[inline(always)]
        fn mask(h: &Hits16) -> u32 {
            h.mask
        }
        #[inline(always)]
        fn lane(h: &Hits16, k: usize) -> TriangleHit {
            TriangleHit { t: h.t[k], u: h.u[k], v: h.v[k] }
        }
        #[inline(always)]
        fn leaf(
            self,
            p: &T::Prepared16,
            g: &mut RayGroup16,
            lanes: u32,
            tris: &[[Vec3; 3]],
            rays: &mut [Ray],
            base: usize,
            record: impl FnMut(usize, usize, TriangleHit),
        ) -> bool {
            unsafe { leaf16::<T, _>(self, p, g, lanes, tris, rays, base, record) }
        }
    }

    /// `leaf_loop` compiled for AVX-512, so that the triangle test inlines into the loop over the
    /// leaf's triangles (the packet walk calls it from a closure, which has no target features).
    ///
    /// # Safety
    /// The CPU has AVX-512F/VL (`k.0` proves it).
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn leaf16<T: TriangleIntersector, F: FnMut(usize, usize, TriangleHit)>(
        k: Sixteen,
        p: &T::Prepared16,
        g: &mut RayGroup16,
        lanes: u32,
        tris: &[[Vec3; 3]],
        rays: &mut [Ray],
        base: usize,
        record: F,
    ) -> bool {
        leaf_loop::<T, Sixteen>(k, p, g, lanes, tris, rays, base, record)
    }
}
