//! `bvhscope compare`: the lab-report table. Every strategy is built and measured on the same
//! primary rays, next to a linear scan of all triangles.
//!
//! Three timings per strategy. "trace ms" is what a student's renderer would see: one thread (or
//! `--threads`), one ray at a time, closest hit only, no shading; it follows the work per ray, and
//! the speedup over the linear scan compares it with the scan timed the same way. "frame ms" is
//! the app's frame: the renderer on all threads (or `--threads`), 8×8 ray packets, shading
//! included; there, making rays and shading cost as much as tracing, so strategies differ little.
//! Both are medians of `--runs` frames of the plain (non-counting) traversal; the per-ray means
//! come from one extra counting frame, over all rays and over the rays that enter the root box.
//! Build times are the median of as many builds, or of fewer when they pass a second in all: one
//! build of a small mesh takes a few milliseconds, and a single one can be twice the next on a
//! busy machine. The linear scan is timed on the full frame when that is projected to take at most
//! ~10 s, else on an evenly spread sample of its rays, and the table says so.

use super::args::{BuildArgs, DeviceArgs, GpuNodes, ViewArgs};
use super::{load_mesh, progress, CliError};
use crate::bvh::{epo, AnyBvh, BuildParams, LinearScan, SplitStrategy, TreeStats, TreeView};
use crate::render::{render, Camera, RenderSettings};
use clap::{Args, ValueEnum};
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
    /// With --device gpu, GPU rows follow the table: every strategy's binary tree traced on the
    /// GPU in both node formats (or --gpu-nodes'), counted and plain, primary and incoherent rays.
    #[command(flatten)]
    pub device: DeviceArgs,
    #[command(flatten)]
    pub view_args: ViewArgs,
    #[arg(long, value_enum, default_value = "markdown")]
    pub format: CompareFormat,
    /// Frames timed per strategy, and builds (the medians are reported; builds stop early once
    /// they have taken a second).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub runs: u32,
    /// Threads for all the work: builds, frames and the single-ray trace timing [default: all
    /// cores for builds and frames, one for the trace timing].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
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
    /// Means over all primary rays.
    pub nodes_per_ray: f64,
    pub tri_tests_per_ray: f64,
    /// Means over the rays that enter the root box.
    pub root_nodes_per_ray: f64,
    pub root_tri_tests_per_ray: f64,
    /// Single rays, closest hit, no shading, on `trace_threads` (median; projected from a sample
    /// for a sampled row).
    pub trace_ms: f64,
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

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

use crate::explain::timing::{ms, time_linear, trace_rays};

