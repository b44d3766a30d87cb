//! `bvhscope stats`: the statistics of one BVH, and the work per primary ray of one frame (the
//! figures of the app's statistics panel, from the same camera and size when given the same).

use super::args::{BuildArgs, DeviceArgs, ViewArgs};
use super::{device, progress};
use crate::bvh::{epo, Hierarchy, RayCounters, SceneBvh, TreeStats, TreeView};
use crate::cli::error::CliError;
use crate::cli::load::load_noted;
use crate::gpu_path::{GpuBuild, GpuTree};
use crate::options::Named;
use crate::render::warp::{WarpSize, WarpSummary, WarpView, WarpWork};
use crate::render::{render, Camera, RaySummary, RenderSettings, SecondaryRays, SecondarySpec};
use clap::Args;
use std::fmt::Write;
use std::path::PathBuf;

/// How `stats` prints (`--format`); the app's stats files are `app::StatsFormat`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StatsOutput {
    Text,
    Json,
}

const STATS_OUTPUTS: [Named<StatsOutput>; 2] = [
    Named { value: StatsOutput::Text, name: "text", label: "Text", help: "plain text, to read" },
    Named { value: StatsOutput::Json, name: "json", label: "JSON", help: "one JSON document, for scripts" },
];
bvhscope_core::choice!(StatsOutput, STATS_OUTPUTS, 2);

#[derive(Args, Debug)]
pub struct StatsArgs {
    #[arg(help = crate::cli::args::MESH_HELP)]
    pub mesh: PathBuf,
    #[command(flatten)]
    pub build: BuildArgs,
    #[command(flatten)]
    pub device: DeviceArgs,
    /// Lanes of a GPU warp for the warp figures: 32 (NVIDIA, most GPUs) or 64 (AMD's wave64).
    #[arg(long, value_name = "LANES", default_value = "32", value_parser = parse_warp)]
    pub warp: WarpSize,
    /// The frame whose primary rays are counted (camera and size as `render` takes them).
    #[command(flatten)]
    pub view_args: ViewArgs,
    #[command(flatten)]
    pub rays: super::rays::RayArgs,
    /// Only the tree's statistics: trace no rays.
    #[arg(long)]
    pub no_rays: bool,
    #[arg(long, value_parser = crate::cli::args::choice::<StatsOutput>(), default_value = "text")]
    pub format: StatsOutput,
}

fn parse_warp(s: &str) -> Result<WarpSize, String> {
    s.trim().parse().ok().and_then(WarpSize::from_lanes).ok_or_else(|| format!("'{s}' is not 32 or 64 lanes"))
}

/// The warp view's figures from per-pixel counts (row by row), the GPU's and the CPU's.
struct Warp {
    size: WarpSize,
    gpu: Option<WarpSummary>,
    cpu: WarpSummary,
}

impl Warp {
    fn of(camera: &Camera, size: WarpSize, counts: &[RayCounters]) -> WarpSummary {
        WarpView::frame(camera.width, camera.height, counts, size, WarpWork::Steps).summary()
    }

    fn text(&self) -> String {
        let (bw, bh) = self.size.block();
        let mut o = format!(
            "warp            {} lanes: groups of {bw}×{bh} pixels; a group costs its rays' most steps (nodes visited + triangle tests)\n",
            self.size.lanes()
        );
        let line = |who: &str, s: &WarpSummary| format!("  {who:<14}{}\n", s.text());
        if let Some(g) = &self.gpu {
            o += &line("GPU's counts", g);
        }
        o + &line("CPU's counts", &self.cpu)
    }

    fn json(&self) -> serde_json::Value {
        serde_json::json!({ "lanes": self.size.lanes(), "gpu_counts": self.gpu, "cpu_counts": self.cpu })
    }
}

/// The per-ray block of the text output.
fn format_rays(camera: &Camera, trace: &crate::bvh::TraceOptions, spec: &SecondarySpec, r: &RaySummary) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "traversal       {} order, {} test", trace.order.label(), trace.test.label());
    if spec.kind.is_secondary() {
        let _ = writeln!(
            o,
            "rays            {}x{} pixels, {} camera rays hit; from each, {}: {} rays, {} ({:.1}%) enter the root box",
            camera.width,
            camera.height,
            r.hits,
            spec.describe(),
            r.rays,
            r.root_rays,
            100.0 * r.root_fraction(),
        );
    } else {
        let _ = writeln!(
            o,
            "rays            {}x{} primary rays: {} ({:.1}%) enter the root box, {} hit",
            camera.width,
            camera.height,
            r.root_rays,
            100.0 * r.root_fraction(),
            r.hits
        );
    }
    let _ = writeln!(
        o,
        "  in root box   per ray: nodes visited {:.2}, box tests {:.2}, triangle tests {:.2}",
        r.root_mean_nodes_visited, r.root_mean_box_tests, r.root_mean_triangle_tests
    );
    let _ = writeln!(
        o,
        "  all rays      per ray: nodes visited {:.2} (max {}), box tests {:.2}, triangle tests {:.2} (max {})",
        r.mean_nodes_visited, r.max_nodes_visited, r.mean_box_tests, r.mean_triangle_tests, r.max_triangle_tests
    );
    o
}

