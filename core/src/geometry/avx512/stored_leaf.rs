//! One ray against up to sixteen triangles of a stored leaf in one AVX-512 pass: Möller–Trumbore
//! on stored edges and normal (`geometry::stored_triangle`, Embree's form) with one lane per
//! triangle, `stored_group4`'s operations in the same order, so lane k is the scalar
//! `intersect_stored` of triangle k bit for bit. The masked loads read exactly the leaf's
//! triangles; up to eight take 256-bit registers (AVX-512VL), more take 512-bit ones, as
//! `leaf::watertight_leaf16` does.

use crate::geometry::avx512::lanes::{Avx512, Lanes};
use crate::geometry::avx512::leaf::Hits16;
use crate::geometry::ray::Ray;
use std::arch::x86_64::*;

/// Triangles `16g..16g + 16` (those below `count`) of a leaf in stored form, coordinate by
/// coordinate (`stored`: the `count` values of v0.x, then of v0.y, …, ng.z), against one ray
/// within `[ray.t_min, ray.t_max)`. The `Avx512` argument proves the CPU has AVX-512F/VL.
#[inline]
#[target_feature(enable = "avx512f,avx512vl")]
pub(crate) fn stored_leaf16(_: Avx512, ray: &Ray, stored: &[f32], count: usize, g: usize) -> Hits16 {
    let n = count.saturating_sub(16 * g).min(16);
    // Twelve floats a triangle (`stored_triangle::STORED_FLOATS`; not imported: that file calls this one).
    assert!(stored.len() >= 12 * count, "a stored leaf's twelve coordinates of {count} triangles");
    if n == 0 {
        return Hits16::NONE;
    }
    let lanes = (1u32 << n) - 1;
    let base = stored.as_ptr();
    // SAFETY: the `Avx512` argument proves the CPU has AVX-512F/VL; lane k < n of coordinate j
    // reads stored[j·count + 16g + k], inside the slice (asserted above); masked-off lanes are
    // not read.
    unsafe {
        let at = |j: usize| base.add(j * count + 16 * g);
        if n <= 8 {
            one_ray::<__m256>(ray, &at, lanes)
        } else {
            one_ray::<__m512>(ray, &at, lanes)
        }
    }
}

/// The test in registers of `V::N` lanes; `at(j)` points at stored coordinate j of the group's
/// first triangle.
///
/// # Safety
/// The CPU has AVX-512F/VL, and `at(j) + k` is readable for every j < 12 and lane k in `lanes`.
#[inline]
#[target_feature(enable = "avx512f,avx512vl")]
unsafe fn one_ray<V: Lanes>(ray: &Ray, at: &impl Fn(usize) -> *const f32, lanes: u32) -> Hits16 {
    let vec = |i: usize| [V::load(at(3 * i), lanes), V::load(at(3 * i + 1), lanes), V::load(at(3 * i + 2), lanes)];
    let (v0, e1, e2, ng) = (vec(0), vec(1), vec(2), vec(3));
    let (dir, org) = (ray.dir(), ray.origin());
    let d = [V::splat(dir.x), V::splat(dir.y), V::splat(dir.z)];
    let c = [v0[0].sub(V::splat(org.x)), v0[1].sub(V::splat(org.y)), v0[2].sub(V::splat(org.z))];
    let dot = |a: [V; 3], b: [V; 3]| a[0].mul(b[0]).add(a[1].mul(b[1])).add(a[2].mul(b[2]));
    let r =
        [d[1].mul(c[2]).sub(c[1].mul(d[2])), d[2].mul(c[0]).sub(c[2].mul(d[0])), d[0].mul(c[1]).sub(c[0].mul(d[1]))];
    let den = dot(ng, d);
    let sign = den.and(V::splat(-0.0));
    let abs_den = den.xor(sign);
    let u = dot(r, e2).xor(sign);
    let v = dot(r, e1).xor(sign);
    let zero = V::splat(0.0);
    // `den != 0` holds for NaN, which then fails `u + v <= abs_den`.
    let inside = den.cmp::<_CMP_NEQ_UQ>(zero)
        & u.cmp::<_CMP_GE_OQ>(zero)
        & v.cmp::<_CMP_GE_OQ>(zero)
        & u.add(v).cmp::<_CMP_LE_OQ>(abs_den);
    let rcp = V::splat(1.0).div(abs_den);
    let t = dot(ng, c).xor(sign).mul(rcp);
    let within = t.cmp::<_CMP_GE_OQ>(V::splat(ray.t_min)) & t.cmp::<_CMP_LT_OQ>(V::splat(ray.t_max));
    let mask = inside & within & lanes;
    let mut hits = Hits16 { mask, ..Hits16::NONE };
    if mask != 0 {
        t.store(&mut hits.t);
        u.mul(rcp).store(&mut hits.u);
        v.mul(rcp).store(&mut hits.v);
    }
    hits
}
