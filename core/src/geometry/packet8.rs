//! Eight rays of a packet in one AVX2 register per value, the AVX2 family's packet groups: their
//! slab test against one box (`RayGroup8`) and their watertight test against one triangle
//! (`WatertightRay8`), each the four-lane groups' arithmetic (`slab_packet::RayGroup`,
//! `Watertight::intersect4`) lane for lane, as the sixteen-ray groups of AVX-512 are
//! (`avx512::packet`, whose operations these follow with AVX2's vector masks in place of mask
//! registers). A packet of 64 rays (an 8×8 tile, `bvh::packet`'s Z-order) is eight such groups,
//! each a 4×2 block of pixels: a box costs one pass for eight rays where the four-lane groups need
//! two (Wald, Boulos & Shirley, "Ray Tracing Deformable Scenes Using Dynamic Bounding Volume
//! Hierarchies", TOG 2007, §4). Every function here is compiled for AVX2 (`#[target_feature]`)
//! and takes the `Avx2` proof.

use crate::geometry::ray::Ray;
use crate::geometry::slab::SLACK;
use crate::geometry::slab8::Avx2;
use crate::geometry::slab_packet::RayInterval;
use crate::geometry::triangle8::{edge_test8, Hits8};
use glam::Vec3;
use std::arch::x86_64::*;

/// Eight rays of a packet (lane k = ray `base + k`). Padding lanes (past the packet's end) repeat
/// the last ray with `t_max = -inf`, as in the four-lane groups; the packet masks them out at leaves.
#[derive(Clone, Copy, Debug)]
pub struct RayGroup8 {
    org: [__m256; 3],
    inv: [__m256; 3],
    inv_far: [__m256; 3],
    /// Per axis, the lanes whose direction is negative (their near plane is `max`): as a vector
    /// mask for the blends, and as bits.
    neg_v: [__m256; 3],
    pub(crate) neg: [u8; 3],
    pub(crate) t_min: __m256,
    /// The rays' current `t_max`, and it widened (what boxes are compared with).
    pub(crate) t_max: __m256,
    t_limit: __m256,
}

/// `|x|`: the sign bit cleared.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn abs8(x: __m256) -> __m256 {
    _mm256_andnot_ps(_mm256_set1_ps(-0.0), x)
}

/// Eight floats in a register.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn load8(a: &[f32; 8]) -> __m256 {
    // SAFETY: eight floats, the width of the load.
    unsafe { _mm256_loadu_ps(a.as_ptr()) }
}

/// A register's eight floats.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn lanes8(x: __m256) -> [f32; 8] {
    let mut a = [0f32; 8];
    // SAFETY: eight floats, the width of the store.
    unsafe { _mm256_storeu_ps(a.as_mut_ptr(), x) };
    a
}

/// `widen` in eight lanes: `max_keep(t + |t|·SLACK, t)`, the four-lane `widen4`'s operations.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn widen8(t: __m256) -> __m256 {
    _mm256_max_ps(_mm256_add_ps(t, _mm256_mul_ps(abs8(t), _mm256_set1_ps(SLACK))), t)
}