/// Builds of one strategy stop once they have taken this long in all (at least one is made).
const BUILD_BUDGET_MS: f64 = 1000.0;

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
/// cores when `None`), the single-ray trace timing on `threads` (one when `None`).
pub fn compare_rows(
    mesh: &crate::mesh::Mesh,
    camera: &Camera,
    build: &BuildArgs,
    scene: Option<&BuildParams>,
    runs: u32,
    threads: Option<u32>,
    linear_budget: Duration,
) -> (Vec<CompareRow>, CompareSetup) {
    let (frames, traces) = (pool(threads), pool(Some(threads.unwrap_or(1))));
    let rays = camera.width as f64 * camera.height as f64;
    let trace = build.trace();
    let plain = RenderSettings { trace, count: false, progressive: false };
    let counting = RenderSettings { count: true, ..plain };
    let mut rows = Vec::new();
    let mut root_rays = 0;
    let mut epo_of = std::collections::HashMap::new();
    let layouts = build.compare_layouts();
    for (strategy, layout) in SplitStrategy::ALL.into_iter().flat_map(|s| layouts.iter().map(move |&l| (s, l))) {
        let params = build.params_with(scene, strategy, layout);
        let name = format!("{} ({})", strategy.label(), layout.name());
        let (bvh, build_ms) = progress::with_spinner(&format!("building {name}"), || {
            frames.install(|| {
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
            })
        });
        let (stats, summary, frame_times, trace_times) = progress::with_spinner(&format!("tracing {name}"), || {
            let stats = TreeStats::of(&bvh);
            let (summary, frame_times) = frames.install(|| {
                let summary = render(&bvh, mesh, camera, &counting).ray_summary();
                let times: Vec<f64> = (0..runs)
                    .map(|_| {
                        let t = Instant::now();
                        std::hint::black_box(render(&bvh, mesh, camera, &plain));
                        ms(t.elapsed())
                    })
                    .collect();
                (summary, times)
            });
            let total = rays as usize;
            let trace_times: Vec<f64> =
                traces.install(|| (0..runs).map(|_| ms(trace_rays(&bvh, camera, trace, total))).collect());
            (stats, summary, frame_times, trace_times)
        });
        root_rays = summary.root_rays;
        let frame_ms = median(frame_times);
        let epo = *epo_of.entry(strategy).or_insert_with(|| {
            progress::with_spinner(&format!("measuring the end-point overlap of {}", strategy.label()), || {
                frames.install(|| epo::of(&bvh.binary_tree(mesh)))
            })
        });
        rows.push(CompareRow {
            name,
            build_ms: Some(build_ms),
            nodes: stats.nodes,
            max_depth: stats.max_depth,
            mean_leaf_depth: stats.mean_leaf_depth,
            sah_cost: Some(stats.sah_cost),
            epo: Some(epo),
            nodes_per_ray: summary.mean_nodes_visited,
            tri_tests_per_ray: summary.mean_triangle_tests,
            root_nodes_per_ray: summary.root_mean_nodes_visited,
            root_tri_tests_per_ray: summary.root_mean_triangle_tests,
            trace_ms: median(trace_times),
            frame_ms,
            mrays_per_s: rays / frame_ms / 1e3,
            speedup_over_linear: 0.0,
            sampled_rays: None,
            fallback_splits: stats.fallback_splits,
        });
    }
    let linear = LinearScan::new(mesh);
    let ((linear_ms, sampled), (frame_ms, _)) = progress::with_spinner("timing the linear scan", || {
        // The scan has no packets: its "frame" is its trace on the frame's threads.
        let control = crate::work::WorkControl::new();
        let timed = |pool: &rayon::ThreadPool| {
            pool.install(|| time_linear(&linear, camera, trace, linear_budget, &control))
                .expect("nobody else holds this control")
        };
        (timed(&traces), timed(&frames))
    });
    let n = mesh.triangle_count() as f64;
    rows.push(CompareRow {
        name: "Linear scan".to_string(),
        build_ms: None,
        nodes: 0,
        max_depth: 0,
        mean_leaf_depth: 0.0,
        sah_cost: None,
        epo: None,
        nodes_per_ray: 0.0,
        tri_tests_per_ray: n,
        root_nodes_per_ray: 0.0,
        root_tri_tests_per_ray: n,
        trace_ms: linear_ms,
        frame_ms,
        mrays_per_s: rays / frame_ms / 1e3,
        speedup_over_linear: 1.0,
        sampled_rays: sampled,
        fallback_splits: 0,
    });
    for r in &mut rows {
        r.speedup_over_linear = linear_ms / r.trace_ms;
    }
    let setup = CompareSetup {
        trace_threads: traces.current_num_threads(),
        frame_threads: frames.current_num_threads(),
        root_rays,
        rays: rays as u64,
    };
    (rows, setup)
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or(String::new(), |v| format!("{v:.digits$}"))
}

const CSV_HEADER: [&str; 16] = [
    "strategy",
    "build_ms",
    "nodes",
    "max_depth",
    "mean_leaf_depth",
    "sah_cost",
    "epo",
    "nodes_per_ray",
    "tri_tests_per_ray",
    "root_box_nodes_per_ray",
    "root_box_tri_tests_per_ray",
    "trace_ms",
    "frame_ms",
    "mrays_per_s",
    "speedup_over_linear",
    "sampled_rays",
];

/// One row's CSV fields, in `CSV_HEADER`'s order.
fn csv_record(r: &CompareRow) -> Vec<String> {
    vec![
        r.name.clone(),
        opt(r.build_ms, 2),
        r.nodes.to_string(),
        r.max_depth.to_string(),
        format!("{:.2}", r.mean_leaf_depth),
        opt(r.sah_cost, 3),
        opt(r.epo, 3),
        format!("{:.3}", r.nodes_per_ray),
        format!("{:.3}", r.tri_tests_per_ray),
        format!("{:.3}", r.root_nodes_per_ray),
        format!("{:.3}", r.root_tri_tests_per_ray),
        format!("{:.2}", r.trace_ms),
        format!("{:.2}", r.frame_ms),
        format!("{:.3}", r.mrays_per_s),
        format!("{:.1}", r.speedup_over_linear),
        r.sampled_rays.map_or(String::new(), |n| n.to_string()),
    ]
}

