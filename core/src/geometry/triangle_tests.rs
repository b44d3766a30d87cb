use super::*;
use crate::geometry::{intersect_triangle, TriangleTest};

const TRI: [Vec3; 3] = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];

fn both(ray: &Ray, tri: &[Vec3; 3]) -> [Option<TriangleHit>; 2] {
    [intersect_triangle(TriangleTest::Watertight, ray, tri), intersect_triangle(TriangleTest::MollerTrumbore, ray, tri)]
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-6 * (1.0 + a.abs().max(b.abs()))
}

#[test]
fn hit_gives_distance_and_barycentrics() {
    let r = Ray::new(Vec3::new(0.25, 0.5, 2.0), -Vec3::Z);
    for h in both(&r, &TRI) {
        let h = h.expect("hit");
        assert!(close(h.t, 2.0) && close(h.u, 0.25) && close(h.v, 0.5), "{h:?}");
    }
}

#[test]
fn barycentrics_reconstruct_the_hit_point_for_an_oblique_ray() {
    let tri = [Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 0.0, 2.0), Vec3::new(2.0, 5.0, -1.0)];
    let target = tri[0] * 0.2 + tri[1] * 0.3 + tri[2] * 0.5;
    let o = Vec3::new(-3.0, 7.0, 9.0);
    let r = Ray::new(o, (target - o) * 0.37);
    for h in both(&r, &tri) {
        let h = h.expect("hit");
        assert!(close(h.u, 0.3) && close(h.v, 0.5), "{h:?}");
        assert!((r.at(h.t) - target).length() < 1e-4);
    }
}

#[test]
fn miss_outside_the_triangle() {
    for o in [Vec3::new(0.6, 0.6, 1.0), Vec3::new(-0.1, 0.5, 1.0), Vec3::new(0.5, -0.1, 1.0)] {
        let r = Ray::new(o, -Vec3::Z);
        assert_eq!(both(&r, &TRI), [None, None], "origin {o}");
    }
}

#[test]
fn back_faces_are_hit() {
    let r = Ray::new(Vec3::new(0.25, 0.25, -1.0), Vec3::Z);
    for h in both(&r, &TRI) {
        assert!(close(h.expect("back face hit").t, 1.0));
    }
}

#[test]
fn parallel_ray_misses() {
    // In the plane, through the triangle's interior, and above it.
    for o in [Vec3::new(-1.0, 0.25, 0.0), Vec3::new(-1.0, 0.25, 0.5)] {
        let r = Ray::new(o, Vec3::X);
        assert_eq!(both(&r, &TRI), [None, None], "origin {o}");
    }
}

#[test]
fn t_interval_is_respected() {
    let r = Ray::segment(Vec3::new(0.25, 0.25, 2.0), -Vec3::Z, 0.0, 1.5);
    assert_eq!(both(&r, &TRI), [None, None], "hit beyond t_max");
    let r = Ray::segment(Vec3::new(0.25, 0.25, 2.0), -Vec3::Z, 2.5, 10.0);
    assert_eq!(both(&r, &TRI), [None, None], "hit before t_min");
    let r = Ray::segment(Vec3::new(0.25, 0.25, 2.0), -Vec3::Z, 2.0, 10.0);
    assert!(both(&r, &TRI).iter().all(Option::is_some), "t_min is inclusive");
    let r = Ray::segment(Vec3::new(0.25, 0.25, 2.0), -Vec3::Z, 0.0, 2.0);
    assert_eq!(both(&r, &TRI), [None, None], "t_max is exclusive");
    let r = Ray::new(Vec3::new(0.25, 0.25, -2.0), -Vec3::Z);
    assert_eq!(both(&r, &TRI), [None, None], "triangle behind the origin");
}

#[test]
fn watertight_hits_edges_and_vertices() {
    let points = [
        Vec3::new(0.5, 0.0, 0.0), // on edge v0-v1
        Vec3::new(0.0, 0.5, 0.0), // on edge v0-v2
        Vec3::new(0.5, 0.5, 0.0), // on the hypotenuse
        Vec3::new(0.0, 0.0, 0.0), // vertices
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    for p in points {
        for dir in [-Vec3::Z, Vec3::new(0.3, -0.2, -1.0)] {
            let o = p - dir * 3.0;
            let r = Ray::new(o, dir);
            let h = intersect_triangle(TriangleTest::Watertight, &r, &TRI);
            assert!(h.is_some(), "point {p} dir {dir}");
            assert!(close(h.unwrap().t, 3.0));
        }
    }
}

#[test]
fn watertight_shared_edge_is_never_missed() {
    // Two triangles sharing the diagonal of the unit square; rays along the diagonal in
    // awkward floating-point positions must hit at least one of them.
    let t1 = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0)];
    let t2 = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
    for i in 1..1000 {
        let s = i as f32 / 1000.0 * 0.999_37;
        let p = Vec3::new(s, s, 0.0);
        let dir = Vec3::new(0.113, 0.071, -1.0);
        let r = Ray::new(p - dir * 1.7, dir);
        let hit1 = intersect_triangle(TriangleTest::Watertight, &r, &t1).is_some();
        let hit2 = intersect_triangle(TriangleTest::Watertight, &r, &t2).is_some();
        assert!(hit1 || hit2, "gap at s = {s}");
    }
}

