//! `compare --device gpu`: the GPU's rows. Every strategy's binary tree (lbvh and ploc built on the
//! GPU, the others on the CPU) is traced on the GPU in each node format, counted and plain, on the
//! frame's primary rays and on as many incoherent rays (from random points on the surface in
//! random directions): MRays/s of each, from the GPU's submit-to-completion time (read-backs left
//! out), the median of `--runs` runs after one untimed run that compiles the kernels.

use super::rows::CompareRow;
use crate::bvh::{AnyBvh, BuildParams, Bvh, Layout, SceneBvh, Strategy, TraceOptions, TreeStats, TreeView};
use crate::cli::args::BuildArgs;
use crate::cli::error::CliError;
use crate::cli::{device, progress};
use crate::gpu_path::{GpuNodes, GpuTree};
use crate::mesh::Mesh;
use crate::render::warp::{WarpSize, WarpView, WarpWork};
use crate::render::Camera;
use bvhscope_gpu::{Gpu, Rays};
use std::sync::Arc;

/// One GPU row: the table's columns (`row`, its times the GPU's primary frame) and the GPU's own.
#[derive(Clone, Debug, serde::Serialize)]
pub struct GpuRow {
    #[serde(flatten)]
    pub row: CompareRow,
    pub gpu_nodes: GpuNodes,
    pub counted: bool,
    /// Whether the tree was built on the GPU (lbvh, ploc) or on the CPU.
    pub built_on_gpu: bool,
    pub primary_mrays_per_s: f64,
    pub incoherent_ms: f64,
    pub incoherent_mrays_per_s: f64,
    /// 32-lane SIMT efficiency of the primary frame (from the counted walk's counts).
    pub simt_efficiency: f64,
    /// Rays (primary and incoherent) whose walk reached the GPU's step budget and was finished on
    /// the CPU: their hits and counts are the CPU's, their time is not in the GPU's.
    pub cpu_finished: usize,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The GPU rows for every strategy (`nodes`: the formats to trace), and the incoherent rays' count.
/// `linear_trace_ms` is the linear scan's trace time, for the speed-up column.
#[allow(clippy::too_many_arguments)]
pub fn gpu_rows(
    gpu: &Gpu,
    mesh: &Arc<Mesh>,
    camera: &Camera,
    build: &BuildArgs,
    scene: Option<&BuildParams>,
    runs: u32,
    nodes: &[GpuNodes],
    linear_trace_ms: f64,
) -> Result<(Vec<GpuRow>, usize), CliError> {
    let trace = build.trace_options();
    device::check_traceable(&build.scene_build(build.params(scene)), trace)?;
    let pixels = camera.width as usize * camera.height as usize;
    let incoherent = crate::render::incoherent_rays(mesh, pixels, 1);
    let mut rows = Vec::new();
    for strategy in Strategy::ALL {
        let params = build.params_with(scene, strategy, Layout::Binary);
        let (bvh, built_on_gpu) = match device::gpu_build(gpu, mesh, &params)? {
            Some((bvh, _)) => (bvh, true),
            None => {
                let label = format!("building {} for the GPU", strategy.label());
                (progress::with_spinner(&label, || AnyBvh::Binary(Bvh::build(mesh, &params))), false)
            }
        };
        let stats = TreeStats::of(&bvh);
        let build_ms = bvh.report().total_time().as_secs_f64() * 1e3;
        let scene_bvh = SceneBvh::Single { bvh, mesh: mesh.clone(), imported: None };
        for &format in nodes {
            let (tree, _) = GpuTree::upload(gpu, &scene_bvh, format)?;
            let cw_nodes = tree.own_nodes();
            let label = format!("timing {} ({} nodes) on the GPU", strategy.label(), format.label());
            let measured = progress::with_spinner(&label, || -> Result<_, CliError> {
                let mut out = Vec::new();
                for counted in [true, false] {
                    let time = |rays: Rays| -> Result<(f64, bvhscope_gpu::GpuTrace), CliError> {
                        let mut last = tree.trace(gpu, rays, trace, counted)?;
                        let mut times = Vec::new();
                        for _ in 0..runs {
                            last = tree.trace(gpu, rays, trace, counted)?;
                            times.push(last.gpu_time.as_secs_f64() * 1e3);
                        }
                        Ok((median(times), last))
                    };
                    let (primary_ms, primary) = time(Rays::Camera(camera))?;
                    let (incoherent_ms, inc) = time(Rays::List(&incoherent))?;
                    let finished = primary.cpu_finished + inc.cpu_finished;
                    out.push((counted, primary_ms, primary, incoherent_ms, finished));
                }
                Ok(out)
            })?;
            // Work per ray and the warp's efficiency come from the counted walk (the plain one
            // does the same work, uncounted).
            let counts = &measured[0].2.counters;
            let summary = frame_summary(mesh, camera, &measured[0].2)?;
            let simt = WarpView::frame(camera.width, camera.height, counts, WarpSize::W32, WarpWork::Steps)
                .summary()
                .simt_efficiency;
            for (counted, primary_ms, _, incoherent_ms, cpu_finished) in measured {
                let mrays = |n: usize, ms: f64| n as f64 / ms.max(1e-9) / 1e3;
                let kind = if counted { "counted" } else { "plain" };
                rows.push(GpuRow {
                    row: CompareRow {
                        name: format!("{} (GPU {}, {kind})", strategy.label(), format.label()),
                        build_ms: Some(build_ms),
                        nodes: cw_nodes.unwrap_or(stats.nodes),
                        max_depth: stats.max_depth,
                        mean_leaf_depth: stats.mean_leaf_depth,
                        sah_cost: Some(stats.sah_cost),
                        epo: None,
                        epo_error: None,
                        nodes_per_ray: summary.mean_nodes_visited,
                        tri_tests_per_ray: summary.mean_triangle_tests,
                        root_nodes_per_ray: summary.root_mean_nodes_visited,
                        root_tri_tests_per_ray: summary.root_mean_triangle_tests,
                        trace_ms: primary_ms,
                        trace_runs: runs as usize,
                        frame_ms: primary_ms,
                        mrays_per_s: mrays(pixels, primary_ms),
                        speedup_over_linear: linear_trace_ms / primary_ms.max(1e-9),
                        sampled_rays: None,
                        fallback_splits: stats.fallback_splits,
                    },
                    gpu_nodes: format,
                    counted,
                    built_on_gpu,
                    primary_mrays_per_s: mrays(pixels, primary_ms),
                    incoherent_ms,
                    incoherent_mrays_per_s: mrays(incoherent.len(), incoherent_ms),
                    simt_efficiency: simt,
                    cpu_finished,
                });
            }
        }
    }
    Ok((rows, incoherent.len()))
}

/// The per-ray means of a counted camera walk (the same figures the CPU rows give).
fn frame_summary(
    mesh: &Mesh,
    camera: &Camera,
    t: &bvhscope_gpu::GpuTrace,
) -> Result<crate::render::RaySummary, CliError> {
    let frame = crate::render::Frame::from_hits(mesh, camera, &t.hits, &t.counters)
        .map_err(|e| CliError::Usage(format!("--device gpu: {e}")))?;
    Ok(frame.ray_summary())
}

/// The GPU table in Markdown, with what it measured.
pub fn markdown(
    gpu: &Gpu,
    rows: &[GpuRow],
    camera: &Camera,
    incoherent: usize,
    runs: u32,
    trace: TraceOptions,
) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let _ = writeln!(o);
    let _ = writeln!(o, "GPU: {}", gpu.name());
    let _ = writeln!(o);
    let _ = writeln!(o, "| strategy | built on | nodes | nodes / ray: all / in root box | tri tests / ray | SIMT eff. (32) | primary ms | primary MRays/s | incoherent ms | incoherent MRays/s |");
    let _ = writeln!(o, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for g in rows {
        let r = &g.row;
        let _ = writeln!(
            o,
            "| {} | {} | {} | {:.1} / {:.1} | {:.1} | {:.3} | {} | {:.1} | {} | {:.1} |",
            r.name,
            if g.built_on_gpu { "GPU" } else { "CPU" },
            r.nodes,
            r.nodes_per_ray,
            r.root_nodes_per_ray,
            r.tri_tests_per_ray,
            g.simt_efficiency,
            crate::bvh::fmt_ms(r.frame_ms),
            g.primary_mrays_per_s,
            crate::bvh::fmt_ms(g.incoherent_ms),
            g.incoherent_mrays_per_s
        );
    }
    let _ = writeln!(o);
    let _ = writeln!(
        o,
        "GPU rows: primary = the {}x{} frame's rays, incoherent = {incoherent} rays from random points on the surface in random directions (seed 1); {} order (binary nodes; CWBVH orders by octant), {} test; ms: submit to completion on the GPU, read-backs left out, median of {runs} runs after one untimed run; counted: per-ray counts kept and read back.",
        camera.width,
        camera.height,
        trace.order.label(),
        trace.test.label()
    );
    let finished: Vec<String> =
        rows.iter().filter(|g| g.cpu_finished > 0).map(|g| format!("{} ({})", g.row.name, g.cpu_finished)).collect();
    if !finished.is_empty() {
        let _ = writeln!(
            o,
            "Rays whose walk reached the GPU's step budget ({} steps) were finished on the CPU (their hits and counts are the CPU's, their time is left out of the GPU's): {}.",
            bvhscope_gpu::STEP_BUDGET,
            finished.join(", ")
        );
    }
    if gpu.is_software() {
        let _ = writeln!(
            o,
            "This adapter is software (lavapipe or llvmpipe): its times are this CPU's emulating a GPU, not a GPU's."
        );
    }
    o
}
