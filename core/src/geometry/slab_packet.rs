//! The slab tests of a packet (`slab`'s rules hold here too): four rays of a packet against one
//! box in one SIMD pass (`RayGroup`), and the interval of all its rays against one or four boxes
//! (`RayInterval`, the packet's frustum test).

use super::slab::{max_keep, min_keep, widen, widen4, Boxes4, SLACK};
use crate::geometry::aabb::Aabb;
use crate::geometry::ray::Ray;
use wide::f32x4;

/// Four rays of a packet in SIMD form (lane k = ray k), for one slab test of a box against all
/// four. Padding lanes (past the packet's end) repeat the last ray with `t_max = -inf`, so boxes
/// nearly always miss them (a box can still pass one whose ray starts inside it with
/// `t_min = -inf`); the packet masks them out at leaves.
pub struct RayGroup {
    org: [f32x4; 3],
    inv: [f32x4; 3],
    inv_far: [f32x4; 3],
    /// Per axis, all-ones lanes where the direction is negative (the far plane is `min`).
    pub(crate) neg: [f32x4; 3],
    pub t_min: f32x4,
    /// The rays' current `t_max` (the nearest hit so far).
    pub t_max: f32x4,
    /// `t_max` widened, what boxes are compared with.
    t_limit: f32x4,
}

impl RayGroup {
    /// Rays `base..base + 4` of `rays`; lanes past the end repeat the last ray (its padding).
    #[inline(always)]
    pub fn new(rays: &[Ray], base: usize) -> Self {
        let last = rays.len() - 1;
        let ray = |k: usize| &rays[(base + k).min(last)];
        let lanes = |f: &dyn Fn(&Ray) -> f32| f32x4::from([f(ray(0)), f(ray(1)), f(ray(2)), f(ray(3))]);
        let inv = [lanes(&|r| r.inv_dir().x), lanes(&|r| r.inv_dir().y), lanes(&|r| r.inv_dir().z)];
        let far = |i: f32x4| i * f32x4::splat(1.0 + SLACK);
        let t_max = Self::t_max_of(rays, base);
        // The scalar test picks planes by `is_sign_negative`; `< 0` agrees for every valid ray (a
        // -0 component gives -inf; an invalid ray has t_max = -inf and misses anyway).
        let sign = |v: f32x4| v.simd_lt(f32x4::ZERO);
        RayGroup {
            org: [lanes(&|r| r.origin().x), lanes(&|r| r.origin().y), lanes(&|r| r.origin().z)],
            neg: [sign(inv[0]), sign(inv[1]), sign(inv[2])],
            inv_far: [far(inv[0]), far(inv[1]), far(inv[2])],
            inv,
            t_min: lanes(&|r| r.t_min),
            t_limit: widen4(t_max),
            t_max,
        }
    }

    /// Set the rays' `t_max` (after hits).
    #[inline(always)]
    pub fn set_t_max(&mut self, t_max: f32x4) {
        self.t_max = t_max;
        self.t_limit = widen4(t_max);
    }

    /// The `t_max` of rays `base..base + 4` (`-inf` past the end).
    #[inline(always)]
    pub fn t_max_of(rays: &[Ray], base: usize) -> f32x4 {
        let lane = |k: usize| rays.get(base + k).map_or(f32::NEG_INFINITY, |r| r.t_max);
        f32x4::from([lane(0), lane(1), lane(2), lane(3)])
    }

    /// Lanes whose ray hits the box `[lo, hi]` within [t_min, t_max]: the scalar test's
    /// arithmetic, lane by lane.
    #[inline(always)]
    pub fn hit(&self, lo: [f32; 3], hi: [f32; 3]) -> u32 {
        let mut enter = self.t_min;
        let mut exit = self.t_limit;
        for axis in 0..3 {
            let (lo, hi) = (f32x4::splat(lo[axis]), f32x4::splat(hi[axis]));
            let near = self.neg[axis].bitselect(hi, lo);
            let far = self.neg[axis].bitselect(lo, hi);
            enter = max_keep((near - self.org[axis]) * self.inv[axis], enter);
            exit = min_keep((far - self.org[axis]) * self.inv_far[axis], exit);
        }
        enter.simd_le(exit).to_bitmask()
    }

