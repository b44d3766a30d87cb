//! Tests of `packet8.rs`: eight-ray groups pass the checks every wide group passes
//! (`geometry::group_tests`: against the four-lane groups and the scalar tests).

use super::*;
use crate::geometry::group_tests::{self as checks, GroupKernel};
use proptest::prelude::*;

// SAFETY (each `unsafe`): `self` comes from `Avx2::detect`, so the CPU has AVX2 and FMA.
impl GroupKernel for Avx2 {
    const N: usize = 8;
    type Group = RayGroup8;
    type Rows = WatertightRay8;
    fn detect() -> Option<Self> {
        Avx2::detect()
    }
    fn group(self, rays: &[Ray], base: usize) -> RayGroup8 {
        unsafe { RayGroup8::new(self, rays, base) }
    }
    fn hit(self, g: &RayGroup8, lo: [f32; 3], hi: [f32; 3]) -> u32 {
        unsafe { g.hit(self, lo, hi) }
    }
    fn hit_planes(self, g: &RayGroup8, near: [f32; 3], far: [f32; 3]) -> u32 {
        unsafe { g.hit_planes(self, near, far) }
    }
    fn interval(self, groups: &[RayGroup8]) -> RayInterval {
        unsafe { interval8(self, groups) }
    }
    fn rows(self, rays: &[Ray], base: usize) -> WatertightRay8 {
        unsafe { WatertightRay8::new(self, rays, base) }
    }
    fn intersect(self, p: &WatertightRay8, g: &RayGroup8, lanes: u32, tri: &[Vec3; 3]) -> (u32, Vec<[f32; 3]>) {
        let h = unsafe { p.intersect(self, g.t_min, g.t_max, lanes, tri) };
        (h.mask, (0..8).map(|k| [h.t[k], h.u[k], h.v[k]]).collect())
    }
    fn row_lanes(p: &WatertightRay8) -> [[Vec<f32>; 3]; 3] {
        let axes = |v: &[__m256; 3]| v.map(|x| unsafe { lanes8(x) }.to_vec());
        [axes(&p.rx), axes(&p.ry), axes(&p.rz)]
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]
    #[test]
    fn eight_rays_against_a_box_are_the_scalar_tests(rays in checks::rays(), a in checks::point(), b in checks::point()) {
        checks::box_test_is_scalar::<Avx2>(&rays, a, b)?;
    }

    #[test]
    fn the_frustum_of_eight_ray_groups_is_the_four_lane_one(rays in checks::rays()) {
        checks::frustum_is_four_lanes::<Avx2>(&rays)?;
    }

    #[test]
    fn eight_rays_rows_are_the_branchy_rows(dirs in proptest::collection::vec(checks::point(), 1..=8)) {
        checks::rows_are_branchy_rows::<Avx2>(&dirs)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]
    #[test]
    fn eight_rays_against_a_triangle_are_the_scalar_tests((tri, rays) in checks::triangle_case(8), drop in 0u32..8) {
        checks::triangle_test_is_scalar::<Avx2>(&tri, &rays, drop)?;
    }
}

#[test]
fn rays_lying_in_box_planes_hit_as_the_scalar_test_says() {
    checks::rays_in_box_planes_hit::<Avx2>();
}
