//! The checks every wide packet group passes (`packet8::RayGroup8` with AVX2,
//! `avx512::packet::RayGroup16` with AVX-512), written once over `GroupKernel`: against the
//! four-lane groups and the scalar tests, on adversarial rays (box corners, axis-parallel
//! directions with origins on box planes, both zeros). Each group's test file implements the
//! kernel and runs these under proptest.

use crate::geometry::aabb::Aabb;
use crate::geometry::ray::Ray;
use crate::geometry::slab::{widen, OneRay};
use crate::geometry::slab_packet::{RayGroup, RayInterval};
use crate::geometry::triangle::{TriangleIntersector, Watertight};
use glam::Vec3;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

/// A kernel family's packet group, as the checks call it (each call made safe by the proof `self`).
pub(crate) trait GroupKernel: Copy {
    /// Rays per group.
    const N: usize;
    type Group;
    type Rows;
    fn detect() -> Option<Self>;
    fn group(self, rays: &[Ray], base: usize) -> Self::Group;
    fn hit(self, g: &Self::Group, lo: [f32; 3], hi: [f32; 3]) -> u32;
    fn hit_planes(self, g: &Self::Group, near: [f32; 3], far: [f32; 3]) -> u32;
    fn interval(self, groups: &[Self::Group]) -> RayInterval;
    fn rows(self, rays: &[Ray], base: usize) -> Self::Rows;
    /// The triangle test's mask and each lane's `(t, u, v)`.
    fn intersect(self, p: &Self::Rows, g: &Self::Group, lanes: u32, tri: &[Vec3; 3]) -> (u32, Vec<[f32; 3]>);
    /// The rows `rx`, `ry`, `rz` per axis and lane.
    fn row_lanes(p: &Self::Rows) -> [[Vec<f32>; 3]; 3];
}

