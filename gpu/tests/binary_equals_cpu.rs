//! The binary BVH's GPU walk against the CPU's: the same hits and the same counts (nodes visited,
//! box tests with the root's, leaves, triangle tests) ray for ray. On a mesh where every test is
//! exact, all rays; on camera rays and the shared meshes, at least 99.9 % of them, and every ray
//! that differs within a few ulps of a boundary (`common::explain`).

mod common;

use bvhscope_core::bvh::{BuildParams, Bvh, BvhNode, Hit, Layout, RayCounters, Strategy, TraversalOrder};
use bvhscope_core::geometry::{Aabb, Ray};
use bvhscope_core::mesh::Mesh;
use bvhscope_core::render::Camera;
use bvhscope_gpu::{GpuBinaryBvh, GpuTraceOptions, Rays};
use common::*;
use glam::Vec3;

const STRATEGIES: [Strategy; 6] =
    [Strategy::Midpoint, Strategy::EqualCount, Strategy::SahBinned, Strategy::Lbvh, Strategy::Ploc, Strategy::Sbvh];

fn opts(order: TraversalOrder) -> GpuTraceOptions {
    GpuTraceOptions { order, ..GpuTraceOptions::default() }
}

/// Every ray of `rays` answered alike by GPU and CPU, or the first that is not.
fn assert_all_equal(
    what: &str,
    bvh: &Bvh,
    rays: &[Ray],
    gpu_hits: &[Option<Hit>],
    gpu_counts: &[RayCounters],
    order: TraversalOrder,
) {
    let (hits, counts) = cpu_trace(bvh, rays, order);
    assert_eq!(gpu_hits.len(), rays.len(), "{what}: one hit per ray");
    for i in 0..rays.len() {
        assert_eq!(gpu_hits[i], hits[i], "{what}: ray {i} {:?}: hit", rays[i]);
        assert_eq!(gpu_counts[i], counts[i], "{what}: ray {i} {:?}: counts", rays[i]);
    }
}

#[test]
fn on_the_exact_mesh_every_ray_has_the_cpus_hit_and_counts() {
    let Some(gpu) = gpu() else { return };
    let mesh = exact_mesh();
    let rays = exact_rays();
    let mut hit = 0;
    for strategy in STRATEGIES {
        for leaf in [1, 4] {
            let bvh = build(&mesh, strategy, leaf);
            let g = GpuBinaryBvh::upload(&gpu, &bvh).unwrap();
            for order in ORDERS {
                let what = format!("{strategy:?}, leaves of {leaf}, {order:?}");
                let t = g.trace(&gpu, Rays::List(&rays), opts(order)).unwrap();
                assert_all_equal(&what, &bvh, &rays, &t.hits, &t.counters, order);
                hit += t.hits.iter().flatten().count();
            }
        }
    }
    // The rays do meet the mesh (and its edges): the test is not all misses.
    assert!(hit > rays.len() * 24 / 4, "{hit} hits");
}

#[test]
fn plain_walks_find_the_counted_walks_hits_and_the_global_stack_the_private_ones() {
    let Some(gpu) = gpu() else { return };
    let mesh = exact_mesh();
    let rays = exact_rays();
    let bvh = build(&mesh, Strategy::SahBinned, 4);
    let g = GpuBinaryBvh::upload(&gpu, &bvh).unwrap();
    assert!(!g.global_stack());
    let counted = g.trace(&gpu, Rays::List(&rays), GpuTraceOptions::default()).unwrap();
    let plain = g.trace(&gpu, Rays::List(&rays), GpuTraceOptions { counted: false, ..Default::default() }).unwrap();
    assert!(plain.counters.is_empty());
    assert_eq!(plain.hits, counted.hits);
    let global = g.trace_with_global_stack(&gpu, Rays::List(&rays), GpuTraceOptions::default()).unwrap();
    assert_eq!(global.hits, counted.hits);
    assert_eq!(global.counters, counted.counters);
}

