//! One ray against up to eight triangles of a leaf in one AVX2 pass: the watertight test (Woop,
//! Benthin & Wald, "Watertight Ray/Triangle Intersection", JCGT 2013) with one lane per triangle,
//! for the AVX2 family's leaves, stored coordinate by coordinate (`bvh::wide::leaves`). Without it
//! an AVX2 CPU tested a leaf four triangles at a time (`triangle4`), so leaves of eight took two
//! passes. The arithmetic is `Watertight::intersect`'s in the same order and `triangle4`'s lane by
//! lane (glam's dot is `(x·x' + y·y') + z·z'`, nothing fused, the double-precision fallback per lane
//! where an edge function is exactly zero), so lane k is the scalar test of triangle k bit for bit.
//! A lane's nine coordinates are plain loads of eight floats; a load that would reach past the
//! array's end is masked (`vmaskmovps`), so nothing outside the triangles is read.

use super::shear::WatertightRay;
use super::slab8::Avx2;
use crate::geometry::ray::Ray;
use std::arch::x86_64::*;

/// The hits of one pass: lane k (triangle k of the group) hit when bit k of `mask` is set, with
/// its `t` and barycentrics.
#[derive(Clone, Copy, Debug)]
pub struct Hits8 {
    pub mask: u32,
    pub t: [f32; 8],
    pub u: [f32; 8],
    pub v: [f32; 8],
}

impl Hits8 {
    pub const NONE: Hits8 = Hits8 { mask: 0, t: [0.0; 8], u: [0.0; 8], v: [0.0; 8] };
}

/// The watertight test of triangles `8g..8g + 8` (those below `count`) of a leaf stored coordinate
/// by coordinate (`coords`: the `count` values of v0.x, then of v0.y, …, v2.z, and possibly more
/// after them) against one ray prepared as `p`, within `[ray.t_min, ray.t_max)`. Lanes past the
/// leaf read the next coordinate's values (or nothing, at the array's end) and are masked off.
/// The `Avx2` argument proves the CPU has AVX2.
#[inline]
#[target_feature(enable = "avx2,fma")]
pub(crate) fn watertight_leaf8(_: Avx2, p: &WatertightRay, ray: &Ray, coords: &[f32], count: usize, g: usize) -> Hits8 {
    let n = count.saturating_sub(8 * g).min(8);
    assert!(coords.len() >= 9 * count, "a leaf's nine coordinates of {count} triangles");
    if n == 0 {
        return Hits8::NONE;
    }
    if n <= 4 {
        // Four lanes suffice (the AVX2 preset's leaves): `triangle4`'s pass, the same arithmetic,
        // measured faster inlined into the walk than an eight-lane pass half empty (BENCHMARKS.md,
        // "AVX2 leaves").
        let h = super::triangle4::watertight_group_coords(p, ray, coords, count, 2 * g);
        let mut hits = Hits8 { mask: h.mask, ..Hits8::NONE };
        hits.t[..4].copy_from_slice(&h.t);
        hits.u[..4].copy_from_slice(&h.u);
        hits.v[..4].copy_from_slice(&h.v);
        return hits;
    }
    let lanes = (1u32 << n) - 1;
    let load = loads(coords, count, g, n);
    {
        let o = ray.origin();
        let vertex = |v: usize| {
            [
                _mm256_sub_ps(load(3 * v), _mm256_set1_ps(o.x)),
                _mm256_sub_ps(load(3 * v + 1), _mm256_set1_ps(o.y)),
                _mm256_sub_ps(load(3 * v + 2), _mm256_set1_ps(o.z)),
            ]
        };
        let (a, b, c) = (vertex(0), vertex(1), vertex(2));
        let dot = |v: &[__m256; 3], r: glam::Vec3| {
            let xy = _mm256_add_ps(_mm256_mul_ps(v[0], _mm256_set1_ps(r.x)), _mm256_mul_ps(v[1], _mm256_set1_ps(r.y)));
            _mm256_add_ps(xy, _mm256_mul_ps(v[2], _mm256_set1_ps(r.z)))
        };
        let xy = [dot(&a, p.rx), dot(&a, p.ry), dot(&b, p.rx), dot(&b, p.ry), dot(&c, p.rx), dot(&c, p.ry)];
        let z = [dot(&a, p.rz), dot(&b, p.rz), dot(&c, p.rz)];
        edge_test8(xy, z, _mm256_set1_ps(ray.t_min), _mm256_set1_ps(ray.t_max), lanes)
    }
}

