//! One ray against the eight child boxes of an 8-wide node: with AVX2, one pass of eight lanes
//! (`Avx2`, only where the CPU has it: `crate::cpu` decides at run time); elsewhere two passes of
//! four (`Simd4`) or one box at a time (`Scalar`, in `slab.rs`). The arithmetic is that of
//! `slab.rs` lane for lane (Williams et al.'s sign-selected planes, Ize's enlarged far
//! reciprocal), so every kernel returns the same entries and masks bit for bit. Nothing is fused:
//! an FMA would round `(plane − origin)·inv` once instead of twice and break that equality.

use super::slab::{Boxes, RayX4, Simd4, SlabKernel};
use crate::geometry::ray::Ray;

/// Eight boxes: an 8-wide node's children.
pub type Boxes8 = Boxes<8>;

impl SlabKernel<8> for Simd4 {
    type Ray = RayX4;
    #[inline(always)]
    fn prepare(self, ray: &Ray) -> RayX4 {
        RayX4::new(ray)
    }
    #[inline(always)]
    fn test(self, ray: &RayX4, boxes: &Boxes8, valid: u32, t_min: f32, t_max: f32) -> ([f32; 8], u32) {
        let half = |k: usize| {
            let part = |planes: &[[f32; 8]; 3]| planes.map(|p| [p[4 * k], p[4 * k + 1], p[4 * k + 2], p[4 * k + 3]]);
            ray.lanes(&part(&boxes.min), &part(&boxes.max), t_min, t_max)
        };
        let ((e0, x0), (e1, x1)) = (half(0), half(1));
        let mask = e0.simd_le(x0).to_bitmask() | e1.simd_le(x1).to_bitmask() << 4;
        let (a, b) = (e0.to_array(), e1.to_array());
        ([a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]], mask & valid)
    }
}

