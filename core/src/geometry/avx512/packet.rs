//! Sixteen rays of a packet in one AVX-512 register per value: their slab test against one box
//! (`RayGroup16`, `slab_packet::RayGroup`'s arithmetic lane for lane: sign-selected planes, NaN
//! kept out by `vmaxps`/`vminps`, the far planes with the enlarged reciprocal, boxes compared with
//! `t_max` widened by `SLACK`) and their watertight test against one triangle
//! (`WatertightRay16`, `Watertight::intersect4`'s arithmetic lane for lane). A packet of 64 rays
//! (an 8×8 tile) is four such groups, each a 4×4 block of pixels (`bvh::packet`'s Z-order): a box
//! costs one pass for sixteen rays where the four-lane groups need four (Wald, Boulos & Shirley,
//! "Ray Tracing Deformable Scenes Using Dynamic Bounding Volume Hierarchies", TOG 2007, §4, with
//! Embree's sixteen-wide packets of AVX-512). Every function here is compiled for AVX-512
//! (`#[target_feature]`, see `Lanes`) and takes the `Avx512` proof; callers without the features
//! call them in `unsafe`, the proof in hand.

use super::leaf::{edge_test, Hits16};
use crate::geometry::avx512::lanes::Avx512;
use crate::geometry::ray::Ray;
use crate::geometry::slab::SLACK;
use crate::geometry::slab_packet::RayInterval;
use glam::Vec3;
use std::arch::x86_64::*;

/// Sixteen rays of a packet (lane k = ray `base + k`). Padding lanes (past the packet's end) repeat
/// the last ray with `t_max = -inf`, as in the four-lane groups; the packet masks them out at leaves.
#[derive(Clone, Copy, Debug)]
pub struct RayGroup16 {
    org: [__m512; 3],
    inv: [__m512; 3],
    inv_far: [__m512; 3],
    /// Per axis, the lanes whose direction is negative (their near plane is `max`).
    pub(crate) neg: [u16; 3],
    pub(crate) t_min: __m512,
    /// The rays' current `t_max`, and it widened (what boxes are compared with).
    pub(crate) t_max: __m512,
    t_limit: __m512,
}

/// # Safety
/// The CPU has AVX-512F.
#[inline]
#[target_feature(enable = "avx512f,avx512vl")]
unsafe fn load(a: &[f32; 16]) -> __m512 {
    _mm512_loadu_ps(a.as_ptr())
}

/// `widen` in sixteen lanes: `max_keep(t + |t|·SLACK, t)`, the four-lane `widen4`'s operations.
#[inline]
#[target_feature(enable = "avx512f,avx512vl")]
fn widen16(t: __m512) -> __m512 {
    _mm512_max_ps(_mm512_add_ps(t, _mm512_mul_ps(_mm512_abs_ps(t), _mm512_set1_ps(SLACK))), t)
}