pub fn run(a: &StatsArgs) -> Result<(), CliError> {
    super::out(&output(a)?);
    Ok(())
}

/// What `run` prints (the app's tests compare it with the build panel and statistics).
pub fn output(a: &StatsArgs) -> Result<String, CliError> {
    let gpu = device::open(&a.device)?;
    let loaded = load_noted(&a.mesh, true)?;
    let mut params = a.build.params(loaded.build.as_ref());
    let trace = a.build.trace_options();
    if gpu.is_some() {
        params = device::gpu_params(&a.build, loaded.build.as_ref(), params)?;
        device::check_traceable(&a.build.scene_build(params), trace)?;
    }
    let (bvh, gpu_build) = crate::cli::load::build_scene(gpu.as_ref(), &loaded, &a.build.scene_build(params))?;
    let report = &loaded.report;
    let kind = a.rays.one("stats")?;
    if gpu.is_some() && kind.is_secondary() && !a.no_rays {
        return Err(super::render::gpu_traces_primary_only(kind));
    }
    let spec = a.rays.spec(kind);
    let rays = if a.no_rays {
        None
    } else {
        let camera = a.view_args.camera(&loaded.bounds(), loaded.camera.as_ref())?;
        let secondary = a.rays.secondary(kind, &loaded.bounds(), &camera);
        Some(trace_rays(a, gpu.as_ref(), &bvh, &camera, secondary)?)
    };
    let rays_json = rays.as_ref().map(|(camera, summary, warp)| {
        let device = gpu.as_ref().map(|g| serde_json::json!({ "adapter": g.name(), "nodes": a.device.nodes() }));
        serde_json::json!({
            "camera": camera, "trace": trace, "ray_kind": spec, "summary": summary, "device": a.device.device,
            "gpu": device, "warp": warp.as_ref().map(Warp::json),
        })
    });
    let mut rays_text = rays.as_ref().map_or(String::new(), |(camera, r, warp)| {
        let on = gpu.as_ref().map_or(String::new(), |g| {
            format!("device          GPU, {} nodes: {}\n", a.device.nodes().label(), g.name())
        });
        let warp = warp.as_ref().map_or(String::new(), Warp::text);
        format!("{on}{}{warp}", format_rays(camera, &trace, &spec, r))
    });
    if let Some(b) = &gpu_build {
        rays_text = format!("GPU build       {}\n{rays_text}", b.text());
    }
    let gpu_build_json = gpu_build.as_ref().map(GpuBuild::json);
    Ok(match (&bvh, a.format) {
        (SceneBvh::Single { bvh: b, mesh, .. }, format) => {
            let (epo, ms) = progress::with_spinner("measuring the end-point overlap", || {
                let tree = b.binary_tree(mesh);
                let start = std::time::Instant::now();
                (epo::measure(&tree, &Hierarchy::of(&tree)), start.elapsed().as_secs_f64() * 1e3)
            });
            let stats = TreeStats {
                epo: Some(epo.value),
                epo_error: epo.error(),
                epo_ms: Some(ms),
                walk_bytes: b.walk_bytes(trace),
                ..TreeStats::of(b)
            };
            if let StatsOutput::Json = format {
                let v = serde_json::json!({
                    "mesh": report, "params": params, "stats": stats, "gpu_build": gpu_build_json, "rays": rays_json,
                });
                format!("{}\n", serde_json::to_string_pretty(&v).expect("plain data serialises"))
            } else {
                format!("{}{rays_text}", format_text(report, &params, &stats))
            }
        }
        (SceneBvh::TwoLevel { bvh: t, .. }, format) => {
            let top = TreeStats::of(&t.top);
            let names = loaded.instances().map(|i| i.meshes.iter().map(|m| m.name.clone()).collect::<Vec<_>>());
            let bottom: Vec<(String, TreeStats)> = t
                .bottom
                .iter()
                .enumerate()
                .map(|(k, b)| {
                    let name = names
                        .as_ref()
                        .and_then(|n| n.get(k).cloned())
                        .unwrap_or_else(|| report.path.display().to_string());
                    (name, TreeStats::of(b))
                })
                .collect();
            if let StatsOutput::Json = format {
                let bottom_json: Vec<_> =
                    bottom.iter().map(|(name, s)| serde_json::json!({ "mesh": name, "stats": s })).collect();
                let v = serde_json::json!({
                    "scene": report, "instances": t.instances.len(), "memory_bytes": t.memory_bytes(),
                    "build_ms": (t.bottom_time + t.top_time).as_secs_f64() * 1e3,
                    "top": { "params": t.top.params, "stats": top }, "bottom": { "params": params, "meshes": bottom_json },
                    "rays": rays_json,
                });
                format!("{}\n", serde_json::to_string_pretty(&v).expect("plain data serialises"))
            } else {
                format!("{}{rays_text}", format_two_level(report, t, &top, &bottom))
            }
        }
    })
}

