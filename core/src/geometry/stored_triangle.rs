//! Möller–Trumbore on a triangle's stored edges and normal: Embree's form of the test
//! (`Triangle4` and its `MoellerTrumboreIntersector`; Möller & Trumbore, "Fast, Minimum Storage
//! Ray/Triangle Intersection", JGT 2(1), 1997, rewritten around the normal as in Wald et al.,
//! "Embree: A Kernel Framework for Efficient CPU Ray Tracing", SIGGRAPH 2014). Each triangle is
//! kept as `v0`, `e1 = v0 − v1`, `e2 = v2 − v0` and `ng = e1 × e2` (`stored_form`); a ray then
//! needs one cross product, four dot products and one division per triangle, against the
//! classic test's two cross products, four dot products, three square roots and a division, and
//! no edge is recomputed from the vertices. Like the classic test it can miss a ray exactly
//! through a shared edge. The 8-wide tree keeps its leaves in this form, coordinate by coordinate,
//! when a walk asks for this test (`bvh::wide::leaves`): twelve floats a triangle beside the
//! vertices, tested sixteen at a time with AVX-512 (`avx512::stored_leaf16`), eight with AVX2
//! (`stored_leaf8`) or four elsewhere (`stored_group4`). Every other structure (the binary tree, the 4-wide one, the linear scan,
//! the GPU) computes the same form from the vertices with the same operations, so every path
//! gives the same bits.

#[cfg(target_arch = "x86_64")]
use super::{avx512::lanes::Avx512, avx512::leaf::Hits16, slab8::Avx2, triangle8::Hits8};
use crate::geometry::ray::Ray;
use crate::geometry::shear::Hits4;
use crate::geometry::triangle::{lane_by_lane, lane_by_lane_packets, TriangleHit, TriangleIntersector};
use glam::Vec3;
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::{__m256, __m512};
use wide::f32x4;

/// Floats per triangle in the stored form: v0, e1, e2, ng.
pub(crate) const STORED_FLOATS: usize = 12;

/// A triangle's stored form: `[v0, e1 = v0 − v1, e2 = v2 − v0, ng = e1 × e2]` (glam's cross:
/// each product rounded, nothing fused), the one definition every path uses.
#[inline(always)]
pub fn stored_form(tri: &[Vec3; 3]) -> [Vec3; 4] {
    let e1 = tri[0] - tri[1];
    let e2 = tri[2] - tri[0];
    [tri[0], e1, e2, e1.cross(e2)]
}

/// The test of one triangle in stored form against `ray` within `[t_min, t_max)`. With
/// `c = v0 − o` and `r = d × c`, Cramer's rule on `t·d + u·e1 − v·e2 = c` gives `den = ng·d`,
/// `u = r·e2 / den`, `v = r·e1 / den`, `t = ng·c / den`; the signs are made those of a positive
/// `den` (so the inside test needs no division) and only then divided.
#[inline(always)]
pub fn intersect_stored(ray: &Ray, f: &[Vec3; 4]) -> Option<TriangleHit> {
    let [v0, e1, e2, ng] = *f;
    let d = ray.dir();
    let c = v0 - ray.origin();
    let r = d.cross(c);
    let den = ng.dot(d);
    let sign = den.to_bits() & 0x8000_0000;
    let flip = |x: f32| f32::from_bits(x.to_bits() ^ sign);
    let abs_den = den.abs();
    let u = flip(r.dot(e2));
    let v = flip(r.dot(e1));
    // `den != 0` holds for NaN, which then fails `u + v <= abs_den`.
    if !(den != 0.0 && u >= 0.0 && v >= 0.0 && u + v <= abs_den) {
        return None;
    }
    let rcp = 1.0 / abs_den;
    let t = flip(ng.dot(c)) * rcp;
    if !(t >= ray.t_min && t < ray.t_max) {
        return None;
    }
    Some(TriangleHit { t, u: u * rcp, v: v * rcp })
}

