//! The stored form's test: the same hits as the classic Möller–Trumbore away from edges, the hit
//! point its barycentrics name, and every SIMD pass bit for bit the scalar test.

use super::*;
use crate::geometry::triangle::MollerTrumbore;
use proptest::prelude::*;

/// Grid points: shared vertices and edges, axis-parallel rays and exactly-zero terms come up often.
fn point() -> impl Strategy<Value = Vec3> {
    [(-4i32..=4), (-4i32..=4), (-4i32..=4)].prop_map(|v| Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32) * 0.5)
}

/// A leaf of up to nineteen triangles (often sharing vertices, some degenerate), a ray aimed at a
/// vertex, an edge point or an inner point of one of them, an interval that may cut the hits, and
/// whether more floats follow the leaf (else the array ends with it: the masked loads).
fn leaf_case() -> impl Strategy<Value = (Vec<[Vec3; 3]>, Ray, bool)> {
    let pool = proptest::collection::vec(point(), 6);
    let picks = proptest::collection::vec([0usize..6, 0usize..6, 0usize..6], 1..=19);
    let aim = (0usize..19, 0u32..3, 0u32..3, 0u32..3, [-3i32..=3, -3i32..=3, -3i32..=3], 1u32..4, 0u32..4);
    (pool, picks, aim, proptest::bool::ANY).prop_map(|(pool, picks, (target, i, j, k, d, s, interval), more)| {
        let tris: Vec<[Vec3; 3]> = picks.iter().map(|p| p.map(|q| pool[q])).collect();
        let t = &tris[target % tris.len()];
        let w = (i + j + k).max(1) as f32;
        let at = (t[0] * i as f32 + t[1] * j as f32 + t[2] * k as f32) / w;
        let dir = Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
        let mut ray = Ray::new(at - dir * s as f32, dir);
        match interval {
            0 => ray.t_max = s as f32, // a hit exactly at t_max is excluded
            1 => ray.t_min = s as f32 + 0.25,
            _ => {}
        }
        (tris, ray, more)
    })
}

/// A leaf's stored form, coordinate by coordinate, as `WideBvh::stored_leaves` keeps it.
fn stored_leaf(tris: &[[Vec3; 3]]) -> Vec<f32> {
    let forms: Vec<[Vec3; 4]> = tris.iter().map(stored_form).collect();
    (0..STORED_FLOATS).flat_map(|j| forms.iter().map(move |f| f[j / 3][j % 3])).collect()
}

fn bits(h: &TriangleHit) -> (u32, u32, u32) {
    (h.t.to_bits(), h.u.to_bits(), h.v.to_bits())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]
    /// Every pass over a stored leaf, four lanes, eight or sixteen (where the CPU has them), is the scalar test of its triangles
    /// (`MollerTrumboreStored::intersect`, from the vertices), bit for bit.
    #[test]
    fn stored_passes_are_the_scalar_test((tris, ray, more) in leaf_case()) {
        let count = tris.len();
        let mut stored = stored_leaf(&tris);
        if more {
            stored.extend([7.0, -3.5, 1e9, f32::NAN, 0.0, -0.0, 1e-30, 2.0]);
        }
        let want: Vec<Option<TriangleHit>> = tris.iter().map(|t| MollerTrumboreStored::intersect(&(), &ray, t)).collect();
        for g in 0..count.div_ceil(4) {
            let got = stored_group4(&ray, &stored, count, g);
            let n = (count - 4 * g).min(4);
            prop_assert_eq!(got.mask >> n, 0, "no lane past the leaf");
            for lane in 0..n {
                let w = want[4 * g + lane];
                prop_assert_eq!(got.mask & (1 << lane) != 0, w.is_some(), "four lanes: pass {} lane {}", g, lane);
                if let Some(h) = w {
                    let lane_hit = TriangleHit { t: got.t[lane], u: got.u[lane], v: got.v[lane] };
                    prop_assert_eq!(bits(&lane_hit), bits(&h), "four lanes: pass {} lane {} bit for bit", g, lane);
                }
            }
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(k) = Avx2::detect() {
            for g in 0..count.div_ceil(8) {
                // SAFETY: `detect` found AVX2.
                let got = unsafe { stored_leaf8(k, &ray, &stored, count, g) };
                let n = (count - 8 * g).min(8);
                prop_assert_eq!(got.mask >> n, 0, "no lane past the leaf");
                for lane in 0..n {
                    let w = want[8 * g + lane];
                    prop_assert_eq!(got.mask & (1 << lane) != 0, w.is_some(), "eight lanes: pass {} lane {}", g, lane);
                    if let Some(h) = w {
                        let lane_hit = TriangleHit { t: got.t[lane], u: got.u[lane], v: got.v[lane] };
                        prop_assert_eq!(bits(&lane_hit), bits(&h), "eight lanes: pass {} lane {} bit for bit", g, lane);
                    }
                }
            }
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(k) = crate::geometry::avx512::Avx512::detect() {
            for g in 0..count.div_ceil(16) {
                // SAFETY: `detect` found AVX-512F/VL.
                let got = unsafe { crate::geometry::avx512::stored_leaf16(k, &ray, &stored, count, g) };
                let n = (count - 16 * g).min(16);
                prop_assert_eq!(got.mask >> n, 0, "no lane past the leaf");
                for lane in 0..n {
                    let w = want[16 * g + lane];
                    prop_assert_eq!(got.mask & (1 << lane) != 0, w.is_some(), "sixteen lanes: pass {} lane {}", g, lane);
                    if let Some(h) = w {
                        let lane_hit = TriangleHit { t: got.t[lane], u: got.u[lane], v: got.v[lane] };
                        prop_assert_eq!(bits(&lane_hit), bits(&h), "sixteen lanes: pass {} lane {} bit for bit", g, lane);
                    }
                }
            }
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