/// The frame's per-ray work (on the GPU when there is one) and the warp figures, from the GPU's
/// counts and from the CPU's walk of the same tree.
fn trace_rays(
    a: &StatsArgs,
    gpu: Option<&bvhscope_gpu::Gpu>,
    bvh: &SceneBvh,
    camera: &Camera,
    secondary: Option<SecondaryRays>,
) -> Result<(Camera, RaySummary, Option<Warp>), CliError> {
    let trace = a.build.trace_options();
    let counts = |f: &crate::render::Frame| f.traced().map(|(_, c)| c).collect::<Vec<_>>();
    Ok(match gpu {
        Some(gpu) => {
            let (tree, mesh) = GpuTree::upload(gpu, bvh, a.device.nodes())?;
            let (frame, _) = tree.frame(gpu, &mesh, camera, trace, true)?;
            let cpu =
                progress::with_spinner("counting the same walk on the CPU", || tree.cpu_counts(bvh, camera, trace));
            let warp = Warp {
                size: a.warp,
                gpu: Some(Warp::of(camera, a.warp, &counts(&frame))),
                cpu: Warp::of(camera, a.warp, &cpu),
            };
            (*camera, frame.ray_summary(), Some(warp))
        }
        None => {
            let settings = RenderSettings { trace, count: true, progressive: false, secondary };
            let frame = progress::with_spinner("tracing the frame", || render(bvh, bvh, camera, &settings));
            // A warp is of camera rays side by side on screen; a pixel's secondary rays are not.
            let warp = secondary.is_none().then(|| Warp {
                size: a.warp,
                gpu: None,
                cpu: Warp::of(camera, a.warp, &counts(&frame)),
            });
            (*camera, frame.ray_summary(), warp)
        }
    })
}

/// A two-level BVH's statistics: the top level over placements, then each mesh's BVH.
fn format_two_level(
    report: &crate::mesh::LoadReport,
    t: &crate::bvh::TwoLevelBvh,
    top: &TreeStats,
    bottom: &[(String, TreeStats)],
) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "scene           {}", report.path.display());
    let _ = writeln!(
        o,
        "two levels      {} placements of {} meshes: {} triangles as placed, {} stored",
        t.instances.len(),
        t.bottom.len(),
        t.instanced_triangle_count(),
        t.bottom.iter().map(|b| b.triangle_count()).sum::<usize>()
    );
    let _ = writeln!(
        o,
        "build           {:.2} ms (mesh BVHs {:.2}, top level {:.2})",
        (t.bottom_time + t.top_time).as_secs_f64() * 1e3,
        t.bottom_time.as_secs_f64() * 1e3,
        t.top_time.as_secs_f64() * 1e3
    );
    let _ = writeln!(
        o,
        "memory          {} bytes (every node, index and triangle array, each mesh BVH once)",
        t.memory_bytes()
    );
    let p = &t.top.params;
    let _ = writeln!(o, "top level       {}, max {} placements per leaf", p.strategy.label(), p.max_leaf_size);
    let _ = writeln!(
        o,
        "                {} nodes ({} leaves), depth max {}, SAH cost {:.3}",
        top.nodes, top.leaves, top.max_depth, top.sah_cost
    );
    let b = &t.bottom_params;
    let _ = writeln!(o, "bottom level    {}", params_text(b));
    for (name, s) in bottom {
        let _ = writeln!(
            o,
            "  {name}: {} triangles, {} nodes, depth max {}, SAH cost {:.3}",
            s.triangles, s.nodes, s.max_depth, s.sah_cost
        );
    }
    o
}

/// Strategy, layout, leaf size and bins, as the text blocks print them.
fn params_text(p: &crate::bvh::BuildParams) -> String {
    format!(
        "{}, {} layout (max leaf size {}, {} SAH bins)",
        p.strategy.label(),
        p.layout.label(),
        p.max_leaf_size,
        p.sah_bins
    )
}