fn write_csv(records: Vec<Vec<String>>) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    for rec in records {
        w.write_record(&rec).expect("writing CSV to memory");
    }
    String::from_utf8(w.into_inner().expect("writing CSV to memory")).expect("CSV of UTF-8 fields")
}

/// The rows as CSV (RFC 4180, by the `csv` crate): one header, one record per row; values not
/// measured (a linear scan's build time) are empty fields.
pub fn rows_csv(rows: &[CompareRow]) -> String {
    let mut records = vec![CSV_HEADER.map(String::from).to_vec()];
    records.extend(rows.iter().map(csv_record));
    write_csv(records)
}

/// `rows_csv` with the GPU's rows after the CPU's, in one table: five more columns say where a
/// row ran (device, node format, counted) and give its incoherent rays' time and MRays/s (empty
/// on the CPU's rows); a GPU row's trace and frame ms are its primary frame's GPU time.
pub fn rows_csv_with_gpu(rows: &[CompareRow], gpu: &[super::compare_gpu::GpuRow]) -> String {
    let extra = ["device", "gpu_nodes", "counted", "incoherent_ms", "incoherent_mrays_per_s"];
    let mut records = vec![CSV_HEADER.iter().chain(&extra).map(|s| s.to_string()).collect::<Vec<_>>()];
    for r in rows {
        records.push(
            [csv_record(r), vec!["cpu".into(), String::new(), String::new(), String::new(), String::new()]].concat(),
        );
    }
    for g in gpu {
        let more = vec![
            "gpu".into(),
            g.gpu_nodes.name().to_lowercase(),
            g.counted.to_string(),
            format!("{:.3}", g.incoherent_ms),
            format!("{:.3}", g.incoherent_mrays_per_s),
        ];
        records.push([csv_record(&g.row), more].concat());
    }
    write_csv(records)
}

