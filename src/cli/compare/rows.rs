//! The table's rows: every strategy built and measured on the same primary rays, next to a
//! linear scan of all triangles (how, in `compare`'s module comment).

use crate::bvh::{epo, AnyBvh, BuildParams, Hierarchy, LinearScan, Strategy, TraceOptions, TreeStats, TreeView};
use crate::cli::args::BuildArgs;
use crate::cli::progress;
use crate::explain::timing::{self, ms, time_linear, time_tree};
use crate::render::{render, Camera, RenderSettings};
use std::time::{Duration, Instant};

/// More measured of every tree while the rows are made (`compare --ray-kind`'s table), each tree
/// while it is built, so no tree is kept.
pub trait PerTree {
    fn tree(&mut self, t: Tree<'_>);
    /// After the last tree: the linear scan's measures within `budget`.
    fn done(&mut self, mesh: &crate::mesh::Mesh, budget: Duration, traces: &rayon::ThreadPool);
}

/// A tree as `PerTree` is given it: `bvh`, the tree of `row`; `first_layout`: of the first layout
/// compared; `runs` as `--runs`; `pools`: the frames' and the single-ray traces'.
pub struct Tree<'a> {
    pub bvh: &'a AnyBvh,
    pub row: &'a CompareRow,
    pub first_layout: bool,
    pub runs: u32,
    pub pools: (&'a rayon::ThreadPool, &'a rayon::ThreadPool),
}

/// One row of the table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CompareRow {
    pub name: String,
    pub build_ms: Option<f64>,
    pub nodes: usize,
    pub max_depth: u32,
    pub mean_leaf_depth: f64,
    pub sah_cost: Option<f64>,
    /// End-point overlap of the binary tree (the same for both layouts of a strategy).
    pub epo: Option<f64>,
    /// Where the EPO was estimated (`bvh::epo::Epo`): two standard errors of it.
    pub epo_error: Option<f64>,
    /// Means over all primary rays.
    pub nodes_per_ray: f64,
    pub tri_tests_per_ray: f64,
    /// Means over the rays that enter the root box.
    pub root_nodes_per_ray: f64,
    pub root_tri_tests_per_ray: f64,
    /// Single rays, closest hit, no shading, on `trace_threads` (median; projected from a sample
    /// for a sampled row).
    pub trace_ms: f64,
    /// Runs of `trace_ms` timed (`timing::time_tree`; the linear scan's one).
    pub trace_runs: usize,
    /// The renderer's full frame with shading (median of the timed frames; the linear scan's is
    /// its single-ray trace on the frame's threads, as it has no packets).
    pub frame_ms: f64,
    /// Rays per second of the frame.
    pub mrays_per_s: f64,
    /// The linear scan's trace time over this row's.
    pub speedup_over_linear: f64,
    /// Rays actually timed, when fewer than the frame's.
    pub sampled_rays: Option<usize>,
    pub fallback_splits: u32,
}

/// How the rows were measured (for the table's footer and the JSON).
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct CompareSetup {
    pub trace_threads: usize,
    pub frame_threads: usize,
    /// Rays that enter the root box (the same for every strategy: they share the root box).
    pub root_rays: u64,
    pub rays: u64,
}

/// `timing::budgeted_median` of a timing that cannot fail: the builds' and frames' medians, by
/// the rule the trace column's runs follow too.
pub(super) fn budgeted_median(runs: u32, mut time: impl FnMut() -> f64) -> f64 {
    let r: Result<_, std::convert::Infallible> = timing::budgeted_median(runs, || Ok(time()));
    r.map_or_else(|e| match e {}, |(median, _)| median)
}

/// A thread pool of `n` threads (`None`: rayon's default, one per core).
fn pool(n: Option<u32>) -> rayon::ThreadPool {
    let b = rayon::ThreadPoolBuilder::new();
    let b = match n {
        Some(n) => b.num_threads(n as usize),
        None => b,
    };
    b.build().expect("a thread pool can be started")
}

