//! Tests of `packet8.rs`: eight-ray groups against the four-lane groups and the scalar tests, on
//! adversarial rays (box corners, axis-parallel directions with origins on box planes, both zeros).

use super::*;
use crate::geometry::aabb::Aabb;
use crate::geometry::slab::{widen, OneRay};
use crate::geometry::slab8::Avx2;
use crate::geometry::slab_packet::RayGroup;
use crate::geometry::triangle::{TriangleIntersector, Watertight};
use proptest::prelude::*;

// The kernels are compiled for AVX2 (`#[target_feature]`): called through these wrappers.
// SAFETY (each): `k` comes from `Avx2::detect`, so the CPU has AVX2 and FMA.
fn group(k: Avx2, rays: &[Ray], base: usize) -> RayGroup8 {
    unsafe { RayGroup8::new(k, rays, base) }
}
fn hit(k: Avx2, g: &RayGroup8, lo: [f32; 3], hi: [f32; 3]) -> u32 {
    unsafe { g.hit(k, lo, hi) }
}
fn hit_planes(k: Avx2, g: &RayGroup8, near: [f32; 3], far: [f32; 3]) -> u32 {
    unsafe { g.hit_planes(k, near, far) }
}
fn interval(k: Avx2, groups: &[RayGroup8]) -> RayInterval {
    unsafe { interval8(k, groups) }
}
fn rows(k: Avx2, rays: &[Ray], base: usize) -> WatertightRay8 {
    unsafe { WatertightRay8::new(k, rays, base) }
}
fn intersect(k: Avx2, p: &WatertightRay8, g: &RayGroup8, lanes: u32, tri: &[Vec3; 3]) -> Hits8 {
    unsafe { p.intersect(k, g.t_min, g.t_max, lanes, tri) }
}