/// Triangles `4g..4g + 4` (those below `count`) of a leaf stored in this form coordinate by
/// coordinate (`stored`: the `count` values of v0.x, then of v0.y, …, ng.z, possibly more after
/// them) against one ray: `intersect_stored` lane by lane, bit for bit.
#[inline(always)]
pub(crate) fn stored_group4(ray: &Ray, stored: &[f32], count: usize, g: usize) -> Hits4 {
    let n = count.saturating_sub(4 * g).min(4);
    if n == 0 {
        return Hits4 { mask: 0, t: [0.0; 4], u: [0.0; 4], v: [0.0; 4] };
    }
    let lanes = (1u32 << n) - 1;
    let load = |j: usize| {
        let at = j * count + 4 * g;
        match stored.get(at..at + 4) {
            Some(four) => f32x4::new([four[0], four[1], four[2], four[3]]),
            None => f32x4::new(std::array::from_fn(|k| stored.get(at + k).copied().unwrap_or(0.0))),
        }
    };
    let vec = |i: usize| [load(3 * i), load(3 * i + 1), load(3 * i + 2)];
    let (v0, e1, e2, ng) = (vec(0), vec(1), vec(2), vec(3));
    let (d, o) = (ray.dir(), ray.origin());
    let d = [f32x4::splat(d.x), f32x4::splat(d.y), f32x4::splat(d.z)];
    let c = [v0[0] - f32x4::splat(o.x), v0[1] - f32x4::splat(o.y), v0[2] - f32x4::splat(o.z)];
    let dot = |a: [f32x4; 3], b: [f32x4; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let r = [d[1] * c[2] - c[1] * d[2], d[2] * c[0] - c[2] * d[0], d[0] * c[1] - c[0] * d[1]];
    let den = dot(ng, d);
    let sign = den & f32x4::splat(-0.0);
    let abs_den = den.abs();
    let u = dot(r, e2) ^ sign;
    let v = dot(r, e1) ^ sign;
    let zero = f32x4::ZERO;
    let inside = den.simd_ne(zero) & u.simd_ge(zero) & v.simd_ge(zero) & (u + v).simd_le(abs_den);
    let rcp = f32x4::ONE / abs_den;
    let t = (dot(ng, c) ^ sign) * rcp;
    let ok = inside & t.simd_ge(f32x4::splat(ray.t_min)) & t.simd_lt(f32x4::splat(ray.t_max));
    Hits4 { mask: ok.to_bitmask() & lanes, t: t.to_array(), u: (u * rcp).to_array(), v: (v * rcp).to_array() }
}

/// `stored_group4` of triangles `8g..8g + 8` in one AVX2 pass (the AVX2 family's leaves of five
/// to eight triangles; up to four take the four-lane pass, inlined into the walk): the same
/// operations in the same order, lane by lane. Loads that would reach past `stored`'s end are
/// masked (`vmaskmovps`). The `Avx2` argument proves the CPU has AVX2.
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2,fma")]
pub(crate) fn stored_leaf8(_: Avx2, ray: &Ray, stored: &[f32], count: usize, g: usize) -> Hits8 {
    use std::arch::x86_64::*;
    let n = count.saturating_sub(8 * g).min(8);
    assert!(stored.len() >= STORED_FLOATS * count, "a stored leaf's twelve coordinates of {count} triangles");
    if n == 0 {
        return Hits8::NONE;
    }
    if n <= 4 {
        let h = stored_group4(ray, stored, count, 2 * g);
        let mut hits = Hits8 { mask: h.mask, ..Hits8::NONE };
        hits.t[..4].copy_from_slice(&h.t);
        hits.u[..4].copy_from_slice(&h.u);
        hits.v[..4].copy_from_slice(&h.v);
        return hits;
    }
    let lanes = (1u32 << n) - 1;
    let keep = _mm256_cmpgt_epi32(_mm256_set1_epi32(n as i32), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    let load = |j: usize| {
        let at = j * count + 8 * g;
        // SAFETY: AVX2 is enabled here. A full load reads stored[at..at + 8], inside the slice
        // when checked so; the masked load reads lanes k < n only, stored[j·count + 8g + k] with
        // 8g + k < count, inside the slice (asserted above).
        unsafe {
            if at + 8 <= stored.len() {
                _mm256_loadu_ps(stored.as_ptr().add(at))
            } else {
                _mm256_maskload_ps(stored.as_ptr().add(at), keep)
            }
        }
    };
    let (add, sub, mul) = (|a, b| _mm256_add_ps(a, b), |a, b| _mm256_sub_ps(a, b), |a, b| _mm256_mul_ps(a, b));
    let dot = |a: [__m256; 3], b: [__m256; 3]| add(add(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]));
    let vec = |i: usize| [load(3 * i), load(3 * i + 1), load(3 * i + 2)];
    let (v0, e1, e2, ng) = (vec(0), vec(1), vec(2), vec(3));
    let (dir, org) = (ray.dir(), ray.origin());
    let d = [_mm256_set1_ps(dir.x), _mm256_set1_ps(dir.y), _mm256_set1_ps(dir.z)];
    let c = [sub(v0[0], _mm256_set1_ps(org.x)), sub(v0[1], _mm256_set1_ps(org.y)), sub(v0[2], _mm256_set1_ps(org.z))];
    let r = [
        sub(mul(d[1], c[2]), mul(c[1], d[2])),
        sub(mul(d[2], c[0]), mul(c[2], d[0])),
        sub(mul(d[0], c[1]), mul(c[0], d[1])),
    ];
    let den = dot(ng, d);
    let minus = _mm256_set1_ps(-0.0);
    let sign = _mm256_and_ps(den, minus);
    let abs_den = _mm256_andnot_ps(minus, den);
    let u = _mm256_xor_ps(dot(r, e2), sign);
    let v = _mm256_xor_ps(dot(r, e1), sign);
    let zero = _mm256_setzero_ps();
    let inside = _mm256_and_ps(
        _mm256_and_ps(_mm256_cmp_ps::<_CMP_NEQ_UQ>(den, zero), _mm256_cmp_ps::<_CMP_GE_OQ>(u, zero)),
        _mm256_and_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(v, zero), _mm256_cmp_ps::<_CMP_LE_OQ>(add(u, v), abs_den)),
    );
    let rcp = _mm256_div_ps(_mm256_set1_ps(1.0), abs_den);
    let t = mul(_mm256_xor_ps(dot(ng, c), sign), rcp);
    let ok = _mm256_and_ps(
        inside,
        _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GE_OQ>(t, _mm256_set1_ps(ray.t_min)),
            _mm256_cmp_ps::<_CMP_LT_OQ>(t, _mm256_set1_ps(ray.t_max)),
        ),
    );
    let mask = _mm256_movemask_ps(ok) as u32 & lanes;
    let mut hits = Hits8 { mask, ..Hits8::NONE };
    if mask != 0 {
        // SAFETY: each array holds eight floats, the width of the stores.
        unsafe {
            _mm256_storeu_ps(hits.t.as_mut_ptr(), t);
            _mm256_storeu_ps(hits.u.as_mut_ptr(), mul(u, rcp));
            _mm256_storeu_ps(hits.v.as_mut_ptr(), mul(v, rcp));
        }
    }
    hits
}