pub fn run(a: &CompareArgs) -> Result<(), CliError> {
    let gpu = super::device::open(&a.device)?;
    let loaded = load_mesh(&a.mesh)?;
    let mesh_arc = loaded.flat_mesh()?;
    let mesh = &*mesh_arc;
    let camera = a.view_args.camera(&mesh.bounds(), loaded.camera.as_ref())?;
    let scene = loaded.build.as_ref();
    if gpu.is_some() {
        // Refused before the CPU rows are measured, not after.
        super::device::check_traceable(&a.build.scene_build(a.build.params(scene)), a.build.trace())?;
    }
    let (rows, setup) = compare_rows(mesh, &camera, &a.build, scene, a.runs, a.threads, Duration::from_secs(10));
    let linear_ms = rows.last().map_or(0.0, |r| r.trace_ms);
    let formats = a.device.gpu_nodes.map_or(vec![GpuNodes::Binary, GpuNodes::Cwbvh], |n| vec![n]);
    let gpu_rows = match &gpu {
        Some(g) => {
            Some(super::compare_gpu::gpu_rows(g, &mesh_arc, &camera, &a.build, scene, a.runs, &formats, linear_ms)?)
        }
        None => None,
    };
    let rays = setup.rays;
    let trace = a.build.trace();
    let mut o = String::new();
    match a.format {
        CompareFormat::Json => {
            let v = serde_json::json!({
                "mesh": a.mesh, "triangles": mesh.triangle_count(), "width": camera.width, "height": camera.height,
                "setup": setup, "trace": trace, "preset": a.build.preset, "rows": rows,
                "gpu": gpu.as_ref().zip(gpu_rows.as_ref()).map(|(g, (r, n))| serde_json::json!({
                    "adapter": g.name(), "software": g.is_software(), "incoherent_rays": n, "rows": r,
                })),
            });
            let _ = writeln!(o, "{}", serde_json::to_string_pretty(&v).expect("plain data serialises"));
        }
        CompareFormat::Csv => {
            o = match &gpu_rows {
                Some((g, _)) => rows_csv_with_gpu(&rows, g),
                None => rows_csv(&rows),
            }
        }
        CompareFormat::Markdown => {
            let _ = writeln!(o, "| strategy | build ms | nodes | depth max / mean | SAH cost | EPO | nodes / ray: all / in root box | tri tests / ray: all / in root box | trace ms | frame ms | speedup vs linear |");
            let _ = writeln!(o, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
            for r in &rows {
                let depth =
                    if r.nodes > 0 { format!("{} / {:.1}", r.max_depth, r.mean_leaf_depth) } else { "—".into() };
                let sampled = if r.sampled_rays.is_some() { " *" } else { "" };
                let dash = |v: Option<f64>, d: usize| v.map_or("—".to_string(), |v| format!("{v:.d$}"));
                let _ = writeln!(
                    o,
                    "| {} | {} | {} | {} | {} | {} | {:.1} / {:.1} | {:.1} / {:.1} | {}{sampled} | {}{sampled} | {:.0}× |",
                    r.name,
                    r.build_ms.map_or("—".to_string(), crate::bvh::fmt_ms),
                    r.nodes,
                    depth,
                    dash(r.sah_cost, 2),
                    dash(r.epo, 2),
                    r.nodes_per_ray,
                    r.root_nodes_per_ray,
                    r.tri_tests_per_ray,
                    r.root_tri_tests_per_ray,
                    crate::bvh::fmt_ms(r.trace_ms),
                    crate::bvh::fmt_ms(r.frame_ms),
                    r.speedup_over_linear
                );
            }
            let _ = writeln!(o);
            let preset = a.build.preset.map_or(String::new(), |p| format!("preset {}; ", p.name()));
            let _ = writeln!(
                o,
                "{}: {} triangles; {}x{} primary rays ({} rays, {} = {:.0}% enter the root box); {preset}traversal {}, {} test.",
                a.mesh.display(), mesh.triangle_count(), camera.width, camera.height, rays, setup.root_rays,
                100.0 * setup.root_rays as f64 / rays.max(1) as f64, trace.order.label(), trace.test.label()
            );
            let _ = writeln!(
                o,
                "trace ms: single rays, closest hit, no shading, {} thread(s); frame ms: the renderer (8×8 packets, shading) on {} thread(s); medians of {} frames; build ms: median of up to {} builds on {} thread(s); speedup: the linear scan's trace ms over the row's.",
                setup.trace_threads, setup.frame_threads, a.runs, a.runs, setup.frame_threads
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
            if let (Some(g), Some((r, n))) = (&gpu, &gpu_rows) {
                o += &super::compare_gpu::markdown(g, r, &camera, *n, a.runs, trace);
            }
        }
    }
    super::out(&o);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(name: &str, build_ms: Option<f64>) -> CompareRow {
        CompareRow {
            name: name.into(),
            build_ms,
            nodes: 7,
            max_depth: 2,
            mean_leaf_depth: 1.5,
            sah_cost: build_ms.map(|_| 3.25),
            epo: build_ms.map(|_| 0.5),
            nodes_per_ray: 1.0,
            tri_tests_per_ray: 2.0,
            root_nodes_per_ray: 4.0,
            root_tri_tests_per_ray: 8.0,
            trace_ms: 1.0,
            frame_ms: 2.0,
            mrays_per_s: 3.0,
            speedup_over_linear: 4.0,
            sampled_rays: None,
            fallback_splits: 0,
        }
    }

    #[test]
    fn the_csv_has_as_many_fields_in_every_record_and_empty_ones_for_what_was_not_measured() {
        let text = rows_csv(&[row("Equal count, binary \"quoted\"", Some(1.0)), row("Linear scan", None)]);
        let mut r = csv::Reader::from_reader(text.as_bytes());
        let header = r.headers().unwrap().clone();
        let records: Vec<csv::StringRecord> = r.records().map(|r| r.unwrap()).collect();
        assert_eq!(records.len(), 2);
        for rec in &records {
            assert_eq!(rec.len(), header.len(), "{text}");
        }
        assert_eq!(&records[0][0], "Equal count, binary \"quoted\"");
        let build = header.iter().position(|h| h == "build_ms").unwrap();
        assert_eq!(&records[1][build], "", "the linear scan has no build");
        assert_eq!(&records[0][header.iter().position(|h| h == "root_box_nodes_per_ray").unwrap()], "4.000");
    }
}
