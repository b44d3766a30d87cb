//! The stored form's test: the same hits as the classic Möller–Trumbore away from edges, the hit
//! point its barycentrics name, and every SIMD pass bit for bit the scalar test.

use super::*;
use crate::geometry::leaf_cases::leaf_case;
use crate::geometry::triangle::MollerTrumbore;
use proptest::prelude::*;

/// A leaf's stored form, coordinate by coordinate, as `WideBvh::stored_leaves` keeps it.
fn stored_leaf(tris: &[[Vec3; 3]]) -> Vec<f32> {
    let forms: Vec<[Vec3; 4]> = tris.iter().map(stored_form).collect();
    (0..STORED_FLOATS).flat_map(|j| forms.iter().map(move |f| f[j / 3][j % 3])).collect()
}

fn bits(h: &TriangleHit) -> (u32, u32, u32) {
    (h.t.to_bits(), h.u.to_bits(), h.v.to_bits())
}

/// Pass `g` of `width` lanes over a leaf (its mask and each lane's t, u, v) against the scalar
/// test's hits `want`, bit for bit, for every pass of the leaf; `name` says which passes failed.
fn check_passes(
    want: &[Option<TriangleHit>],
    width: usize,
    name: &str,
    pass: impl Fn(usize) -> (u32, Vec<f32>, Vec<f32>, Vec<f32>),
) -> Result<(), TestCaseError> {
    for g in 0..want.len().div_ceil(width) {
        let (mask, t, u, v) = pass(g);
        let n = (want.len() - width * g).min(width);
        prop_assert_eq!(mask >> n, 0, "{} lanes: no lane past the leaf", name);
        for lane in 0..n {
            let w = want[width * g + lane];
            prop_assert_eq!(mask & (1 << lane) != 0, w.is_some(), "{} lanes: pass {} lane {}", name, g, lane);
            if let Some(h) = w {
                let lane_hit = TriangleHit { t: t[lane], u: u[lane], v: v[lane] };
                prop_assert_eq!(bits(&lane_hit), bits(&h), "{} lanes: pass {} lane {} bit for bit", name, g, lane);
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]
    /// Every pass over a stored leaf, four lanes, eight or sixteen (where the CPU has them), is the scalar test of its triangles
    /// (`MollerTrumboreStored::intersect`, from the vertices), bit for bit.
    #[test]
    fn stored_passes_are_the_scalar_test((tris, ray, more) in leaf_case(19)) {
        let count = tris.len();
        let mut stored = stored_leaf(&tris);
        if more {
            stored.extend([7.0, -3.5, 1e9, f32::NAN, 0.0, -0.0, 1e-30, 2.0]);
        }
        let want: Vec<Option<TriangleHit>> = tris.iter().map(|t| MollerTrumboreStored::intersect(&(), &ray, t)).collect();
        let lanes = |got_mask: u32, t: &[f32], u: &[f32], v: &[f32]| (got_mask, t.to_vec(), u.to_vec(), v.to_vec());
        check_passes(&want, 4, "four", |g| {
            let got = stored_group4(&ray, &stored, count, g);
            lanes(got.mask, &got.t, &got.u, &got.v)
        })?;
        #[cfg(target_arch = "x86_64")]
        if let Some(k) = Avx2::detect() {
            check_passes(&want, 8, "eight", |g| {
                // SAFETY: `detect` found AVX2.
                let got = unsafe { stored_leaf8(k, &ray, &stored, count, g) };
                lanes(got.mask, &got.t, &got.u, &got.v)
            })?;
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(k) = crate::geometry::avx512::Avx512::detect() {
            check_passes(&want, 16, "sixteen", |g| {
                // SAFETY: `detect` found AVX-512F/VL.
                let got = unsafe { crate::geometry::avx512::stored_leaf16(k, &ray, &stored, count, g) };
                lanes(got.mask, &got.t, &got.u, &got.v)
            })?;
        }
    }

    /// Away from edges and grazing angles the stored form finds what the classic test finds, at
    /// the same place, and its barycentrics name the hit point (u weighs v1, v weighs v2).
    #[test]
    fn stored_form_finds_the_classic_hits(
        v in proptest::collection::vec(-10.0f32..10.0, 9),
        o in proptest::collection::vec(-20.0f32..20.0, 3),
        bary in (0.0f32..1.0, 0.0f32..1.0),
    ) {
        let tri = [Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]), Vec3::new(v[6], v[7], v[8])];
        let (mut a, mut b) = bary;
        if a + b > 1.0 {
            (a, b) = (1.0 - a, 1.0 - b);
        }
        let target = tri[0] * (1.0 - a - b) + tri[1] * a + tri[2] * b;
        let origin = Vec3::new(o[0], o[1], o[2]);
        let ray = Ray::new(origin, target - origin);
        let normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
        let grazing = normal.normalize_or_zero().dot((target - origin).normalize_or_zero()).abs() < 0.05;
        let near_edge = a < 1e-3 || b < 1e-3 || a + b > 1.0 - 1e-3;
        prop_assume!(!grazing && !near_edge && normal.length() > 1e-2 && (target - origin).length() > 1e-2);
        let stored = MollerTrumboreStored::intersect(&(), &ray, &tri);
        let classic = MollerTrumbore::intersect(&(), &ray, &tri);
        prop_assert_eq!(stored.is_some(), classic.is_some());
        let (s, c) = (stored.unwrap(), classic.unwrap());
        prop_assert!((s.t - c.t).abs() <= 1e-3 * c.t.abs().max(1.0), "t {} against {}", s.t, c.t);
        prop_assert!((s.u - c.u).abs() <= 1e-3 && (s.v - c.v).abs() <= 1e-3, "barycentrics {:?} against {:?}", s, c);
        let at = tri[0] * (1.0 - s.u - s.v) + tri[1] * s.u + tri[2] * s.v;
        prop_assert!((at - ray.at(s.t)).length() <= 1e-3 * (1.0 + at.length()), "{} is not the hit point {}", at, ray.at(s.t));
    }
}

/// A degenerate triangle (its normal zero) and a ray in the triangle's plane hit nothing; a hit
/// exactly at `t_max` is excluded and one at `t_min` kept, as the other tests do.
#[test]
fn degenerate_parallel_and_interval_ends() {
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let line = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
    let down = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
    assert_eq!(MollerTrumboreStored::intersect(&(), &down, &line), None);
    assert_eq!(MollerTrumboreStored::intersect(&(), &Ray::new(Vec3::new(-1.0, 0.25, 0.0), Vec3::X), &tri), None);
    let hit = MollerTrumboreStored::intersect(&(), &down, &tri).expect("straight down through the inside");
    assert_eq!((hit.t, hit.u, hit.v), (1.0, 0.25, 0.25));
    let mut to_it = down;
    to_it.t_max = 1.0;
    assert_eq!(MollerTrumboreStored::intersect(&(), &to_it, &tri), None, "t_max is excluded");
    let mut from_it = down;
    from_it.t_min = 1.0;
    assert!(MollerTrumboreStored::intersect(&(), &from_it, &tri).is_some(), "t_min is included");
    let up = Ray::new(Vec3::new(0.25, 0.25, -1.0), Vec3::Z);
    assert!(MollerTrumboreStored::intersect(&(), &up, &tri).is_some(), "both faces are hit");
}
