//! The GPU LBVH is core's LBVH node for node: the same nodes (boxes, children, leaves, split
//! axes), the same primitive order, the same triangles in leaf order, for leaves of 1 to 7 and
//! meshes with long runs of equal Morton codes (split by their places, Karras's tie-break, as core splits them), tiny meshes
//! and an empty one. Where core's multi-threaded sort puts equal codes out of triangle order (it
//! sorts on the code alone, unstably), the trees agree on everything the codes decide.

mod common;

use bvhscope_core::bvh::morton::MortonOrder;
use bvhscope_core::bvh::{BuildParams, Bvh, Layout, Strategy};
use bvhscope_core::dump::BvhDump;
use bvhscope_core::explain::check::check_tree;
use bvhscope_core::mesh::{generate, Mesh};
use bvhscope_gpu::{Gpu, GpuError, GpuLbvh, GpuOptions};
use common::*;
use glam::Vec3;

fn params(max_leaf_size: u32) -> BuildParams {
    BuildParams { strategy: Strategy::Lbvh, max_leaf_size, layout: Layout::Binary, ..BuildParams::default() }
}

/// Whether core's tree keeps equal codes in triangle order (its sort is stable on this mesh).
fn cpu_order_is_stable(cpu: &Bvh) -> bool {
    let Some(order) = MortonOrder::of(cpu) else { return true };
    (1..order.codes.len()).all(|i| order.codes[i] != order.codes[i - 1] || cpu.prim_ids[i] > cpu.prim_ids[i - 1])
}

fn assert_same_tree(what: &str, mesh: &Mesh, cpu: &Bvh, gpu: &Bvh) {
    assert_eq!(gpu.nodes.len(), cpu.nodes.len(), "{what}: node count");
    if cpu_order_is_stable(cpu) {
        for (i, (g, c)) in gpu.nodes.iter().zip(&cpu.nodes).enumerate() {
            assert_eq!(g, c, "{what}: node {i}");
        }
        assert_eq!(gpu.prim_ids, cpu.prim_ids, "{what}: primitive order");
        assert_eq!(gpu.tris, cpu.tris, "{what}: triangles in leaf order");
    } else {
        // The codes decide the topology and the split axes; equal codes may sit in another order.
        for (i, (g, c)) in gpu.nodes.iter().zip(&cpu.nodes).enumerate() {
            assert_eq!((g.index, g.count, g.axis), (c.index, c.count, c.axis), "{what}: node {i}'s topology");
        }
        let (go, co) = (MortonOrder::of(gpu).expect("an LBVH"), MortonOrder::of(cpu).expect("an LBVH"));
        assert_eq!(go.codes, co.codes, "{what}: codes in leaf order");
        let mut a = gpu.prim_ids.clone();
        let mut b = cpu.prim_ids.clone();
        a.sort();
        b.sort();
        assert_eq!(a, b);
        let defects: Vec<String> = check_tree(&BvhDump::of_bvh(gpu, mesh, None), mesh)
            .into_iter()
            .filter(|f| f.defect)
            .map(|f| f.text)
            .collect();
        assert!(defects.is_empty(), "{what}: {defects:?}");
    }
}

/// `copies` triangles with the same centroid among others: a run of equal codes longer than any leaf.
fn with_a_long_run(copies: u32) -> Mesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..copies + 40 {
        let s = if i < copies { 0.5 + i as f32 * 1e-3 } else { (i - copies) as f32 * 0.37 };
        let c = if i < copies { Vec3::splat(2.0) } else { Vec3::new(s, (s * 3.1).sin() * 4.0, (s * 1.7).cos() * 4.0) };
        let b = positions.len() as u32;
        // Symmetric about c, so every copy's box has the centre c.
        positions.extend([
            c + Vec3::new(-s, -s, 0.0),
            c + Vec3::new(s, s, 0.0),
            c + Vec3::new(s, -s, 0.0),
            c + Vec3::new(-s, s, 0.0),
        ]);
        triangles.push([b, b + 1, b + 2]);
        triangles.push([b, b + 3, b + 1]);
    }
    Mesh::from_triangles("run", positions, triangles)
}

