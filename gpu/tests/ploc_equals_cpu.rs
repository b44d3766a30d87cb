//! GPU PLOC clusters as core's PLOC does (same neighbour rule, same ties, same merges) and lays the
//! tree out as core does: the same tree node for node where core's Morton order keeps equal codes
//! in triangle order; elsewhere an SAH cost within 2 % of core's and a tree the checker passes.

mod common;

use bvhscope_core::bvh::morton::MortonOrder;
use bvhscope_core::bvh::{BuildParams, Bvh, Layout, Strategy, TreeStats};
use bvhscope_core::dump::BvhDump;
use bvhscope_core::explain::check::check_tree;
use bvhscope_core::mesh::{generate, Mesh};
use bvhscope_gpu::{Gpu, GpuError, GpuOptions, GpuPloc};
use common::*;
use glam::Vec3;

fn params(max_leaf_size: u32, ploc_radius: u32) -> BuildParams {
    BuildParams {
        strategy: Strategy::Ploc,
        max_leaf_size,
        ploc_radius,
        layout: Layout::Binary,
        ..BuildParams::default()
    }
}

/// Whether core's Morton sort kept equal codes in triangle order on this mesh (it sorts unstably
/// on the code alone; small meshes are sorted stably): computed from core's LBVH, whose leaf order
/// is that sort.
fn cpu_sort_is_stable(mesh: &Mesh) -> bool {
    let lbvh =
        Bvh::build(mesh, &BuildParams { strategy: Strategy::Lbvh, layout: Layout::Binary, ..BuildParams::default() });
    let Some(order) = MortonOrder::of(&lbvh) else { return true };
    (1..order.codes.len()).all(|i| order.codes[i] != order.codes[i - 1] || lbvh.prim_ids[i] > lbvh.prim_ids[i - 1])
}

fn no_defects(what: &str, mesh: &Mesh, bvh: &Bvh) {
    let defects: Vec<String> =
        check_tree(&BvhDump::of_bvh(bvh, mesh, None), mesh).into_iter().filter(|f| f.defect).map(|f| f.text).collect();
    assert!(defects.is_empty(), "{what}: {defects:?}");
}

#[test]
fn the_gpu_ploc_is_the_cpu_ploc_node_for_node() {
    let Some(gpu) = gpu() else { return };
    let ploc = GpuPloc::new(&gpu).unwrap();
    // Equal boxes (copies of one triangle) exercise the tie rule and rounds without a mutual pair.
    let copies = {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        Mesh::from_triangles(
            "copies",
            (0..90).map(|i| tri[i % 3]).collect(),
            (0..30).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect(),
        )
    };
    let one = Mesh::from_triangles("one", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
    let mut meshes = vec![
        ("exact", exact_mesh()),
        ("knot", generate::torus_knot(2, 3, 0.3, 256, 24)),
        ("copies", copies),
        ("one", one),
    ];
    if let Some(m) = shared_mesh("stanford-bunny.obj") {
        meshes.push(("bunny", m));
    }
    for (name, mesh) in &meshes {
        assert!(cpu_sort_is_stable(mesh), "{name}: core's sort is stable on small meshes");
        for (leaf, radius) in [(1, 16), (4, 16), (4, 1), (8, 5)] {
            let what = format!("{name}, leaves of {leaf}, radius {radius}");
            let cpu = Bvh::build(mesh, &params(leaf, radius));
            let (g, t) = ploc.build(&gpu, mesh, &params(leaf, radius)).unwrap();
            assert_eq!(g.nodes.len(), cpu.nodes.len(), "{what}: node count");
            for (i, (a, b)) in g.nodes.iter().zip(&cpu.nodes).enumerate() {
                assert_eq!(a, b, "{what}: node {i}");
            }
            assert_eq!(g.prim_ids, cpu.prim_ids, "{what}: primitive order");
            assert_eq!(g.tris, cpu.tris, "{what}: triangles");
            assert!(t.rounds as usize <= mesh.triangle_count(), "{what}: rounds");
        }
    }
    let empty = Mesh::from_triangles("empty", vec![], vec![]);
    let (g, _) = ploc.build(&gpu, &empty, &params(4, 16)).unwrap();
    assert_eq!(g.nodes, Bvh::build(&empty, &params(4, 16)).nodes);
}

#[test]
fn on_a_big_mesh_the_sah_cost_is_core_s_within_two_percent_and_the_tree_checks_clean() {
    let Some(gpu) = gpu() else { return };
    let mesh = generate::torus_knot(2, 3, 0.3, 2048, 64);
    let cpu = Bvh::build(&mesh, &params(4, 16));
    let (g, t) = GpuPloc::new(&gpu).unwrap().build(&gpu, &mesh, &params(4, 16)).unwrap();
    let (a, b) = (TreeStats::of(&g).sah_cost, TreeStats::of(&cpu).sah_cost);
    use std::io::Write;
    let _ = writeln!(
        std::io::stderr(),
        "GPU PLOC of {} triangles: SAH {a:.3} (core's {b:.3}), {} rounds, {:?} (clustering {:?}, layout on the host {:?}); same tree: {}",
        mesh.triangle_count(),
        t.rounds,
        t.total(),
        t.emission,
        t.boxes,
        g.nodes == cpu.nodes
    );
    assert!((a - b).abs() <= 0.02 * b, "SAH {a} against core's {b}");
    no_defects("big knot", &mesh, &g);
}

#[test]
fn a_mesh_beyond_a_buffer_limit_is_refused_before_upload() {
    let Some(_) = gpu() else { return };
    let gpu = Gpu::with_options(&GpuOptions { max_buffer_bytes: Some(64 * 1024), ..Default::default() }).unwrap();
    let big = generate::torus(2.0, 0.5, 64, 32);
    let e = GpuPloc::new(&gpu).unwrap().build(&gpu, &big, &params(4, 16)).unwrap_err();
    assert!(matches!(e, GpuError::TooLarge { limit: 65536, .. }), "{e}");
}
