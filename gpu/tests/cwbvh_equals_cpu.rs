//! The compressed 8-wide BVH: built from any binary tree (every strategy, leaves of 1 to 16, a
//! deep chain), its decoded boxes hold the binary tree's, its GPU walk has the counts of the same
//! walk on the CPU (`Cwbvh::trace_cpu`) and the binary tree's closest hits.

mod common;

use bvhscope_core::bvh::{Bvh, Hit, RayCounters, Strategy, TraversalOrder};
use bvhscope_core::geometry::{intersect_triangle, Aabb, Ray, TriangleTest};
use bvhscope_core::mesh::Mesh;
use bvhscope_core::render::Camera;
use bvhscope_gpu::{Cwbvh, GpuCwbvh, GpuTraceOptions, Rays};
use common::*;

const STRATEGIES: [Strategy; 5] =
    [Strategy::Midpoint, Strategy::SahBinned, Strategy::Lbvh, Strategy::Ploc, Strategy::Sbvh];

/// The tree's shape: every binary leaf once as a leaf record, every decoded child box holding the
/// binary node it stands for (checked by walking both trees together), groups contiguous.
fn check_structure(bvh: &Bvh, w: &Cwbvh) {
    let mut leaves: Vec<[u32; 2]> =
        bvh.nodes.iter().filter(|n| n.is_leaf()).map(|n| [n.index, n.count as u32]).collect();
    let mut got = w.leaves.clone();
    leaves.sort();
    got.sort();
    assert_eq!(got, leaves, "the binary tree's leaves, each once");
    let interior = bvh.nodes.iter().filter(|n| !n.is_leaf()).count();
    assert!(w.nodes.len() <= interior.max(1), "{} wide nodes for {interior} binary interior nodes", w.nodes.len());
    // Each leaf child's decoded box holds the binary leaf's box (interior children: the unit
    // test in src/cwbvh/mod.rs, which knows which binary node each slot came from).
    let boxes: std::collections::HashMap<[u32; 2], Aabb> =
        bvh.nodes.iter().filter(|n| n.is_leaf()).map(|n| ([n.index, n.count as u32], n.bounds())).collect();
    for n in &w.nodes {
        for s in (0..8).filter(|&s| n.meta[s] != 0 && !n.is_interior(s)) {
            let (lo, hi) = n.child_box(s);
            let decoded = Aabb::new(glam::Vec3::from_array(lo), glam::Vec3::from_array(hi));
            let exact = boxes[&w.leaves[n.leaf(s) as usize]];
            assert!(decoded.contains_box(&exact), "slot {s}: {decoded:?} does not hold {exact:?}");
        }
    }
}

/// GPU hits and counts equal the CPU's walk of the same tree; hits equal the binary tree's
/// (the same distance; the same triangle but where two are hit at that very distance).
fn compare(
    what: &str,
    bvh: &Bvh,
    w: &Cwbvh,
    rays: &[Ray],
    gpu_hits: &[Option<Hit>],
    gpu_counts: &[RayCounters],
) -> usize {
    let (binary, _) = cpu_trace(bvh, rays, TraversalOrder::EntryDistance);
    let mut differ = 0;
    for (i, ray) in rays.iter().enumerate() {
        let (h, c) = w.trace_cpu(&mut ray.clone(), TriangleTest::Watertight);
        if gpu_hits[i] != h || gpu_counts[i] != c {
            differ += 1;
            assert!(
                explain_cwbvh(w, ray, gpu_hits[i], gpu_counts[i]),
                "{what}: ray {i} {ray:?}: GPU {:?} {:?}, CPU {h:?} {c:?}",
                gpu_hits[i],
                gpu_counts[i]
            );
        }
        assert_eq!(
            h.map(|h| h.t.to_bits()),
            binary[i].map(|h| h.t.to_bits()),
            "{what}: ray {i}: the binary tree's distance"
        );
        if let (Some(a), Some(b)) = (h, binary[i]) {
            let t = intersect_triangle(TriangleTest::Watertight, ray, &mesh_tri(w, a.prim)).map(|x| x.t);
            assert!(a.prim == b.prim || t == Some(b.t), "{what}: ray {i}: triangle {} vs {}", a.prim, b.prim);
        }
    }
    differ
}

fn mesh_tri(w: &Cwbvh, prim: u32) -> [glam::Vec3; 3] {
    w.tris[w.prim_ids.iter().position(|&p| p == prim).expect("a triangle of the tree")]
}