/// Möller–Trumbore (`MollerTrumbore::intersect`, operation for operation: glam's `cross` and dot,
/// the lengths' square roots, the same rejections in the same order, nothing fused) of triangles
/// `8g..8g + 8` of a leaf stored coordinate by coordinate, so that the two tests are raced on one
/// tree with the same loads and lanes (BENCHMARKS.md, "Watertight or Möller–Trumbore on AVX2").
#[inline]
#[target_feature(enable = "avx2,fma")]
pub(crate) fn moller_trumbore_leaf8(_: Avx2, ray: &Ray, coords: &[f32], count: usize, g: usize) -> Hits8 {
    let n = count.saturating_sub(8 * g).min(8);
    assert!(coords.len() >= 9 * count, "a leaf's nine coordinates of {count} triangles");
    if n == 0 {
        return Hits8::NONE;
    }
    let lanes = (1u32 << n) - 1;
    let load = loads(coords, count, g, n);
    {
        let (add, sub, mul) = (|a, b| _mm256_add_ps(a, b), |a, b| _mm256_sub_ps(a, b), |a, b| _mm256_mul_ps(a, b));
        let dot = |a: [__m256; 3], b: [__m256; 3]| add(add(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]));
        let cross = |a: [__m256; 3], b: [__m256; 3]| {
            [
                sub(mul(a[1], b[2]), mul(b[1], a[2])),
                sub(mul(a[2], b[0]), mul(b[2], a[0])),
                sub(mul(a[0], b[1]), mul(b[0], a[1])),
            ]
        };
        let v0 = [load(0), load(1), load(2)];
        let e1 = [sub(load(3), v0[0]), sub(load(4), v0[1]), sub(load(5), v0[2])];
        let e2 = [sub(load(6), v0[0]), sub(load(7), v0[1]), sub(load(8), v0[2])];
        let (dir, org) = (ray.dir(), ray.origin());
        let d = [_mm256_set1_ps(dir.x), _mm256_set1_ps(dir.y), _mm256_set1_ps(dir.z)];
        let pv = cross(d, e2);
        let det = dot(e1, pv);
        let scale = mul(mul(_mm256_set1_ps(dir.length()), _mm256_sqrt_ps(dot(e1, e1))), _mm256_sqrt_ps(dot(e2, e2)));
        let abs = _mm256_andnot_ps(_mm256_set1_ps(-0.0), det);
        let mut ok = _mm256_cmp_ps::<_CMP_GT_OQ>(abs, mul(_mm256_set1_ps(1e-7), scale));
        let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
        let s =
            [sub(_mm256_set1_ps(org.x), v0[0]), sub(_mm256_set1_ps(org.y), v0[1]), sub(_mm256_set1_ps(org.z), v0[2])];
        let u = mul(dot(s, pv), inv_det);
        let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
        ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_GE_OQ>(u, zero));
        ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_LE_OQ>(u, one));
        let q = cross(s, e1);
        let v = mul(dot(d, q), inv_det);
        // `!(v < 0 || u + v > 1 || v is NaN)`: v ≥ 0 (false for NaN) and not u + v > 1.
        ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_GE_OQ>(v, zero));
        ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_NGT_UQ>(add(u, v), one));
        let t = mul(dot(e2, q), inv_det);
        ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_GE_OQ>(t, _mm256_set1_ps(ray.t_min)));
        ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_LT_OQ>(t, _mm256_set1_ps(ray.t_max)));
        let mask = _mm256_movemask_ps(ok) as u32 & lanes;
        let mut hits = Hits8 { mask, ..Hits8::NONE };
        if mask != 0 {
            // SAFETY: each array holds eight floats, the width of the stores.
            unsafe {
                _mm256_storeu_ps(hits.t.as_mut_ptr(), t);
                _mm256_storeu_ps(hits.u.as_mut_ptr(), u);
                _mm256_storeu_ps(hits.v.as_mut_ptr(), v);
            }
        }
        hits
    }
}

