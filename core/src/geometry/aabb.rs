//! The axis-aligned bounding box: the one box type of the project. Its corners are SIMD vectors
//! (`Vec3A`), so the builder's unions over millions of boxes (node bounds, centroid bounds, the
//! SAH's bins) are one instruction each; nodes store their boxes as plain floats (`BvhNode`,
//! `WideNode`) and hand them to the slab tests of `slab.rs`.

use crate::geometry::ray::Ray;
use glam::{Vec3, Vec3A};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3A,
    pub max: Vec3A,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The empty box: the identity of `union`.
    pub const EMPTY: Aabb = Aabb { min: Vec3A::INFINITY, max: Vec3A::NEG_INFINITY };

    pub fn new(min: impl Into<Vec3A>, max: impl Into<Vec3A>) -> Self {
        Self { min: min.into(), max: max.into() }
    }

    pub fn from_points(points: &[Vec3]) -> Self {
        points.iter().fold(Self::EMPTY, |b, &p| b.grow(p))
    }

    /// The box of some boxes (`EMPTY` for none): what a node's bounds are, from its children's
    /// or its references' boxes.
    pub fn of(boxes: impl IntoIterator<Item = Aabb>) -> Self {
        boxes.into_iter().fold(Self::EMPTY, Self::union)
    }

    #[inline(always)]
    pub fn grow(self, p: impl Into<Vec3A>) -> Self {
        let p = p.into();
        Self { min: self.min.min(p), max: self.max.max(p) }
    }

    #[inline(always)]
    pub fn union(self, o: Aabb) -> Self {
        Self { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    /// The part of both boxes; `EMPTY` itself where they do not meet (not a box with some `min`
    /// above its `max`), so the result can be unioned into another box and its area is 0.
    #[inline(always)]
    pub fn intersection(self, o: Aabb) -> Self {
        let i = Self { min: self.min.max(o.min), max: self.max.min(o.max) };
        if i.is_empty() {
            Self::EMPTY
        } else {
            i
        }
    }

    /// The box grown by `d` on every side.
    #[inline]
    pub fn grown(self, d: f32) -> Self {
        Self { min: self.min - Vec3A::splat(d), max: self.max + Vec3A::splat(d) }
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// Size on each axis; zero for an empty box.
    #[inline(always)]
    pub fn extent(&self) -> Vec3 {
        (self.max - self.min).max(Vec3A::ZERO).into()
    }

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
        ((self.min + self.max) * 0.5).into()
    }

    /// Surface area; 0 for `EMPTY` (so empty children add no SAH cost) and so for every empty
    /// box `union`, `of` and `intersection` make (not for one made inverted with `new`).
    #[inline(always)]
    pub fn area(&self) -> f32 {
        let e = (self.max - self.min).max(Vec3A::ZERO);
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

    /// The lower and upper planes as arrays (how nodes store them).
    #[inline(always)]
    pub fn planes(&self) -> ([f32; 3], [f32; 3]) {
        (self.min.to_array(), self.max.to_array())
    }

    /// Entry and exit parameters `(t_enter, t_exit)` of the ray within `[ray.t_min, ray.t_max]`,
    /// or `None` when the ray misses the box in that interval. Boundaries count as inside, and
    /// the exit is loosened to cover rounding (`slab`).
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray) -> Option<(f32, f32)> {
        let (lo, hi) = self.planes();
        let (t0, t1) = super::slab::box_once(&lo, &hi, ray);
        (t0 <= t1).then_some((t0, t1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> Aabb {
        Aabb::new(Vec3::ZERO, Vec3::ONE)
    }

    /// The interval `got` is `(t0, t1)` as `slab.rs` loosens it: the exit raised by no more than
    /// `SLACK` of its magnitude, never lowered.
    fn interval(got: Option<(f32, f32)>, t0: f32, t1: f32) -> bool {
        use super::super::slab::SLACK;
        got.is_some_and(|(a, b)| a == t0 && b >= t1 && b <= t1 + t1.abs() * SLACK)
    }

    #[test]
    fn axis_parallel_ray_hits_with_exact_interval() {
        let r = Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::X);
        assert!(interval(unit().intersect(&r), 1.0, 2.0));
        let r = Ray::new(Vec3::new(2.0, 0.5, 0.5), -Vec3::X);
        assert!(interval(unit().intersect(&r), 1.0, 2.0));
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
        assert!(interval(unit().intersect(&r), 0.0, 0.5));
    }

    #[test]
    fn origin_on_face_with_zero_component_lying_in_the_face_hits() {
        // The ray runs inside the plane y = 0 (a face of the box): 0 * inf = NaN must not reject it.
        for (y, dy) in [(0.0f32, 0.0f32), (0.0, -0.0), (1.0, 0.0), (1.0, -0.0)] {
            let r = Ray::new(Vec3::new(-1.0, y, 0.5), Vec3::new(1.0, dy, 0.0));
            assert!(interval(unit().intersect(&r), 1.0, 2.0), "y = {y}, dy = {dy:?}");
        }
    }

    #[test]
    fn origin_on_face_leaving_and_entering() {
        // On the face x = 0, heading out: touches only at t = 0.
        let r = Ray::new(Vec3::new(0.0, 0.5, 0.5), -Vec3::X);
        assert_eq!(unit().intersect(&r), Some((0.0, 0.0)));
        // On the face x = 0, heading in.
        let r = Ray::new(Vec3::new(0.0, 0.5, 0.5), Vec3::X);
        assert!(interval(unit().intersect(&r), 0.0, 1.0));
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
        assert!(interval(unit().intersect(&r), 1.5, 2.0));
    }

    #[test]
    fn box_behind_origin_misses() {
        let r = Ray::new(Vec3::new(2.0, 0.5, 0.5), Vec3::X);
        assert_eq!(unit().intersect(&r), None);
    }

    #[test]
    fn boxes_that_do_not_meet_intersect_in_the_empty_box() {
        let far = Aabb::new(Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 1.0, 1.0));
        assert_eq!(unit().intersection(far), Aabb::EMPTY);
        assert_eq!(unit().intersection(far).area(), 0.0);
        let half = Aabb::new(Vec3::splat(0.5), Vec3::splat(2.0));
        assert_eq!(unit().intersection(half), Aabb::new(Vec3::splat(0.5), Vec3::ONE));
        assert_eq!(Aabb::of([unit(), far]), Aabb::new(Vec3::ZERO, Vec3::new(3.0, 1.0, 1.0)));
        assert_eq!(Aabb::of([]), Aabb::EMPTY);
    }

    #[test]
    fn empty_box_never_hits() {
        let r = Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::X);
        assert_eq!(Aabb::EMPTY.intersect(&r), None);
        assert_eq!(Aabb::EMPTY.area(), 0.0);
    }
}