/// A tree far deeper than any private stack (as an imported dump may be): a chain of 300 interior
/// nodes, each with one leaf. Its walk keeps its stack in global memory, with the CPU's results.
#[test]
fn a_tree_deeper_than_the_private_stack_is_walked_with_the_cpus_results() {
    let Some(gpu) = gpu() else { return };
    let n = 300u32;
    let tris: Vec<[Vec3; 3]> = (0..n)
        .map(|i| {
            let x = i as f32;
            [Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 0.0, 0.0), Vec3::new(x, 1.0, 0.0)]
        })
        .collect();
    let bounds = |r: std::ops::Range<u32>| r.fold(Aabb::EMPTY, |b, i| b.union(Aabb::from_points(&tris[i as usize])));
    // Node 0: the root over all; interior k (k = 0..n-1) at index 2k has its leaf at 2k+1 and the
    // next interior at 2k+2; the last triangle is a leaf at 2(n-1).
    let mut nodes = Vec::new();
    for k in 0..n - 1 {
        nodes.push(BvhNode::interior(bounds(k..n), 2 * k + 1, 0));
        nodes.push(BvhNode::leaf(bounds(k..k + 1), k, 1));
    }
    nodes.push(BvhNode::leaf(bounds(n - 1..n), n - 1, 1));
    // Interior 2k's children are the pair (2k+1, 2k+2): its leaf and the next interior.
    let bvh = Bvh {
        nodes,
        prim_ids: (0..n).collect(),
        tris,
        params: BuildParams { layout: Layout::Binary, ..BuildParams::default() },
        report: Default::default(),
    };
    let g = GpuBinaryBvh::upload(&gpu, &bvh).unwrap();
    assert_eq!(g.depth(), n - 1);
    assert!(g.global_stack());
    // Rays along the row from the far end (every box is entered: the stack grows to the depth),
    // and down onto single triangles.
    let mut rays = vec![Ray::new(Vec3::new(n as f32 + 5.0, 0.25, 0.0), -Vec3::X)];
    rays.extend((0..n).step_by(7).map(|i| Ray::new(Vec3::new(i as f32 + 0.25, 0.25, 3.0), -Vec3::Z)));
    rays.push(Ray::new(Vec3::new(-3.0, 0.25, 1e-3), Vec3::new(1.0, 0.0, -1e-6)));
    for order in ORDERS {
        let t = g.trace(&gpu, Rays::List(&rays), opts(order)).unwrap();
        assert_all_equal(&format!("chain, {order:?}"), &bvh, &rays, &t.hits, &t.counters, order);
    }
}

#[test]
fn an_empty_mesh_is_missed_with_one_box_test_and_a_broken_tree_is_refused() {
    let Some(gpu) = gpu() else { return };
    let empty = build(&Mesh::from_triangles("empty", vec![], vec![]), Strategy::SahBinned, 4);
    let g = GpuBinaryBvh::upload(&gpu, &empty).unwrap();
    let rays = [Ray::new(Vec3::ZERO, Vec3::X), Ray::new(Vec3::splat(f32::NAN), Vec3::X)];
    let t = g.trace(&gpu, Rays::List(&rays), GpuTraceOptions::default()).unwrap();
    assert_eq!(t.hits, [None, None]);
    let one_box = RayCounters { box_tests: 1, ..RayCounters::ZERO };
    assert_eq!(t.counters, [one_box, one_box]);

    let mut broken = build(&exact_mesh(), Strategy::SahBinned, 4);
    let last = broken.nodes.len() as u32;
    broken.nodes[0].index = last - 1;
    let e = GpuBinaryBvh::upload(&gpu, &broken).err().expect("refused");
    assert!(e.to_string().contains("past the last node"), "{e}");
}

