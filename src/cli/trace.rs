//! `bvhscope trace`: one ray's walk through the BVH, step by step: the steps the app's Ray panel
//! lists, from the same traversal (`bvh::trace`). The ray is a pixel of the camera (0-based, x from
//! the left, y from the top, as everywhere) or typed as an origin and a direction.

use super::args::{BuildArgs, DeviceArgs, ViewArgs};
use super::device::{self, GpuTree};
use super::{load_mesh, CliError};
use crate::bvh::{trace_ray, RayCounters, SceneBvh, StepKind, TraceLevel};
use crate::geometry::Ray;
use clap::{Args, ValueEnum};
use glam::Vec3;
use std::fmt::Write;
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum TraceFormat {
    Text,
    Json,
}

#[derive(Args, Debug)]
pub struct TraceArgs {
    /// The mesh (.obj) or scene (.json: bvhscope's or Moer-lite's).
    pub mesh: PathBuf,
    /// The pixel X,Y of the camera's image (0-based, x from the left, y from the top).
    #[arg(long, value_parser = parse_pixel, conflicts_with_all = ["ray", "hottest"], required_unless_present_any = ["ray", "hottest"])]
    pub pixel: Option<(u32, u32)>,
    /// The pixel with the K-th most work of --view's heatmap (1: the hottest; ties in reading
    /// order), as the app's "Hottest pixel" and "Next" pin it.
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u32).range(1..), conflicts_with = "ray")]
    pub hottest: Option<u32>,
    /// The heatmap whose work --hottest ranks.
    #[arg(long, value_parser = super::args::choice::<crate::render::View>(), default_value = "visits")]
    pub view: crate::render::View,
    /// A ray typed as OX,OY,OZ:DX,DY,DZ (origin and direction, world space).
    #[arg(long, value_parser = parse_ray, allow_hyphen_values = true)]
    pub ray: Option<(Vec3, Vec3)>,
    #[command(flatten)]
    pub build: BuildArgs,
    /// With --device gpu the ray (and --hottest's frame) is traced on the GPU: its hit and counts
    /// are printed, without steps, which the GPU walk does not record.
    #[command(flatten)]
    pub device: DeviceArgs,
    /// The camera whose pixel is traced (as `render` takes it).
    #[command(flatten)]
    pub view_args: ViewArgs,
    #[arg(long, value_enum, default_value = "text")]
    pub format: TraceFormat,
    /// Trace through a BVH written by another program (bvhscope-bvh, as `check` reads it) instead
    /// of building one.
    #[arg(long, value_name = "FILE")]
    pub bvh: Option<PathBuf>,
    #[command(flatten)]
    pub dump_limit: super::args::DumpLimit,
}

fn parse_pixel(s: &str) -> Result<(u32, u32), String> {
    let (x, y) = s.split_once(',').ok_or_else(|| format!("'{s}' is not X,Y"))?;
    match (x.trim().parse::<u32>(), y.trim().parse::<u32>()) {
        (Ok(x), Ok(y)) => Ok((x, y)),
        _ => Err(format!("'{s}' is not X,Y (two whole numbers from 0)")),
    }
}

fn parse_ray(s: &str) -> Result<(Vec3, Vec3), String> {
    let (o, d) = s.split_once(':').ok_or_else(|| format!("'{s}' is not OX,OY,OZ:DX,DY,DZ"))?;
    let (o, d) = (super::args::parse_vec3(o)?, super::args::parse_vec3(d)?);
    if d == Vec3::ZERO {
        return Err(format!("'{s}': the direction is zero"));
    }
    Ok((o, d))
}

fn level_text(l: TraceLevel) -> String {
    match l {
        TraceLevel::Mesh => "".into(),
        TraceLevel::Top => "top".into(),
        TraceLevel::Bottom { instance } => format!("mesh@{instance}"),
    }
}

