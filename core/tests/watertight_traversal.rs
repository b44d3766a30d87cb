//! The traversal is as watertight as the triangle test: rays aimed at exact vertices, edge
//! midpoints and node-box corners, axis-parallel ones and ones starting on a surface get the
//! linear scan's hit (the same triangle test, so the same distance) in every strategy, layout,
//! order and test, one by one and in packets (with Möller–Trumbore, within its own rounding:
//! `same_hit`). A box such a ray only touches, at the vertex it is
//! aimed at, used to be culled by rounding in the slab test (`geometry::slab`, "Robustness").

mod common;

use bvhscope_core::bvh;
use bvhscope_core::bvh::{Accelerator, AnyBvh, BuildParams, Hit, Layout, LinearScan, NoStats, TraceOptions};
use bvhscope_core::bvh::{TraversalOrder, TreeView};
use bvhscope_core::geometry::{Ray, TriangleTest};
use bvhscope_core::mesh::Mesh;
use glam::Vec3;
use proptest::prelude::*;

fn all_options() -> Vec<TraceOptions> {
    TriangleTest::ALL
        .into_iter()
        .flat_map(|test| TraversalOrder::ALL.map(|order| TraceOptions { order, test }))
        .collect()
}

/// Every strategy in both layouts, with leaves of 1 and 4 (small leaves make more boxes touch).
fn build_all(mesh: &Mesh) -> Vec<AnyBvh> {
    bvh::Strategy::ALL
        .into_iter()
        .flat_map(|s| [1, 4].map(move |leaf| (s, leaf)))
        .flat_map(|(s, leaf)| {
            Layout::ALL.map(move |layout| BuildParams { layout, max_leaf_size: leaf, ..BuildParams::with_strategy(s) })
        })
        .map(|p| AnyBvh::build(mesh, &p))
        .collect()
}

/// Points worth aiming at: every vertex, the midpoint of every edge, and the corners of the
/// node boxes of one tree down to `depth`.
fn targets(mesh: &Mesh, bvh: &AnyBvh, depth: u32) -> Vec<Vec3> {
    let mut out: Vec<Vec3> = mesh.positions.clone();
    for t in &mesh.triangles {
        let v = t.map(|i| mesh.positions[i as usize]);
        out.extend([(v[0] + v[1]) * 0.5, (v[1] + v[2]) * 0.5, (v[2] + v[0]) * 0.5]);
    }
    for d in 0..=depth {
        for (_, b) in bvh.boxes_at_depth(d, true) {
            out.extend(b.corners());
        }
    }
    out
}

/// How far beyond the linear scan's distance a Möller–Trumbore hit may lie (relative): see
/// `same_hit`.
const MOLLER_TRUMBORE_SPREAD: f32 = 1.0 / 1024.0;

/// Whether `got` is the closest hit the linear scan finds: the same distance, and a different
/// triangle only where two are hit at exactly that distance.
///
/// With Möller–Trumbore (either form), one exception: its distance has no fixed error bound (it grows with the
/// origin's distance from the triangle against the triangle's size; 300 units in the last place
/// were seen with the same triangle listed twice in two vertex orders, hit at its vertex), so two
/// triangles meeting at the point a ray is aimed at can report distances further apart than the
/// slab test's `SLACK`, and the BVH, having found one, culls the box of the other, which starts at
/// the exact distance. There the BVH's hit is accepted if the test hits its triangle at that
/// distance and it lies within `MOLLER_TRUMBORE_SPREAD` beyond the linear scan's. The watertight
/// test's error is bounded and gets no exception; the traversal is the same code for both.
fn same_hit(mesh: &Mesh, ray: &Ray, opts: TraceOptions, want: Option<Hit>, got: Option<Hit>) -> bool {
    let hits_at = |g: &Hit, t: f32| {
        bvhscope_core::geometry::intersect_triangle(opts.test, ray, &mesh.triangle(g.prim)).is_some_and(|h| h.t == t)
    };
    match (want, got) {
        (None, None) => true,
        (Some(w), Some(g)) if w.t == g.t => w.prim == g.prim || hits_at(&g, w.t),
        (Some(w), Some(g)) if opts.test != TriangleTest::Watertight => {
            g.t > w.t && g.t - w.t <= w.t * MOLLER_TRUMBORE_SPREAD && hits_at(&g, g.t)
        }
        _ => false,
    }
}

/// Trace `rays` one by one and in packets of 64 through every BVH and option, against the
/// linear scan; returns the first disagreement.
fn first_disagreement(mesh: &Mesh, bvhs: &[AnyBvh], rays: &[Ray]) -> Option<String> {
    let linear = LinearScan::new(mesh);
    for opts in all_options() {
        let want: Vec<Option<Hit>> =
            rays.iter().map(|r| linear.closest_hit(&mut r.clone(), opts, &mut NoStats)).collect();
        for bvh in bvhs {
            let p = bvh.params();
            let what = |k: usize, how: &str| {
                format!(
                    "{}: {:?} {:?} leaf {} {:?} {how}: ray {:?} towards {:?}: linear {:?}",
                    mesh.name,
                    p.strategy,
                    p.layout,
                    p.max_leaf_size,
                    opts,
                    rays[k].origin(),
                    rays[k].origin() + rays[k].dir(),
                    want[k]
                )
            };
            for (k, ray) in rays.iter().enumerate() {
                let got = bvh.closest_hit(&mut ray.clone(), opts, &mut NoStats);
                if !same_hit(mesh, ray, opts, want[k], got) {
                    return Some(format!("{}, single ray got {got:?}", what(k, "")));
                }
                if bvh.any_hit(ray, opts, &mut NoStats) != want[k].is_some() {
                    return Some(what(k, "any-hit"));
                }
            }
            for (c, chunk) in rays.chunks(64).enumerate() {
                let mut packet = chunk.to_vec();
                let mut got = vec![None; chunk.len()];
                bvh.closest_hits(&mut packet, &mut got, opts);
                for (i, g) in got.into_iter().enumerate() {
                    let k = 64 * c + i;
                    if !same_hit(mesh, &rays[k], opts, want[k], g) {
                        return Some(format!("{}, packet got {g:?}", what(k, "")));
                    }
                }
            }
        }
    }
    None
}