impl RayGroup16 {
    /// Rays `base..base + 16` of `rays`. The lanes are gathered in one loop over the rays into
    /// arrays, then loaded: a closure per value (through `&dyn Fn`) made the packet's setup a third
    /// of its time.
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    pub fn new(_: Avx512, rays: &[Ray], base: usize) -> Self {
        use crate::geometry::ray::at;
        // Lane k reads ray base + k (the last ray past the end), each value by one gather: rows
        // written float by float and loaded whole stalled on every load (a 64-byte load cannot
        // take its bytes from sixteen pending 4-byte stores), a sixth of the packet walk's time.
        let n = rays.len() - base;
        let lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
        let ray = _mm512_min_epi32(lane, _mm512_set1_epi32(n as i32 - 1));
        let start = _mm512_mullo_epi32(ray, _mm512_set1_epi32(at::FLOATS as i32));
        let from = rays[base..].as_ptr().cast::<f32>();
        // SAFETY: every index is that of a float inside rays[base..] (lane k reads ray
        // min(k, n - 1) < n, at a value's place within it, `at`).
        let row =
            |j: usize| unsafe { _mm512_i32gather_ps::<4>(_mm512_add_epi32(start, _mm512_set1_epi32(j as i32)), from) };
        let value = |j: usize| match j {
            0..=2 => row(at::ORIGIN + j),
            3..=5 => row(at::INV_DIR + j - 3),
            6 => row(at::T_MIN),
            _ => {
                let real = if n >= 16 { u16::MAX } else { (1u16 << n) - 1 };
                _mm512_mask_blend_ps(real, _mm512_set1_ps(f32::NEG_INFINITY), row(at::T_MAX))
            }
        };
        let row = value;
        let inv = [row(3), row(4), row(5)];
        let far = |i: __m512| _mm512_mul_ps(i, _mm512_set1_ps(1.0 + SLACK));
        // `< 0`, as the four-lane groups decide (the same as `is_sign_negative` for valid rays).
        let sign = |i: __m512| _mm512_cmp_ps_mask::<_CMP_LT_OQ>(i, _mm512_setzero_ps());
        let t_max = row(7);
        RayGroup16 {
            org: [row(0), row(1), row(2)],
            inv_far: [far(inv[0]), far(inv[1]), far(inv[2])],
            neg: [sign(inv[0]), sign(inv[1]), sign(inv[2])],
            inv,
            t_min: row(6),
            t_limit: widen16(t_max),
            t_max,
        }
    }

    /// The `t_max` of rays `base..base + 16` (`-inf` past the end).
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    fn t_max_of(rays: &[Ray], base: usize) -> __m512 {
        let mut t = [f32::NEG_INFINITY; 16];
        for (k, r) in rays.iter().skip(base).take(16).enumerate() {
            t[k] = r.t_max;
        }
        // SAFETY: sixteen floats.
        unsafe { load(&t) }
    }

    /// Take the rays' `t_max` again (after hits).
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    pub fn refresh(&mut self, _: Avx512, rays: &[Ray], base: usize) {
        self.t_max = Self::t_max_of(rays, base);
        self.t_limit = widen16(self.t_max);
    }

    /// The largest `t_max` of the sixteen rays.
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    pub fn t_far(&self, _: Avx512) -> f32 {
        let mut t = [0f32; 16];
        // SAFETY: the `Avx512` argument proves the CPU has AVX-512F.
        unsafe { _mm512_storeu_ps(t.as_mut_ptr(), self.t_max) };
        t.into_iter().fold(f32::NEG_INFINITY, f32::max)
    }

    /// Lanes whose ray hits the box `[lo, hi]`: the scalar test's arithmetic lane by lane.
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    pub fn hit(&self, _: Avx512, lo: [f32; 3], hi: [f32; 3]) -> u32 {
        let (mut enter, mut exit) = (self.t_min, self.t_limit);
        for axis in 0..3 {
            let (l, h) = (_mm512_set1_ps(lo[axis]), _mm512_set1_ps(hi[axis]));
            let near = _mm512_mask_blend_ps(self.neg[axis], l, h);
            let far = _mm512_mask_blend_ps(self.neg[axis], h, l);
            let t0 = _mm512_mul_ps(_mm512_sub_ps(near, self.org[axis]), self.inv[axis]);
            let t1 = _mm512_mul_ps(_mm512_sub_ps(far, self.org[axis]), self.inv_far[axis]);
            enter = _mm512_max_ps(t0, enter);
            exit = _mm512_min_ps(t1, exit);
        }
        _mm512_cmp_ps_mask::<_CMP_LE_OQ>(enter, exit) as u32
    }