#[test]
fn the_gpu_lbvh_is_the_cpu_lbvh_node_for_node() {
    let Some(gpu) = gpu() else { return };
    let lbvh = GpuLbvh::new(&gpu).unwrap();
    let tri = |k: u32| {
        let positions: Vec<Vec3> =
            (0..3 * k).map(|i| Vec3::new(i as f32, (i * i % 7) as f32, (i % 3) as f32)).collect();
        Mesh::from_triangles("few", positions, (0..k).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect())
    };
    let mut meshes = vec![
        ("exact", exact_mesh()),
        ("knot", generate::torus_knot(2, 3, 0.3, 256, 24)),
        ("run", with_a_long_run(300)),
        ("one", tri(1)),
        ("three", tri(3)),
        ("nine", tri(9)),
        ("empty", Mesh::from_triangles("empty", vec![], vec![])),
    ];
    for name in ["stanford-bunny.obj", "spot.obj"] {
        if let Some(m) = shared_mesh(name) {
            meshes.push((name, m));
        }
    }
    for (name, mesh) in &meshes {
        for leaf in [1, 4, 7] {
            let cpu = Bvh::build(mesh, &params(leaf));
            let (g, t) = lbvh.build(&gpu, mesh, &params(leaf)).unwrap();
            assert_same_tree(&format!("{name}, leaves of {leaf}"), mesh, &cpu, &g);
            assert_eq!(
                g.report.fallback_splits, cpu.report.fallback_splits,
                "{name}/{leaf}: ranges of equal codes split by places"
            );
            assert!(t.verify_passes >= 1 || mesh.triangle_count() == 0);
            if *name == "run" {
                assert!(g.report.fallback_splits > 0, "the run of 600 equal codes is split by places");
            }
        }
    }
}

/// Core's sort is stable for small meshes only; on a big one its order of equal codes differs,
/// and the trees must still agree on all the codes decide (and the GPU's pass the checker).
#[test]
fn on_a_big_mesh_the_trees_agree_on_what_the_codes_decide() {
    let Some(gpu) = gpu() else { return };
    let mesh = generate::torus_knot(2, 3, 0.3, 2048, 64);
    let cpu = Bvh::build(&mesh, &params(4));
    let (g, t) = GpuLbvh::new(&gpu).unwrap().build(&gpu, &mesh, &params(4)).unwrap();
    assert_same_tree("big knot", &mesh, &cpu, &g);
    use std::io::Write;
    let _ = writeln!(
        std::io::stderr(),
        "GPU LBVH of {} triangles on {}: {:?} (upload {:?}, codes {:?}, sort {:?}, emission {:?}, boxes {:?} in {} check passes, download {:?}); core's sort stable here: {}",
        mesh.triangle_count(),
        gpu.name(),
        t.total(),
        t.upload,
        t.codes,
        t.sort,
        t.emission,
        t.boxes,
        t.verify_passes,
        t.download,
        cpu_order_is_stable(&cpu)
    );
}

#[test]
fn a_mesh_beyond_a_buffer_limit_is_refused_before_upload() {
    let Some(_) = gpu() else { return };
    let gpu = Gpu::with_options(&GpuOptions { max_buffer_bytes: Some(64 * 1024), ..Default::default() }).unwrap();
    let lbvh = GpuLbvh::new(&gpu).unwrap();
    let small = generate::torus(2.0, 0.5, 16, 8);
    assert!(lbvh.build(&gpu, &small, &params(4)).is_ok(), "{} triangles fit", small.triangle_count());
    let big = generate::torus(2.0, 0.5, 64, 32);
    let e = lbvh.build(&gpu, &big, &params(4)).unwrap_err();
    match &e {
        GpuError::TooLarge { what, bytes, limit, .. } => {
            assert_eq!(*limit, 64 * 1024);
            assert!(*bytes > *limit);
            assert_eq!(what, "the build's triangles", "the first buffer too large is named");
        }
        other => panic!("{other}"),
    }
    assert!(GpuLbvh::check_size(&gpu, small.triangle_count()).is_ok());
}

/// A device lost before or during a build: an error, never a panic, and no tree.
#[test]
fn a_lost_device_gives_an_error() {
    let Some(gpu) = gpu() else { return };
    let lbvh = GpuLbvh::new(&gpu).unwrap();
    let mesh = generate::torus(2.0, 0.5, 32, 16);
    assert!(lbvh.build(&gpu, &mesh, &params(4)).is_ok());
    gpu.destroy();
    let e = lbvh.build(&gpu, &mesh, &params(4)).unwrap_err();
    assert!(matches!(e, GpuError::Lost(_) | GpuError::Rejected(_)), "{e:?}");
    let bvh = Bvh::build(&mesh, &params(4));
    let e = bvhscope_gpu::GpuBinaryBvh::upload(&gpu, &bvh).and_then(|g| {
        g.trace(
            &gpu,
            bvhscope_gpu::Rays::List(&[bvhscope_core::geometry::Ray::new(Vec3::ZERO, Vec3::X)]),
            Default::default(),
        )
    });
    assert!(e.is_err());
}
