//! One ray against an 8-wide node's eight boxes with AVX-512VL: the AVX2 kernel's arithmetic
//! (`geometry::slab8`: a subtraction and a product per plane, `vmaxps`/`vminps` keeping the running
//! value on NaN, Ize's enlarged far reciprocal), with two differences that change no result. The
//! compare writes a mask register, already restricted to the node's valid slots, so no `movemask`
//! and `and` follow it. And the near and far planes are not chosen per node by a branch on the
//! direction's sign but read at offsets fixed once per ray (where Embree's BVH8 kernel reads them
//! too, Wald et al., "Embree: A Kernel Framework for Efficient CPU Ray Tracing", SIGGRAPH 2014):
//! for rays in random directions those three branches mispredict at every ray's first nodes.

use crate::geometry::avx512::lanes::Avx512;
use crate::geometry::ray::Ray;
use crate::geometry::slab::{SlabKernel, SLACK};
use crate::geometry::slab8::Boxes8;
use std::arch::x86_64::*;

/// One ray splat over eight lanes, with the float offsets in a `Boxes8` of its near and far plane
/// of each axis (`min[axis]` or `max[axis]` by the sign of the reciprocal direction).
#[derive(Clone, Copy, Debug)]
pub struct RayX8Masked {
    org: [__m256; 3],
    inv: [__m256; 3],
    inv_far: [__m256; 3],
    near: [usize; 3],
    far: [usize; 3],
}

/// Where `min[axis]` and `max[axis]` start in a `Boxes8` (`repr(C)`: `min`, then `max`), in floats.
const fn offset(max: bool, axis: usize) -> usize {
    (max as usize) * 24 + axis * 8
}
const _: () = assert!(std::mem::size_of::<Boxes8>() == 48 * 4);

impl SlabKernel<8> for Avx512 {
    type Ray = RayX8Masked;

    #[inline(always)]
    fn prepare(self, ray: &Ray) -> RayX8Masked {
        // SAFETY: `self` exists only if the CPU has AVX-512F/VL (`Avx512::detect`).
        unsafe { prepare(ray) }
    }

    #[inline(always)]
    fn test(self, r: &RayX8Masked, boxes: &Boxes8, valid: u32, t_min: f32, t_max: f32) -> ([f32; 8], u32) {
        // SAFETY: `self` exists only if the CPU has AVX-512F/VL.
        unsafe { eight_boxes(r, boxes, valid, t_min, t_max) }
    }
}

/// The ray splat and its planes' offsets, compiled for AVX-512 (see `eight_boxes`).
///
/// # Safety
/// The CPU has AVX-512F/VL.
#[inline]
#[target_feature(enable = "avx512f,avx512vl")]
unsafe fn prepare(ray: &Ray) -> RayX8Masked {
    let (o, i) = (ray.origin(), ray.inv_dir());
    let f = i * (1.0 + SLACK);
    let s = |x: f32| _mm256_set1_ps(x);
    // `is_sign_negative`, as the scalar test: -0 gives -inf, whose near plane is the max.
    let neg = [i.x.is_sign_negative(), i.y.is_sign_negative(), i.z.is_sign_negative()];
    RayX8Masked {
        org: [s(o.x), s(o.y), s(o.z)],
        inv: [s(i.x), s(i.y), s(i.z)],
        inv_far: [s(f.x), s(f.y), s(f.z)],
        near: [offset(neg[0], 0), offset(neg[1], 1), offset(neg[2], 2)],
        far: [offset(!neg[0], 0), offset(!neg[1], 1), offset(!neg[2], 2)],
    }
}

