//! One ray against up to sixteen triangles of a leaf in one pass: the watertight test (Woop,
//! Benthin & Wald, "Watertight Ray/Triangle Intersection", JCGT 2013) with one lane per triangle,
//! for the 8-wide layout's leaves stored coordinate by coordinate (`bvh::wide::leaves`). The
//! arithmetic is `Watertight::intersect`'s in the same order and `triangle4`'s lane by lane (glam's
//! dot is `(x·x' + y·y') + z·z'`, nothing fused, the double-precision fallback per lane where an edge
//! function is exactly zero), so lane k is the scalar test of triangle k bit for bit. AVX-512's
//! masked loads read exactly the leaf's triangles: nothing past its end is touched, so the
//! four-lane kernel's copy at the array's end is not needed. Up to eight triangles take 256-bit
//! registers (AVX-512VL); nine to sixteen take two such passes, not one of 512 bits: on an Intel
//! Xeon (family 6 model 207) one 512-bit pass made the whole walk 0.83× the AVX2 walk on the same
//! tree, two 256-bit passes 0.95–0.96× (BENCHMARKS.md, "Leaves of sixteen in two 256-bit passes").
//! Either the core's slower clock for 512-bit arithmetic or the division a half skips when its
//! eight lanes all miss (`edge_test`) is why; the two were not separated.

use crate::geometry::avx512::lanes::{Avx512, Lanes};
use crate::geometry::ray::Ray;
use crate::geometry::shear::WatertightRay;
use std::arch::x86_64::*;

/// The hits of one pass: lane k (triangle k of the group) hit when bit k of `mask` is set, with
/// its `t` and barycentrics.
#[derive(Clone, Copy, Debug)]
pub struct Hits16 {
    pub mask: u32,
    pub t: [f32; 16],
    pub u: [f32; 16],
    pub v: [f32; 16],
}

impl Hits16 {
    pub const NONE: Hits16 = Hits16 { mask: 0, t: [0.0; 16], u: [0.0; 16], v: [0.0; 16] };
}

/// The watertight test of triangles `16g..16g + 16` (those below `count`) of a leaf stored
/// coordinate by coordinate (`coords`: the `count` values of v0.x, then of v0.y, …, v2.z) against
/// one ray prepared as `p`, within `[ray.t_min, ray.t_max)`. Compiled for AVX-512 (see `Lanes`);
/// the `Avx512` argument proves the CPU has it.
#[inline]
#[target_feature(enable = "avx512f,avx512vl")]
pub(crate) fn watertight_leaf16(
    _: Avx512,
    p: &WatertightRay,
    ray: &Ray,
    coords: &[f32],
    count: usize,
    g: usize,
) -> Hits16 {
    let n = count.saturating_sub(16 * g).min(16);
    assert!(coords.len() >= 9 * count, "a leaf's nine coordinates of {count} triangles");
    if n == 0 {
        return Hits16::NONE;
    }
    let lanes = (1u32 << n) - 1;
    let base = coords.as_ptr();
    // SAFETY: the `Avx512` argument proves the CPU has AVX-512F/VL; lane k < n of coordinate j
    // reads coords[j·count + 16g + k], inside the slice (asserted above); masked-off lanes are not
    // read.
    unsafe {
        let at = |j: usize| base.add(j * count + 16 * g);
        if n <= 8 {
            one_ray::<__m256>(p, ray, &at, lanes)
        } else {
            // Both halves against the same `t_max`, as one pass: the same hits, lane for lane.
            let low = one_ray::<__m256>(p, ray, &at, 0xff);
            let high = one_ray::<__m256>(p, ray, &|j| at(j).add(8), lanes >> 8);
            let mut h = Hits16 { mask: low.mask | high.mask << 8, ..low };
            if high.mask != 0 {
                h.t[8..].copy_from_slice(&high.t[..8]);
                h.u[8..].copy_from_slice(&high.u[..8]);
                h.v[8..].copy_from_slice(&high.v[..8]);
            }
            h
        }
    }
}

/// The test in registers of `V::N` lanes; `at(j)` points at coordinate j of the group's first
/// triangle.
///
/// Inlined always (it has no target features of its own: a `#[target_feature]` function cannot be):
/// called twice for a leaf of sixteen, LLVM kept it out of line, a call and a copy of its hits per
/// half (10 % of a primary walk's samples in a profile).
///
/// # Safety
/// The CPU has AVX-512F/VL, and `at(j) + k` is readable for every j < 9 and lane k in `lanes`;
/// only called from functions compiled with those features, into which it inlines.
#[inline(always)]
unsafe fn one_ray<V: Lanes>(p: &WatertightRay, ray: &Ray, at: &impl Fn(usize) -> *const f32, lanes: u32) -> Hits16 {
    let o = ray.origin();
    let vertex = |v: usize| {
        [
            V::load(at(3 * v), lanes).sub(V::splat(o.x)),
            V::load(at(3 * v + 1), lanes).sub(V::splat(o.y)),
            V::load(at(3 * v + 2), lanes).sub(V::splat(o.z)),
        ]
    };
    let (a, b, c) = (vertex(0), vertex(1), vertex(2));
    let dot =
        |v: &[V; 3], r: glam::Vec3| v[0].mul(V::splat(r.x)).add(v[1].mul(V::splat(r.y))).add(v[2].mul(V::splat(r.z)));
    let (ax, ay) = (dot(&a, p.rx), dot(&a, p.ry));
    let (bx, by) = (dot(&b, p.rx), dot(&b, p.ry));
    let (cx, cy) = (dot(&c, p.rx), dot(&c, p.ry));
    let z = [dot(&a, p.rz), dot(&b, p.rz), dot(&c, p.rz)];
    edge_test([ax, ay, bx, by, cx, cy], z, V::splat(ray.t_min), V::splat(ray.t_max), lanes)
}

