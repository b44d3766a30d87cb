//! The build driver's tests: the parallel and sequential builds agree, progress adds up, a build
//! can be cancelled while it runs.

use super::*;
use crate::bvh::builders::common::PARALLEL_MIN_PRIMS;
use crate::bvh::params::Strategy;
use crate::mesh::generate::torus;

#[test]
fn the_parallel_build_lays_out_the_same_tree_as_the_sequential_one() {
    // Big enough for several parallel levels (and parallel binning at the root).
    let mesh = torus(2.0, 0.5, 256, 160);
    assert!(mesh.triangle_count() > 16 * PARALLEL_MIN_PRIMS);
    // (LBVH's own parallel build is compared with its one-thread build in `bvh::lbvh`.)
    for strategy in Strategy::ALL.into_iter().filter(|&s| s != Strategy::SahSweep && s.splits_top_down()) {
        let params = BuildParams::with_strategy(strategy).clamped();
        let bvh = Bvh::build(&mesh, &params);
        let mut prims: Vec<BuildPrim> = (0..mesh.triangle_count())
            .map(|i| BuildPrim::new(Aabb::from_points(&mesh.triangle(i as u32)), i as u32))
            .collect();
        let progress = Progress { control: &WorkControl::new(), levels: 1 };
        let tri = |i: u32| mesh.triangle(i);
        let root = node_info(&prims).bounds;
        let setup = Setup { params: &params, tri: Some(&tri), root };
        let splitter = || strategy.splitter_for(&setup).unwrap();
        let d = Driver { params: &params, progress: &progress, splitter: &splitter };
        let (nodes, ids) = if strategy.splits_references() {
            let (nodes, refs, _) = driver::build_sequential(sbvh::Work::root(prims, &params), &d).unwrap();
            (nodes, refs.iter().map(|p| p.index()).collect::<Vec<_>>())
        } else {
            let (nodes, (), _) = driver::build_sequential(InPlace::root(&mut prims), &d).unwrap();
            (nodes, prims.iter().map(|p| p.index()).collect())
        };
        assert_eq!(bvh.nodes.len(), nodes.len(), "{strategy:?}");
        assert!(bvh.nodes == nodes, "{strategy:?}: the same nodes in the same places");
        assert!(bvh.prim_ids == ids, "{strategy:?}");
    }
}

#[test]
fn build_reports_progress_and_can_be_cancelled() {
    let mesh = torus(2.0, 0.5, 64, 32);
    for strategy in Strategy::ALL {
        for max_leaf_size in [1, 4, 16] {
            let control = WorkControl::new();
            let params = BuildParams { max_leaf_size, ..BuildParams::with_strategy(strategy) };
            let bvh = Bvh::build_controlled(&mesh, &params, &control).unwrap();
            let n = mesh.triangle_count() as u64;
            assert!(control.total() >= n * 8, "4096 triangles pass at least 8 levels");
            assert_eq!(control.done(), control.total(), "{strategy:?}/{max_leaf_size}: the work adds up");
            assert_eq!(crate::bvh::tree::distinct(&bvh.prim_ids), mesh.triangle_count(), "every triangle in a leaf");
        }
    }

    let cancelled = WorkControl::new();
    cancelled.cancel();
    assert_eq!(Bvh::build_controlled(&mesh, &BuildParams::default(), &cancelled).unwrap_err(), Cancelled);
}

#[test]
fn progress_moves_at_the_first_split_not_only_at_the_first_leaf() {
    // The exact sweep's first splits of a million triangles are the slow part of its build;
    // progress that counted only triangles placed in leaves stayed at 0 through them.
    let mesh = torus(2.0, 0.5, 1024, 512);
    let n = mesh.triangle_count() as u64;
    let control = WorkControl::new();
    let first_seen = std::thread::scope(|s| {
        let build = s.spawn(|| Bvh::build_controlled(&mesh, &BuildParams::with_strategy(Strategy::SahSweep), &control));
        let mut seen = 0;
        while seen == 0 && !build.is_finished() {
            seen = control.done();
        }
        control.cancel();
        let _ = build.join().expect("the build thread does not panic");
        seen
    });
    assert!(first_seen >= n, "the root's split counts its {n} triangles at once (first progress seen: {first_seen})");
    assert!(first_seen < control.total(), "and is only part of the work");
}

#[test]
fn a_build_cancelled_while_running_stops() {
    // A million triangles: the build runs long enough to be cancelled once it has made leaves.
    let mesh = torus(2.0, 0.5, 1024, 512);
    let control = WorkControl::new();
    let result = std::thread::scope(|s| {
        let build = s.spawn(|| Bvh::build_controlled(&mesh, &BuildParams::with_strategy(Strategy::SahSweep), &control));
        while control.done() == 0 && !build.is_finished() {
            std::thread::yield_now();
        }
        control.cancel();
        build.join().expect("the build thread does not panic")
    });
    assert_eq!(result.unwrap_err(), Cancelled, "cancelled part-way, after {} units", control.done());
    assert!(control.done() < control.total());
}

/// Issue 37: the builds split big nodes, cluster and lay out in parallel, and the tree must not
/// depend on the thread count. Every strategy builds a mesh big enough for every parallel path
/// (the partition, the selection and the sweep from 65,536 triangles, PLOC's chunked rounds, the
/// SBVH's passes from 16,384 references, and its spatial binning on crossing needles) on one
/// and on four threads; the nodes must be equal to the bit, and the leaves' triangles too.
#[test]
fn every_strategy_builds_the_same_tree_on_one_and_four_threads() {
    let big = torus(2.0, 0.5, 512, 256);
    assert!(big.triangle_count() >= 4 * crate::parallel::PARTITION_MIN);
    let needles = crate::mesh::generate::needles(40_000, 37);
    let bits = |nodes: &[BvhNode]| -> Vec<[u32; 8]> {
        let f = |x: [f32; 3]| x.map(f32::to_bits);
        nodes
            .iter()
            .map(|n| {
                let (lo, hi) = (f(n.lo), f(n.hi));
                [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], n.index, (n.count as u32) << 8 | n.axis as u32]
            })
            .collect()
    };
    for strategy in Strategy::ALL {
        let meshes = if strategy == Strategy::Sbvh { vec![&big, &needles] } else { vec![&big] };
        for mesh in meshes {
            let params = BuildParams { strategy, layout: crate::bvh::Layout::Binary, ..Default::default() };
            let build = |threads| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| Bvh::build(mesh, &params))
            };
            let (one, four) = (build(1), build(4));
            let what = format!("{strategy:?}, {} triangles", mesh.triangle_count());
            assert_eq!(one.nodes.len(), four.nodes.len(), "{what}");
            assert!(bits(&one.nodes) == bits(&four.nodes), "{what}: the same nodes, to the bit");
            assert!(one.prim_ids == four.prim_ids, "{what}: the same triangles in the same leaves");
            if std::ptr::eq(mesh, &needles) {
                assert!(one.report.spatial_splits > 0, "{what}: spatial splits were made");
            }
        }
    }
}