/// Möller–Trumbore on stored edges and normal (`TriangleTest::MollerTrumboreStored`).
#[derive(Clone, Copy, Debug, Default)]
pub struct MollerTrumboreStored;

impl TriangleIntersector for MollerTrumboreStored {
    const STORED: bool = true;
    type Prepared = ();

    #[inline]
    fn prepare(_ray: &Ray) {}

    /// The form computed from the vertices, then tested: what every layout without stored
    /// leaves does, with the stored leaves' bits.
    #[inline(always)]
    fn intersect(_: &(), ray: &Ray, tri: &[Vec3; 3]) -> Option<TriangleHit> {
        intersect_stored(ray, &stored_form(tri))
    }

    /// `coords` is a stored leaf here (`STORED`).
    #[inline(always)]
    fn intersect_group_coords(_: &(), ray: &Ray, stored: &[f32], count: usize, g: usize) -> Hits4 {
        stored_group4(ray, stored, count, g)
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn intersect_group8_coords(k: Avx2, _: &(), ray: &Ray, stored: &[f32], count: usize, g: usize) -> Hits8 {
        // SAFETY: `k` proves the CPU has AVX2.
        unsafe { stored_leaf8(k, ray, stored, count, g) }
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn intersect_group16_coords(k: Avx512, _: &(), ray: &Ray, stored: &[f32], count: usize, g: usize) -> Hits16 {
        // SAFETY: `k` proves the CPU has AVX-512F/VL.
        unsafe { super::avx512::stored_leaf16(k, ray, stored, count, g) }
    }

    lane_by_lane_packets!();
}

#[cfg(test)]
#[path = "stored_triangle_tests.rs"]
mod tests;
