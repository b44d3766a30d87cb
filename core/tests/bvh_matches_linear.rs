//! Every strategy, layout and traversal order gives the linear scan's closest hit; any-hit agrees.
//! The wide layouts also run with every SIMD kernel forced (`cpu::Simd`): each must find the same
//! hit with the same counts as the kernel the CPU would choose.

mod common;

use bvhscope_core::bvh;
use bvhscope_core::bvh::{
    Accelerator, AnyBvh, BuildParams, Layout, LinearScan, NoStats, RayCounters, TraceOptions, TraversalOrder, TreeView,
};
use bvhscope_core::cpu::Simd;
use bvhscope_core::geometry::{Ray, TriangleTest};
use bvhscope_core::mesh::Mesh;
use glam::Vec3;
use proptest::prelude::*;

fn all_options() -> Vec<TraceOptions> {
    let mut v = Vec::new();
    for test in TriangleTest::ALL {
        for order in TraversalOrder::ALL {
            v.push(TraceOptions { order, test });
        }
    }
    v
}

/// Compare one ray on every strategy's BVH against the linear scan.
fn check_ray(mesh: &Mesh, bvhs: &[AnyBvh], linear: &LinearScan, ray: Ray) {
    for opts in all_options() {
        let mut r = ray;
        let expected = linear.closest_hit(&mut r, opts, &mut NoStats);
        // The first result of each tree, which the same tree with another kernel must repeat.
        let mut by_tree = std::collections::HashMap::new();
        for bvh in bvhs {
            let mut r = ray;
            let mut counters = RayCounters::default();
            let got = bvh.closest_hit(&mut r, opts, &mut counters);
            let p = bvh.params();
            let what = format!(
                "{:?} {:?} leaf {} {:?} kernels {:?} ray {:?}",
                p.strategy,
                p.layout,
                p.max_leaf_size,
                opts,
                simd_of(bvh),
                ray
            );
            let mut any_counters = RayCounters::default();
            let any_found = bvh.any_hit(&ray, opts, &mut any_counters);
            let result = (got, counters, any_found, any_counters);
            let first = by_tree.entry(format!("{p:?}")).or_insert(result);
            assert_eq!(*first, result, "another kernel, another result or count: {what}");
            match (expected, got) {
                (None, None) => {}
                (Some(e), Some(g)) => {
                    assert!((e.t - g.t).abs() <= 1e-5 * e.t.abs().max(1e-30), "t {} vs {}: {what}", e.t, g.t);
                    if e.prim != g.prim {
                        // Allowed only when the two triangles are hit at the same distance.
                        let tri = mesh.triangle(g.prim);
                        let h = bvhscope_core::geometry::intersect_triangle(opts.test, &ray, &tri)
                            .expect("BVH prim is hit");
                        assert_eq!(h.t, e.t, "different primitive at a different t: {what}");
                    }
                    assert_eq!(r.t_max, g.t, "ray t_max updated to the hit: {what}");
                }
                _ => panic!("linear {expected:?} but BVH {got:?}: {what}"),
            }
            let any = bvh.any_hit(&ray, opts, &mut NoStats);
            assert_eq!(any, expected.is_some(), "any-hit disagrees with closest hit: {what}");
            assert!(counters.nodes_visited >= 1 || expected.is_none(), "counters ran: {what}");
            // "Rays in the root box" are the rays that visit a node: every layout tests the root
            // box first and visits nothing when it misses.
            let mut root = None;
            bvh.visit_nodes(&mut |n| {
                root.get_or_insert(n.bounds);
                false
            });
            let enters_root = root.is_some_and(|b| b.intersect(&ray).is_some()) && bvh.triangle_count() > 0;
            assert_eq!(counters.nodes_visited > 0, enters_root, "nodes visited iff the root box is entered: {what}");
        }
    }
}