    /// `hit` where every ray has the direction's signs of the packet: the planes chosen once.
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    pub fn hit_planes(&self, _: Avx512, near: [f32; 3], far: [f32; 3]) -> u32 {
        let (mut enter, mut exit) = (self.t_min, self.t_limit);
        for axis in 0..3 {
            let t0 = _mm512_mul_ps(_mm512_sub_ps(_mm512_set1_ps(near[axis]), self.org[axis]), self.inv[axis]);
            let t1 = _mm512_mul_ps(_mm512_sub_ps(_mm512_set1_ps(far[axis]), self.org[axis]), self.inv_far[axis]);
            enter = _mm512_max_ps(t0, enter);
            exit = _mm512_min_ps(t1, exit);
        }
        _mm512_cmp_ps_mask::<_CMP_LE_OQ>(enter, exit) as u32
    }
}

/// The frustum of a packet's groups: `RayInterval::new`'s bounds, sixteen lanes at a time.
#[inline]
#[target_feature(enable = "avx512f,avx512vl")]
pub fn interval16(_: Avx512, groups: &[RayGroup16]) -> RayInterval {
    let inf = _mm512_set1_ps(f32::INFINITY);
    let ninf = _mm512_set1_ps(f32::NEG_INFINITY);
    let (mut org_lo, mut org_hi, mut inv_lo, mut inv_hi) = ([inf; 3], [ninf; 3], [inf; 3], [ninf; 3]);
    let mut t_min = inf;
    // |x| < inf is false for infinities and NaNs, which switch the test off.
    let finite = |v: __m512| _mm512_cmp_ps_mask::<_CMP_LT_OQ>(_mm512_abs_ps(v), inf);
    let mut all = u16::MAX;
    for g in groups {
        for axis in 0..3 {
            let (o, i) = (g.org[axis], g.inv[axis]);
            all &= finite(o) & finite(i);
            org_lo[axis] = _mm512_min_ps(org_lo[axis], o);
            org_hi[axis] = _mm512_max_ps(org_hi[axis], o);
            inv_lo[axis] = _mm512_min_ps(inv_lo[axis], i);
            inv_hi[axis] = _mm512_max_ps(inv_hi[axis], i);
        }
        t_min = _mm512_min_ps(t_min, g.t_min);
    }
    // With every value finite the reductions are exact, whatever their order.
    let low = |v: &[__m512; 3]| [0, 1, 2].map(|a| _mm512_reduce_min_ps(v[a]));
    let high = |v: &[__m512; 3]| [0, 1, 2].map(|a| _mm512_reduce_max_ps(v[a]));
    let bounds = [low(&org_lo), high(&org_hi), low(&inv_lo), high(&inv_hi)];
    RayInterval::of_bounds(bounds, _mm512_reduce_min_ps(t_min), !groups.is_empty() && all == u16::MAX)
}

/// Sixteen rays' `WatertightRay` rows and origins, lane k for ray k.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay16 {
    org: [__m512; 3],
    rx: [__m512; 3],
    ry: [__m512; 3],
    rz: [__m512; 3],
}

