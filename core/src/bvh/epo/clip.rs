//! The area of a triangle inside a box (Sutherland & Hodgman's polygon clipping, 1974), and the
//! box tests the EPO walks make.

use crate::geometry::Aabb;
use glam::{DVec3, Vec3, Vec3A};

/// The area of the part of `tri` inside `b` (boundary included).
pub fn clipped_area(tri: &[Vec3; 3], b: &Aabb) -> f64 {
    // A triangle clipped by six planes has at most 9 corners. Only the planes that cut the
    // triangle's box are clipped against (most planes of a box cut nothing).
    let tb = tri_box(tri);
    let mut poly = Polygon { p: [[0.0; 3]; 9], len: 3 };
    for (i, v) in tri.iter().enumerate() {
        poly.p[i] = v.as_dvec3().to_array();
    }
    let (cut_lo, cut_hi) = (tb.min.cmplt(b.min), tb.max.cmpgt(b.max));
    let planes = [(cut_lo.test(0), cut_hi.test(0)), (cut_lo.test(1), cut_hi.test(1)), (cut_lo.test(2), cut_hi.test(2))];
    for (axis, (lo, hi)) in planes.into_iter().enumerate() {
        let alive = match axis {
            0 => poly.clip::<0>(lo, hi, b),
            1 => poly.clip::<1>(lo, hi, b),
            _ => poly.clip::<2>(lo, hi, b),
        };
        if !alive {
            return 0.0;
        }
    }
    poly.area()
}

/// A convex polygon of at most 9 corners, in double precision.
struct Polygon {
    p: [[f64; 3]; 9],
    len: usize,
}

impl Polygon {
    /// Clip to the box's lower (`lo`) and upper (`hi`) planes on `AXIS`; false once nothing is
    /// left.
    #[inline(always)]
    fn clip<const AXIS: usize>(&mut self, lo: bool, hi: bool, b: &Aabb) -> bool {
        (!lo || self.clip_plane::<AXIS>(b.min[AXIS] as f64, 1.0))
            && (!hi || self.clip_plane::<AXIS>(b.max[AXIS] as f64, -1.0))
    }

    /// Keep the part where `sign · (x[AXIS] − bound) ≥ 0`.
    #[inline(always)]
    fn clip_plane<const AXIS: usize>(&mut self, bound: f64, sign: f64) -> bool {
        let mut out = [[0.0; 3]; 9];
        let mut n = 0;
        let len = self.len.min(9);
        let mut p = self.p[len - 1];
        let mut dp = sign * (p[AXIS] - bound);
        for &q in &self.p[..len] {
            let dq = sign * (q[AXIS] - bound);
            if (dp >= 0.0) != (dq >= 0.0) && n < 9 {
                let t = dp / (dp - dq);
                let mut x = [p[0] + (q[0] - p[0]) * t, p[1] + (q[1] - p[1]) * t, p[2] + (q[2] - p[2]) * t];
                x[AXIS] = bound; // exactly on the plane, whatever the rounding
                out[n] = x;
                n += 1;
            }
            if dq >= 0.0 && n < 9 {
                out[n] = q;
                n += 1;
            }
            (p, dp) = (q, dq);
        }
        (self.p, self.len) = (out, n);
        n >= 3
    }

    fn area(&self) -> f64 {
        let p = |k: usize| DVec3::from_array(self.p[k]);
        let mut twice = DVec3::ZERO;
        for k in 1..self.len.min(9) - 1 {
            twice += (p(k) - p(0)).cross(p(k + 1) - p(0));
        }
        0.5 * twice.length()
    }
}

/// Whether the triangle, whose box meets `b`, meets it only in a plane it crosses (a face or an
/// edge of the box that the triangle touches or passes through): then the part inside has no area.
/// A triangle lying in that plane (flat on that axis) may have area there.
#[inline(always)]
pub(super) fn meets_only_in_a_plane(tb: &Aabb, b: &Aabb) -> bool {
    let thin = tb.max.min(b.max).cmpeq(tb.min.max(b.min));
    let flat = tb.max.cmpeq(tb.min);
    (thin & !flat).any()
}

/// A triangle's area, computed as `clipped_area` computes that of a triangle inside the box (so
/// the two agree to the last bit there).
#[inline]
pub fn triangle_area(t: &[Vec3; 3]) -> f64 {
    let (a, b, c) = (t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3());
    0.5 * (b - a).cross(c - a).length()
}

/// The triangle's box.
#[inline(always)]
pub(super) fn tri_box(t: &[Vec3; 3]) -> Aabb {
    let (a, b, c) = (Vec3A::from(t[0]), Vec3A::from(t[1]), Vec3A::from(t[2]));
    Aabb { min: a.min(b).min(c), max: a.max(b).max(c) }
}

/// Whether the boxes meet (touching counts).
#[inline(always)]
pub(super) fn overlaps(a: &Aabb, b: &Aabb) -> bool {
    !(a.max.cmplt(b.min).any() || b.max.cmplt(a.min).any())
}

/// Whether `inner` lies inside `outer`, boundary included.
#[inline(always)]
pub(super) fn inside(inner: &Aabb, outer: &Aabb) -> bool {
    inner.min.cmpge(outer.min).all() && inner.max.cmple(outer.max).all()
}

/// Whether the point lies in the box, boundary included.
#[inline(always)]
pub(super) fn holds_point(b: &Aabb, p: Vec3A) -> bool {
    p.cmpge(b.min).all() && p.cmple(b.max).all()
}