/// The share of rays answered alike, after checking that every other one is explained.
fn compare_explained(
    what: &str,
    bvh: &Bvh,
    rays: &[Ray],
    gpu_hits: &[Option<Hit>],
    gpu_counts: &[RayCounters],
    order: TraversalOrder,
) -> f64 {
    let (hits, counts) = cpu_trace(bvh, rays, order);
    let mut differ = 0;
    for i in 0..rays.len() {
        if gpu_hits[i] != hits[i] || gpu_counts[i] != counts[i] {
            differ += 1;
            let why = explain(bvh, &rays[i], order, (gpu_hits[i], Some(gpu_counts[i])), 4);
            assert!(
                why.is_some(),
                "{what}: ray {i} {:?}: GPU {:?} {:?}, CPU {:?} {:?}, not near a boundary",
                rays[i],
                gpu_hits[i],
                gpu_counts[i],
                hits[i],
                counts[i]
            );
        }
    }
    let equal = 1.0 - differ as f64 / rays.len() as f64;
    use std::io::Write;
    let _ =
        writeln!(std::io::stderr(), "{what}: {differ} of {} rays differ ({:.3} % equal)", rays.len(), 100.0 * equal);
    equal
}

#[test]
fn camera_frames_equal_the_cpus_frames() {
    let Some(gpu) = gpu() else { return };
    let mesh = exact_mesh();
    let cam = Camera::framing(&mesh.bounds(), 64, 48);
    let rays = camera_rays(&cam);
    for strategy in [Strategy::SahBinned, Strategy::Lbvh] {
        let bvh = build(&mesh, strategy, 4);
        let g = GpuBinaryBvh::upload(&gpu, &bvh).unwrap();
        for order in ORDERS {
            let t = g.trace(&gpu, Rays::Camera(&cam), opts(order)).unwrap();
            let equal = compare_explained(
                &format!("exact mesh, camera, {strategy:?}, {order:?}"),
                &bvh,
                &rays,
                &t.hits,
                &t.counters,
                order,
            );
            assert!(equal >= 0.999, "{equal}");
        }
    }
}

#[test]
fn shared_meshes_equal_the_cpu_on_nearly_every_ray_and_the_rest_are_explained() {
    let Some(gpu) = gpu() else { return };
    for name in ["stanford-bunny.obj", "spot.obj", "suzanne.obj"] {
        let Some(mesh) = shared_mesh(name) else { return };
        let bvh = build(&mesh, Strategy::SahBinned, 4);
        let g = GpuBinaryBvh::upload(&gpu, &bvh).unwrap();
        let cam = Camera::framing(&mesh.bounds(), 96, 72);
        let primary = camera_rays(&cam);
        let incoherent = incoherent_rays(&mesh, 4096, 1);
        for order in ORDERS {
            let t = g.trace(&gpu, Rays::Camera(&cam), opts(order)).unwrap();
            let e = compare_explained(&format!("{name} camera {order:?}"), &bvh, &primary, &t.hits, &t.counters, order);
            assert!(e >= 0.999, "{name}: {e}");
            let t = g.trace(&gpu, Rays::List(&incoherent), opts(order)).unwrap();
            let e = compare_explained(
                &format!("{name} incoherent {order:?}"),
                &bvh,
                &incoherent,
                &t.hits,
                &t.counters,
                order,
            );
            assert!(e >= 0.999, "{name}: {e}");
        }
    }
}