/// Coordinate j (0..9) of triangles `8g..8g + n` of a leaf of `count` stored coordinate by
/// coordinate, as eight lanes: a plain load where eight floats lie inside `coords`, else a masked
/// one of the `n` lanes only (lanes past them are zero). `coords` holds at least `9·count` floats.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn loads(coords: &[f32], count: usize, g: usize, n: usize) -> impl Fn(usize) -> __m256 + '_ {
    let keep = _mm256_cmpgt_epi32(_mm256_set1_epi32(n as i32), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    move |j: usize| {
        let at = j * count + 8 * g;
        // SAFETY: the CPU has AVX2 (the callers' features, proved by their `Avx2` argument). A full
        // load reads coords[at..at + 8], inside the slice when checked so; the masked load reads
        // lanes k < n only, coords[j·count + 8g + k] with 8g + k < count, inside the slice.
        unsafe {
            if at + 8 <= coords.len() {
                _mm256_loadu_ps(coords.as_ptr().add(at))
            } else {
                _mm256_maskload_ps(coords.as_ptr().add(at), keep)
            }
        }
    }
}

/// The watertight test's second half in eight lanes, `triangle4::edge_test4` lane for lane: from
/// the sheared vertices `[ax, ay, bx, by, cx, cy]` and their distances `z`, the edge functions (in
/// double precision in a lane where one is exactly zero), the inside test and the hit within
/// `[t_min, t_max)` (per lane: one ray's interval in every lane for a leaf, each ray's own for a
/// packet's group, `packet8`), for the lanes in `lanes`.
#[inline]
#[target_feature(enable = "avx2,fma")]
pub(crate) fn edge_test8(xy: [__m256; 6], z: [__m256; 3], t_min: __m256, t_max: __m256, lanes: u32) -> Hits8 {
    let [ax, ay, bx, by, cx, cy] = xy;
    let diff = |p: __m256, q: __m256, r: __m256, s: __m256| _mm256_sub_ps(_mm256_mul_ps(p, q), _mm256_mul_ps(r, s));
    let mut u = diff(cx, by, cy, bx);
    let mut v = diff(ax, cy, ay, cx);
    let mut w = diff(bx, ay, by, ax);
    let zero_v = _mm256_setzero_ps();
    let zero = any::<_CMP_EQ_OQ>(u, v, w) & lanes;
    if zero != 0 {
        (u, v, w) = in_double(xy, [u, v, w], zero);
    }
    let outside = any::<_CMP_LT_OQ>(u, v, w) & any::<_CMP_GT_OQ>(u, v, w);
    // Every lane outside its triangle: no hit, and no division to wait for.
    if lanes & !outside == 0 {
        return Hits8::NONE;
    }
    let det = _mm256_add_ps(_mm256_add_ps(u, v), w);
    let t_scaled = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(u, z[0]), _mm256_mul_ps(v, z[1])), _mm256_mul_ps(w, z[2]));
    let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
    let t = _mm256_mul_ps(t_scaled, inv_det);
    // `det != 0` is true for NaN (unordered), as the scalar `det == 0.0` rejects only zero.
    let inside = _mm256_and_ps(
        _mm256_cmp_ps::<_CMP_NEQ_UQ>(det, zero_v),
        _mm256_and_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(t, t_min), _mm256_cmp_ps::<_CMP_LT_OQ>(t, t_max)),
    );
    let mask = _mm256_movemask_ps(inside) as u32 & !outside & lanes;
    let mut hits = Hits8 { mask, ..Hits8::NONE };
    if mask != 0 {
        // SAFETY: each array holds eight floats, the width of the stores.
        unsafe {
            _mm256_storeu_ps(hits.t.as_mut_ptr(), t);
            _mm256_storeu_ps(hits.u.as_mut_ptr(), _mm256_mul_ps(v, inv_det));
            _mm256_storeu_ps(hits.v.as_mut_ptr(), _mm256_mul_ps(w, inv_det));
        }
    }
    hits
}