/// The watertight test's second half in `V::N` lanes, `triangle4::edge_test4` lane for lane: from
/// the sheared vertices `[ax, ay, bx, by, cx, cy]` and their distances `z`, the edge functions (in
/// double precision in a lane where one is exactly zero), the inside test and the hit within
/// `[t_min, t_max)`, for the lanes in `lanes`.
///
/// # Safety
/// The CPU has AVX-512F/VL.
#[inline]
#[target_feature(enable = "avx512f,avx512vl")]
pub(super) unsafe fn edge_test<V: Lanes>(xy: [V; 6], z: [V; 3], t_min: V, t_max: V, lanes: u32) -> Hits16 {
    let [ax, ay, bx, by, cx, cy] = xy;
    let mut u = cx.mul(by).sub(cy.mul(bx));
    let mut v = ax.mul(cy).sub(ay.mul(cx));
    let mut w = bx.mul(ay).sub(by.mul(ax));
    let zero_v = V::splat(0.0);
    let zero = (u.cmp::<_CMP_EQ_OQ>(zero_v) | v.cmp::<_CMP_EQ_OQ>(zero_v) | w.cmp::<_CMP_EQ_OQ>(zero_v)) & lanes;
    if zero != 0 {
        (u, v, w) = in_double(xy, [u, v, w], zero);
    }
    let neg = u.cmp::<_CMP_LT_OQ>(zero_v) | v.cmp::<_CMP_LT_OQ>(zero_v) | w.cmp::<_CMP_LT_OQ>(zero_v);
    let pos = u.cmp::<_CMP_GT_OQ>(zero_v) | v.cmp::<_CMP_GT_OQ>(zero_v) | w.cmp::<_CMP_GT_OQ>(zero_v);
    let outside = neg & pos;
    // Every lane outside its triangle (most passes of a packet's rays against one triangle, and
    // many of a leaf against one ray): no hit, and no division to wait for.
    if lanes & !outside == 0 {
        return Hits16::NONE;
    }
    let det = u.add(v).add(w);
    let t_scaled = u.mul(z[0]).add(v.mul(z[1])).add(w.mul(z[2]));
    let inv_det = V::splat(1.0).div(det);
    let t = t_scaled.mul(inv_det);
    // `det != 0` true for NaN, as the scalar `det == 0.0` rejects only zero.
    let inside = det.cmp::<_CMP_NEQ_UQ>(zero_v) & t.cmp::<_CMP_GE_OQ>(t_min) & t.cmp::<_CMP_LT_OQ>(t_max);
    let mask = inside & !outside & lanes;
    let mut hits = Hits16 { mask, ..Hits16::NONE };
    if mask != 0 {
        t.store(&mut hits.t);
        v.mul(inv_det).store(&mut hits.u);
        w.mul(inv_det).store(&mut hits.v);
    }
    hits
}