/// Every strategy in both layouts: default parameters, plus odd ones (leaf size 1 and 7, few bins).
fn build_all(mesh: &Mesh) -> Vec<AnyBvh> {
    bvh::Strategy::ALL
        .into_iter()
        .flat_map(|s| {
            [
                BuildParams::with_strategy(s),
                BuildParams { max_leaf_size: 1, sah_bins: 4, ..BuildParams::with_strategy(s) },
                BuildParams { max_leaf_size: 7, sah_bins: 3, ..BuildParams::with_strategy(s) },
                // Reinsertion after any build (single triangles move, then leaves are gathered
                // again); for the SBVH, spatial splits priced everywhere with room to cut.
                BuildParams { reinsert_passes: 2, sbvh_alpha: 0.0, sbvh_growth: 100, ..BuildParams::with_strategy(s) },
            ]
        })
        .flat_map(|p| Layout::ALL.map(|layout| BuildParams { layout, ..p }))
        .map(|p| AnyBvh::build(mesh, &p))
        .flat_map(with_every_kernel)
        .collect()
}

/// A wide tree as built, then the same tree with each more portable kernel forced.
fn with_every_kernel(bvh: AnyBvh) -> Vec<AnyBvh> {
    let forced = |simd: Simd| match &bvh {
        AnyBvh::Binary(_) => None,
        AnyBvh::Wide(w) => Some(AnyBvh::Wide(w.clone().with_simd(simd))),
        AnyBvh::Wide8(w) => Some(AnyBvh::Wide8(w.clone().with_simd(simd))),
    };
    let lower: Vec<AnyBvh> = Simd::ALL.into_iter().filter(|&s| s < Simd::detected()).filter_map(forced).collect();
    std::iter::once(bvh).chain(lower).collect()
}

fn simd_of(bvh: &AnyBvh) -> Option<Simd> {
    match bvh {
        AnyBvh::Binary(_) => None,
        AnyBvh::Wide(w) => Some(w.simd),
        AnyBvh::Wide8(w) => Some(w.simd),
    }
}

fn vec3(range: f32) -> impl Strategy<Value = Vec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Triangle soups: random small triangles around random centres, some clustered, some huge,
/// some axis-aligned (flat boxes), some sharing exact vertices.
fn soup() -> impl Strategy<Value = Mesh> {
    prop::collection::vec((vec3(10.0), vec3(2.0), vec3(2.0), 0u8..4), 1..120).prop_map(|tris| {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for (c, a, b, kind) in tris {
            let (a, b) = match kind {
                0 => (a, b),
                1 => (a * 8.0, b * 8.0),                                   // large, overlapping
                2 => (Vec3::new(a.x, a.y, 0.0), Vec3::new(b.x, b.y, 0.0)), // flat in z
                _ => (a * 0.01, b * 0.01),                                 // tiny
            };
            let base = positions.len() as u32;
            positions.extend([c, c + a, c + b]);
            triangles.push([base, base + 1, base + 2]);
            if kind == 3 && base >= 3 {
                // A second triangle sharing an edge with the previous one.
                triangles.push([base - 3, base - 2, base]);
            }
        }
        let mut m = Mesh::from_triangles("soup", positions, triangles);
        // Drop triangles that came out degenerate, as the loader does.
        let pos = m.positions.clone();
        m.triangles.retain(|t| bvhscope_core::geometry::triangle_double_area(&t.map(|i| pos[i as usize])) > 0.0);
        m.groups[0].triangles = 0..m.triangles.len() as u32;
        m
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, .. ProptestConfig::default() })]

    #[test]
    fn random_soups_closest_hit_equals_linear(
        mesh in soup(),
        rays in prop::collection::vec((vec3(20.0), vec3(1.0), 0usize..1000, 0.0f32..1.0, 0.0f32..1.0), 1..40),
    ) {
        prop_assume!(mesh.triangle_count() > 0);
        let bvhs = build_all(&mesh);
        for bvh in &bvhs {
            common::check_any(bvh, &mesh);
        }
        let linear = LinearScan::new(&mesh);
        for (origin, dir, target, u, v) in rays {
            // Half the rays aim at a point on a triangle so hits are common; the rest are random.
            let d = if target % 2 == 0 {
                let tri = mesh.triangle((target / 2 % mesh.triangle_count()) as u32);
                let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
                tri[0] * (1.0 - u - v) + tri[1] * u + tri[2] * v - origin
            } else {
                dir
            };
            check_ray(&mesh, &bvhs, &linear, Ray::new(origin, d));
        }
    }
}