/// A ray a few ulps away gives the GPU's answer on the CPU (see common::explain).
fn explain_cwbvh(w: &Cwbvh, ray: &Ray, hit: Option<Hit>, counts: RayCounters) -> bool {
    let mut rng = Rng::new(ray.origin().y.to_bits() as u64);
    (0..512).any(|_| {
        let mut k = || (below(&mut rng, 9) as i32 - 4) as f32 * f32::EPSILON;
        let (o, d) = (ray.origin(), ray.dir());
        let o = o * glam::Vec3::new(1.0 + k(), 1.0 + k(), 1.0 + k());
        let d = d * glam::Vec3::new(1.0 + k(), 1.0 + k(), 1.0 + k());
        let (h, c) = w.trace_cpu(&mut Ray::segment(o, d, ray.t_min, ray.t_max), TriangleTest::Watertight);
        h.map(|h| h.prim) == hit.map(|h| h.prim) && c == counts
    })
}

#[test]
fn on_the_exact_mesh_every_ray_has_the_cpu_walks_hit_and_counts() {
    let Some(gpu) = gpu() else { return };
    let mesh = exact_mesh();
    let rays = exact_rays();
    for strategy in STRATEGIES {
        for leaf in [1, 4, 16] {
            let bvh = build(&mesh, strategy, leaf);
            let w = Cwbvh::from_bvh(&bvh).unwrap();
            check_structure(&bvh, &w);
            let g = GpuCwbvh::upload(&gpu, &w).unwrap();
            let t = g.trace(&gpu, Rays::List(&rays), GpuTraceOptions::default()).unwrap();
            let differ = compare(&format!("{strategy:?}/{leaf}"), &bvh, &w, &rays, &t.hits, &t.counters);
            assert_eq!(differ, 0, "{strategy:?}/{leaf}: every test is exact");
        }
    }
}

#[test]
fn a_deep_chain_and_an_empty_mesh_convert_and_trace() {
    let Some(gpu) = gpu() else { return };
    // Leaves of one along a line, built by midpoint: a tall tree.
    let n = 200u32;
    let positions: Vec<glam::Vec3> = (0..n)
        .flat_map(|i| {
            let x = (1u64 << (i % 20)) as f32 * 1e-3;
            [glam::Vec3::new(x, 0.0, 0.0), glam::Vec3::new(x, 1.0, 0.0), glam::Vec3::new(x, 0.0, 1.0)]
        })
        .collect();
    let mesh = Mesh::from_triangles("chain", positions, (0..n).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect());
    let bvh = build(&mesh, Strategy::Midpoint, 1);
    let w = Cwbvh::from_bvh(&bvh).unwrap();
    check_structure(&bvh, &w);
    let g = GpuCwbvh::upload(&gpu, &w).unwrap();
    let rays: Vec<Ray> =
        (0..64).map(|k| Ray::new(glam::Vec3::new(-1.0, 0.1 + k as f32 * 0.01, 0.2), glam::Vec3::X)).collect();
    let t = g.trace(&gpu, Rays::List(&rays), GpuTraceOptions::default()).unwrap();
    assert_eq!(compare("chain", &bvh, &w, &rays, &t.hits, &t.counters), 0);

    let empty = build(&Mesh::from_triangles("empty", vec![], vec![]), Strategy::SahBinned, 4);
    let w = Cwbvh::from_bvh(&empty).unwrap();
    let g = GpuCwbvh::upload(&gpu, &w).unwrap();
    let t = g.trace(&gpu, Rays::List(&rays[..2]), GpuTraceOptions::default()).unwrap();
    assert_eq!(t.hits, [None, None]);
    assert_eq!(t.counters[0], RayCounters { box_tests: 1, ..RayCounters::ZERO });
}

#[test]
fn shared_meshes_and_camera_frames_match_the_cpu_walk() {
    let Some(gpu) = gpu() else { return };
    let mut meshes = vec![("exact".to_string(), exact_mesh())];
    for name in ["stanford-bunny.obj", "suzanne.obj"] {
        match shared_mesh(name) {
            Some(m) => meshes.push((name.to_string(), m)),
            None => break,
        }
    }
    for (name, mesh) in meshes {
        let bvh = build(&mesh, Strategy::SahBinned, 4);
        let w = Cwbvh::from_bvh(&bvh).unwrap();
        check_structure(&bvh, &w);
        let g = GpuCwbvh::upload(&gpu, &w).unwrap();
        let cam = Camera::framing(&mesh.bounds(), 96, 72);
        let primary = camera_rays(&cam);
        let incoherent = incoherent_rays(&mesh, 4096, 2);
        for (kind, rays, t) in [
            ("camera", &primary, g.trace(&gpu, Rays::Camera(&cam), GpuTraceOptions::default()).unwrap()),
            ("incoherent", &incoherent, g.trace(&gpu, Rays::List(&incoherent), GpuTraceOptions::default()).unwrap()),
        ] {
            let differ = compare(&format!("{name} {kind}"), &bvh, &w, rays, &t.hits, &t.counters);
            use std::io::Write;
            let _ =
                writeln!(std::io::stderr(), "{name} {kind}: {differ} of {} rays differ from the CPU walk", rays.len());
            assert!(differ as f64 <= rays.len() as f64 * 0.001, "{name} {kind}: {differ}");
        }
    }
}
