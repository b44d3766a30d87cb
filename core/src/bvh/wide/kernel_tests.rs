//! Every kernel of the wide walks (`cpu::Simd`, forced with `with_simd`) against the scalar one and
//! the linear scan: single rays' hits and counts bit for bit the scalar kernel's, any-hit answers
//! the same, packets the same hits, on adversarial rays (aimed at the corners of the tree's own
//! boxes, axis-parallel along shared edges with origins on box planes, both zeros), with leaves of
//! up to 20 triangles so the AVX2 leaf test runs in its four- and eight-lane passes and more than
//! one (`geometry::triangle8`, Möller–Trumbore too), and the AVX-512 one in 256-bit, 512-bit and
//! two passes.

use crate::bvh::accel::{Accelerator, Hit, TraceOptions};
use crate::bvh::any::AnyBvh;
use crate::bvh::counters::{NoStats, RayCounters};
use crate::bvh::linear::LinearScan;
use crate::bvh::params::{BuildParams, Layout};
use crate::bvh::preset::Preset;
use crate::bvh::tree::{TreeNode, TreeView};
use crate::cpu::Simd;
use crate::geometry::Ray;
use crate::mesh::Mesh;
use glam::Vec3;
use proptest::prelude::*;

/// A grid of unit quads in z = 0 (shared edges and vertices), a tilted copy, and `extra` random
/// triangles around it.
fn mesh(extra: &[(Vec3, Vec3, Vec3)]) -> Mesh {
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for i in 0..8 {
        for j in 0..8 {
            let b = positions.len() as u32;
            let (x, y) = (i as f32, j as f32);
            let z = if i >= 4 { 0.25 * y } else { 0.0 };
            positions.extend([
                Vec3::new(x, y, z),
                Vec3::new(x + 1.0, y, z),
                Vec3::new(x + 1.0, y + 1.0, z + if i >= 4 { 0.25 } else { 0.0 }),
                Vec3::new(x, y + 1.0, z + if i >= 4 { 0.25 } else { 0.0 }),
            ]);
            triangles.extend([[b, b + 1, b + 2], [b, b + 2, b + 3]]);
        }
    }
    for &(a, b, c) in extra {
        let base = positions.len() as u32;
        positions.extend([a, b, c]);
        triangles.push([base, base + 1, base + 2]);
    }
    let mut m = Mesh::from_triangles("kernels", positions, triangles);
    let pos = m.positions.clone();
    m.triangles.retain(|t| crate::geometry::triangle_double_area(&t.map(|i| pos[i as usize])) > 0.0);
    m.groups[0].triangles = 0..m.triangles.len() as u32;
    m
}

/// The tree built with `params` and forced to each kernel this CPU has, the scalar one first.
fn every_kernel(mesh: &Mesh, params: &BuildParams) -> Vec<(Simd, AnyBvh)> {
    let built = AnyBvh::build(mesh, params);
    Simd::ALL
        .into_iter()
        .filter(|&s| s <= Simd::detected())
        .map(|s| match &built {
            AnyBvh::Wide(w) => (s, AnyBvh::Wide(w.clone().with_simd(s))),
            AnyBvh::Wide8(w) => (s, AnyBvh::Wide8(w.clone().with_simd(s))),
            AnyBvh::Binary(_) => panic!("a wide layout"),
        })
        .collect()
}

/// Rays that stress the kernels: from far away at each corner of every box of the tree (a box
/// touched at one point), axis-parallel along the grid's lines and through its vertices (origins on
/// box planes: 0·inf = NaN in the slab test), with both signs of zero.
fn adversarial_rays(tree: &AnyBvh, from: &[Vec3]) -> Vec<Ray> {
    let mut rays = Vec::new();
    let mut boxes = Vec::new();
    tree.visit_nodes(&mut |n: &TreeNode| {
        boxes.push(n.bounds);
        boxes.len() < 200
    });
    for (i, b) in boxes.iter().enumerate() {
        for c in 0..8 {
            let corner = Vec3::new(
                if c & 1 == 0 { b.min.x } else { b.max.x },
                if c & 2 == 0 { b.min.y } else { b.max.y },
                if c & 4 == 0 { b.min.z } else { b.max.z },
            );
            let o = from[(i + c) % from.len()];
            rays.push(Ray::new(o, corner - o));
        }
    }
    for k in 0..=8 {
        let f = k as f32;
        for zero in [0.0f32, -0.0] {
            rays.push(Ray::new(Vec3::new(f, f * 0.5, 3.0), Vec3::new(zero, zero, -1.0)));
            rays.push(Ray::new(Vec3::new(-1.0, f, 0.0), Vec3::new(1.0, zero, zero)));
            rays.push(Ray::new(Vec3::new(f, 9.0, 0.0), Vec3::new(zero, -1.0, zero)));
            rays.push(Ray::new(Vec3::new(f, f, -2.0), Vec3::new(zero, zero, 1.0)));
        }
    }
    rays
}