#[test]
fn axis_parallel_and_negative_zero_rays_match_linear() {
    // A grid of axis-aligned unit quads hit by rays with exact zero (and -0) direction parts,
    // through shared edges and vertices.
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..6 {
        for j in 0..6 {
            let b = positions.len() as u32;
            let (x, y) = (i as f32, j as f32);
            positions.extend([
                Vec3::new(x, y, 0.0),
                Vec3::new(x + 1.0, y, 0.0),
                Vec3::new(x + 1.0, y + 1.0, 0.0),
                Vec3::new(x, y + 1.0, 0.0),
            ]);
            triangles.extend([[b, b + 1, b + 2], [b, b + 2, b + 3]]);
        }
    }
    let mesh = Mesh::from_triangles("grid", positions, triangles);
    let bvhs = build_all(&mesh);
    let linear = LinearScan::new(&mesh);
    for i in 0..=24 {
        for j in 0..=24 {
            let (x, y) = (i as f32 * 0.25, j as f32 * 0.25);
            for dir in [Vec3::new(0.0, 0.0, -1.0), Vec3::new(-0.0, -0.0, -1.0), Vec3::new(0.0, -0.0, 1.0)] {
                let o = Vec3::new(x, y, -dir.z * 3.0);
                check_ray(&mesh, &bvhs, &linear, Ray::new(o, dir));
            }
        }
    }
    // Rays lying in the plane of the grid, along its lines.
    for k in 0..=6 {
        check_ray(&mesh, &bvhs, &linear, Ray::new(Vec3::new(-1.0, k as f32, 0.0), Vec3::X));
        check_ray(&mesh, &bvhs, &linear, Ray::new(Vec3::new(k as f32, 7.0, 0.0), Vec3::new(-0.0, -1.0, 0.0)));
    }
}

#[test]
fn identical_triangles_build_a_bounded_tree() {
    // A million copies of one triangle: no split can separate them; the tree must still have
    // small leaves and bounded depth, and rays must find one of them.
    let n = 1_000_000u32;
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let mesh = Mesh::from_triangles("same", positions, vec![[0, 1, 2]; n as usize]);
    for (s, layout) in bvh::Strategy::ALL.into_iter().flat_map(|s| Layout::ALL.map(|l| (s, l))) {
        let bvh = AnyBvh::build(&mesh, &BuildParams { layout, ..BuildParams::with_strategy(s) });
        let stats = bvhscope_core::bvh::TreeStats::of(&bvh);
        assert!(stats.max_depth < bvhscope_core::bvh::TRAVERSAL_STACK_SIZE as u32, "{s:?} depth {}", stats.max_depth);
        assert!(stats.leaf_size_histogram.len() <= 5, "{s:?} leaf sizes");
        // Equal count always separates; PLOC merges and never splits, so nothing falls back.
        if !matches!(s, bvh::Strategy::EqualCount | bvh::Strategy::Ploc) {
            assert!(stats.fallback_splits > 0, "{s:?} must report its fallback splits");
        }
        let mut r = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
        let hit = bvh.closest_hit(&mut r, TraceOptions::default(), &mut NoStats).expect("hit");
        assert_eq!(hit.t, 1.0);
    }
}

#[test]
fn exponentially_spaced_triangles_stay_within_the_stack_depth() {
    // Midpoint splits peel one triangle off at a time here; the depth limit must kick in.
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    // Centroids at 4^i: every midpoint split separates only the largest one.
    for i in -60..60 {
        let x = 4f32.powi(i);
        let b = positions.len() as u32;
        positions.extend([Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1.0, 0.0), Vec3::new(x, 0.0, 1.0)]);
        triangles.push([b, b + 1, b + 2]);
    }
    let mesh = Mesh::from_triangles("exp", positions, triangles);
    let linear = LinearScan::new(&mesh);
    let bvhs: Vec<AnyBvh> = Layout::ALL
        .map(|layout| {
            let p = BuildParams { max_leaf_size: 1, layout, ..BuildParams::with_strategy(bvh::Strategy::Midpoint) };
            AnyBvh::build(&mesh, &p)
        })
        .into();
    for bvh in &bvhs {
        let stats = bvhscope_core::bvh::TreeStats::of(bvh);
        assert!(stats.max_depth < bvhscope_core::bvh::TRAVERSAL_STACK_SIZE as u32);
        assert!(stats.depth_limited_splits > 0, "this input must reach the depth limit: {stats:?}");
        common::check_any(bvh, &mesh);
    }
    for i in 0..50 {
        let ray = Ray::new(Vec3::new(-1.0, 0.1 + i as f32 * 0.01, 0.2), Vec3::new(1.0, 1e-20, 0.0));
        check_ray(&mesh, &bvhs, &linear, ray);
    }
}

