//! `bvhscope compare`: the lab-report table. Every strategy is built and measured on the same
//! primary rays, next to a linear scan of all triangles.
//!
//! Frame times are the median of several full frames of the plain (non-counting) traversal on all
//! threads; the per-ray means come from one extra counting frame. Build times are the median of as
//! many builds, or of fewer when they pass a second in all: one build of a small mesh takes a few
//! milliseconds, and a single one can be twice the next on a busy machine. The linear scan is timed on the
//! full frame when that is projected to take at most ~10 s, else on an evenly spread sample of
//! its rays, and the table says so.

use super::args::{BuildArgs, ViewArgs};
use super::{load_mesh, progress, CliError};
use crate::bvh::{Accelerator, AnyBvh, Layout, LinearScan, NoStats, SplitStrategy, TraceOptions, TreeStats, TreeView};
use crate::mesh::Mesh;
use crate::render::{render, Camera, RenderSettings};
use clap::{Args, ValueEnum};
use rayon::prelude::*;
use std::fmt::Write;
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum CompareFormat {
    Markdown,
    Csv,
    Json,
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The mesh (.obj) or scene (.json: bvhscope's or Moer-lite's).
    pub mesh: PathBuf,
    #[command(flatten)]
    pub build: BuildArgs,
    #[command(flatten)]
    pub view_args: ViewArgs,
    #[arg(long, value_enum, default_value = "markdown")]
    pub format: CompareFormat,
    /// Frames timed per strategy, and builds (the medians are reported; builds stop early once
    /// they have taken a second).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub runs: u32,
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
    pub nodes_per_ray: f64,
    pub tri_tests_per_ray: f64,
    /// Full-frame time (median of the timed frames; projected from a sample for a sampled row).
    pub frame_ms: f64,
    pub mrays_per_s: f64,
    pub speedup_over_linear: f64,
    /// Rays actually timed, when fewer than the frame's.
    pub sampled_rays: Option<usize>,
    pub fallback_splits: u32,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Time the linear scan: on the whole frame if that is cheap enough, else on a spread sample.
fn time_linear(mesh: &Mesh, camera: &Camera, trace: TraceOptions, budget: Duration) -> (f64, Option<usize>) {
    let linear = LinearScan::new(mesh);
    let gen = camera.ray_gen();
    let total = camera.width as usize * camera.height as usize;
    let time_sample = |n: usize| {
        let start = Instant::now();
        (0..n).into_par_iter().for_each(|i| {
            let p = (i * total / n) as u32;
            let mut ray = gen.pixel_ray(p % camera.width, p / camera.width);
            std::hint::black_box(linear.closest_hit(&mut ray, trace, &mut NoStats));
        });
        start.elapsed()
    };
    let probe = 256.min(total);
    let t = time_sample(probe);
    let projected = t.as_secs_f64() * total as f64 / probe as f64;
    if projected <= budget.as_secs_f64() {
        return (ms(time_sample(total)), None);
    }
    // About a fifth of the budget on the sample.
    let n = ((budget.as_secs_f64() / 5.0 / t.as_secs_f64().max(1e-9)) * probe as f64) as usize;
    let n = n.clamp(probe, total);
    let t = time_sample(n);
    (ms(t) * total as f64 / n as f64, Some(n))
}

/// Builds of one strategy stop once they have taken this long in all (at least one is made).
const BUILD_BUDGET_MS: f64 = 1000.0;

/// Build and measure every strategy and the linear scan.
pub fn compare_rows(
    mesh: &Mesh,
    camera: &Camera,
    build: &BuildArgs,
    runs: u32,
    linear_budget: Duration,
) -> Vec<CompareRow> {
    let rays = camera.width as f64 * camera.height as f64;
    let plain = RenderSettings { trace: build.trace(), count: false, progressive: false };
    let counting = RenderSettings { count: true, ..plain };
    let mut rows = Vec::new();
    let layouts: Vec<Layout> = match build.layout {
        Some(l) => vec![l],
        None => Layout::ALL.to_vec(),
    };
    for (strategy, layout) in SplitStrategy::ALL.into_iter().flat_map(|s| layouts.iter().map(move |&l| (s, l))) {
        let params = build.params_with(strategy, layout);
        let name = format!("{} ({})", strategy.label(), layout.short_name());
        let (bvh, build_ms) = progress::with_spinner(&format!("building {name}"), || {
            let build_ms = |bvh: &AnyBvh| ms(bvh.report().total_time());
            let mut bvh = AnyBvh::build(mesh, &params);
            let mut times = vec![build_ms(&bvh)];
            // Past the budget, one more build when the count is even: the median of two would be
            // the slower, often the first, cold one.
            while times.len() < runs as usize
                && (times.iter().sum::<f64>() < BUILD_BUDGET_MS || times.len().is_multiple_of(2))
            {
                bvh = AnyBvh::build(mesh, &params);
                times.push(build_ms(&bvh));
            }
            (bvh, median(times))
        });
        let (stats, summary, times) = progress::with_spinner(&format!("tracing {name}"), || {
            let stats = TreeStats::of(&bvh);
            let summary = render(&bvh, mesh, camera, &counting).ray_summary();
            let times: Vec<f64> = (0..runs)
                .map(|_| {
                    let t = Instant::now();
                    std::hint::black_box(render(&bvh, mesh, camera, &plain));
                    ms(t.elapsed())
                })
                .collect();
            (stats, summary, times)
        });
        let frame_ms = median(times);
        rows.push(CompareRow {
            name,
            build_ms: Some(build_ms),
            nodes: stats.nodes,
            max_depth: stats.max_depth,
            mean_leaf_depth: stats.mean_leaf_depth,
            sah_cost: Some(stats.sah_cost),
            nodes_per_ray: summary.mean_nodes_visited,
            tri_tests_per_ray: summary.mean_triangle_tests,
            frame_ms,
            mrays_per_s: rays / frame_ms / 1e3,
            speedup_over_linear: 0.0,
            sampled_rays: None,
            fallback_splits: stats.fallback_splits,
        });
    }
    let (linear_ms, sampled) =
        progress::with_spinner("timing the linear scan", || time_linear(mesh, camera, build.trace(), linear_budget));
    rows.push(CompareRow {
        name: "Linear scan".to_string(),
        build_ms: None,
        nodes: 0,
        max_depth: 0,
        mean_leaf_depth: 0.0,
        sah_cost: None,
        nodes_per_ray: 0.0,
        tri_tests_per_ray: mesh.triangle_count() as f64,
        frame_ms: linear_ms,
        mrays_per_s: rays / linear_ms / 1e3,
        speedup_over_linear: 1.0,
        sampled_rays: sampled,
        fallback_splits: 0,
    });
    for r in &mut rows {
        r.speedup_over_linear = linear_ms / r.frame_ms;
    }
    rows
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".to_string(), |v| format!("{v:.digits$}"))
}

pub fn run(a: &CompareArgs) -> Result<(), CliError> {
    let loaded = load_mesh(&a.mesh)?;
    let mesh = loaded.mesh;
    let camera = a.view_args.camera(&mesh.bounds(), loaded.camera.as_ref())?;
    let rows = compare_rows(&mesh, &camera, &a.build, a.runs, Duration::from_secs(10));
    let rays = camera.width as usize * camera.height as usize;
    let threads = rayon::current_num_threads();
    let mut o = String::new();
    match a.format {
        CompareFormat::Json => {
            let v = serde_json::json!({
                "mesh": a.mesh, "triangles": mesh.triangle_count(), "width": camera.width, "height": camera.height,
                "threads": threads, "trace": a.build.trace(), "rows": rows,
            });
            let _ = writeln!(o, "{}", serde_json::to_string_pretty(&v).expect("plain data serialises"));
        }
        CompareFormat::Csv => {
            let _ = writeln!(o, "strategy,build_ms,nodes,max_depth,mean_leaf_depth,sah_cost,nodes_per_ray,tri_tests_per_ray,frame_ms,mrays_per_s,speedup_over_linear,sampled_rays");
            for r in &rows {
                let _ = writeln!(
                    o,
                    "{},{},{},{},{:.2},{},{:.2},{:.2},{:.2},{:.3},{:.1},{}",
                    r.name,
                    opt(r.build_ms, 2),
                    r.nodes,
                    r.max_depth,
                    r.mean_leaf_depth,
                    opt(r.sah_cost, 3),
                    r.nodes_per_ray,
                    r.tri_tests_per_ray,
                    r.frame_ms,
                    r.mrays_per_s,
                    r.speedup_over_linear,
                    r.sampled_rays.map_or(String::new(), |n| n.to_string())
                );
            }
        }
        CompareFormat::Markdown => {
            let _ = writeln!(o, "| strategy | build ms | nodes | depth max / mean | SAH cost | nodes / ray | tri tests / ray | frame ms | MRays/s | speedup vs linear |");
            let _ = writeln!(o, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
            for r in &rows {
                let depth =
                    if r.nodes > 0 { format!("{} / {:.1}", r.max_depth, r.mean_leaf_depth) } else { "—".into() };
                let frame = if r.sampled_rays.is_some() {
                    format!("{:.0} *", r.frame_ms)
                } else {
                    format!("{:.1}", r.frame_ms)
                };
                let _ = writeln!(
                    o,
                    "| {} | {} | {} | {} | {} | {:.1} | {:.1} | {} | {:.2} | {:.0}× |",
                    r.name,
                    opt(r.build_ms, 1),
                    r.nodes,
                    depth,
                    opt(r.sah_cost, 2),
                    r.nodes_per_ray,
                    r.tri_tests_per_ray,
                    frame,
                    r.mrays_per_s,
                    r.speedup_over_linear
                );
            }
            let _ = writeln!(o);
            let _ = writeln!(
                o,
                "{}: {} triangles; {}x{} primary rays ({} rays), {} threads; traversal {}, {} test; frame ms = median of {} frames; build ms = median of up to {} builds.",
                a.mesh.display(), mesh.triangle_count(), camera.width, camera.height, rays, threads,
                a.build.order.label(), a.build.test.label(), a.runs, a.runs
            );
            if let Some(n) = rows.last().and_then(|r| r.sampled_rays) {
                let _ = writeln!(o, "* linear scan timed on {n} of {rays} rays (a full frame would take over 10 s) and scaled to the full frame.");
            }
            let fallbacks: Vec<String> = rows
                .iter()
                .filter(|r| r.fallback_splits > 0)
                .map(|r| format!("{} {}", r.name, r.fallback_splits))
                .collect();
            if !fallbacks.is_empty() {
                let _ = writeln!(o, "Equal-count fallback splits (no useful split found): {}.", fallbacks.join(", "));
            }
        }
    }
    print!("{o}");
    Ok(())
}