fn counts_json(c: &RayCounters) -> serde_json::Value {
    serde_json::json!({
        "nodes_visited": c.nodes_visited, "box_tests": c.box_tests,
        "leaves_visited": c.leaves_visited, "triangle_tests": c.triangle_tests,
    })
}

pub fn run(a: &TraceArgs) -> Result<(), CliError> {
    super::out(&output(a)?);
    Ok(())
}

/// What `run` prints: the text table or the JSON (the app's tests compare it with the Ray window).
pub fn output(a: &TraceArgs) -> Result<String, CliError> {
    let gpu = device::open(&a.device)?;
    let scene = load_mesh(&a.mesh)?;
    let mut params = a.build.params(scene.build.as_ref());
    if gpu.is_some() {
        params = device::gpu_params(&a.build, scene.build.as_ref(), params)?;
        device::check_traceable(&a.build.scene_build(params), a.build.trace())?;
    }
    let bvh = match &a.bvh {
        Some(path) => a.dump_limit.import(&scene, path)?,
        None => device::build_scene(gpu.as_ref(), &scene, &a.build.scene_build(params))?.0,
    };
    let on_gpu = match &gpu {
        Some(g) => Some((g, GpuTree::upload(g, &bvh, a.device.nodes())?)),
        None => None,
    };
    // The K-th hottest pixel: the frame traced and counted, as the app's heatmap is.
    let hot = match a.hottest {
        Some(k) => {
            let camera = a.view_args.camera(&scene.bounds(), scene.camera.as_ref())?;
            if !a.view.is_heatmap() {
                return Err(CliError::Usage(
                    "--hottest ranks a heatmap's work: --view visits, tri-tests or cost".into(),
                ));
            }
            let settings = crate::render::RenderSettings { trace: a.build.trace(), count: true, progressive: false };
            let frame = match &on_gpu {
                Some((g, (tree, mesh))) => tree.frame(g, mesh, &camera, settings.trace, true)?.0,
                None => super::progress::with_spinner("tracing the frame", || {
                    crate::render::render(&bvh, &bvh, &camera, &settings)
                }),
            };
            let (x, y, _) = crate::render::hottest(&frame, a.view, params.cost, k as usize - 1).ok_or_else(|| {
                CliError::Usage(format!("--hottest {k}: the {}x{} frame has fewer pixels", camera.width, camera.height))
            })?;
            Some((x, y))
        }
        None => None,
    };
    let (ray, source) = match (a.pixel.or(hot), a.ray) {
        (_, Some((o, d))) => (Ray::new(o, d), serde_json::json!({ "typed": true })),
        (Some((x, y)), None) => {
            let camera = a.view_args.camera(&scene.bounds(), scene.camera.as_ref())?;
            if x >= camera.width || y >= camera.height {
                return Err(CliError::Usage(format!(
                    "--pixel {x},{y} is outside the {}x{} image (pixels are 0-based)",
                    camera.width, camera.height
                )));
            }
            (camera.ray_gen().pixel_ray(x, y), serde_json::json!({ "pixel": [x, y], "camera": camera }))
        }
        (None, None) => unreachable!("clap requires --pixel or --ray"),
    };
    let opts = a.build.trace();
    // On the GPU: its hit and counts, and no steps (an empty trace).
    let mut finished_on_cpu = false;
    let (mut hit, mut trace, gpu_counts) = match &on_gpu {
        Some((g, (tree, _))) => {
            let t = tree.trace(g, bvhscope_gpu::Rays::List(&[ray]), opts, true)?;
            let counts = t.counters.first().copied().unwrap_or_default();
            finished_on_cpu = t.cpu_finished > 0;
            (t.hits.first().copied().flatten(), crate::bvh::Trace::new(), Some(counts))
        }
        None => {
            let (hit, trace) = trace_ray(&bvh, &ray, opts);
            (hit, trace, None)
        }
    };
    // An imported tree's nodes by the dump's ids, its triangles by the file's numbers.
    if let (SceneBvh::Single { mesh, imported: Some(names), .. }, true) = (&bvh, a.bvh.is_some()) {
        trace.steps = trace.steps.iter().map(|s| names.rename(s, mesh)).collect();
        if let Some(h) = &mut hit {
            h.prim = mesh.file_number(h.prim);
        }
    }
    let build_label = bvh.label();
    let counts = gpu_counts.unwrap_or_else(|| trace.counts());
    let gpu_note = on_gpu.as_ref().map(|(g, (tree, _))| {
        let finished = if finished_on_cpu {
            format!(
                "; its walk reached the GPU's step budget ({} steps) and was finished on the CPU (the same walk: its hit and counts are the CPU's)",
                bvhscope_gpu::STEP_BUDGET
            )
        } else {
            String::new()
        };
        format!(
            "traced on the GPU ({} nodes, {}){finished}: the GPU walk records no steps (its kernels keep each ray's hit and counts only); for the walk step by step, run this with --device cpu",
            tree.nodes().name(),
            g.name()
        )
    });
    let mut o = String::new();
    match a.format {
        TraceFormat::Json => {
            let v = serde_json::json!({
                "ray": { "origin": ray.origin().to_array(), "dir": ray.dir().to_array(), "from": source },
                "build": build_label,
                "trace": opts,
                "hit": hit.map(|h| serde_json::json!({ "triangle": h.prim, "t": h.t })),
                "counts": counts_json(&counts),
                "steps": if gpu_note.is_some() { serde_json::Value::Null } else { serde_json::json!(trace.steps) },
                "device": a.device.device,
                "note": gpu_note,
            });
            let _ = writeln!(o, "{}", serde_json::to_string_pretty(&v).expect("plain data serialises"));
        }
        TraceFormat::Text => {
            let (o3, d3) = (ray.origin(), ray.dir());
            let _ = writeln!(
                o,
                "ray             origin ({}, {}, {}), direction ({}, {}, {})",
                o3.x, o3.y, o3.z, d3.x, d3.y, d3.z
            );
            if let Some((x, y)) = a.pixel.or(hot).filter(|_| a.ray.is_none()) {
                let rank = a.hottest.map_or(String::new(), |k| {
                    format!(
                        " (the pixel with the {} most work of {})",
                        crate::explain::words::ordinal(k),
                        a.view.label().to_lowercase()
                    )
                });
                let _ = writeln!(o, "pixel           {x},{y}{rank}");
            }
            let _ = writeln!(o, "build           {build_label}");
            let _ = writeln!(o, "traversal       {} order, {} test", opts.order.label(), opts.test.label());
            let _ = writeln!(o);
            if let Some(note) = &gpu_note {
                let _ = writeln!(o, "steps           {note}");
            }
            let levels = trace.steps.iter().any(|s| s.level != TraceLevel::Mesh);
            let mut entered = 0;
            for (i, s) in trace.steps.iter().enumerate() {
                let (depth, text) = (s.depth(), s.text());
                if let StepKind::Enter { depth, .. } = s.kind {
                    entered = depth;
                }
                let depth = depth.unwrap_or(entered + 1);
                let level = if levels { format!("{:<10}", level_text(s.level)) } else { String::new() };
                let _ = writeln!(o, "{:>5}  {level}{}{text}", i + 1, crate::bvh::trace::indent(depth));
            }
            let _ = writeln!(o);
            match hit {
                Some(h) => {
                    let _ = writeln!(
                        o,
                        "hit             triangle {} at t = {:.6} (u {:.4}, v {:.4})",
                        h.prim, h.t, h.u, h.v
                    );
                }
                None => {
                    let _ = writeln!(o, "hit             nothing");
                }
            }
            let _ = writeln!(
                o,
                "counts          nodes visited {}, box tests {}, leaves visited {}, triangle tests {}",
                counts.nodes_visited, counts.box_tests, counts.leaves_visited, counts.triangle_tests
            );
        }
    }
    Ok(o)
}