/// Build and measure every strategy and the linear scan. Builds and frames run on `threads` (all
/// cores when `None`), the single-ray trace timing on `threads` (one when `None`). `kinds`, when
/// given, measures every tree on its rays of each kind too.
#[allow(clippy::too_many_arguments)]
pub fn compare_rows(
    mesh: &crate::mesh::Mesh,
    camera: &Camera,
    build: &BuildArgs,
    scene: Option<&BuildParams>,
    runs: u32,
    threads: Option<u32>,
    linear_budget: Duration,
    mut kinds: Option<&mut (dyn PerTree + Send)>,
) -> (Vec<CompareRow>, CompareSetup) {
    let (frames, traces) = (pool(threads), pool(Some(threads.unwrap_or(1))));
    let rays = camera.width as f64 * camera.height as f64;
    let trace = build.trace_options();
    let plain = RenderSettings { trace, count: false, progressive: false, secondary: None };
    let counting = RenderSettings { count: true, ..plain };
    let mut rows = Vec::new();
    let mut root_rays = 0;
    let mut epo_of = std::collections::HashMap::new();
    let layouts = build.compare_layouts();
    let rows_to_make = Strategy::ALL.len() * layouts.len();
    for (row, (strategy, layout)) in
        Strategy::ALL.into_iter().flat_map(|s| layouts.iter().map(move |&l| (s, l))).enumerate()
    {
        let params = build.params_with(scene, strategy, layout);
        let name = format!("{} ({})", strategy.label(), layout.name());
        // Which row of how many, before each step's own spinner.
        let step = |what: &str| format!("[{}/{rows_to_make}] {what} {name}", row + 1);
        let (bvh, build_ms) = progress::with_spinner(&step("building"), || {
            frames.install(|| {
                let mut bvh = None;
                let build_ms = budgeted_median(runs, || {
                    let b = AnyBvh::build(mesh, &params);
                    let t = ms(b.report().total_time());
                    bvh = Some(b);
                    t
                });
                (bvh.expect("at least one build"), build_ms)
            })
        });
        let (stats, summary, frame_ms, (trace_ms, trace_runs)) = progress::with_spinner(&step("tracing"), || {
            let stats = TreeStats::of(&bvh);
            let (summary, frame_ms) = frames.install(|| {
                let summary = render(&bvh, mesh, camera, &counting).ray_summary();
                let frame_ms = budgeted_median(runs, || {
                    let t = Instant::now();
                    std::hint::black_box(render(&bvh, mesh, camera, &plain));
                    ms(t.elapsed())
                });
                (summary, frame_ms)
            });
            // The app's speed-up times its tree by the same `time_tree` (issue 59).
            let control = crate::work::WorkControl::new();
            let timed = traces.install(|| time_tree(&bvh, camera, trace, runs, &control));
            let timed = timed.expect("nobody else holds this control");
            (stats, summary, frame_ms, timed)
        });
        root_rays = summary.root_rays;
        // Within a budget of about the build's time (`bvh::epo`), so bounded on any mesh.
        let (epo, epo_error) = *epo_of.entry(strategy).or_insert_with(|| {
            progress::with_spinner(&step("measuring the end-point overlap of"), || {
                frames.install(|| {
                    let tree = bvh.binary_tree(mesh);
                    let e = epo::measure(&tree, &Hierarchy::of(&tree));
                    (e.value, e.error())
                })
            })
        });
        let row = CompareRow {
            name: name.clone(),
            build_ms: Some(build_ms),
            nodes: stats.nodes,
            max_depth: stats.max_depth,
            mean_leaf_depth: stats.mean_leaf_depth,
            sah_cost: Some(stats.sah_cost),
            epo: Some(epo),
            epo_error,
            nodes_per_ray: summary.mean_nodes_visited,
            tri_tests_per_ray: summary.mean_triangle_tests,
            root_nodes_per_ray: summary.root_mean_nodes_visited,
            root_tri_tests_per_ray: summary.root_mean_triangle_tests,
            trace_ms,
            trace_runs,
            frame_ms,
            mrays_per_s: rays / frame_ms / 1e3,
            speedup_over_linear: 0.0,
            sampled_rays: None,
            fallback_splits: stats.fallback_splits,
        };
        if let Some(k) = kinds.as_deref_mut() {
            progress::with_spinner(&step("tracing every ray kind through"), || {
                k.tree(Tree {
                    bvh: &bvh,
                    row: &row,
                    first_layout: layout == layouts[0],
                    runs,
                    pools: (&frames, &traces),
                })
            });
        }
        rows.push(row);
    }
    let linear = linear_scan_row(mesh, camera, trace, linear_budget, (&frames, &traces));
    let linear_ms = linear.trace_ms;
    rows.push(linear);
    for r in &mut rows {
        r.speedup_over_linear = linear_ms / r.trace_ms;
    }
    if let Some(k) = kinds {
        k.done(mesh, linear_budget, &traces);
    }
    let setup = CompareSetup {
        trace_threads: traces.current_num_threads(),
        frame_threads: frames.current_num_threads(),
        root_rays,
        rays: rays as u64,
    };
    (rows, setup)
}

/// The linear scan's row: its single-ray trace timed on the trace threads, its "frame" (the scan
/// has no packets) on the frame threads, each within `budget` (sampled past it).
fn linear_scan_row(
    mesh: &crate::mesh::Mesh,
    camera: &Camera,
    trace: TraceOptions,
    budget: Duration,
    (frames, traces): (&rayon::ThreadPool, &rayon::ThreadPool),
) -> CompareRow {
    let linear = LinearScan::new(mesh);
    let ((linear_ms, sampled), (frame_ms, _)) = progress::with_spinner("timing the linear scan", || {
        // The scan has no packets: its "frame" is its trace on the frame's threads.
        let control = crate::work::WorkControl::new();
        let timed = |pool: &rayon::ThreadPool| {
            pool.install(|| time_linear(&linear, camera, trace, budget, &control))
                .expect("nobody else holds this control")
        };
        (timed(traces), timed(frames))
    });
    let n = mesh.triangle_count() as f64;
    let rays = camera.width as f64 * camera.height as f64;
    CompareRow {
        name: "Linear scan".to_string(),
        build_ms: None,
        nodes: 0,
        max_depth: 0,
        mean_leaf_depth: 0.0,
        sah_cost: None,
        epo: None,
        epo_error: None,
        nodes_per_ray: 0.0,
        tri_tests_per_ray: n,
        root_nodes_per_ray: 0.0,
        root_tri_tests_per_ray: n,
        trace_ms: linear_ms,
        trace_runs: 1,
        frame_ms,
        mrays_per_s: rays / frame_ms / 1e3,
        speedup_over_linear: 1.0,
        sampled_rays: sampled,
        fallback_splits: 0,
    }
}