impl RayGroup8 {
    /// Rays `base..base + 8` of `rays`, gathered in one loop into arrays, then loaded.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub fn new(_: Avx2, rays: &[Ray], base: usize) -> Self {
        let last = rays.len() - 1;
        // [origin x, y, z, inverse direction x, y, z, t_min, t_max][lane]
        let mut v = [[0f32; 8]; 8];
        for k in 0..8 {
            let r = &rays[(base + k).min(last)];
            let (o, i) = (r.origin(), r.inv_dir());
            let t_max = if base + k < rays.len() { r.t_max } else { f32::NEG_INFINITY };
            for (row, x) in v.iter_mut().zip([o.x, o.y, o.z, i.x, i.y, i.z, r.t_min, t_max]) {
                row[k] = x;
            }
        }
        let inv = [load8(&v[3]), load8(&v[4]), load8(&v[5])];
        let far = |i: __m256| _mm256_mul_ps(i, _mm256_set1_ps(1.0 + SLACK));
        // `< 0`, as the four-lane groups decide (the same as `is_sign_negative` for valid rays).
        let sign = |i: __m256| _mm256_cmp_ps::<_CMP_LT_OQ>(i, _mm256_setzero_ps());
        let neg_v = [sign(inv[0]), sign(inv[1]), sign(inv[2])];
        let t_max = load8(&v[7]);
        RayGroup8 {
            org: [load8(&v[0]), load8(&v[1]), load8(&v[2])],
            inv_far: [far(inv[0]), far(inv[1]), far(inv[2])],
            neg: neg_v.map(|m| _mm256_movemask_ps(m) as u8),
            neg_v,
            inv,
            t_min: load8(&v[6]),
            t_limit: widen8(t_max),
            t_max,
        }
    }

    /// Take the rays' `t_max` again (after hits): rays `base..base + 8` (`-inf` past the end).
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub fn refresh(&mut self, _: Avx2, rays: &[Ray], base: usize) {
        let mut t = [f32::NEG_INFINITY; 8];
        for (k, r) in rays.iter().skip(base).take(8).enumerate() {
            t[k] = r.t_max;
        }
        self.t_max = load8(&t);
        self.t_limit = widen8(self.t_max);
    }

    /// The largest `t_max` of the eight rays.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub fn t_far(&self, _: Avx2) -> f32 {
        lanes8(self.t_max).into_iter().fold(f32::NEG_INFINITY, f32::max)
    }

    /// Lanes whose ray hits the box `[lo, hi]`: the scalar test's arithmetic lane by lane
    /// (`vmaxps`/`vminps` return their second operand when one is NaN: the running value
    /// survives a ray lying in a plane).
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub fn hit(&self, _: Avx2, lo: [f32; 3], hi: [f32; 3]) -> u32 {
        let (mut enter, mut exit) = (self.t_min, self.t_limit);
        for axis in 0..3 {
            let (l, h) = (_mm256_set1_ps(lo[axis]), _mm256_set1_ps(hi[axis]));
            let near = _mm256_blendv_ps(l, h, self.neg_v[axis]);
            let far = _mm256_blendv_ps(h, l, self.neg_v[axis]);
            let t0 = _mm256_mul_ps(_mm256_sub_ps(near, self.org[axis]), self.inv[axis]);
            let t1 = _mm256_mul_ps(_mm256_sub_ps(far, self.org[axis]), self.inv_far[axis]);
            enter = _mm256_max_ps(t0, enter);
            exit = _mm256_min_ps(t1, exit);
        }
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit)) as u32
    }

    /// `hit` where every ray has the direction's signs of the packet: the planes chosen once.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub fn hit_planes(&self, _: Avx2, near: [f32; 3], far: [f32; 3]) -> u32 {
        let (mut enter, mut exit) = (self.t_min, self.t_limit);
        for axis in 0..3 {
            let t0 = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(near[axis]), self.org[axis]), self.inv[axis]);
            let t1 = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(far[axis]), self.org[axis]), self.inv_far[axis]);
            enter = _mm256_max_ps(t0, enter);
            exit = _mm256_min_ps(t1, exit);
        }
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit)) as u32
    }
}

/// The frustum of a packet's groups: `RayInterval::new`'s bounds, eight lanes at a time.
#[inline]
#[target_feature(enable = "avx2,fma")]
pub fn interval8(_: Avx2, groups: &[RayGroup8]) -> RayInterval {
    let inf = _mm256_set1_ps(f32::INFINITY);
    let ninf = _mm256_set1_ps(f32::NEG_INFINITY);
    let (mut org_lo, mut org_hi, mut inv_lo, mut inv_hi) = ([inf; 3], [ninf; 3], [inf; 3], [ninf; 3]);
    let mut t_min = inf;
    // |x| < inf is false for infinities and NaNs, which switch the test off.
    let finite = |v: __m256| _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(abs8(v), inf)) as u32;
    let mut all = 0xFF;
    for g in groups {
        for axis in 0..3 {
            let (o, i) = (g.org[axis], g.inv[axis]);
            all &= finite(o) & finite(i);
            org_lo[axis] = _mm256_min_ps(org_lo[axis], o);
            org_hi[axis] = _mm256_max_ps(org_hi[axis], o);
            inv_lo[axis] = _mm256_min_ps(inv_lo[axis], i);
            inv_hi[axis] = _mm256_max_ps(inv_hi[axis], i);
        }
        t_min = _mm256_min_ps(t_min, g.t_min);
    }
    // With every value finite the reductions are exact, whatever their order.
    let min = |v: __m256| lanes8(v).into_iter().fold(f32::INFINITY, f32::min);
    let max = |v: __m256| lanes8(v).into_iter().fold(f32::NEG_INFINITY, f32::max);
    let low = |v: &[__m256; 3]| [min(v[0]), min(v[1]), min(v[2])];
    let high = |v: &[__m256; 3]| [max(v[0]), max(v[1]), max(v[2])];
    let bounds = [low(&org_lo), high(&org_hi), low(&inv_lo), high(&inv_hi)];
    RayInterval::of_bounds(bounds, min(t_min), !groups.is_empty() && all == 0xFF)
}

/// Eight rays' `WatertightRay` rows and origins, lane k for ray k.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay8 {
    org: [__m256; 3],
    pub(crate) rx: [__m256; 3],
    pub(crate) ry: [__m256; 3],
    pub(crate) rz: [__m256; 3],
}