    /// `hit` for a packet whose rays all share the direction's sign on every axis: the near and
    /// far planes per axis are chosen once for all lanes (the same values `hit` selects, so the
    /// same result), which saves the per-lane selects, a third of the test.
    #[inline(always)]
    pub fn hit_planes(&self, near: [f32; 3], far_planes: [f32; 3]) -> u32 {
        let mut enter = self.t_min;
        let mut exit = self.t_limit;
        for axis in 0..3 {
            let t_near = (f32x4::splat(near[axis]) - self.org[axis]) * self.inv[axis];
            let t_far = (f32x4::splat(far_planes[axis]) - self.org[axis]) * self.inv_far[axis];
            enter = max_keep(t_near, enter);
            exit = min_keep(t_far, exit);
        }
        enter.simd_le(exit).to_bitmask()
    }
}

/// A conservative bound of a packet's rays: where they start and the range of their inverse
/// directions per axis. Valid only when every ray's direction has the same sign on each axis and
/// no component is zero (then each ray's near plane of a box is the same one, and the bounds on
/// its slab distances follow from the corners of the ranges).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayInterval {
    valid: bool,
    org_lo: [f32; 3],
    org_hi: [f32; 3],
    inv_lo: [f32; 3],
    inv_hi: [f32; 3],
    neg: [bool; 3],
    t_min: f32,
}

impl RayInterval {
    /// Whether the bounds hold (one direction sign per axis, finite values); when not, the
    /// interval rejects nothing.
    pub fn is_valid(&self) -> bool {
        self.valid
    }

    /// An interval that rejects nothing.
    pub const OFF: RayInterval = RayInterval {
        valid: false,
        org_lo: [0.0; 3],
        org_hi: [0.0; 3],
        inv_lo: [0.0; 3],
        inv_hi: [0.0; 3],
        neg: [false; 3],
        t_min: 0.0,
    };

    /// The bounds of the rays in `groups` (padding lanes repeat a ray, so they change nothing).
    #[inline(always)]
    pub fn new(groups: &[RayGroup]) -> Self {
        let inf = f32x4::splat(f32::INFINITY);
        let (mut org_lo, mut org_hi) = ([inf; 3], [-inf; 3]);
        let (mut inv_lo, mut inv_hi) = ([inf; 3], [-inf; 3]);
        let mut t_min = inf;
        // |x| < inf is false for infinities and NaNs; min and max skip NaNs, so a ray with one
        // must switch the test off here.
        let is_finite = |v: f32x4| v.abs().simd_lt(inf);
        let mut finite = f32x4::ZERO.simd_eq(f32x4::ZERO);
        for g in groups {
            for axis in 0..3 {
                let (o, i) = (g.org[axis], g.inv[axis]);
                finite &= is_finite(o) & is_finite(i);
                (org_lo[axis], org_hi[axis]) = (org_lo[axis].min(o), org_hi[axis].max(o));
                (inv_lo[axis], inv_hi[axis]) = (inv_lo[axis].min(i), inv_hi[axis].max(i));
            }
            t_min = t_min.min(g.t_min);
        }
        let low = |v: f32x4| v.to_array().into_iter().fold(f32::INFINITY, f32::min);
        let high = |v: f32x4| v.to_array().into_iter().fold(f32::NEG_INFINITY, f32::max);
        // Written out per axis: `array::map` was left out of line here, a twentieth of a packet.
        let lows = |v: &[f32x4; 3]| [low(v[0]), low(v[1]), low(v[2])];
        let highs = |v: &[f32x4; 3]| [high(v[0]), high(v[1]), high(v[2])];
        let (org_lo, org_hi, inv_lo, inv_hi) = (lows(&org_lo), highs(&org_hi), lows(&inv_lo), highs(&inv_hi));
        Self::of_bounds([org_lo, org_hi, inv_lo, inv_hi], low(t_min), !groups.is_empty() && finite.all())
    }

