//! The GPU never answers silently wrong (issue 46), on lavapipe in CI: walks longer than the GPU's
//! step budget (a fan of triangles sharing one box, thousands of identical triangles, a correct
//! tree of fat boxes, a 100,000-deep chain) are finished on the CPU and said to be, so every hit
//! and count equals the CPU's walk; the Möller–Trumbore tests and the split-axis-sign order run on
//! the GPU with the CPU's hits and counts; the GPU's LBVH and PLOC build the CPU's trees on
//! thousands of identical centroids, and a broken tree is refused before anyone uses it.

use bvhscope::bvh::{
    Accelerator, AnyBvh, BuildParams, Bvh, BvhNode, Layout, RayCounters, SceneBvh, Strategy, TraceOptions,
    TraversalOrder,
};
use bvhscope::geometry::{Ray, TriangleTest};
use bvhscope::gpu_path::{build_on_gpu, GpuNodes, GpuTree};
use bvhscope::mesh::{generate, Mesh};
use bvhscope::render::Camera;
use bvhscope_gpu::{Gpu, Rays, STEP_BUDGET};
use glam::Vec3;
use std::sync::Arc;

const ALL_TRACES: [TraceOptions; 6] = [
    TraceOptions { order: TraversalOrder::EntryDistance, test: TriangleTest::Watertight },
    TraceOptions { order: TraversalOrder::SplitAxisSign, test: TriangleTest::Watertight },
    TraceOptions { order: TraversalOrder::EntryDistance, test: TriangleTest::MollerTrumbore },
    TraceOptions { order: TraversalOrder::SplitAxisSign, test: TriangleTest::MollerTrumbore },
    TraceOptions { order: TraversalOrder::EntryDistance, test: TriangleTest::MollerTrumboreStored },
    TraceOptions { order: TraversalOrder::SplitAxisSign, test: TriangleTest::MollerTrumboreStored },
];

/// `n` triangles of one box, the unit square: two corners shared, the third anywhere inside.
fn fan(n: usize) -> Mesh {
    let mut positions = vec![Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0)];
    let mut triangles = Vec::new();
    for k in 0..n {
        let a = k as f32 / n as f32;
        positions.push(Vec3::new(a, 1.0 - a * a, 0.0));
        triangles.push([0, 1, 2 + k as u32]);
    }
    Mesh::from_triangles("fan", positions, triangles)
}

/// `n` copies of one triangle.
fn identical(n: usize) -> Mesh {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    Mesh::from_triangles("same", positions, vec![[0, 1, 2]; n])
}

/// A tree whose every box is the root's: correct (every box holds its triangles), and every ray
/// that enters it visits every node.
fn fat(bvh: &Bvh) -> Bvh {
    let root = bvh.nodes[0].bounds();
    let nodes =
        bvh.nodes
            .iter()
            .map(|n| {
                if n.is_leaf() {
                    BvhNode::leaf(root, n.index, n.count)
                } else {
                    BvhNode::interior(root, n.index, n.axis)
                }
            })
            .collect();
    Bvh { nodes, ..bvh.clone() }
}

/// A chain `depth` deep over `depth + 1` triangles: each interior node's left child a leaf of
/// one triangle, its right child the rest of the chain; every box the mesh's.
fn chain(mesh: &Mesh, depth: usize) -> Bvh {
    let b = mesh.bounds();
    let mut nodes = Vec::with_capacity(2 * depth + 1);
    for k in 0..depth {
        // Node 2k: interior, children 2k + 1 (leaf of triangle k) and 2k + 2.
        nodes.push(BvhNode::interior(b, 2 * k as u32 + 1, 0));
        nodes.push(BvhNode::leaf(b, k as u32, 1));
    }
    nodes.push(BvhNode::leaf(b, depth as u32, 1));
    let prim_ids: Vec<u32> = (0..=depth as u32).collect();
    let tris = prim_ids.iter().map(|&p| mesh.triangle(p)).collect();
    let params = BuildParams { layout: Layout::Binary, ..Default::default() };
    Bvh { nodes, prim_ids, tris, params, report: Default::default() }
}

/// Strips of small triangles in the plane z = 0, `n` in all.
fn strips(n: usize) -> Mesh {
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    let side = (n as f32).sqrt().ceil() as usize;
    for k in 0..n {
        let (x, y) = ((k % side) as f32, (k / side) as f32);
        let i = positions.len() as u32;
        positions.extend([Vec3::new(x, y, 0.0), Vec3::new(x + 0.9, y, 0.0), Vec3::new(x, y + 0.9, 0.0)]);
        triangles.push([i, i + 1, i + 2]);
    }
    Mesh::from_triangles("strips", positions, triangles)
}

