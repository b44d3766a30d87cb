//! `bvhscope compare`: the lab-report table. Every strategy is built and measured on the same
//! primary rays, next to a linear scan of all triangles.
//!
//! Three timings per strategy. "trace ms" is what a student's renderer would see: one thread (or
//! `--threads`), one ray at a time, closest hit only, no shading; it follows the work per ray, and
//! the speedup over the linear scan compares it with the scan timed the same way. "frame ms" is
//! the app's frame: the renderer on all threads (or `--threads`), 8×8 ray packets, shading
//! included; there, making rays and shading cost as much as tracing, so strategies differ little.
//! Both are medians of up to `--runs` frames of the plain (non-counting) traversal; the per-ray
//! means come from one extra counting frame, over all rays and over the rays that enter the root
//! box. Build times are the median of as many builds. Each of the three stops at fewer once its
//! runs pass a second in all: one build of a small mesh takes a few milliseconds, and a single one
//! can be twice the next on a busy machine, while a dense mesh's frames take a second each and
//! twenty-one rows of five would pass the two minutes a table may take (issue 37). The linear scan is timed on the full frame when that is projected to take at most
//! ~10 s, else on an evenly spread sample of its rays, and the table says so.

mod csv;
mod gpu;
mod kinds;
mod rows;

pub use csv::{rows_csv, rows_csv_with_gpu};
pub use rows::{compare_rows, CompareRow};

use crate::bvh::TraceOptions;
use crate::cli::args::{BuildArgs, DeviceArgs, ViewArgs};
use crate::cli::compare::rows::CompareSetup;
use crate::cli::error::CliError;
use crate::cli::load::load_mesh;
use crate::gpu_path::GpuNodes;
use crate::options::Named;
use crate::render::Camera;
use clap::Args;
use std::fmt::Write;
use std::path::PathBuf;
use std::time::Duration;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CompareFormat {
    Markdown,
    Csv,
    Json,
}

const COMPARE_FORMATS: [Named<CompareFormat>; 3] = [
    Named {
        value: CompareFormat::Markdown,
        name: "markdown",
        label: "Markdown",
        help: "a Markdown table, for a lab report",
    },
    Named {
        value: CompareFormat::Csv,
        name: "csv",
        label: "CSV",
        help: "one row per strategy and figure, for a spreadsheet",
    },
    Named { value: CompareFormat::Json, name: "json", label: "JSON", help: "one JSON document, for scripts" },
];
bvhscope_core::choice!(CompareFormat, COMPARE_FORMATS, 3);