/// `ray` through each tree with each triangle test: closest hit and counters equal to the first
/// tree's (the scalar kernel, which tests a leaf's triangles one by one from their vertices; the
/// SIMD ones read the stored leaves for `MollerTrumboreStored`), any-hit too; with the watertight
/// test, the hit at the linear scan's distance (Möller–Trumbore may return a neighbour a few units
/// in the last place farther, see `slab.rs`).
fn check(trees: &[(Simd, AnyBvh)], linear: &LinearScan, ray: Ray) -> Result<(), TestCaseError> {
    let fastest = Preset::Fastest.trace_options();
    for opts in crate::geometry::TriangleTest::ALL.map(|test| TraceOptions { test, ..fastest }) {
        let run = |bvh: &AnyBvh| {
            let (mut r, mut c, mut a) = (ray, RayCounters::default(), RayCounters::default());
            let hit =
                bvh.closest_hit(&mut r, opts, &mut c).map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits(), h.prim));
            (hit, c, bvh.any_hit(&ray, opts, &mut a), a)
        };
        let want = run(&trees[0].1);
        for (simd, bvh) in &trees[1..] {
            prop_assert_eq!(run(bvh), want, "{:?} against scalar, {:?}, {:?}", simd, opts.test, ray);
        }
        if opts.test == crate::geometry::TriangleTest::Watertight {
            let mut r = ray;
            let linear_t = linear.closest_hit(&mut r, opts, &mut NoStats).map(|h| h.t.to_bits());
            prop_assert_eq!(want.0.map(|h| h.0), linear_t, "the linear scan's distance, {:?}", ray);
        }
    }
    Ok(())
}

/// Packets of 64 of `rays` with each kernel: the scalar kernel's single-ray distances.
fn check_packets(trees: &[(Simd, AnyBvh)], rays: &[Ray]) -> Result<(), TestCaseError> {
    let opts = TraceOptions::default();
    for chunk in rays.chunks(crate::bvh::packet::PACKET) {
        let want: Vec<Option<u32>> = chunk
            .iter()
            .map(|r| trees[0].1.closest_hit(&mut r.clone(), opts, &mut NoStats).map(|h| h.t.to_bits()))
            .collect();
        for (simd, bvh) in trees {
            let mut packet = chunk.to_vec();
            let mut got: Vec<Option<Hit>> = vec![None; chunk.len()];
            bvh.closest_hits(&mut packet, &mut got, opts);
            let got: Vec<Option<u32>> = got.iter().map(|h| h.map(|h| h.t.to_bits())).collect();
            prop_assert_eq!(&got, &want, "{:?} packets", simd);
        }
    }
    Ok(())
}

fn vec3(r: f32) -> impl Strategy<Value = Vec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// Hits and counts of every kernel are the scalar kernel's, in both wide layouts and with
    /// leaves of 4 to 20 triangles; packets find the same hits.
    #[test]
    fn every_kernel_finds_the_scalar_kernels_hits_with_its_counts(
        extra in proptest::collection::vec((vec3(6.0), vec3(6.0), vec3(6.0)), 0..60),
        from in proptest::collection::vec(vec3(30.0), 4..8),
        random in proptest::collection::vec((vec3(12.0), vec3(1.0)), 32..64),
        leaf in prop_oneof![Just(4u32), Just(8), Just(12), Just(16), Just(20)],
        wide8 in proptest::bool::ANY,
    ) {
        let m = mesh(&extra);
        let layout = if wide8 { Layout::Wide8 } else { Layout::Wide4 };
        let params = BuildParams { layout, max_leaf_size: leaf, ..Preset::Fastest.build() };
        let trees = every_kernel(&m, &params);
        prop_assert!(trees.len() >= 2, "scalar and at least one SIMD kernel");
        let linear = LinearScan::new(&m);
        let mut rays = adversarial_rays(&trees[0].1, &from);
        rays.extend(random.iter().map(|&(o, d)| Ray::new(o, d)));
        for &ray in &rays {
            check(&trees, &linear, ray)?;
        }
        check_packets(&trees, &rays)?;
    }
}

/// On this machine's CPU the best kernel is one of those compared (the AVX-512 one here: the
/// tests above would otherwise only compare what is below it).
#[test]
fn the_detected_kernel_is_among_those_forced() {
    let trees = every_kernel(&mesh(&[]), &Preset::Fastest.build());
    assert_eq!(trees.last().map(|t| t.0), Some(Simd::detected()));
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f") && std::arch::is_x86_feature_detected!("avx512vl") {
        assert_eq!(Simd::detected(), Simd::Avx512);
    }
}
