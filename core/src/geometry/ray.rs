//! A ray with a parametric interval `[t_min, t_max]`.
//!
//! The reciprocal direction is computed once here because every box test needs it. A ray whose
//! origin or direction is not finite, or whose direction is zero, is born *empty* (`t_max = -inf`),
//! so no box or triangle test can report a hit for it: a NaN can never turn a miss into a hit.

use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    origin: Vec3,
    dir: Vec3,
    inv_dir: Vec3,
    /// Start of the valid interval (inclusive).
    pub t_min: f32,
    /// End of the valid interval (inclusive); a closest-hit query shrinks it to the nearest hit.
    pub t_max: f32,
}

/// Where a ray's values lie in it, in floats from its start (`Vec3` is three `f32`s in order):
/// the packets' gathers read sixteen rays' values from there at once.
pub(crate) mod at {
    use super::Ray;
    pub(crate) const ORIGIN: usize = std::mem::offset_of!(Ray, origin) / 4;
    pub(crate) const INV_DIR: usize = std::mem::offset_of!(Ray, inv_dir) / 4;
    pub(crate) const T_MIN: usize = std::mem::offset_of!(Ray, t_min) / 4;
    pub(crate) const T_MAX: usize = std::mem::offset_of!(Ray, t_max) / 4;
    /// A ray's size in floats.
    pub(crate) const FLOATS: usize = std::mem::size_of::<Ray>() / 4;
    const _: () = assert!(std::mem::size_of::<Ray>().is_multiple_of(4) && std::mem::align_of::<Ray>() == 4);
}

impl Ray {
    /// A ray over `[0, +inf]`.
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self::segment(origin, dir, 0.0, f32::INFINITY)
    }

    /// A ray over `[t_min, t_max]`. Non-finite input gives an empty ray (see the module docs).
    #[inline]
    pub fn segment(origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self {
        // 1/±0 = ±inf keeps the sign of a -0 component, which the slab test relies on.
        let inv_dir = Vec3::ONE / dir;
        // Without short-circuits: one branch-free test (rays are made by the million).
        let valid = origin.is_finite() & dir.is_finite() & (dir != Vec3::ZERO) & !t_min.is_nan() & !t_max.is_nan();
        Self {
            origin,
            dir,
            inv_dir,
            t_min: if valid { t_min } else { f32::INFINITY },
            t_max: if valid { t_max } else { f32::NEG_INFINITY },
        }
    }

    #[inline(always)]
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    #[inline(always)]
    pub fn dir(&self) -> Vec3 {
        self.dir
    }

    #[inline(always)]
    pub fn inv_dir(&self) -> Vec3 {
        self.inv_dir
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }

    /// True when the interval is empty (also the case for a ray built from non-finite input).
    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.t_min <= self.t_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_or_zero_input_gives_an_empty_ray() {
        assert!(Ray::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X).is_empty());
        assert!(Ray::new(Vec3::ZERO, Vec3::new(0.0, f32::NAN, 0.0)).is_empty());
        assert!(Ray::new(Vec3::ZERO, Vec3::ZERO).is_empty());
        assert!(Ray::new(Vec3::splat(f32::INFINITY), Vec3::X).is_empty());
        assert!(Ray::segment(Vec3::ZERO, Vec3::X, 0.0, f32::NAN).is_empty());
        assert!(!Ray::new(Vec3::ZERO, Vec3::X).is_empty());
    }

    #[test]
    fn negative_zero_direction_gives_negative_infinite_reciprocal() {
        let r = Ray::new(Vec3::ZERO, Vec3::new(1.0, -0.0, 0.0));
        assert_eq!(r.inv_dir().y, f32::NEG_INFINITY);
        assert_eq!(r.inv_dir().z, f32::INFINITY);
    }
}