/// The lanes where comparison `P` with zero holds for `x`, `y` or `z`.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn any<const P: i32>(x: __m256, y: __m256, z: __m256) -> u32 {
    let c = |a: __m256| _mm256_cmp_ps::<P>(a, _mm256_setzero_ps());
    _mm256_movemask_ps(_mm256_or_ps(_mm256_or_ps(c(x), c(y)), c(z))) as u32
}

/// The edge functions `uvw` with the lanes of `which` recomputed in double precision from the
/// sheared vertices `xy`, as the scalar test does when one of them is exactly zero (rare: a ray
/// through an edge or a vertex), so it takes the lanes one by one.
#[cold]
#[inline(never)]
#[target_feature(enable = "avx2,fma")]
fn in_double(xy: [__m256; 6], uvw: [__m256; 3], which: u32) -> (__m256, __m256, __m256) {
    let array = |x: __m256| {
        let mut a = [0f32; 8];
        // SAFETY: `a` holds eight floats, the width of the store.
        unsafe { _mm256_storeu_ps(a.as_mut_ptr(), x) };
        a
    };
    let xy = xy.map(array);
    let [mut u, mut v, mut w] = uvw.map(array);
    let mut m = which;
    while m != 0 {
        let k = m.trailing_zeros() as usize;
        m &= m - 1;
        let [ax, ay, bx, by, cx, cy] = xy.map(|c| c[k] as f64);
        u[k] = (cx * by - cy * bx) as f32;
        v[k] = (ax * cy - ay * cx) as f32;
        w[k] = (bx * ay - by * ax) as f32;
    }
    // SAFETY: each array holds eight floats, the width of the loads.
    unsafe { (_mm256_loadu_ps(u.as_ptr()), _mm256_loadu_ps(v.as_ptr()), _mm256_loadu_ps(w.as_ptr())) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::leaf_cases::{by_coordinate, leaf_case};
    use crate::geometry::triangle::{MollerTrumbore, TriangleIntersector, Watertight};
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]
        /// Each pass of eight over a leaf stored coordinate by coordinate is the scalar test of
        /// its triangles, bit for bit (the watertight one and Möller–Trumbore), whether more data follows the leaf or the array ends there.
        #[test]
        fn eight_triangles_at_once_are_eight_scalar_tests((tris, ray, more) in leaf_case(19)) {
            let Some(k) = Avx2::detect() else { return Ok(()) };
            let count = tris.len();
            let coords = by_coordinate(&tris, more);
            let p = Watertight::prepare(&ray);
            for g in 0..count.div_ceil(8) {
                // SAFETY: `detect` found AVX2.
                let got = unsafe { watertight_leaf8(k, &p, &ray, &coords, count, g) };
                let n = (count - 8 * g).min(8);
                prop_assert_eq!(got.mask >> n, 0, "no lane past the leaf");
                for lane in 0..n {
                    let want = Watertight::intersect(&p, &ray, &tris[8 * g + lane]);
                    prop_assert_eq!(got.mask & (1 << lane) != 0, want.is_some(), "pass {} lane {}", g, lane);
                    if let Some(h) = want {
                        let bits = |x: f32| x.to_bits();
                        prop_assert_eq!(
                            (bits(got.t[lane]), bits(got.u[lane]), bits(got.v[lane])),
                            (bits(h.t), bits(h.u), bits(h.v)),
                            "pass {} lane {}: bit for bit", g, lane
                        );
                    }
                }
                // SAFETY: `detect` found AVX2.
                let mt = unsafe { moller_trumbore_leaf8(k, &ray, &coords, count, g) };
                prop_assert_eq!(mt.mask >> n, 0, "no Möller–Trumbore lane past the leaf");
                for lane in 0..n {
                    let want = MollerTrumbore::intersect(&(), &ray, &tris[8 * g + lane]);
                    prop_assert_eq!(mt.mask & (1 << lane) != 0, want.is_some(), "Möller–Trumbore pass {} lane {}", g, lane);
                    if let Some(h) = want {
                        let bits = |x: f32| x.to_bits();
                        prop_assert_eq!(
                            (bits(mt.t[lane]), bits(mt.u[lane]), bits(mt.v[lane])),
                            (bits(h.t), bits(h.u), bits(h.v)),
                            "Möller–Trumbore pass {} lane {}: bit for bit", g, lane
                        );
                    }
                }
            }
        }
    }
}