    /// The interval of rays whose origins lie in `[org_lo, org_hi]` and reciprocal directions in
    /// `[inv_lo, inv_hi]` per axis (`bounds`, in that order), starting at `t_min` or later; valid
    /// when every value was `finite` and each axis has one sign. Shared by the four-lane groups
    /// (`new`) and the sixteen-lane ones (`avx512::packet`).
    #[inline(always)]
    pub(crate) fn of_bounds(bounds: [[f32; 3]; 4], t_min: f32, finite: bool) -> Self {
        let [org_lo, org_hi, inv_lo, inv_hi] = bounds;
        // One sign per axis, no zero or infinite component, finite origins.
        let one_sign = (0..3).all(|a| inv_lo[a] > 0.0 || inv_hi[a] < 0.0);
        RayInterval {
            valid: finite && one_sign,
            org_lo,
            org_hi,
            neg: [inv_hi[0] < 0.0, inv_hi[1] < 0.0, inv_hi[2] < 0.0],
            inv_lo,
            inv_hi,
            t_min,
        }
    }

    /// True when no ray of the packet can hit `b` before `t_far` (the farthest `t_max` of the
    /// packet). Each ray's slab distance `(plane - o) · inv` is a rounded expression monotonic in
    /// `o` and in `inv`, so its extremes over the ranges are at their corners: the bounds below
    /// contain every ray's own rounded value, and the exit is widened as the rays' own is.
    #[inline(always)]
    pub fn misses(&self, b: &Aabb, t_far: f32) -> bool {
        if !self.valid {
            return false;
        }
        let mut enter = self.t_min;
        let mut exit = t_far;
        for axis in 0..3 {
            let (near, far_plane) =
                if self.neg[axis] { (b.max[axis], b.min[axis]) } else { (b.min[axis], b.max[axis]) };
            let corners = |plane: f32| {
                let (d0, d1) = (plane - self.org_hi[axis], plane - self.org_lo[axis]);
                let (i0, i1) = (self.inv_lo[axis], self.inv_hi[axis]);
                [d0 * i0, d0 * i1, d1 * i0, d1 * i1]
            };
            let n = corners(near);
            let f = corners(far_plane);
            enter = enter.max(n[0].min(n[1]).min(n[2]).min(n[3]));
            exit = exit.min(f[0].max(f[1]).max(f[2]).max(f[3]));
        }
        enter > widen(exit)
    }

    /// The four-box form of `misses`: the mask of the boxes some ray of the packet may hit
    /// before `t_far`, all four when the test does not apply. The same bounds, one SIMD lane per
    /// box.
    #[inline(always)]
    pub fn may_hit4(&self, boxes: &Boxes4, t_far: f32) -> u32 {
        let (min, max) = (&boxes.min, &boxes.max);
        if !self.valid {
            return 0b1111;
        }
        let mut enter = f32x4::splat(self.t_min);
        let mut exit = f32x4::splat(t_far);
        for axis in 0..3 {
            let (near, far_plane) = if self.neg[axis] { (max[axis], min[axis]) } else { (min[axis], max[axis]) };
            let (o_lo, o_hi) = (f32x4::splat(self.org_lo[axis]), f32x4::splat(self.org_hi[axis]));
            let (i0, i1) = (f32x4::splat(self.inv_lo[axis]), f32x4::splat(self.inv_hi[axis]));
            let corners = |plane: [f32; 4]| {
                let p = f32x4::from(plane);
                let (d0, d1) = (p - o_hi, p - o_lo);
                (d0 * i0, d0 * i1, d1 * i0, d1 * i1)
            };
            let n = corners(near);
            let f = corners(far_plane);
            enter = enter.max(n.0.min(n.1).min(n.2.min(n.3)));
            exit = exit.min(f.0.max(f.1).max(f.2.max(f.3)));
        }
        // Rejected only when surely empty, as in `misses` (a NaN keeps the box).
        !enter.simd_gt(widen4(exit)).to_bitmask() & 0b1111
    }
}