#[test]
fn empty_mesh_builds_and_misses() {
    let mesh = Mesh::from_triangles("empty", vec![], vec![]);
    for bvh in build_all(&mesh) {
        let mut r = Ray::new(Vec3::ZERO, Vec3::X);
        assert!(bvh.closest_hit(&mut r, TraceOptions::default(), &mut NoStats).is_none());
        assert!(!bvh.any_hit(&r, TraceOptions::default(), &mut NoStats));
    }
}

struct SharedCase {
    name: &'static str,
    mesh: Mesh,
    bvhs: Vec<AnyBvh>,
    linear: LinearScan,
}

/// The shared meshes with a BVH per strategy, built once for all proptest cases.
fn shared_cases() -> &'static [SharedCase] {
    static CASES: std::sync::OnceLock<Vec<SharedCase>> = std::sync::OnceLock::new();
    CASES.get_or_init(|| {
        if common::shared_models().is_none() {
            return Vec::new();
        }
        [
            "suzanne.obj",
            "teapot.obj",
            "spot.obj",
            "cow.obj",
            "stanford-bunny.obj",
            "beast.obj",
            "moer-lite-lab1-bvh/models/Monkey.obj",
        ]
        .into_iter()
        .map(|name| {
            let mesh = common::shared_mesh(name).unwrap();
            let bvhs: Vec<AnyBvh> = bvh::Strategy::ALL
                .into_iter()
                .flat_map(|s| Layout::ALL.map(|layout| BuildParams { layout, ..BuildParams::with_strategy(s) }))
                .map(|p| AnyBvh::build(&mesh, &p))
                .collect();
            for bvh in &bvhs {
                common::check_any(bvh, &mesh);
            }
            let linear = LinearScan::new(&mesh);
            SharedCase { name, mesh, bvhs, linear }
        })
        .collect()
    })
}

/// A ray from a point on (or, for `inside`, within) the mesh's bounding sphere towards a point
/// in its box; all parameters in [0, 1].
fn mesh_ray(mesh: &Mesh, from: Vec3, to: Vec3, inside: bool) -> Ray {
    let b = mesh.bounds();
    let target = Vec3::from(b.min) + b.extent() * to;
    let origin = if inside {
        Vec3::from(b.min) + b.extent() * from
    } else {
        let d = (from - 0.5).normalize_or(Vec3::X);
        b.center() + d * b.extent().length()
    };
    Ray::new(origin, target - origin)
}

fn unit3() -> impl Strategy<Value = Vec3> {
    (0.0f32..1.0, 0.0f32..1.0, 0.0f32..1.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, .. ProptestConfig::default() })]

    #[test]
    fn shared_meshes_closest_hit_equals_linear(
        which in 0usize..7,
        rays in prop::collection::vec((unit3(), unit3(), prop::bool::weighted(0.25)), 1..12),
    ) {
        let cases = shared_cases();
        if cases.is_empty() {
            return Ok(()); // notice printed by shared_models()
        }
        let case = &cases[which % cases.len()];
        for (from, to, inside) in rays {
            check_ray(&case.mesh, &case.bvhs, &case.linear, mesh_ray(&case.mesh, from, to, inside));
        }
    }
}

#[test]
fn shared_meshes_are_hit_by_the_test_rays() {
    // Guards the property test above: its rays must actually hit the meshes often.
    for case in shared_cases() {
        let mut hits = 0;
        for i in 0..200 {
            let f = |k: u32| ((i * 7919 + k * 104729) % 1000) as f32 / 1000.0;
            let mut r = mesh_ray(&case.mesh, Vec3::new(f(1), f(2), f(3)), Vec3::new(f(4), f(5), f(6)), false);
            hits += case.linear.closest_hit(&mut r, TraceOptions::default(), &mut NoStats).is_some() as usize;
        }
        assert!(hits > 20, "{}: only {hits} of 200 rays hit", case.name);
    }
}