/// The branch-free choice of axes in `prepare` against the paper's rule as `with_branches`
/// writes it (Woop, Benthin & Wald 2013, §3: kz the largest component, kx and ky the next two,
/// swapped when that component is negative), bit for bit, on directions with ties, zeros of
/// both signs and every sign pattern.
#[test]
fn the_shear_axes_follow_the_papers_rule_in_every_case() {
    let reference = WatertightRay::with_branches;
    let values = [-2.0f32, -1.0, -0.5, -0.0, 0.0, 0.5, 1.0, 2.0];
    let mut tested = 0;
    for x in values {
        for y in values {
            for z in values {
                let d = Vec3::new(x, y, z);
                if d == Vec3::ZERO {
                    continue;
                }
                let ray = Ray::new(Vec3::ZERO, d);
                let p = Watertight::prepare(&ray);
                let bits = |v: [Vec3; 3]| v.map(|r| r.to_array().map(f32::to_bits));
                let r = reference(ray.dir());
                assert_eq!(bits([p.rx, p.ry, p.rz]), bits([r.rx, r.ry, r.rz]), "direction {d}");
                tested += 1;
            }
        }
    }
    assert_eq!(tested, 8 * 8 * 8 - 8, "all but the zero directions (both signs of zero)");
}

#[test]
fn degenerate_triangle_is_never_hit() {
    let tri = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
    let r = Ray::new(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z);
    assert_eq!(both(&r, &tri), [None, None]);
    assert_eq!(double_area(&tri), 0.0);
}

#[test]
fn empty_ray_is_never_hit() {
    let r = Ray::new(Vec3::new(0.25, f32::NAN, 1.0), -Vec3::Z);
    assert_eq!(both(&r, &TRI), [None, None]);
}

/// Four rays aimed at points of a triangle (on its edges and vertices too, where the
/// watertight test's edge functions are exactly zero), with random intervals.
fn four_rays() -> impl proptest::strategy::Strategy<Value = ([Vec3; 3], [Ray; 4], u32)> {
    use proptest::prelude::*;
    let grid = || (-4i32..=4).prop_map(|v| v as f32 * 0.5);
    let point = || [grid(), grid(), grid()].prop_map(Vec3::from_array);
    let ray = (0u32..4, 0u32..4, 0u32..4, [-3i32..=3, -3i32..=3, -3i32..=3], 1u32..4, 0u32..6);
    (point(), point(), point(), [ray.clone(), ray.clone(), ray.clone(), ray], 0u32..16).prop_map(
        |(a, b, c, rays, lanes)| {
            let tri = [a, b, c];
            let rays = rays.map(|(i, j, k, d, s, interval)| {
                let w = (i + j + k).max(1) as f32;
                let target = (a * i as f32 + b * j as f32 + c * k as f32) / w;
                let dir = Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32 + 0.25);
                let mut r = Ray::new(target - dir * s as f32, dir);
                match interval {
                    0 => r.t_max = s as f32, // the hit lies exactly at t_max: excluded
                    1 => r.t_min = s as f32 + 0.5,
                    2 => r.t_max = s as f32 * 0.5,
                    _ => {}
                }
                r
            });
            (tri, rays, lanes)
        },
    )
}

fn agree4<T: TriangleIntersector>(tri: &[Vec3; 3], rays: &[Ray; 4], lanes: u32) {
    let p = T::prepare4(rays, 0);
    let lane = |f: &dyn Fn(&Ray) -> f32| f32x4::from(rays.each_ref().map(f));
    let got = T::intersect4(&p, lane(&|r| r.t_min), lane(&|r| r.t_max), lanes, tri);
    for (k, ray) in rays.iter().enumerate() {
        let want = if lanes & (1 << k) != 0 { T::intersect(&T::prepare(ray), ray, tri) } else { None };
        assert_eq!(got.mask & (1 << k) != 0, want.is_some(), "lane {k}: hit or miss");
        if let Some(h) = want {
            let bits = |x: f32| x.to_bits();
            assert_eq!(
                (bits(got.t[k]), bits(got.u[k]), bits(got.v[k])),
                (bits(h.t), bits(h.u), bits(h.v)),
                "lane {k}: bit for bit"
            );
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(2000))]
    #[test]
    fn four_rays_at_once_find_what_each_ray_finds((tri, rays, lanes) in four_rays()) {
        agree4::<Watertight>(&tri, &rays, lanes);
        agree4::<MollerTrumbore>(&tri, &rays, lanes);
    }
}