#[derive(Args, Debug)]
pub struct CompareArgs {
    #[arg(help = crate::cli::args::MESH_HELP)]
    pub mesh: PathBuf,
    #[command(flatten)]
    pub build: BuildArgs,
    /// With --device gpu, GPU rows follow the table: every strategy's binary tree traced on the
    /// GPU in both node formats (or --gpu-nodes'), counted and plain, primary and incoherent rays.
    #[command(flatten)]
    pub device: DeviceArgs,
    #[command(flatten)]
    pub view_args: ViewArgs,
    /// With a secondary kind or `all`: a second table, every tree on the rays of each kind (the
    /// camera's always first), and how well the SAH cost and EPO rank the trees for each.
    #[command(flatten)]
    pub rays: crate::cli::rays::RayArgs,
    #[arg(long, value_parser = crate::cli::args::choice::<CompareFormat>(), default_value = "markdown")]
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

pub fn run(a: &CompareArgs) -> Result<(), CliError> {
    let gpu = crate::cli::device::open(&a.device)?;
    let loaded = load_mesh(&a.mesh)?;
    let mesh_arc = loaded.flat_mesh()?;
    let mesh = &*mesh_arc;
    let camera = a.view_args.camera(&mesh.bounds(), loaded.camera.as_ref())?;
    let scene = loaded.build.as_ref();
    if gpu.is_some() {
        // Refused before the CPU rows are measured, not after.
        crate::cli::device::check_traceable(&a.build.scene_build(a.build.params(scene)), a.build.trace_options())?;
    }
    let secondary = a.rays.kinds().iter().any(|k| k.is_secondary());
    if gpu.is_some() && secondary {
        let kind = a.rays.kinds().into_iter().find(|k| k.is_secondary()).expect("one is secondary");
        return Err(crate::cli::render::gpu_traces_primary_only(kind));
    }
    let trace = a.build.trace_options();
    let mut kinds = secondary.then(|| {
        let cost = a.build.params(scene).cost;
        kinds::KindsTable::new(mesh, &camera, &a.rays, trace, cost)
    });
    let (rows, setup) = compare_rows(
        mesh,
        &camera,
        &a.build,
        scene,
        a.runs,
        a.threads,
        Duration::from_secs(10),
        kinds.as_mut().map(|k| k as &mut (dyn rows::PerTree + Send)),
    );
    let linear_ms = rows.last().map_or(0.0, |r| r.trace_ms);
    let formats = a.device.gpu_nodes.map_or(GpuNodes::ALL.to_vec(), |n| vec![n]);
    let gpu_rows = match &gpu {
        Some(g) => Some(gpu::gpu_rows(g, &mesh_arc, &camera, &a.build, scene, a.runs, &formats, linear_ms)?),
        None => None,
    };
    let mut o = String::new();
    match a.format {
        CompareFormat::Json => {
            let v = serde_json::json!({
                "mesh": a.mesh, "triangles": mesh.triangle_count(), "width": camera.width, "height": camera.height,
                "setup": setup, "trace": trace, "preset": a.build.preset, "rows": rows,
                "ray_kinds": kinds.as_ref().map(|k| serde_json::json!({
                    "cells": k.cells,
                    "spearman": k.correlations().iter().map(|(kind, sah, epo)| serde_json::json!({
                        "kind": kind, "sah_cost": sah, "epo": epo,
                    })).collect::<Vec<_>>(),
                })),
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
            o = markdown(a, &rows, &setup, mesh, &camera, trace);
            if let (Some(g), Some((r, n))) = (&gpu, &gpu_rows) {
                o += &gpu::markdown(g, r, &camera, *n, a.runs, trace);
            }
            if let Some(k) = &kinds {
                let _ = writeln!(o, "\n## Every strategy on every ray kind\n");
                o += &k.markdown(setup.trace_threads);
            }
        }
    }
    crate::cli::out(&o);
    Ok(())
}

/// The Markdown table of the rows, and the notes that say what its figures are.
fn markdown(
    a: &CompareArgs,
    rows: &[CompareRow],
    setup: &CompareSetup,
    mesh: &crate::mesh::Mesh,
    camera: &Camera,
    trace: TraceOptions,
) -> String {
    let mut o = String::new();
    let rays = setup.rays;
    let _ = writeln!(o, "| strategy | build ms | nodes | depth max / mean | SAH cost | EPO | nodes / ray: all / in root box | tri tests / ray: all / in root box | trace ms | frame ms | speedup vs linear |");
    let _ = writeln!(o, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for r in rows {
        let depth = if r.nodes > 0 { format!("{} / {:.1}", r.max_depth, r.mean_leaf_depth) } else { "—".into() };
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
            r.epo.map_or("—".to_string(), |v| match r.epo_error {
                Some(e) => crate::bvh::epo::figure(v, Some(e)),
                None => format!("{v:.2}"),
            }),
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
        "trace ms: single rays, closest hit, no shading, {} thread(s); frame ms: the renderer (8×8 packets, shading) on {} thread(s); medians of up to {} frames; build ms: median of up to {} builds on {} thread(s) (fewer runs of each where they pass a second in all); speedup: the linear scan's trace ms over the row's.",
        setup.trace_threads, setup.frame_threads, a.runs, a.runs, setup.frame_threads
    );
    if rows.iter().any(|r| r.epo_error.is_some()) {
        let _ = writeln!(o, "EPO a ± b: estimated, where summing every node's overlap would cost more than about the build (± two standard errors).");
    }
    if let Some(n) = rows.last().and_then(|r| r.sampled_rays) {
        let _ = writeln!(o, "* linear scan timed on {n} of {rays} rays (a full frame would take over 10 s) and scaled to the full frame.");
    }
    let fallbacks: Vec<String> =
        rows.iter().filter(|r| r.fallback_splits > 0).map(|r| format!("{} {}", r.name, r.fallback_splits)).collect();
    if !fallbacks.is_empty() {
        let _ = writeln!(o, "Equal-count fallback splits (no useful split found): {}.", fallbacks.join(", "));
    }
    o
}