/// Halves on a small grid, and -0: origins on box planes with zero direction components (the
/// NaN case), rays through corners and edges.
fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![(-6i32..6).prop_map(|v| v as f32 * 0.5), Just(-0.0f32)]
}
pub(crate) fn point() -> impl Strategy<Value = Vec3> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Up to 20 rays (so a second group with padding lanes), some with their `t_max` cut short.
pub(crate) fn rays() -> impl Strategy<Value = Vec<Ray>> {
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

/// Triangles on a small grid and up to `n` rays aimed at their vertices, edges and inner points
/// (the watertight test's exactly-zero edge functions), or anywhere, some with short intervals.
pub(crate) fn triangle_case(n: usize) -> impl Strategy<Value = ([Vec3; 3], Vec<Ray>)> {
    use crate::geometry::leaf_cases::{aim, aimed_ray, grid_point};
    ([grid_point(), grid_point(), grid_point()], proptest::collection::vec(aim(), 1..=n))
        .prop_map(|(tri, aims)| (tri, aims.into_iter().map(|a| aimed_ray(&tri, a)).collect()))
}

/// The box test of a group is its four-lane groups', lane for lane (padding lanes included), and
/// for every real ray the scalar test's verdict; with the planes chosen once (`hit_planes`)
/// where every ray shares the signs, the same.
pub(crate) fn box_test_is_scalar<K: GroupKernel>(rays: &[Ray], a: Vec3, b: Vec3) -> Result<(), TestCaseError> {
    let Some(k) = K::detect() else { return Ok(()) };
    let (lo, hi) = (a.min(b).to_array(), a.max(b).to_array());
    for base in (0..rays.len()).step_by(K::N) {
        let g = k.group(rays, base);
        let got = k.hit(&g, lo, hi);
        let fours = (0..K::N / 4).fold(0, |m, q| m | RayGroup::new(rays, base + 4 * q).hit(lo, hi) << (4 * q));
        prop_assert_eq!(got, fours, "{} lanes against groups of four", K::N);
        for lane in 0..(rays.len() - base).min(K::N) {
            let r = &rays[base + lane];
            let (t0, t1) = OneRay::new(r).one_box(&lo, &hi, r.t_min, widen(r.t_max));
            prop_assert_eq!(got >> lane & 1 == 1, t0 <= t1, "lane {} of {:?}", lane, r);
        }
        let neg = |axis: usize| rays[base].inv_dir()[axis] < 0.0;
        let shared = rays[base..].iter().take(K::N).all(|r| (0..3).all(|a| (r.inv_dir()[a] < 0.0) == neg(a)));
        if shared {
            let pick = |axis: usize, near: bool| if neg(axis) == near { hi[axis] } else { lo[axis] };
            let near = [pick(0, true), pick(1, true), pick(2, true)];
            let far = [pick(0, false), pick(1, false), pick(2, false)];
            prop_assert_eq!(k.hit_planes(&g, near, far), got, "planes chosen once");
        }
    }
    Ok(())
}

/// The frustum of the groups is the four-lane one, field for field.
pub(crate) fn frustum_is_four_lanes<K: GroupKernel>(rays: &[Ray]) -> Result<(), TestCaseError> {
    let Some(k) = K::detect() else { return Ok(()) };
    let wide: Vec<K::Group> = (0..rays.len()).step_by(K::N).map(|b| k.group(rays, b)).collect();
    let g4: Vec<RayGroup> = (0..rays.len()).step_by(4).map(|b| RayGroup::new(rays, b)).collect();
    prop_assert_eq!(k.interval(&wide), RayInterval::new(&g4));
    Ok(())
}

/// Lane k of the triangle test is `Watertight::intersect` of ray k, bit for bit, and no lane
/// outside `lanes` (all but `drop`) is reported.
pub(crate) fn triangle_test_is_scalar<K: GroupKernel>(
    tri: &[Vec3; 3],
    rays: &[Ray],
    drop: u32,
) -> Result<(), TestCaseError> {
    let Some(k) = K::detect() else { return Ok(()) };
    let p = k.rows(rays, 0);
    let g = k.group(rays, 0);
    let lanes = ((1u32 << rays.len()) - 1) & !(1 << drop);
    let (mask, tuv) = k.intersect(&p, &g, lanes, tri);
    prop_assert_eq!(mask & !lanes, 0, "only the lanes asked for");
    for (lane, ray) in rays.iter().enumerate().filter(|&(l, _)| lanes >> l & 1 == 1) {
        let want = Watertight::intersect(&Watertight::prepare(ray), ray, tri);
        prop_assert_eq!(mask >> lane & 1 == 1, want.is_some(), "lane {}: {:?}", lane, ray);
        if let Some(h) = want {
            let bits = |x: f32| x.to_bits();
            prop_assert_eq!(tuv[lane].map(bits), [bits(h.t), bits(h.u), bits(h.v)]);
        }
    }
    Ok(())
}

/// The rows of a group made at once are `WatertightRay::with_branches`'s, bit for bit, zeros'
/// signs included: directions with equal magnitudes on two or three axes (the axis choice's
/// ties), zero and -0 components, negative largest components (the swap).
pub(crate) fn rows_are_branchy_rows<K: GroupKernel>(dirs: &[Vec3]) -> Result<(), TestCaseError> {
    let Some(k) = K::detect() else { return Ok(()) };
    let rays: Vec<Ray> = dirs.iter().map(|&d| Ray::new(Vec3::ONE, d)).collect();
    let [rx, ry, rz] = K::row_lanes(&k.rows(&rays, 0));
    for (lane, ray) in rays.iter().enumerate() {
        let w = crate::geometry::shear::WatertightRay::with_branches(ray.dir());
        for axis in 0..3 {
            let got = [rx[axis][lane], ry[axis][lane], rz[axis][lane]].map(f32::to_bits);
            let want = [w.rx[axis], w.ry[axis], w.rz[axis]].map(f32::to_bits);
            prop_assert_eq!(got, want, "lane {} axis {} of {:?}", lane, axis, ray.dir());
        }
    }
    Ok(())
}

/// Rays lying in a box's face planes (origin on the plane, zero direction component: 0·inf =
/// NaN): every lane keeps its interval (the NaN rule) and hits, as the scalar test does.
pub(crate) fn rays_in_box_planes_hit<K: GroupKernel>() {
    let Some(k) = K::detect() else { return };
    let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
    let (lo, hi) = (b.min.to_array(), b.max.to_array());
    let last = (K::N - 1) as f32;
    let rays: Vec<Ray> = (0..K::N)
        .map(|i| {
            let f = i as f32 / last;
            match i % 4 {
                0 => Ray::new(Vec3::new(0.0, f, -1.0), Vec3::Z),
                1 => Ray::new(Vec3::new(1.0, -1.0, f), Vec3::Y),
                2 => Ray::new(Vec3::new(-1.0, 1.0, f), Vec3::new(1.0, -0.0, 0.0)),
                _ => Ray::new(Vec3::new(f, 0.0, 2.0), Vec3::new(0.0, 0.0, -1.0)),
            }
        })
        .collect();
    let got = k.hit(&k.group(&rays, 0), lo, hi);
    for (lane, r) in rays.iter().enumerate() {
        let (t0, t1) = OneRay::new(r).one_box(&lo, &hi, r.t_min, widen(r.t_max));
        assert_eq!(got >> lane & 1 == 1, t0 <= t1, "lane {lane}: {r:?}");
        assert!(t0 <= t1, "a ray along a face hits the box: {r:?}");
    }
}
