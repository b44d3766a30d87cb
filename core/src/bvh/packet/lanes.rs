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

/// The `PacketLanes` of a wide group (`Eight` with AVX2, `Sixteen` with AVX-512): the same calls
/// on their kernels (`geometry::packet8`, `avx512::packet`), which are compiled for the family's
/// features and take its proof, so every call below is `unsafe` with the proof in hand. The leaf
/// loop is compiled for the features too, so the triangle test inlines into it (the packet walk
/// calls it from a closure, which has no target features).
#[cfg(target_arch = "x86_64")]
macro_rules! wide_lanes {
    (
        $(#[$doc:meta])*
        $name:ident($proof:ty, $features:literal): $n:literal lanes, $bits:ty, frustum first: $ff:literal,
        $group:ty, $hits:ty, $interval:path,
        $prepared:ident, $prepare:ident, $intersect:ident, $leaf:ident
    ) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug)]
        pub(crate) struct $name(pub $proof);

        // SAFETY (every `unsafe` below): the kernels are compiled for the family's features
        // (`#[target_feature]`), and `self.0` proves the CPU has them.
        impl<T: TriangleIntersector> PacketLanes<T> for $name {
            const N: usize = $n;
            const FRUSTUM_FIRST: bool = $ff;
            type Group = $group;
            type Prepared = T::$prepared;
            type Hits = $hits;

            #[inline(always)]
            fn group(self, rays: &[Ray], base: usize) -> $group {
                unsafe { <$group>::new(self.0, rays, base) }
            }
            #[inline(always)]
            fn hit(self, g: &$group, lo: [f32; 3], hi: [f32; 3]) -> u32 {
                unsafe { g.hit(self.0, lo, hi) }
            }
            #[inline(always)]
            fn hit_planes(self, g: &$group, near: [f32; 3], far: [f32; 3]) -> u32 {
                unsafe { g.hit_planes(self.0, near, far) }
            }
            #[inline(always)]
            fn refresh(self, g: &mut $group, rays: &[Ray], base: usize) {
                unsafe { g.refresh(self.0, rays, base) };
            }
            #[inline(always)]
            fn signs(self, groups: &[$group]) -> (bool, [bool; 3]) {
                let (mut all_neg, mut any_neg) = ([<$bits>::MAX; 3], [0 as $bits; 3]);
                for group in groups {
                    for axis in 0..3 {
                        (all_neg[axis], any_neg[axis]) =
                            (all_neg[axis] & group.neg[axis], any_neg[axis] | group.neg[axis]);
                    }
                }
                let one_sign = (0..3).all(|a| all_neg[a] == <$bits>::MAX || any_neg[a] == 0);
                (one_sign, all_neg.map(|m| m == <$bits>::MAX))
            }
            #[inline(always)]
            fn t_far(self, groups: &[$group]) -> f32 {
                groups.iter().map(|g| unsafe { g.t_far(self.0) }).fold(f32::NEG_INFINITY, f32::max)
            }
            #[inline(always)]
            fn frustum(self, groups: &[$group]) -> RayInterval {
                unsafe { $interval(self.0, groups) }
            }
            #[inline(always)]
            fn prepare(self, rays: &[Ray], base: usize) -> T::$prepared {
                T::$prepare(self.0, rays, base)
            }
            #[inline(always)]
            fn intersect(self, p: &T::$prepared, g: &$group, lanes: u32, tri: &[Vec3; 3]) -> $hits {
                T::$intersect(self.0, p, g.t_min, g.t_max, lanes, tri)
            }
            #[inline(always)]
            fn mask(h: &$hits) -> u32 {
                h.mask
            }
            #[inline(always)]
            fn lane(h: &$hits, k: usize) -> TriangleHit {
                TriangleHit { t: h.t[k], u: h.u[k], v: h.v[k] }
            }
            #[inline(always)]
            fn leaf(
                self,
                p: &T::$prepared,
                g: &mut $group,
                lanes: u32,
                tris: &[[Vec3; 3]],
                rays: &mut [Ray],
                base: usize,
                record: impl FnMut(usize, usize, TriangleHit),
            ) -> bool {
                unsafe { $leaf::<T, _>(self, p, g, lanes, tris, rays, base, record) }
            }
        }

        /// `leaf_loop` compiled for the family's features.
        ///
        /// # Safety
        /// The CPU has them (`k.0` proves it).
        #[inline]
        #[target_feature(enable = $features)]
        #[allow(clippy::too_many_arguments)]
        unsafe fn $leaf<T: TriangleIntersector, F: FnMut(usize, usize, TriangleHit)>(
            k: $name,
            p: &T::$prepared,
            g: &mut $group,
            lanes: u32,
            tris: &[[Vec3; 3]],
            rays: &mut [Ray],
            base: usize,
            record: F,
        ) -> bool {
            leaf_loop::<T, $name>(k, p, g, lanes, tris, rays, base, record)
        }
    };
}

#[cfg(target_arch = "x86_64")]
pub(crate) use groups::{Eight, Sixteen};

#[cfg(target_arch = "x86_64")]
mod groups {
    use super::*;
    use crate::geometry::avx512::packet::{interval16, RayGroup16};
    use crate::geometry::avx512::{Avx512, Hits16};
    use crate::geometry::packet8::{interval8, RayGroup8};
    use crate::geometry::slab8::Avx2;
    use crate::geometry::triangle8::Hits8;

    // The frustum first was measured both ways on AVX2 (bunny and beast, leaves of 8): 4 % faster
    // on the bunny's primary packets, 15 % slower on the beast's.
    wide_lanes! {
        /// Groups of eight rays in AVX2 registers (`geometry::packet8`), where the CPU has them.
        Eight(Avx2, "avx2,fma"): 8 lanes, u8, frustum first: false,
        RayGroup8, Hits8, interval8, Prepared8, prepare8, intersect8, leaf8
    }

    wide_lanes! {
        /// Groups of sixteen rays in AVX-512 registers (`avx512::packet`), where the CPU has them.
        Sixteen(Avx512, "avx512f,avx512vl"): 16 lanes, u16, frustum first: true,
        RayGroup16, Hits16, interval16, Prepared16, prepare16, intersect16, leaf16
    }
}