#[cfg(target_arch = "x86_64")]
pub use avx2::{Avx2, RayX8};

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{Boxes8, Ray};
    use crate::geometry::slab::SlabKernel;
    use std::arch::x86_64::*;

    /// Proof that this CPU has AVX2 and FMA, and the bit instructions every such CPU has (POPCNT,
    /// BMI1/2, LZCNT): made only by `detect`, so a kernel holding it may use their instructions. The walk that uses it is compiled for them (`#[target_feature]`)
    /// and chosen at run time; nobody needs `-C target-cpu`.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx2(());

    impl Avx2 {
        /// The proof, if this CPU has the features (asked once; each call after that is one load).
        #[inline]
        pub fn detect() -> Option<Avx2> {
            static HAS: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
            HAS.get_or_init(Self::ask).then_some(Avx2(()))
        }

        fn ask() -> bool {
            is_x86_feature_detected!("avx")
                && is_x86_feature_detected!("avx2")
                && is_x86_feature_detected!("fma")
                && is_x86_feature_detected!("popcnt")
                && is_x86_feature_detected!("bmi1")
                && is_x86_feature_detected!("bmi2")
                && is_x86_feature_detected!("lzcnt")
        }
    }

    /// One ray splat over eight lanes.
    #[derive(Clone, Copy, Debug)]
    pub struct RayX8 {
        org: [__m256; 3],
        inv: [__m256; 3],
        inv_far: [__m256; 3],
        neg: [bool; 3],
    }

    impl SlabKernel<8> for Avx2 {
        type Ray = RayX8;

        #[inline(always)]
        fn prepare(self, ray: &Ray) -> RayX8 {
            let (o, i) = (ray.origin(), ray.inv_dir());
            let f = i * (1.0 + super::super::slab::SLACK);
            // SAFETY: `self` exists only if the CPU has AVX2 (`Avx2::detect`).
            let s = |x: f32| unsafe { _mm256_set1_ps(x) };
            RayX8 {
                org: [s(o.x), s(o.y), s(o.z)],
                inv: [s(i.x), s(i.y), s(i.z)],
                inv_far: [s(f.x), s(f.y), s(f.z)],
                neg: [i.x.is_sign_negative(), i.y.is_sign_negative(), i.z.is_sign_negative()],
            }
        }

        #[inline(always)]
        fn test(self, r: &RayX8, boxes: &Boxes8, valid: u32, t_min: f32, t_max: f32) -> ([f32; 8], u32) {
            // SAFETY: `self` exists only if the CPU has AVX2; the loads read the node's own arrays
            // of eight floats.
            unsafe {
                let mut enter = _mm256_set1_ps(t_min);
                let mut exit = _mm256_set1_ps(t_max);
                for axis in 0..3 {
                    let (near, far) = if r.neg[axis] {
                        (&boxes.max[axis], &boxes.min[axis])
                    } else {
                        (&boxes.min[axis], &boxes.max[axis])
                    };
                    let t0 = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(near.as_ptr()), r.org[axis]), r.inv[axis]);
                    let t1 = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(far.as_ptr()), r.org[axis]), r.inv_far[axis]);
                    // maxps/minps return their second operand when one is NaN: the running value
                    // survives a ray lying in a plane, as `max_keep` says.
                    enter = _mm256_max_ps(t0, enter);
                    exit = _mm256_min_ps(t1, exit);
                }
                let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit)) as u32;
                let mut out = [0.0f32; 8];
                _mm256_storeu_ps(out.as_mut_ptr(), enter);
                (out, mask & valid)
            }
        }
    }
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

    /// Small integers and halves: rays through box corners, along faces and axis-parallel ones
    /// (direction components of exactly zero) come up often.
    fn coord() -> impl Strategy<Value = f32> {
        (-8i32..8).prop_map(|v| v as f32 * 0.5)
    }
    fn point() -> impl Strategy<Value = Vec3> {
        (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    proptest! {
        /// Every kernel returns the scalar kernel's entries and mask bit for bit.
        #[test]
        fn eight_box_kernels_agree_with_the_scalar_one(
            corners in proptest::collection::vec((point(), point()), 1..=8),
            origin in point(),
            dir in point(),
            t_max in prop_oneof![Just(f32::INFINITY), 0.0f32..20.0],
        ) {
            let b = boxes(&corners);
            let valid = (1u32 << corners.len()) - 1;
            let mut ray = Ray::new(origin, dir);
            ray.t_max = t_max;
            let want = Scalar.test(&SlabKernel::<8>::prepare(Scalar, &ray), &b, valid, ray.t_min, t_max);
            let simd4 = Simd4.test(&SlabKernel::<8>::prepare(Simd4, &ray), &b, valid, ray.t_min, t_max);
            let same = |a: &([f32; 8], u32), b: &([f32; 8], u32)| {
                a.1 == b.1 && (0..8).all(|k| a.1 & (1 << k) == 0 || a.0[k].to_bits() == b.0[k].to_bits())
            };
            prop_assert!(same(&want, &simd4), "Simd4 {simd4:?} vs scalar {want:?}");
            #[cfg(target_arch = "x86_64")]
            if let Some(k) = Avx2::detect() {
                let avx = k.test(&k.prepare(&ray), &b, valid, ray.t_min, t_max);
                prop_assert!(same(&want, &avx), "AVX2 {avx:?} vs scalar {want:?}");
            }
        }
    }

    /// A ray aimed exactly at a box's corner from far away touches the box at one point, where
    /// rounding can put the entry above the exit: every kernel must still report it (the enlarged
    /// far reciprocal, `slab.rs`). Without it this fails for some of these rays.
    #[test]
    fn rays_aimed_at_box_corners_from_afar_hit_in_every_kernel() {
        let mut rng = crate::random::Rng::new(0x2545_f491);
        let mut rand = move || rng.unit();
        for _ in 0..20_000 {
            let lo = Vec3::new(rand(), rand(), rand()) * 10.0 - 5.0;
            let hi = lo + Vec3::new(rand(), rand(), rand()) * 3.0 + 0.01;
            let corner = Vec3::new(
                if rand() < 0.5 { lo.x } else { hi.x },
                if rand() < 0.5 { lo.y } else { hi.y },
                if rand() < 0.5 { lo.z } else { hi.z },
            );
            let from =
                corner + (Vec3::new(rand(), rand(), rand()) - 0.5).normalize_or(Vec3::X) * (100.0 + 900.0 * rand());
            let ray = Ray::new(from, corner - from);
            let b = boxes(&[(lo, hi)]);
            let (_, scalar) = Scalar.test(&SlabKernel::<8>::prepare(Scalar, &ray), &b, 1, ray.t_min, ray.t_max);
            let (_, simd4) = Simd4.test(&SlabKernel::<8>::prepare(Simd4, &ray), &b, 1, ray.t_min, ray.t_max);
            assert_eq!((scalar, simd4), (1, 1), "{ray:?} at the corner {corner} of {lo}..{hi}");
            #[cfg(target_arch = "x86_64")]
            if let Some(k) = Avx2::detect() {
                assert_eq!(k.test(&k.prepare(&ray), &b, 1, ray.t_min, ray.t_max).1, 1, "AVX2: {ray:?}");
            }
        }
    }
}