/// The statistics as a human-readable block.
pub fn format_text(report: &crate::mesh::LoadReport, params: &crate::bvh::BuildParams, s: &TreeStats) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "mesh            {}", report.path.display());
    let _ = writeln!(o, "load            {:.2} ms", report.load_time.as_secs_f64() * 1e3);
    let _ = writeln!(
        o,
        "triangles       {} ({} degenerate skipped), {} vertices, {} groups",
        report.triangles, report.degenerate_skipped, report.vertices, report.groups
    );
    let _ = writeln!(o, "strategy        {}", params_text(params));
    let _ = writeln!(
        o,
        "build           {:.2} ms (setup {:.2}, split {:.2}, reorder {:.2})",
        s.build_total_ms, s.build_setup_ms, s.build_split_ms, s.build_reorder_ms
    );
    if let Some(r) = &s.reinsertion {
        let _ = writeln!(o, "reinsertion     {} (in the build time)", r.summary());
    }
    let _ = writeln!(o, "nodes           {} ({} interior, {} leaves)", s.nodes, s.interior_nodes, s.leaves);
    if s.references != s.triangles || params.strategy.splits_references() {
        let _ = writeln!(
            o,
            "references      {} ({:.3} per triangle; {} spatial splits cut triangles)",
            s.references,
            s.references_per_triangle(),
            s.spatial_splits
        );
    }
    let _ = writeln!(o, "depth           max {}, mean leaf depth {:.2}", s.max_depth, s.mean_leaf_depth);
    let _ = writeln!(
        o,
        "SAH cost        {:.3} (C_trav = {}, C_isect = {}, normalised by root area)",
        s.sah_cost, s.sah_constants.traversal, s.sah_constants.intersection
    );
    if let Some(epo) = s.epo {
        let how = match s.epo_error {
            Some(_) => "estimated where summing would cost more than the build, ± two standard errors",
            None => "exact",
        };
        let time = s.epo_ms.map_or(String::new(), |ms| format!(", {} ms", crate::bvh::fmt_ms(ms)));
        let _ = writeln!(
            o,
            "EPO             {} (end-point overlap of the binary tree, Aila et al. 2013; {how}{time})",
            epo::figure(epo, s.epo_error)
        );
    }
    let per = |bytes: usize| bytes as f64 / s.triangles.max(1) as f64;
    let _ = writeln!(
        o,
        "memory          {} bytes ({:.1} per triangle: nodes, indices and the triangles in leaf order)",
        s.memory_bytes,
        per(s.memory_bytes)
    );
    if s.walk_bytes > 0 {
        let _ = writeln!(
            o,
            "                + {} bytes ({:.1} per triangle) of leaves kept for the {} test: {} bytes, {:.1} per triangle",
            s.walk_bytes,
            per(s.walk_bytes),
            crate::geometry::TriangleTest::MollerTrumboreStored.name(),
            s.memory_bytes + s.walk_bytes,
            per(s.memory_bytes + s.walk_bytes)
        );
    }
    if let Some(k) = s.simd {
        // A 4-wide tree's four boxes fit one four-lane pass, its leaves take AVX2's passes of
        // eight: AVX-512 serves the 8-wide layout only.
        let chosen = crate::cpu::Simd::chosen();
        let why = if params.layout == crate::bvh::Layout::Wide4 && k == crate::cpu::Simd::Avx2.name() {
            format!(
                "four children per node take one four-lane pass, leaves up to eight triangles a pass{}",
                if chosen > crate::cpu::Simd::Avx2 {
                    format!("; this CPU's {} serves --layout wide8", chosen.name())
                } else {
                    String::new()
                }
            )
        } else {
            "the best this CPU has for this layout, unless BVHSCOPE_SIMD=avx2|simd4|scalar asks for less".to_string()
        };
        let _ = writeln!(o, "SIMD kernels    {k} ({why})");
    }
    if s.fallback_splits > 0 || s.depth_limited_splits > 0 {
        let _ = writeln!(
            o,
            "fallbacks       {} equal-count splits where the strategy found none, {} below the depth limit",
            s.fallback_splits, s.depth_limited_splits
        );
    }
    let _ = writeln!(o, "leaf sizes      (triangles: leaves)");
    let most = s.leaf_size_histogram.iter().copied().max().unwrap_or(1).max(1);
    for (k, &n) in s.leaf_size_histogram.iter().enumerate().filter(|(_, &n)| n > 0) {
        let bar = "#".repeat((n * 40).div_ceil(most));
        let _ = writeln!(o, "  {k:>3}: {n:>8}  {bar}");
    }
    o
}