/// The GPU's hits and counts of `rays` through `bvh` in `nodes` against the CPU's walk of the
/// same tree, for every trace option; how many rays were finished on the CPU (the most of any).
fn agrees(gpu: &Gpu, what: &str, bvh: Bvh, mesh: Mesh, rays: Rays, nodes: GpuNodes, traces: &[TraceOptions]) -> usize {
    let mesh = Arc::new(mesh);
    let binary = bvh.clone();
    let scene = SceneBvh::Single { bvh: AnyBvh::Binary(bvh), mesh, imported: None };
    let (tree, _) = GpuTree::new(gpu, &scene, nodes).unwrap_or_else(|e| panic!("{what}: {e}"));
    let mut most = 0;
    for &trace in traces {
        let t = tree.trace_rays(gpu, rays, trace, true).unwrap_or_else(|e| panic!("{what}: {e}"));
        assert!(t.unfinished.is_empty(), "{what}: every unfinished ray is finished");
        most = most.max(t.cpu_finished);
        for i in 0..rays.len() {
            let (hit, counts) = tree.cpu_walk(&mut rays.ray(i), trace);
            assert_eq!(t.hits[i], hit, "{what} {trace:?} {nodes:?}: ray {i}'s hit");
            assert_eq!(t.counters[i], counts, "{what} {trace:?} {nodes:?}: ray {i}'s counts");
            // Binary nodes: the counts are core's walk's (an independent reference).
            if nodes == GpuNodes::Binary {
                let mut c = RayCounters::ZERO;
                let h = binary.closest_hit(&mut rays.ray(i), trace, &mut c);
                assert_eq!((t.hits[i], t.counters[i]), (h, c), "{what} {trace:?}: ray {i} against core's walk");
            }
        }
    }
    most
}

/// Rays straight down through an `n`×`n` grid over the unit square (z from 1).
fn down(n: usize) -> Vec<Ray> {
    (0..n * n)
        .map(|k| {
            let (x, y) = ((k % n) as f32 + 0.5, (k / n) as f32 + 0.5);
            Ray::new(Vec3::new(x / n as f32, y / n as f32, 1.0), Vec3::new(0.0, 0.0, -1.0))
        })
        .collect()
}

#[test]
fn walks_past_the_step_budget_are_finished_on_the_cpu_never_taken_for_misses() {
    let Some(gpu) = bvhscope_gpu::gpu_for_tests() else { return };
    let formats = GpuNodes::ALL;
    let sah = BuildParams { layout: Layout::Binary, ..Default::default() };
    // The fan: 40,000 triangles of one box; the ray among the grid's.
    let mesh = fan(40_000);
    let mut rays = down(8);
    rays.push(Ray::new(Vec3::new(0.95, 0.99995, 1.0), Vec3::new(0.0, 0.0, -1.0)));
    for nodes in formats {
        let bvh = Bvh::build(&mesh, &sah);
        let finished = agrees(&gpu, "fan", bvh, mesh.clone(), Rays::List(&rays), nodes, &ALL_TRACES);
        assert!(finished > 0, "the fan's walks pass {STEP_BUDGET} steps");
    }
    let bvh = Bvh::build(&mesh, &sah);
    let scene = SceneBvh::Single { bvh: AnyBvh::Binary(bvh), mesh: Arc::new(mesh.clone()), imported: None };
    let (tree, _) = GpuTree::new(&gpu, &scene, GpuNodes::Binary).unwrap();
    let last = [*rays.last().unwrap()];
    let t = tree.trace_rays(&gpu, Rays::List(&last), TraceOptions::default(), true).unwrap();
    assert!(t.hits[0].is_some() && t.cpu_finished == 1, "the issue's ray hits: {:?}", t.hits[0]);

    // 20,000 identical triangles.
    let mesh = identical(20_000);
    for nodes in formats {
        let bvh = Bvh::build(&mesh, &sah);
        assert!(agrees(&gpu, "identical", bvh, mesh.clone(), Rays::List(&down(6)), nodes, &ALL_TRACES[..1]) > 0);
    }

    // A correct tree of fat boxes over a 20,000-triangle knot, seen by a camera.
    let mesh = generate::torus_knot(2, 3, 0.3, 500, 20);
    let camera = Camera::framing(&mesh.bounds(), 12, 8);
    for nodes in formats {
        let bvh = fat(&Bvh::build(&mesh, &sah));
        let finished = agrees(&gpu, "fat boxes", bvh, mesh.clone(), Rays::Camera(&camera), nodes, &ALL_TRACES[..1]);
        assert!(finished > 0);
    }

    // A 100,000-deep chain: its walks need no stack past the budget, and are finished too.
    let mesh = strips(100_001);
    let bvh = chain(&mesh, 100_000);
    let camera = Camera::framing(&mesh.bounds(), 8, 8);
    let finished = agrees(&gpu, "chain", bvh, mesh, Rays::Camera(&camera), GpuNodes::Binary, &ALL_TRACES[..1]);
    assert!(finished > 0);

    // An ordinary mesh: no ray needs the CPU.
    let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
    let camera = Camera::framing(&mesh.bounds(), 24, 16);
    for nodes in formats {
        let bvh = Bvh::build(&mesh, &sah);
        assert_eq!(agrees(&gpu, "knot", bvh, mesh.clone(), Rays::Camera(&camera), nodes, &ALL_TRACES), 0);
    }
}

