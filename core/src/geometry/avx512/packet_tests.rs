//! Tests of `packet.rs`: sixteen-ray groups pass the checks every wide group passes
//! (`geometry::group_tests`: against the four-lane groups and the scalar tests).

use super::*;
use crate::geometry::group_tests::{self as checks, GroupKernel};
use proptest::prelude::*;

/// A register's sixteen floats.
fn lanes16(x: __m512) -> Vec<f32> {
    let mut a = [0f32; 16];
    // SAFETY: `__m512` and `[f32; 16]` have the same size, and every bit pattern is a float.
    a.copy_from_slice(&unsafe { std::mem::transmute::<__m512, [f32; 16]>(x) });
    a.to_vec()
}

// SAFETY (each `unsafe`): `self` comes from `Avx512::detect`, so the CPU has AVX-512F/VL.
impl GroupKernel for Avx512 {
    const N: usize = 16;
    type Group = RayGroup16;
    type Rows = WatertightRay16;
    fn detect() -> Option<Self> {
        Avx512::detect()
    }
    fn group(self, rays: &[Ray], base: usize) -> RayGroup16 {
        unsafe { RayGroup16::new(self, rays, base) }
    }
    fn hit(self, g: &RayGroup16, lo: [f32; 3], hi: [f32; 3]) -> u32 {
        unsafe { g.hit(self, lo, hi) }
    }
    fn hit_planes(self, g: &RayGroup16, near: [f32; 3], far: [f32; 3]) -> u32 {
        unsafe { g.hit_planes(self, near, far) }
    }
    fn interval(self, groups: &[RayGroup16]) -> RayInterval {
        unsafe { interval16(self, groups) }
    }
    fn rows(self, rays: &[Ray], base: usize) -> WatertightRay16 {
        unsafe { WatertightRay16::new(self, rays, base) }
    }
    fn intersect(self, p: &WatertightRay16, g: &RayGroup16, lanes: u32, tri: &[Vec3; 3]) -> (u32, Vec<[f32; 3]>) {
        let h = unsafe { p.intersect(self, g.t_min, g.t_max, lanes, tri) };
        (h.mask, (0..16).map(|k| [h.t[k], h.u[k], h.v[k]]).collect())
    }
    fn row_lanes(p: &WatertightRay16) -> [[Vec<f32>; 3]; 3] {
        let axes = |v: &[__m512; 3]| v.map(lanes16);
        [axes(&p.rx), axes(&p.ry), axes(&p.rz)]
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]
    #[test]
    fn sixteen_rays_against_a_box_are_the_scalar_tests(rays in checks::rays(), a in checks::point(), b in checks::point()) {
        checks::box_test_is_scalar::<Avx512>(&rays, a, b)?;
    }

    #[test]
    fn the_frustum_of_sixteen_ray_groups_is_the_four_lane_one(rays in checks::rays()) {
        checks::frustum_is_four_lanes::<Avx512>(&rays)?;
    }

    #[test]
    fn sixteen_rays_rows_are_the_branchy_rows(dirs in proptest::collection::vec(checks::point(), 1..=16)) {
        checks::rows_are_branchy_rows::<Avx512>(&dirs)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]
    #[test]
    fn sixteen_rays_against_a_triangle_are_the_scalar_tests((tri, rays) in checks::triangle_case(16), drop in 0u32..16) {
        checks::triangle_test_is_scalar::<Avx512>(&tri, &rays, drop)?;
    }
}

#[test]
fn rays_lying_in_box_planes_hit_as_the_scalar_test_says() {
    checks::rays_in_box_planes_hit::<Avx512>();
}