/// Rays at `targets` from `origins` (the target at t = 1), axis-parallel rays onto them, and rays
/// starting at them (on the surface) leaving along a few directions.
fn aimed_rays(targets: &[Vec3], origins: &[Vec3], reach: f32) -> Vec<Ray> {
    let mut rays = Vec::new();
    for &t in targets {
        for &o in origins {
            rays.push(Ray::new(o, t - o));
        }
        for axis in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X] {
            rays.push(Ray::new(t - axis * reach, axis * reach));
        }
        rays.push(Ray::new(t, Vec3::new(0.3, -1.0, 0.2)));
    }
    rays
}

fn check_mesh(mesh: &Mesh, stride: usize) {
    let bvhs = build_all(mesh);
    let b = mesh.bounds();
    let reach = b.extent().length().max(1e-3) * 2.0;
    let c = b.center();
    let origins = [
        c + Vec3::new(0.45, 0.35, 1.0) * reach,
        c + Vec3::new(-1.0, 0.2, -0.3) * reach,
        c + Vec3::new(0.1, -1.0, 0.4) * reach,
    ];
    let all = targets(mesh, &bvhs[0], 5);
    let picked: Vec<Vec3> = all.iter().copied().step_by(stride.max(1)).collect();
    let rays = aimed_rays(&picked, &origins, reach);
    if let Some(e) = first_disagreement(mesh, &bvhs, &rays) {
        panic!("{e}");
    }
}

#[test]
fn rays_at_vertices_edges_and_box_corners_of_generated_meshes() {
    let mut knot = bvhscope_core::mesh::generate::torus_knot(2, 3, 0.3, 48, 8);
    knot.name = "knot".into();
    check_mesh(&knot, 1);
    check_mesh(&bvhscope_core::mesh::generate::cornell_box(), 1);
    check_mesh(&bvhscope_core::mesh::generate::stadium(), 2);
}

#[test]
fn rays_at_vertices_edges_and_box_corners_of_the_shared_meshes() {
    let Some(_) = common::shared_models() else { return };
    check_mesh(&common::shared_mesh("suzanne.obj").unwrap(), 1);
    check_mesh(&common::shared_mesh("moer-lite-lab1-bvh/models/Monkey.obj").unwrap(), 3);
    check_mesh(&common::shared_mesh("teapot.obj").unwrap(), 7);
}

#[test]
fn the_suzanne_ray_that_missed_its_vertex_gets_it() {
    // Reported: aimed at a vertex of triangle 237, the BVH returned triangle 318 at t = 1.0408
    // where the linear scan finds the vertex at t = 1.
    let Some(_) = common::shared_models() else { return };
    let mesh = common::shared_mesh("suzanne.obj").unwrap();
    let (from, to) = (Vec3::new(2.5447755, -1.0397124, 5.2996325), Vec3::new(-2.415937, 0.806373, 4.853892));
    let ray = Ray::new(from, to - from);
    let mut r = ray;
    let want = LinearScan::new(&mesh).closest_hit(&mut r, TraceOptions::default(), &mut NoStats).expect("a hit");
    assert_eq!(want.t, 1.0);
    if let Some(e) = first_disagreement(&mesh, &build_all(&mesh), &[ray]) {
        panic!("{e}");
    }
}

fn vec3(range: f32) -> impl Strategy<Value = Vec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Triangle soups sharing vertices: a fan of random triangles over a small grid of points, so
/// vertices and edges are shared by several triangles, as in real meshes.
fn shared_vertex_soup() -> impl Strategy<Value = Mesh> {
    (prop::collection::vec(vec3(4.0), 6..30), prop::collection::vec((0usize..30, 0usize..30, 0usize..30), 1..60))
        .prop_map(|(points, tris)| {
            let n = points.len();
            let triangles: Vec<[u32; 3]> = tris
                .into_iter()
                .map(|(a, b, c)| [(a % n) as u32, (b % n) as u32, (c % n) as u32])
                .filter(|t| {
                    let v = t.map(|i| points[i as usize]);
                    bvhscope_core::geometry::triangle_double_area(&v) > 1e-4
                })
                .collect();
            Mesh::from_triangles("soup", points, triangles)
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, .. ProptestConfig::default() })]

    #[test]
    fn random_soups_aimed_at_their_vertices_edges_and_corners(
        mesh in shared_vertex_soup(),
        origins in prop::collection::vec(vec3(12.0), 1..4),
    ) {
        prop_assume!(mesh.triangle_count() > 0);
        let bvhs = build_all(&mesh);
        let b = mesh.bounds();
        let rays = aimed_rays(&targets(&mesh, &bvhs[0], 8), &origins, b.extent().length().max(1e-3) * 2.0);
        let disagreement = first_disagreement(&mesh, &bvhs, &rays);
        prop_assert!(disagreement.is_none(), "{}", disagreement.unwrap_or_default());
    }
}