/// Every triangle test and both child orders on the GPU: the CPU's hits and counts, on meshes
/// whose rays meet edges and vertices (the handout's Möller–Trumbore test and its stored form
/// included).
#[test]
fn moller_trumbore_and_the_split_axis_order_run_on_the_gpu_as_on_the_cpu() {
    let Some(gpu) = bvhscope_gpu::gpu_for_tests() else { return };
    let mesh = generate::torus_knot(2, 3, 0.3, 96, 8);
    let camera = Camera::framing(&mesh.bounds(), 32, 24);
    let incoherent = bvhscope::render::incoherent_rays(&mesh, 2000, 1);
    for strategy in [Strategy::SahBinned, Strategy::Midpoint] {
        for nodes in GpuNodes::ALL {
            let bvh = || Bvh::build(&mesh, &BuildParams { strategy, layout: Layout::Binary, ..Default::default() });
            agrees(&gpu, "knot", bvh(), mesh.clone(), Rays::Camera(&camera), nodes, &ALL_TRACES);
            agrees(&gpu, "knot, incoherent", bvh(), mesh.clone(), Rays::List(&incoherent), nodes, &ALL_TRACES);
        }
    }
}

/// The GPU's LBVH and PLOC on 5,000 and 20,000 identical triangles, and on as many triangles
/// sharing one centroid: the CPU's tree, node for node, which passes the structure check.
#[test]
fn gpu_builders_make_the_cpus_tree_on_identical_centroids() {
    let Some(gpu) = bvhscope_gpu::gpu_for_tests() else { return };
    // Triangles turned about one point: one centroid, different boxes.
    let turned = |n: usize| {
        let (mut positions, mut triangles) = (Vec::new(), Vec::new());
        for k in 0..n {
            let a = k as f32 * 0.001;
            let (c, s) = (a.cos(), a.sin());
            let i = positions.len() as u32;
            positions.extend([Vec3::new(c, s, 0.0), Vec3::new(-c, -s, 0.5), Vec3::new(-s, c, -0.5)]);
            triangles.push([i, i + 1, i + 2]);
        }
        Mesh::from_triangles("turned", positions, triangles)
    };
    for (name, mesh) in
        [("5k identical", identical(5000)), ("20k identical", identical(20_000)), ("8k turned", turned(8000))]
    {
        for strategy in [Strategy::Lbvh, Strategy::Ploc] {
            for leaf in [1, 4] {
                let params =
                    BuildParams { strategy, layout: Layout::Binary, max_leaf_size: leaf, ..Default::default() };
                let (built, _) = build_on_gpu(&gpu, &mesh, &params).unwrap().expect("built on the GPU");
                let AnyBvh::Binary(g) = built else { panic!("binary") };
                let cpu = Bvh::build(&mesh, &params);
                assert_eq!(g.nodes, cpu.nodes, "{name} {strategy:?} leaf {leaf}: the CPU's nodes");
                assert_eq!(g.prim_ids, cpu.prim_ids, "{name} {strategy:?} leaf {leaf}: the CPU's order");
                let dump = bvhscope::dump::BvhDump::of_bvh(&g, &mesh, None);
                let findings = bvhscope::explain::check::check_tree(&dump, &mesh);
                assert!(findings.iter().all(|f| !f.defect), "{name} {strategy:?}: {findings:?}");
            }
        }
    }
}

/// A GPU build's tree is checked before it is used: what the check says of a tree with a cycle
/// and of one with a triangle in no leaf (the failures a driver's loop limit made).
#[test]
fn a_broken_gpu_tree_is_named_never_used() {
    let mesh = identical(64);
    let good = Bvh::build(&mesh, &BuildParams { strategy: Strategy::Lbvh, ..Default::default() });
    assert_eq!(bvhscope_gpu::verify::problem(&good, &mesh), None);
    let mut cycle = good.clone();
    let inner = cycle.nodes.iter().rposition(|n| !n.is_leaf() && n.index > 1).unwrap();
    cycle.nodes[inner].index = 1;
    let why = bvhscope_gpu::verify::problem(&cycle, &mesh).unwrap();
    assert!(why.contains("reached twice"), "{why}");
    let mut short = good.clone();
    let leaf = short.nodes.iter().position(|n| n.is_leaf() && n.count >= 2).unwrap();
    short.nodes[leaf].count -= 1;
    let why = bvhscope_gpu::verify::problem(&short, &mesh).unwrap();
    assert!(why.contains("is in no leaf"), "{why}");
}