/// The explanation is no rubber stamp: the CPU's own answer for a ray a few ulps away is
/// explained, a different triangle or other counts far from any boundary are not.
#[test]
fn explain_accepts_a_nearby_rays_answer_and_refuses_a_wrong_one() {
    let mesh = exact_mesh();
    let bvh = build(&mesh, Strategy::SahBinned, 4);
    let order = TraversalOrder::EntryDistance;
    // Aimed exactly at the vertex (1, 1, 1) from above: rays a few ulps away meet the
    // neighbouring triangles.
    let ray = Ray::new(Vec3::new(1.0, 1.0, 9.0), -Vec3::Z);
    let (h, c) = cpu_trace(&bvh, &[ray], order);
    assert!(explain(&bvh, &ray, order, (h[0], Some(c[0])), 4).is_some());
    let moved = Ray::new(Vec3::new(1.0f32.next_up(), 1.0f32.next_down(), 9.0), -Vec3::Z);
    let (mh, mc) = cpu_trace(&bvh, &[moved], order);
    assert!(explain(&bvh, &ray, order, (mh[0], Some(mc[0])), 4).is_some());
    let wrong = Hit { prim: (h[0].unwrap().prim + 5) % mesh.triangle_count() as u32, ..h[0].unwrap() };
    assert!(explain(&bvh, &ray, order, (Some(wrong), Some(c[0])), 4).is_none());
    let more = RayCounters { nodes_visited: c[0].nodes_visited + 9, ..c[0] };
    assert!(explain(&bvh, &ray, order, (h[0], Some(more)), 4).is_none());
}

/// An adapter without 64-bit floats keeps a zero edge function as zero: a ray through a shared
/// edge or vertex still hits (no gap), at the CPU's distance, possibly on the other triangle.
#[test]
fn without_doubles_no_ray_misses_what_the_cpu_hits() {
    let Some(_) = gpu() else { return };
    let gpu =
        bvhscope_gpu::Gpu::with_options(&bvhscope_gpu::GpuOptions { no_f64: true, ..Default::default() }).unwrap();
    assert!(!gpu.has_f64());
    let mesh = exact_mesh();
    let rays = exact_rays();
    let bvh = build(&mesh, Strategy::SahBinned, 4);
    let g = GpuBinaryBvh::upload(&gpu, &bvh).unwrap();
    let t = g.trace(&gpu, Rays::List(&rays), GpuTraceOptions::default()).unwrap();
    let (hits, _) = cpu_trace(&bvh, &rays, TraversalOrder::EntryDistance);
    for (i, (g, c)) in t.hits.iter().zip(&hits).enumerate() {
        assert_eq!(g.map(|h| h.t), c.map(|h| h.t), "ray {i} {:?}", rays[i]);
    }
}

/// A buffer limit too small for the whole frame splits it into batches with the same results; one
/// too small for a single row of results is refused before anything runs.
#[test]
fn small_buffer_limits_split_the_rays_into_batches_or_refuse_them() {
    let Some(_) = gpu() else { return };
    let small = |bytes| {
        bvhscope_gpu::Gpu::with_options(&bvhscope_gpu::GpuOptions {
            max_buffer_bytes: Some(bytes),
            ..Default::default()
        })
        .unwrap()
    };
    let mesh = exact_mesh();
    let bvh = build(&mesh, Strategy::SahBinned, 4);
    let cam = Camera::framing(&mesh.bounds(), 64, 48);
    let rays = camera_rays(&cam);
    let gpu = small(40_000);
    let g = GpuBinaryBvh::upload(&gpu, &bvh).unwrap();
    let t = g.trace(&gpu, Rays::Camera(&cam), GpuTraceOptions::default()).unwrap();
    assert!(t.batches > 1, "{} batches", t.batches);
    assert_all_equal("batched frame", &bvh, &rays, &t.hits, &t.counters, TraversalOrder::EntryDistance);
    let t = g.trace(&gpu, Rays::List(&rays), GpuTraceOptions::default()).unwrap();
    assert!(t.batches > 1);
    assert_all_equal("batched list", &bvh, &rays, &t.hits, &t.counters, TraversalOrder::EntryDistance);
    // The nodes alone need more than 1 KB.
    let e = GpuBinaryBvh::upload(&small(1024), &bvh).err().expect("too large");
    assert!(matches!(e, bvhscope_gpu::GpuError::TooLarge { .. }), "{e}");
    assert!(e.to_string().contains("the BVH's nodes"), "{e}");
}