/// The test itself, compiled for AVX-512 (a trait method cannot carry the features; see `Lanes`).
///
/// # Safety
/// The CPU has AVX-512F/VL.
#[inline]
#[target_feature(enable = "avx512f,avx512vl")]
unsafe fn eight_boxes(r: &RayX8Masked, boxes: &Boxes8, valid: u32, t_min: f32, t_max: f32) -> ([f32; 8], u32) {
    let planes = (boxes as *const Boxes8).cast::<f32>();
    let mut enter = _mm256_set1_ps(t_min);
    let mut exit = _mm256_set1_ps(t_max);
    for axis in 0..3 {
        // SAFETY: every offset is that of one of the six arrays of eight floats of `boxes`
        // (`offset`, checked against its size above).
        let (near, far) = unsafe { (planes.add(r.near[axis]), planes.add(r.far[axis])) };
        let (near, far) = (_mm256_loadu_ps(near), _mm256_loadu_ps(far));
        let t0 = _mm256_mul_ps(_mm256_sub_ps(near, r.org[axis]), r.inv[axis]);
        let t1 = _mm256_mul_ps(_mm256_sub_ps(far, r.org[axis]), r.inv_far[axis]);
        // The second operand survives a NaN: `max_keep`'s rule.
        enter = _mm256_max_ps(t0, enter);
        exit = _mm256_min_ps(t1, exit);
    }
    let mask = _mm256_mask_cmp_ps_mask::<_CMP_LE_OQ>(valid as __mmask8, enter, exit) as u32;
    let mut out = [0.0f32; 8];
    _mm256_storeu_ps(out.as_mut_ptr(), enter);
    (out, mask)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::slab::Scalar;
    use glam::Vec3;
    use proptest::prelude::*;

    fn boxes(corners: &[(Vec3, Vec3)]) -> Boxes8 {
        let mut b = Boxes8::EMPTY;
        for (k, &(lo, hi)) in corners.iter().enumerate() {
            b.set(k, lo.min(hi).to_array(), lo.max(hi).to_array());
        }
        b
    }

    /// Halves on a small grid: origins on box planes with zero direction components (the NaN
    /// case), rays through box corners and edges, and both signs of zero come up often.
    fn coord() -> impl Strategy<Value = f32> {
        prop_oneof![(-8i32..8).prop_map(|v| v as f32 * 0.5), Just(-0.0f32)]
    }
    fn point() -> impl Strategy<Value = Vec3> {
        (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]
        /// The AVX-512 kernel returns the scalar kernel's entries and mask bit for bit.
        #[test]
        fn avx512_eight_boxes_are_the_scalar_kernel(
            corners in proptest::collection::vec((point(), point()), 1..=8),
            origin in point(),
            dir in point(),
            t_min in prop_oneof![Just(0.0f32), Just(f32::NEG_INFINITY), -2.0f32..2.0],
            t_max in prop_oneof![Just(f32::INFINITY), 0.0f32..20.0],
            valid_bits in 0u32..256,
        ) {
            let Some(k) = Avx512::detect() else { return Ok(()) };
            let b = boxes(&corners);
            let valid = valid_bits & ((1u32 << corners.len()) - 1);
            let ray = Ray::new(origin, dir);
            let want = Scalar.test(&SlabKernel::<8>::prepare(Scalar, &ray), &b, valid, t_min, t_max);
            let got = k.test(&k.prepare(&ray), &b, valid, t_min, t_max);
            prop_assert_eq!(got.1, want.1, "masks of {:?}", ray);
            for s in 0..8 {
                if want.1 & (1 << s) != 0 {
                    prop_assert_eq!(got.0[s].to_bits(), want.0[s].to_bits(), "entry of slot {}", s);
                }
            }
        }
    }

    /// Rays aimed exactly at a box's corner from far away touch it at one point: hit in this
    /// kernel too (the enlarged far reciprocal), as in every other.
    #[test]
    fn rays_aimed_at_box_corners_from_afar_hit() {
        let Some(k) = Avx512::detect() else { return };
        let mut rng = crate::random::Rng::new(0x051a_b512);
        let mut rand = move || rng.unit();
        for _ in 0..20_000 {
            let lo = Vec3::new(rand(), rand(), rand()) * 10.0 - 5.0;
            let hi = lo + Vec3::new(rand(), rand(), rand()) * 3.0 + 0.01;
            let pick = |c: bool, a: f32, b: f32| if c { a } else { b };
            let corner = Vec3::new(
                pick(rand() < 0.5, lo.x, hi.x),
                pick(rand() < 0.5, lo.y, hi.y),
                pick(rand() < 0.5, lo.z, hi.z),
            );
            let from =
                corner + (Vec3::new(rand(), rand(), rand()) - 0.5).normalize_or(Vec3::X) * (100.0 + 900.0 * rand());
            let ray = Ray::new(from, corner - from);
            let b = boxes(&[(lo, hi)]);
            assert_eq!(k.test(&k.prepare(&ray), &b, 1, ray.t_min, ray.t_max).1, 1, "{ray:?} at {corner}");
        }
    }
}
