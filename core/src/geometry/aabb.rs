//! Axis-aligned bounding box and the ray–box slab test.
//!
//! Slab test after Williams, Barrus, Morley & Shirley, "An Efficient and Robust Ray–Box
//! Intersection Algorithm" (JGT 2005): the near and far plane of each axis are chosen by the sign
//! of the reciprocal direction rather than by min/max of the two distances. That choice is what
//! makes the edge cases right:
//! * a direction component of +0 or -0 gives a reciprocal of +inf or -inf, so an origin strictly
//!   inside the slab yields (-inf, +inf) and one outside yields an empty interval;
//! * an origin exactly on a plane with a zero component gives 0·inf = NaN for that plane. The ray
//!   then lies in the plane, so the plane must not constrain it; `f32::max`/`f32::min` return the
//!   other operand when one is NaN, which leaves the running interval unchanged — exactly that.
//! * NaN from a malformed ray cannot produce a hit because such a ray is born empty (see `Ray`).

use super::Ray;
use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The empty box: the identity of `union`.
    pub const EMPTY: Aabb = Aabb { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    pub fn new(min: Vec3, max: Vec3) -> Self {
        Self { min, max }
    }

    pub fn from_points(points: &[Vec3]) -> Self {
        points.iter().fold(Self::EMPTY, |b, &p| b.grow(p))
    }

    #[inline]
    pub fn grow(self, p: Vec3) -> Self {
        Self { min: self.min.min(p), max: self.max.max(p) }
    }

    #[inline]
    pub fn union(self, o: Aabb) -> Self {
        Self { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    #[inline]
    pub fn extent(&self) -> Vec3 {
        if self.is_empty() {
            Vec3::ZERO
        } else {
            self.max - self.min
        }
    }

    #[inline]
    /// The eight corners; corner k takes x from `max` if bit 0 of k is set, y if bit 1, z if bit 2.
    pub fn corners(&self) -> [Vec3; 8] {
        std::array::from_fn(|k| {
            Vec3::new(
                if k & 1 == 0 { self.min.x } else { self.max.x },
                if k & 2 == 0 { self.min.y } else { self.max.y },
                if k & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Surface area; 0 for an empty box (so empty children add no SAH cost).
    #[inline]
    pub fn area(&self) -> f32 {
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// The axis (0, 1, 2) of largest extent.
    pub fn widest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    /// True when `other` lies inside this box (boundaries included).
    pub fn contains_box(&self, other: &Aabb) -> bool {
        other.is_empty() || (self.min.cmple(other.min).all() && other.max.cmple(self.max).all())
    }

    /// Entry and exit parameters `(t_enter, t_exit)` of the ray within `[ray.t_min, ray.t_max]`,
    /// or `None` when the ray misses the box in that interval. Boundaries count as inside.
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray) -> Option<(f32, f32)> {
        let (t0, t1) = self.slab(ray.origin(), ray.inv_dir(), ray.t_min, ray.t_max);
        (t0 <= t1).then_some((t0, t1))
    }

    /// The slab test on raw values, for traversal loops that keep the ray's fields in registers.
    /// Returns the clipped interval; it is a hit when `t_enter <= t_exit`.
    #[inline(always)]
    pub fn slab(&self, origin: Vec3, inv_dir: Vec3, t_min: f32, t_max: f32) -> (f32, f32) {
        // Sign-selected planes; `is_sign_negative` distinguishes -inf (from -0) from +inf.
        let (nx, fx) = if inv_dir.x.is_sign_negative() { (self.max.x, self.min.x) } else { (self.min.x, self.max.x) };
        let (ny, fy) = if inv_dir.y.is_sign_negative() { (self.max.y, self.min.y) } else { (self.min.y, self.max.y) };
        let (nz, fz) = if inv_dir.z.is_sign_negative() { (self.max.z, self.min.z) } else { (self.min.z, self.max.z) };
        let t_enter =
            t_min.max((nx - origin.x) * inv_dir.x).max((ny - origin.y) * inv_dir.y).max((nz - origin.z) * inv_dir.z);
        let t_exit =
            t_max.min((fx - origin.x) * inv_dir.x).min((fy - origin.y) * inv_dir.y).min((fz - origin.z) * inv_dir.z);
        (t_enter, t_exit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> Aabb {
        Aabb::new(Vec3::ZERO, Vec3::ONE)
    }

    #[test]
    fn axis_parallel_ray_hits_with_exact_interval() {
        let r = Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::X);
        assert_eq!(unit().intersect(&r), Some((1.0, 2.0)));
        let r = Ray::new(Vec3::new(2.0, 0.5, 0.5), -Vec3::X);
        assert_eq!(unit().intersect(&r), Some((1.0, 2.0)));
    }

    #[test]
    fn axis_parallel_ray_outside_slab_misses_for_both_zero_signs() {
        for dy in [0.0f32, -0.0] {
            let r = Ray::new(Vec3::new(-1.0, 1.5, 0.5), Vec3::new(1.0, dy, 0.0));
            assert_eq!(unit().intersect(&r), None, "dy = {dy:?}");
            let r = Ray::new(Vec3::new(-1.0, -0.5, 0.5), Vec3::new(1.0, dy, -0.0));
            assert_eq!(unit().intersect(&r), None, "dy = {dy:?}");
        }
    }

    #[test]
    fn origin_inside_gives_zero_entry() {
        let r = Ray::new(Vec3::splat(0.5), Vec3::new(1.0, 1.0, 0.0));
        let (t0, t1) = unit().intersect(&r).unwrap();
        assert_eq!(t0, 0.0);
        assert!((t1 - 0.5).abs() < 1e-6);
    }

    #[test]
    fn origin_on_face_with_zero_component_lying_in_the_face_hits() {
        // The ray runs inside the plane y = 0 (a face of the box): 0 * inf = NaN must not reject it.
        for (y, dy) in [(0.0f32, 0.0f32), (0.0, -0.0), (1.0, 0.0), (1.0, -0.0)] {
            let r = Ray::new(Vec3::new(-1.0, y, 0.5), Vec3::new(1.0, dy, 0.0));
            assert_eq!(unit().intersect(&r), Some((1.0, 2.0)), "y = {y}, dy = {dy:?}");
        }
    }

    #[test]
    fn origin_on_face_leaving_and_entering() {
        // On the face x = 0, heading out: touches only at t = 0.
        let r = Ray::new(Vec3::new(0.0, 0.5, 0.5), -Vec3::X);
        assert_eq!(unit().intersect(&r), Some((0.0, 0.0)));
        // On the face x = 0, heading in.
        let r = Ray::new(Vec3::new(0.0, 0.5, 0.5), Vec3::X);
        assert_eq!(unit().intersect(&r), Some((0.0, 1.0)));
    }

    #[test]
    fn nan_ray_never_hits() {
        let boxes = [unit(), Aabb::new(Vec3::splat(-1e30), Vec3::splat(1e30))];
        let rays = [
            Ray::new(Vec3::new(f32::NAN, 0.5, 0.5), Vec3::X),
            Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::new(f32::NAN, 0.0, 0.0)),
            Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::new(1.0, f32::NAN, 0.0)),
            Ray::new(Vec3::splat(0.5), Vec3::ZERO),
        ];
        for b in &boxes {
            for r in &rays {
                assert_eq!(b.intersect(r), None, "{r:?}");
            }
        }
    }

    #[test]
    fn nan_bound_on_one_axis_cannot_rescue_a_miss_on_another() {
        // Our builder never makes NaN boxes (NaN input is rejected at load), but if one appeared,
        // its NaN planes are ignored and the other axes still decide: a ray missing in y misses.
        let b = Aabb::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::new(f32::NAN, 1.0, 1.0));
        let r_miss = Ray::new(Vec3::new(-1.0, 5.0, 0.5), Vec3::X);
        assert_eq!(b.intersect(&r_miss), None);
    }

    #[test]
    fn ray_interval_limits_are_respected() {
        let r = Ray::segment(Vec3::new(-1.0, 0.5, 0.5), Vec3::X, 0.0, 0.5);
        assert_eq!(unit().intersect(&r), None);
        let r = Ray::segment(Vec3::new(-1.0, 0.5, 0.5), Vec3::X, 2.5, 10.0);
        assert_eq!(unit().intersect(&r), None);
        let r = Ray::segment(Vec3::new(-1.0, 0.5, 0.5), Vec3::X, 1.5, 10.0);
        assert_eq!(unit().intersect(&r), Some((1.5, 2.0)));
    }

    #[test]
    fn box_behind_origin_misses() {
        let r = Ray::new(Vec3::new(2.0, 0.5, 0.5), Vec3::X);
        assert_eq!(unit().intersect(&r), None);
    }

    #[test]
    fn empty_box_never_hits() {
        let r = Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::X);
        assert_eq!(Aabb::EMPTY.intersect(&r), None);
        assert_eq!(Aabb::EMPTY.area(), 0.0);
    }
}