impl WatertightRay8 {
    /// The rows of rays `base..base + 8` (lanes past the end repeat the last ray), bit for bit
    /// those `WatertightRay::with_branches` makes for each: the axes chosen by lane masks instead
    /// of branches, then the same operations (`unit(kx) − unit(kz)·sx`, …), as `WatertightRay16`.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub fn new(_: Avx2, rays: &[Ray], base: usize) -> Self {
        let last = rays.len() - 1;
        let mut v = [[0f32; 8]; 6]; // [origin x, y, z, direction x, y, z][lane]
        for k in 0..8 {
            let r = &rays[(base + k).min(last)];
            let (o, d) = (r.origin(), r.dir());
            for (row, x) in v.iter_mut().zip([o.x, o.y, o.z, d.x, d.y, d.z]) {
                row[k] = x;
            }
        }
        let d = [load8(&v[3]), load8(&v[4]), load8(&v[5])];
        let a = [abs8(d[0]), abs8(d[1]), abs8(d[2])];
        let ge = |p: __m256, q: __m256| _mm256_cmp_ps::<_CMP_GE_OQ>(p, q);
        let (and, or, and_not) = (_mm256_and_ps, _mm256_or_ps, |m: __m256, x: __m256| _mm256_andnot_ps(m, x));
        let ones = _mm256_cmp_ps::<_CMP_EQ_OQ>(_mm256_setzero_ps(), _mm256_setzero_ps());
        // kz: x where |x| ≥ |y| and |x| ≥ |z|, else y where |y| ≥ |z|, else z (NaN compares false).
        let x_largest = and(ge(a[0], a[1]), ge(a[0], a[2]));
        let y_largest = and_not(x_largest, ge(a[1], a[2]));
        let z_largest = and_not(or(x_largest, y_largest), ones);
        let kz = [x_largest, y_largest, z_largest];
        let pick = |m: [__m256; 3]| _mm256_blendv_ps(_mm256_blendv_ps(d[0], d[1], m[1]), d[2], m[2]);
        let dz = pick(kz);
        // kx = kz + 1, ky = kz + 2 (mod 3), swapped where d[kz] < 0.
        let neg = _mm256_cmp_ps::<_CMP_LT_OQ>(dz, _mm256_setzero_ps());
        let next = [kz[2], kz[0], kz[1]]; // axis c is kz + 1 where kz = c − 1
        let after = [kz[1], kz[2], kz[0]]; // axis c is kz + 2 where kz = c + 1
        let kx = [0, 1, 2].map(|c| or(and_not(neg, next[c]), and(after[c], neg)));
        let ky = [0, 1, 2].map(|c| or(and_not(neg, after[c]), and(next[c], neg)));
        let one = _mm256_set1_ps(1.0);
        let sx = _mm256_div_ps(pick(kx), dz);
        let sy = _mm256_div_ps(pick(ky), dz);
        let sz = _mm256_div_ps(one, dz);
        // 1.0 in the lanes of `m`, +0.0 elsewhere.
        let unit = |m: __m256| and(m, one);
        let row_of =
            |k: [__m256; 3], s: __m256| [0, 1, 2].map(|c| _mm256_sub_ps(unit(k[c]), _mm256_mul_ps(unit(kz[c]), s)));
        WatertightRay8 {
            org: [load8(&v[0]), load8(&v[1]), load8(&v[2])],
            rx: row_of(kx, sx),
            ry: row_of(ky, sy),
            rz: [0, 1, 2].map(|c| _mm256_mul_ps(unit(kz[c]), sz)),
        }
    }

    /// One triangle against the eight rays, each within `[t_min, t_max)` of its lane, for the
    /// lanes in `lanes`: `Watertight::intersect4`'s operations in the same order, so lane k is
    /// `Watertight::intersect` of ray k bit for bit.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub fn intersect(&self, _: Avx2, t_min: __m256, t_max: __m256, lanes: u32, tri: &[Vec3; 3]) -> Hits8 {
        let s = |x: f32| _mm256_set1_ps(x);
        let rel = |v: Vec3| {
            [_mm256_sub_ps(s(v.x), self.org[0]), _mm256_sub_ps(s(v.y), self.org[1]), _mm256_sub_ps(s(v.z), self.org[2])]
        };
        // glam's dot: (x·x' + y·y') + z·z'.
        let dot = |a: &[__m256; 3], r: &[__m256; 3]| {
            _mm256_add_ps(
                _mm256_add_ps(_mm256_mul_ps(a[0], r[0]), _mm256_mul_ps(a[1], r[1])),
                _mm256_mul_ps(a[2], r[2]),
            )
        };
        let (a, b, c) = (rel(tri[0]), rel(tri[1]), rel(tri[2]));
        let (ax, ay) = (dot(&a, &self.rx), dot(&a, &self.ry));
        let (bx, by) = (dot(&b, &self.rx), dot(&b, &self.ry));
        let (cx, cy) = (dot(&c, &self.rx), dot(&c, &self.ry));
        let z = [dot(&a, &self.rz), dot(&b, &self.rz), dot(&c, &self.rz)];
        edge_test8([ax, ay, bx, by, cx, cy], z, t_min, t_max, lanes)
    }
}

#[cfg(test)]
#[path = "packet8_tests.rs"]
mod tests;