/// The edge functions of the lanes in `zero` redone in double precision (the paper's fallback,
/// as the scalar test does it); the other lanes unchanged. Rare: out of line.
///
/// # Safety
/// The CPU has AVX-512F/VL.
#[inline(never)]
#[cold]
#[target_feature(enable = "avx512f,avx512vl")]
unsafe fn in_double<V: Lanes>(xy: [V; 6], uvw: [V; 3], zero: u32) -> (V, V, V) {
    let lanes = |v: V| {
        let mut a = [0f32; 16];
        v.store(&mut a);
        a
    };
    let [ax, ay, bx, by, cx, cy] = xy.map(lanes);
    let [mut u, mut v, mut w] = uvw.map(lanes);
    let mut m = zero;
    while m != 0 {
        let k = m.trailing_zeros() as usize;
        m &= m - 1;
        let f = |a: &[f32; 16]| a[k] as f64;
        let (ax, ay, bx, by, cx, cy) = (f(&ax), f(&ay), f(&bx), f(&by), f(&cx), f(&cy));
        u[k] = (cx * by - cy * bx) as f32;
        v[k] = (ax * cy - ay * cx) as f32;
        w[k] = (bx * ay - by * ax) as f32;
    }
    let back = |a: &[f32; 16]| V::load(a.as_ptr(), (1u32 << V::N) - 1);
    (back(&u), back(&v), back(&w))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::leaf_cases::{by_coordinate, leaf_case};
    use crate::geometry::triangle::{TriangleIntersector, Watertight};
    use glam::Vec3;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]
        /// Lane k of each pass is the scalar test of its triangle, bit for bit; no lane past the
        /// leaf is set. Also the default of `intersect_group16_coords`, two AVX2 passes of eight
        /// (what the Möller–Trumbore test runs), agrees, so the two paths of `Groups16` are checked.
        #[test]
        fn a_leaf_in_passes_of_sixteen_is_its_scalar_tests((tris, ray, more) in leaf_case(20)) {
            let Some(k) = Avx512::detect() else { return Ok(()) };
            let count = tris.len();
            let coords = by_coordinate(&tris, more);
            let p = Watertight::prepare(&ray);
            for g in 0..count.div_ceil(16) {
                // SAFETY: `k` proves the CPU has AVX-512F/VL.
                let got = unsafe { watertight_leaf16(k, &p, &ray, &coords, count, g) };
                let n = (count - 16 * g).min(16);
                prop_assert_eq!(got.mask >> n, 0, "no lane past the leaf");
                let eights = by_eights(k, &p, &ray, &coords, count, g);
                prop_assert_eq!(eights.mask, got.mask, "groups of eight");
                for lane in 0..n {
                    let want = Watertight::intersect(&p, &ray, &tris[16 * g + lane]);
                    prop_assert_eq!(got.mask & (1 << lane) != 0, want.is_some(), "pass {} lane {}", g, lane);
                    if let Some(h) = want {
                        let bits = |x: f32| x.to_bits();
                        let lanes = |h: &Hits16| (bits(h.t[lane]), bits(h.u[lane]), bits(h.v[lane]));
                        prop_assert_eq!(lanes(&got), (bits(h.t), bits(h.u), bits(h.v)), "lane {}", lane);
                        prop_assert_eq!(lanes(&eights), lanes(&got), "groups of eight, lane {}", lane);
                    }
                }
            }
        }
    }

    /// The trait's default: two passes of the eight-lane kernel (`triangle8`).
    fn by_eights(k: Avx512, p: &WatertightRay, ray: &Ray, coords: &[f32], count: usize, g: usize) -> Hits16 {
        #[derive(Clone, Copy)]
        struct Eights;
        impl TriangleIntersector for Eights {
            type Prepared = WatertightRay;
            fn prepare(ray: &Ray) -> WatertightRay {
                Watertight::prepare(ray)
            }
            fn intersect(p: &WatertightRay, ray: &Ray, tri: &[Vec3; 3]) -> Option<crate::geometry::TriangleHit> {
                Watertight::intersect(p, ray, tri)
            }
            fn intersect_group_coords(p: &WatertightRay, ray: &Ray, c: &[f32], count: usize, g: usize) -> Hits4 {
                Watertight::intersect_group_coords(p, ray, c, count, g)
            }
            fn intersect_group8_coords(k: Avx2, p: &WatertightRay, ray: &Ray, c: &[f32], n: usize, g: usize) -> Hits8 {
                Watertight::intersect_group8_coords(k, p, ray, c, n, g)
            }
            type Prepared4 = <Watertight as TriangleIntersector>::Prepared4;
            fn prepare4(rays: &[Ray], base: usize) -> Self::Prepared4 {
                Watertight::prepare4(rays, base)
            }
            fn intersect4(p: &Self::Prepared4, t0: f32x4, t1: f32x4, lanes: u32, tri: &[Vec3; 3]) -> Hits4 {
                Watertight::intersect4(p, t0, t1, lanes, tri)
            }
            type Prepared8 = <Watertight as TriangleIntersector>::Prepared8;
            fn prepare8(k: Avx2, rays: &[Ray], base: usize) -> Self::Prepared8 {
                Watertight::prepare8(k, rays, base)
            }
            fn intersect8(k: Avx2, p: &Self::Prepared8, t0: __m256, t1: __m256, l: u32, tri: &[Vec3; 3]) -> Hits8 {
                Watertight::intersect8(k, p, t0, t1, l, tri)
            }
            type Prepared16 = <Watertight as TriangleIntersector>::Prepared16;
            fn prepare16(k: Avx512, rays: &[Ray], base: usize) -> Self::Prepared16 {
                Watertight::prepare16(k, rays, base)
            }
            fn intersect16(k: Avx512, p: &Self::Prepared16, t0: __m512, t1: __m512, l: u32, tri: &[Vec3; 3]) -> Hits16 {
                Watertight::intersect16(k, p, t0, t1, l, tri)
            }
        }
        use crate::geometry::shear::Hits4;
        use crate::geometry::slab8::Avx2;
        use crate::geometry::triangle8::Hits8;
        use wide::f32x4;
        Eights::intersect_group16_coords(k, p, ray, coords, count, g)
    }
}