impl WatertightRay16 {
    /// The rows of rays `base..base + 16` (lanes past the end repeat the last ray), bit for bit
    /// those `WatertightRay::with_branches` makes for each (what the four-lane packets use), but
    /// sixteen at once: the axes chosen by lane masks instead of branches, then the same
    /// operations (`unit(kx) − unit(kz)·sx`, …, one subtraction and one product per component, so
    /// even the zeros keep their signs). Ray by ray this setup was a tenth of a packet's time.
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    pub fn new(_: Avx512, rays: &[Ray], base: usize) -> Self {
        let last = rays.len() - 1;
        let mut v = [[0f32; 16]; 6]; // [origin x, y, z, direction x, y, z][lane]
        for k in 0..16 {
            let r = &rays[(base + k).min(last)];
            let (o, d) = (r.origin(), r.dir());
            for (row, x) in v.iter_mut().zip([o.x, o.y, o.z, d.x, d.y, d.z]) {
                row[k] = x;
            }
        }
        // SAFETY: each row is sixteen floats.
        let row = |j: usize| unsafe { load(&v[j]) };
        let d = [row(3), row(4), row(5)];
        let a = d.map(|x| _mm512_abs_ps(x));
        let ge = |p: __m512, q: __m512| _mm512_cmp_ps_mask::<_CMP_GE_OQ>(p, q);
        // kz: x where |x| ≥ |y| and |x| ≥ |z|, else y where |y| ≥ |z|, else z (NaN compares false).
        let x_largest = ge(a[0], a[1]) & ge(a[0], a[2]);
        let y_largest = !x_largest & ge(a[1], a[2]);
        let z_largest = !x_largest & !y_largest;
        let kz = [x_largest, y_largest, z_largest];
        let pick = |m: [u16; 3]| _mm512_mask_blend_ps(m[2], _mm512_mask_blend_ps(m[1], d[0], d[1]), d[2]);
        let dz = pick(kz);
        // kx = kz + 1, ky = kz + 2 (mod 3), swapped where d[kz] < 0.
        let neg = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(dz, _mm512_setzero_ps());
        let next = [kz[2], kz[0], kz[1]]; // axis c is kz + 1 where kz = c − 1
        let after = [kz[1], kz[2], kz[0]]; // axis c is kz + 2 where kz = c + 1
        let kx = [0, 1, 2].map(|c| (next[c] & !neg) | (after[c] & neg));
        let ky = [0, 1, 2].map(|c| (after[c] & !neg) | (next[c] & neg));
        let one = _mm512_set1_ps(1.0);
        let sx = _mm512_div_ps(pick(kx), dz);
        let sy = _mm512_div_ps(pick(ky), dz);
        let sz = _mm512_div_ps(one, dz);
        let unit = |m: u16| _mm512_maskz_mov_ps(m, one);
        let row_of =
            |k: [u16; 3], s: __m512| [0, 1, 2].map(|c| _mm512_sub_ps(unit(k[c]), _mm512_mul_ps(unit(kz[c]), s)));
        WatertightRay16 {
            org: [row(0), row(1), row(2)],
            rx: row_of(kx, sx),
            ry: row_of(ky, sy),
            rz: [0, 1, 2].map(|c| _mm512_mul_ps(unit(kz[c]), sz)),
        }
    }

    /// One triangle against the sixteen rays, each within `[t_min, t_max)` of its lane, for the
    /// lanes in `lanes`: `Watertight::intersect4`'s operations in the same order, so lane k is
    /// `Watertight::intersect` of ray k bit for bit.
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    pub fn intersect(&self, _: Avx512, t_min: __m512, t_max: __m512, lanes: u32, tri: &[Vec3; 3]) -> Hits16 {
        // SAFETY: the `Avx512` argument proves the CPU has AVX-512F/VL.
        unsafe {
            let s = |x: f32| _mm512_set1_ps(x);
            let rel = |v: Vec3| {
                [
                    _mm512_sub_ps(s(v.x), self.org[0]),
                    _mm512_sub_ps(s(v.y), self.org[1]),
                    _mm512_sub_ps(s(v.z), self.org[2]),
                ]
            };
            // glam's dot: (x·x' + y·y') + z·z'.
            let dot = |a: &[__m512; 3], r: &[__m512; 3]| {
                _mm512_add_ps(
                    _mm512_add_ps(_mm512_mul_ps(a[0], r[0]), _mm512_mul_ps(a[1], r[1])),
                    _mm512_mul_ps(a[2], r[2]),
                )
            };
            let (a, b, c) = (rel(tri[0]), rel(tri[1]), rel(tri[2]));
            let (ax, ay) = (dot(&a, &self.rx), dot(&a, &self.ry));
            let (bx, by) = (dot(&b, &self.rx), dot(&b, &self.ry));
            let (cx, cy) = (dot(&c, &self.rx), dot(&c, &self.ry));
            let z = [dot(&a, &self.rz), dot(&b, &self.rz), dot(&c, &self.rz)];
            edge_test::<__m512>([ax, ay, bx, by, cx, cy], z, t_min, t_max, lanes)
        }
    }
}

#[cfg(test)]
#[path = "packet_tests.rs"]
mod tests;
