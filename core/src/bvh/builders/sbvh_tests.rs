//! The SBVH's tests (`sbvh.rs`).

use crate::bvh::node::Bvh;
use crate::bvh::params::{BuildParams, Layout, Strategy};
use crate::bvh::stats::TreeStats;
use crate::mesh::generate;

fn sbvh(growth: u32) -> BuildParams {
    BuildParams { strategy: Strategy::Sbvh, layout: Layout::Binary, sbvh_growth: growth, ..Default::default() }
}

/// Long thin triangles whose boxes overlap: spatial splits cut them, within the growth bound,
/// and the tree is far cheaper than the binned SAH's; with no growth allowed it is the binned
/// SAH's tree (the same object splits by the same code).
#[test]
fn spatial_splits_cut_slivers_within_the_growth_bound() {
    let mesh = generate::diagonal_rods(4, 6, 6.0, 0.03, 0.2);
    let n = mesh.triangle_count();
    let sah = Bvh::build(&mesh, &BuildParams { layout: Layout::Binary, ..Default::default() });
    let none = Bvh::build(&mesh, &sbvh(0));
    assert!(none.nodes == sah.nodes && none.prim_ids == sah.prim_ids, "growth 0: the binned SAH's tree");
    for growth in [30, 100] {
        let bvh = Bvh::build(&mesh, &sbvh(growth));
        let stats = TreeStats::of(&bvh);
        assert_eq!(stats.triangles, n);
        assert!(stats.references > n && stats.references <= n + n * growth as usize / 100, "{stats:?}");
        assert!(stats.spatial_splits > 0 && bvh.report.spatial_splits == stats.spatial_splits);
        let base = TreeStats::of(&sah).sah_cost;
        assert!(stats.sah_cost < 0.85 * base, "growth {growth}: SAH {} against {base}", stats.sah_cost);
    }
}

/// The parallel top of the build and the sequential rest make the same tree on any number of
/// threads: budgets and progress are shared by rule, not by whoever gets there first.
#[test]
fn the_tree_does_not_depend_on_the_thread_count() {
    let mut mesh = generate::torus_knot(2, 3, 0.3, 512, 16);
    let rods = generate::diagonal_rods(4, 6, 6.0, 0.03, 0.2);
    let base = mesh.positions.len() as u32;
    mesh.positions.extend(&rods.positions);
    mesh.triangles.extend(rods.triangles.iter().map(|t| t.map(|i| i + base)));
    mesh.groups.clear();
    mesh.groups.push(crate::mesh::MeshGroup { name: "all".into(), triangles: 0..mesh.triangles.len() as u32 });
    assert!(mesh.triangle_count() > 4 * crate::bvh::builders::common::PARALLEL_MIN_PRIMS);
    let build = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| Bvh::build(&mesh, &sbvh(30)))
    };
    let (one, two) = (build(1), build(2));
    assert!(one.prim_ids.len() > mesh.triangle_count());
    assert!(one.nodes == two.nodes && one.prim_ids == two.prim_ids);
}