/// Halves on a small grid, and -0: origins on box planes with zero direction components (the
/// NaN case), rays through corners and edges.
fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![(-6i32..6).prop_map(|v| v as f32 * 0.5), Just(-0.0f32)]
}
fn point() -> impl Strategy<Value = Vec3> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Up to 20 rays (so a second group with padding lanes), some with their `t_max` cut short.
fn rays() -> impl Strategy<Value = Vec<Ray>> {
    proptest::collection::vec((point(), point(), prop_oneof![Just(f32::INFINITY), 0.0f32..8.0]), 1..=20).prop_map(|v| {
        v.into_iter()
            .map(|(o, d, t)| {
                let mut r = Ray::new(o, d);
                r.t_max = r.t_max.min(t);
                r
            })
            .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]
    /// The box test of a group of eight is two groups of four's, lane for lane (padding lanes
    /// included), and for every real ray the scalar test's verdict; with the planes chosen once
    /// (`hit_planes`) where every ray shares the signs, the same.
    #[test]
    fn eight_rays_against_a_box_are_the_scalar_tests(rays in rays(), a in point(), b in point()) {
        let Some(k) = Avx2::detect() else { return Ok(()) };
        let (lo, hi) = (a.min(b).to_array(), a.max(b).to_array());
        for base in (0..rays.len()).step_by(8) {
            let g = group(k, &rays, base);
            let got = hit(k, &g, lo, hi);
            let four = (0..2).fold(0, |m, q| m | RayGroup::new(&rays, base + 4 * q).hit(lo, hi) << (4 * q));
            prop_assert_eq!(got, four, "eight lanes against two groups of four");
            for lane in 0..(rays.len() - base).min(8) {
                let r = &rays[base + lane];
                let (t0, t1) = OneRay::new(r).one_box(&lo, &hi, r.t_min, widen(r.t_max));
                prop_assert_eq!(got >> lane & 1 == 1, t0 <= t1, "lane {} of {:?}", lane, r);
            }
            let neg = |axis: usize| rays[base].inv_dir()[axis] < 0.0;
            let shared = rays[base..].iter().take(8).all(|r| (0..3).all(|a| (r.inv_dir()[a] < 0.0) == neg(a)));
            if shared {
                let pick = |axis: usize, near: bool| if neg(axis) == near { hi[axis] } else { lo[axis] };
                let near = [pick(0, true), pick(1, true), pick(2, true)];
                let far = [pick(0, false), pick(1, false), pick(2, false)];
                prop_assert_eq!(hit_planes(k, &g, near, far), got, "planes chosen once");
            }
        }
    }

    /// The frustum of eight-ray groups is the four-lane one, field for field.
    #[test]
    fn the_frustum_of_eight_ray_groups_is_the_four_lane_one(rays in rays()) {
        let Some(k) = Avx2::detect() else { return Ok(()) };
        let g8: Vec<RayGroup8> = (0..rays.len()).step_by(8).map(|b| group(k, &rays, b)).collect();
        let g4: Vec<RayGroup> = (0..rays.len()).step_by(4).map(|b| RayGroup::new(&rays, b)).collect();
        prop_assert_eq!(interval(k, &g8), RayInterval::new(&g4));
    }
}

/// Triangles on a small grid and eight rays aimed at their vertices, edges and inner points (the
/// watertight test's exactly-zero edge functions), or anywhere, some with short intervals.
fn triangle_case() -> impl Strategy<Value = ([Vec3; 3], Vec<Ray>)> {
    let grid = || [(-4i32..=4), (-4i32..=4), (-4i32..=4)].prop_map(|v| Vec3::from_array(v.map(|x| x as f32 * 0.5)));
    let aim = (0u32..3, 0u32..3, 0u32..3, [-3i32..=3, -3i32..=3, -3i32..=3], 1u32..4, 0u32..4);
    ([grid(), grid(), grid()], proptest::collection::vec(aim, 1..=8)).prop_map(|(tri, aims)| {
        let rays = aims
            .into_iter()
            .map(|(i, j, k, d, s, interval)| {
                let w = (i + j + k).max(1) as f32;
                let at = (tri[0] * i as f32 + tri[1] * j as f32 + tri[2] * k as f32) / w;
                let dir = Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
                let mut ray = Ray::new(at - dir * s as f32, dir);
                match interval {
                    0 => ray.t_max = s as f32,
                    1 => ray.t_min = s as f32 + 0.25,
                    _ => {}
                }
                ray
            })
            .collect();
        (tri, rays)
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]
    /// Lane k of the eight-ray triangle test is `Watertight::intersect` of ray k, bit for bit,
    /// and no lane outside `lanes` is reported.
    #[test]
    fn eight_rays_against_a_triangle_are_the_scalar_tests((tri, rays) in triangle_case(), drop in 0u32..8) {
        let Some(k) = Avx2::detect() else { return Ok(()) };
        let p = rows(k, &rays, 0);
        let g = group(k, &rays, 0);
        let lanes = ((1u32 << rays.len()) - 1) & !(1 << drop);
        let got = intersect(k, &p, &g, lanes, &tri);
        prop_assert_eq!(got.mask & !lanes, 0, "only the lanes asked for");
        for (lane, ray) in rays.iter().enumerate().filter(|&(l, _)| lanes >> l & 1 == 1) {
            let want = Watertight::intersect(&Watertight::prepare(ray), ray, &tri);
            prop_assert_eq!(got.mask >> lane & 1 == 1, want.is_some(), "lane {}: {:?}", lane, ray);
            if let Some(h) = want {
                let bits = |x: f32| x.to_bits();
                prop_assert_eq!((bits(got.t[lane]), bits(got.u[lane]), bits(got.v[lane])), (bits(h.t), bits(h.u), bits(h.v)));
            }
        }
    }
}

/// Rays lying in a box's face planes (origin on the plane, zero direction component: 0·inf =
/// NaN): every lane keeps its interval (the NaN rule) and hits, as the scalar test does.
#[test]
fn rays_lying_in_box_planes_hit_as_the_scalar_test_says() {
    let Some(k) = Avx2::detect() else { return };
    let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
    let (lo, hi) = (b.min.to_array(), b.max.to_array());
    let rays: Vec<Ray> = (0..8)
        .map(|i| {
            let f = i as f32 / 7.0;
            match i % 4 {
                0 => Ray::new(Vec3::new(0.0, f, -1.0), Vec3::Z),
                1 => Ray::new(Vec3::new(1.0, -1.0, f), Vec3::Y),
                2 => Ray::new(Vec3::new(-1.0, 1.0, f), Vec3::new(1.0, -0.0, 0.0)),
                _ => Ray::new(Vec3::new(f, 0.0, 2.0), Vec3::new(0.0, 0.0, -1.0)),
            }
        })
        .collect();
    let got = hit(k, &group(k, &rays, 0), lo, hi);
    for (lane, r) in rays.iter().enumerate() {
        let (t0, t1) = OneRay::new(r).one_box(&lo, &hi, r.t_min, widen(r.t_max));
        assert_eq!(got >> lane & 1 == 1, t0 <= t1, "lane {lane}: {r:?}");
        assert!(t0 <= t1, "a ray along a face hits the box: {r:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]
    /// The rows of eight rays made at once are `WatertightRay::with_branches`'s, bit for bit,
    /// zeros' signs included: directions with equal magnitudes on two or three axes (the axis
    /// choice's ties), zero and -0 components, negative largest components (the swap).
    #[test]
    fn eight_rays_rows_are_the_branchy_rows(dirs in proptest::collection::vec(point(), 1..=8)) {
        let Some(k) = Avx2::detect() else { return Ok(()) };
        let rays: Vec<Ray> = dirs.iter().map(|&d| Ray::new(Vec3::ONE, d)).collect();
        let p = rows(k, &rays, 0);
        let lanes = |v: &[__m256; 3]| {
            let mut a = [[0f32; 8]; 3];
            for (axis, out) in a.iter_mut().enumerate() {
                // SAFETY: eight floats each way.
                unsafe { _mm256_storeu_ps(out.as_mut_ptr(), v[axis]) };
            }
            a
        };
        let (rx, ry, rz) = (lanes(&p.rx), lanes(&p.ry), lanes(&p.rz));
        for (lane, ray) in rays.iter().enumerate() {
            let w = crate::geometry::shear::WatertightRay::with_branches(ray.dir());
            for axis in 0..3 {
                let got = [rx[axis][lane], ry[axis][lane], rz[axis][lane]].map(f32::to_bits);
                let want = [w.rx[axis], w.ry[axis], w.rz[axis]].map(f32::to_bits);
                prop_assert_eq!(got, want, "lane {} axis {} of {:?}", lane, axis, ray.dir());
            }
        }
    }
}
