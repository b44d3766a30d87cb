//! `bvhscope trace`: one ray's walk through the BVH, step by step: the steps the app's Ray panel
//! lists, from the same traversal (`bvh::trace`). The ray is a pixel of the camera (0-based, x from
//! the left, y from the top, as everywhere) or typed as an origin and a direction.

use super::args::{BuildArgs, DeviceArgs, ViewArgs};
use super::device;
use crate::bvh::{trace_query_into, RayCounters, SceneBvh, StepKind, StepOut, Trace, TraceLevel, TraceStep};
use crate::cli::error::CliError;
use crate::cli::load::load_mesh;
use crate::geometry::Ray;
use crate::gpu_path::GpuTree;
use crate::options::Named;
use clap::Args;
use glam::Vec3;
use std::fmt::Write;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TraceFormat {
    Text,
    Json,
}

const TRACE_FORMATS: [Named<TraceFormat>; 2] = [
    Named { value: TraceFormat::Text, name: "text", label: "Text", help: "plain text, to read" },
    Named { value: TraceFormat::Json, name: "json", label: "JSON", help: "one JSON document, for scripts" },
];
bvhscope_core::choice!(TraceFormat, TRACE_FORMATS, 2);

#[derive(Args, Debug)]
pub struct TraceArgs {
    #[arg(help = crate::cli::args::MESH_HELP)]
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
    /// With a secondary kind the walk is of one of the pixel's secondary rays (from its camera
    /// ray's hit, as the heatmap traces them; --hottest ranks that heatmap).
    #[command(flatten)]
    pub rays: super::rays::RayArgs,
    /// Which of the pixel's secondary rays to walk (0-based; the listing names them all).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub secondary: u32,
    #[arg(long, value_parser = crate::cli::args::choice::<TraceFormat>(), default_value = "text")]
    pub format: TraceFormat,
    /// Trace through a BVH written by another program (bvhscope-bvh, as `check` reads it) instead
    /// of building one.
    #[arg(long, value_name = "FILE")]
    pub bvh: Option<PathBuf>,
    #[command(flatten)]
    pub dump_limit: super::args::DumpLimit,
    /// The most steps listed: a longer walk (a tree whose boxes all overlap, a chain thousands
    /// deep) is listed that far, then counted to its end; its hit and counts are the whole walk's.
    #[arg(long, default_value_t = 1_000_000, value_parser = clap::value_parser!(u64).range(1..))]
    pub max_steps: u64,
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
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    write(a, &mut out)?;
    std::io::Write::flush(&mut out).map_err(CliError::Stdout)
}

/// What `run` prints: the text table or the JSON (the app's tests compare it with the Ray window).
pub fn output(a: &TraceArgs) -> Result<String, CliError> {
    let mut out = Vec::new();
    write(a, &mut out)?;
    Ok(String::from_utf8_lossy(&out).into_owned())
}

/// The listing written to `out` as the walk goes.
pub fn write(a: &TraceArgs, out: &mut dyn std::io::Write) -> Result<(), CliError> {
    let gpu = device::open(&a.device)?;
    let kind = a.rays.one("trace")?;
    if gpu.is_some() && kind.is_secondary() {
        return Err(super::render::gpu_traces_primary_only(kind));
    }
    if kind.is_secondary() && a.ray.is_some() {
        return Err(CliError::Usage(format!(
            "--ray-kind {} starts at a pixel's hit: give --pixel or --hottest, not --ray",
            kind.name()
        )));
    }
    let scene = load_mesh(&a.mesh)?;
    let mut params = a.build.params(scene.build.as_ref());
    if gpu.is_some() {
        params = device::gpu_params(&a.build, scene.build.as_ref(), params)?;
        device::check_traceable(&a.build.scene_build(params), a.build.trace_options())?;
    }
    let bvh = match &a.bvh {
        Some(path) => a.dump_limit.import(&scene, path)?,
        None => crate::cli::load::build_scene(gpu.as_ref(), &scene, &a.build.scene_build(params))?.0,
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
            let settings = crate::render::RenderSettings {
                trace: a.build.trace_options(),
                count: true,
                progressive: false,
                secondary: a.rays.secondary(kind, &scene.bounds(), &camera),
            };
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
            let source = serde_json::json!({ "pixel": [x, y], "camera": camera });
            match a.rays.secondary(kind, &scene.bounds(), &camera) {
                None => (camera.ray_gen().pixel_ray(x, y), source),
                Some(sec) => secondary_ray(a, &bvh, &camera, &sec, (x, y), source)?,
            }
        }
        (None, None) => unreachable!("clap requires --pixel or --ray"),
    };
    let opts = a.build.trace_options();
    let build_label = bvh.label();
    let head = Head { a, ray, source, hot, build_label, opts, two_levels: bvh.two_level().is_some() };
    // On the GPU: its hit and counts, and no steps.
    if let Some((g, (tree, _))) = &on_gpu {
        let t = tree.trace(g, bvhscope_gpu::Rays::List(&[ray]), opts, true)?;
        let counts = t.counters.first().copied().unwrap_or_default();
        let finished = if t.cpu_finished > 0 {
            format!(
                "; its walk reached the GPU's step budget ({} steps) and was finished on the CPU (the same walk: its hit and counts are the CPU's)",
                bvhscope_gpu::STEP_BUDGET
            )
        } else {
            String::new()
        };
        let note = format!(
            "traced on the GPU ({} nodes, {}){finished}: the GPU walk records no steps (its kernels keep each ray's hit and counts only); for the walk step by step, run this with --device cpu",
            tree.nodes().label(),
            g.name()
        );
        let hit = t.hits.first().copied().flatten();
        let mut sink = Listing::new(out, &head);
        sink.start(Some(&note));
        return sink.end(hit, counts, 0, Some(&note));
    }
    // On the CPU: each step written as the walk makes it (an imported tree's nodes by the dump's
    // ids, its triangles by the file's numbers), the first --max-steps of them.
    let names = match (&bvh, a.bvh.is_some()) {
        (SceneBvh::Single { mesh, imported: Some(names), .. }, true) => Some((names.clone(), mesh.clone())),
        _ => None,
    };
    let mut sink = Listing::new(out, &head);
    sink.rename = names;
    sink.start(None);
    let (mut hit, trace) = trace_query_into(&bvh, &ray, opts, kind.any_hit(), Trace::into(sink, a.max_steps));
    if let (SceneBvh::Single { mesh, imported: Some(_), .. }, true, Some(h)) = (&bvh, a.bvh.is_some(), hit.as_mut()) {
        h.prim = mesh.file_number(h.prim);
    }
    let (counts, dropped) = (trace.counts(), trace.dropped());
    trace.steps.end(hit, counts, dropped, None)
}

/// Pixel (x, y)'s secondary ray `a.secondary`, and the listing's source: the pixel, and each of
/// its secondary rays with its hit and counts (the walk is of the one chosen).
fn secondary_ray(
    a: &TraceArgs,
    bvh: &SceneBvh,
    camera: &crate::render::Camera,
    sec: &crate::render::SecondaryRays,
    (x, y): (u32, u32),
    mut source: serde_json::Value,
) -> Result<(Ray, serde_json::Value), CliError> {
    let opts = a.build.trace_options();
    let kind = sec.spec.kind;
    let rays = sec.pixel_rays(bvh, bvh, camera, opts, (x, y)).ok_or_else(|| {
        CliError::Usage(format!("pixel {x},{y}: its camera ray misses the mesh, so it has no {} rays", kind.name()))
    })?;
    let n = a.secondary as usize;
    let ray = *rays.get(n).ok_or_else(|| {
        CliError::Usage(format!("--secondary {n}: pixel {x},{y} has {} {} rays (0-based)", rays.len(), kind.name()))
    })?;
    let listed: Vec<serde_json::Value> = rays
        .iter()
        .map(|r| {
            let mut c = RayCounters::ZERO;
            let hit = kind.trace(bvh, r, opts, &mut c);
            serde_json::json!({
                "origin": r.origin().to_array(), "dir": r.dir().to_array(), "length": r.t_max, "hit": hit,
                "nodes_visited": c.nodes_visited, "triangle_tests": c.triangle_tests,
            })
        })
        .collect();
    source["secondary"] = serde_json::json!({
        "kind": kind.name(), "describe": sec.spec.describe(), "walked": n, "rays": listed,
    });
    Ok((ray, source))
}

/// The text listing's lines for a pixel's secondary rays: which is walked, and each one's hit
/// and counts.
fn secondary_text(sec: &serde_json::Value) -> String {
    let rays = sec["rays"].as_array().map_or(&[][..], |r| r.as_slice());
    let walked = sec["walked"].as_u64().unwrap_or(0) as usize;
    let mut o = format!(
        "secondary       {}: ray {walked} of {} (0-based) walked below\n",
        sec["describe"].as_str().unwrap_or(""),
        rays.len()
    );
    for (i, r) in rays.iter().enumerate() {
        let mark = if i == walked { "▶" } else { " " };
        let _ = writeln!(
            o,
            "  {mark} ray {i:<3}     {}, nodes visited {}, triangle tests {}",
            if r["hit"].as_bool() == Some(true) { "hit " } else { "miss" },
            r["nodes_visited"],
            r["triangle_tests"]
        );
    }
    o
}

/// What the listing of one ray says before and around its steps.
struct Head<'a> {
    a: &'a TraceArgs,
    ray: Ray,
    source: serde_json::Value,
    hot: Option<(u32, u32)>,
    build_label: String,
    opts: crate::bvh::TraceOptions,
    two_levels: bool,
}

/// The walk written as it goes, text or JSON, into `out`: the head, each step as the trace makes
/// it (`StepOut`), then the hit and the counts. Memory holds one step at a time whatever the
/// walk's length; the first write error is kept and returned at the end (the rest is not tried).
struct Listing<'a> {
    out: &'a mut dyn std::io::Write,
    head: &'a Head<'a>,
    rename: Option<(Arc<crate::bvh::imported::Imported>, Arc<crate::mesh::Mesh>)>,
    steps: u64,
    entered: u32,
    error: Option<std::io::Error>,
}

impl<'a> Listing<'a> {
    fn new(out: &'a mut dyn std::io::Write, head: &'a Head<'a>) -> Self {
        Listing { out, head, rename: None, steps: 0, entered: 0, error: None }
    }

    fn json(&self) -> bool {
        matches!(self.head.a.format, TraceFormat::Json)
    }

    fn write(&mut self, text: &str) {
        if self.error.is_none() {
            if let Err(e) = self.out.write_all(text.as_bytes()) {
                self.error = Some(e);
            }
        }
    }

    /// The head: the ray, its pixel, the build and traversal (the JSON's keys before "steps").
    fn start(&mut self, gpu_note: Option<&str>) {
        let h = self.head;
        if self.json() {
            let json = |v: serde_json::Value| serde_json::to_string(&v).expect("plain data serialises");
            let text = format!(
                "{{\n  \"ray\": {},\n  \"build\": {},\n  \"trace\": {},\n  \"device\": {},\n  \"steps\": {}",
                json(
                    serde_json::json!({ "origin": h.ray.origin().to_array(), "dir": h.ray.dir().to_array(), "from": h.source })
                ),
                json(serde_json::json!(h.build_label)),
                json(serde_json::json!(h.opts)),
                json(serde_json::json!(h.a.device.device)),
                if gpu_note.is_some() { "null" } else { "[" }
            );
            self.write(&text);
            return;
        }
        let (o3, d3) = (h.ray.origin(), h.ray.dir());
        let mut o = format!(
            "ray             origin ({}, {}, {}), direction ({}, {}, {}){}\n",
            o3.x,
            o3.y,
            o3.z,
            d3.x,
            d3.y,
            d3.z,
            if h.ray.t_max.is_finite() { format!(", length {}", h.ray.t_max) } else { String::new() }
        );
        if let Some((x, y)) = h.a.pixel.or(h.hot).filter(|_| h.a.ray.is_none()) {
            let rank = h.a.hottest.map_or(String::new(), |k| {
                format!(
                    " (the pixel with the {} most work of {})",
                    crate::explain::words::ordinal(k),
                    h.a.view.label().to_lowercase()
                )
            });
            let _ = writeln!(o, "pixel           {x},{y}{rank}");
        }
        if let Some(sec) = h.source.get("secondary") {
            o += &secondary_text(sec);
        }
        let _ = writeln!(o, "build           {}", h.build_label);
        let _ = writeln!(o, "traversal       {} order, {} test", h.opts.order.label(), h.opts.test.label());
        let _ = writeln!(o);
        if let Some(note) = gpu_note {
            let _ = writeln!(o, "steps           {note}");
        }
        self.write(&o);
    }

    /// The tail: the hit, the counts of the whole walk, and how many steps were left out.
    fn end(
        mut self,
        hit: Option<crate::bvh::Hit>,
        counts: RayCounters,
        dropped: u64,
        gpu_note: Option<&str>,
    ) -> Result<(), CliError> {
        let max = self.head.a.max_steps;
        let cut = (dropped > 0).then(|| {
            format!(
                "the first {max} steps are listed (--max-steps); the walk went on for {dropped} more box tests, nodes, leaves and triangle tests (its stack's steps not counted), and the hit and counts are the whole walk's"
            )
        });
        if self.json() {
            let json = |v: serde_json::Value| serde_json::to_string(&v).expect("plain data serialises");
            let text = format!(
                "{},\n  \"hit\": {},\n  \"counts\": {},\n  \"steps_left_out\": {dropped},\n  \"note\": {}\n}}\n",
                if gpu_note.is_some() { "" } else { "\n  ]" },
                json(serde_json::json!(hit.map(|h| serde_json::json!({ "triangle": h.prim, "t": h.t })))),
                json(counts_json(&counts)),
                json(serde_json::json!(gpu_note.map(str::to_string).or(cut)))
            );
            self.write(&text);
        } else {
            let mut o = String::from("\n");
            if let Some(cut) = &cut {
                let _ = writeln!(o, "… {cut}\n");
            }
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
            self.write(&o);
        }
        match self.error.take() {
            None => Ok(()),
            Some(e) => Err(CliError::Stdout(e)),
        }
    }
}

impl StepOut for Listing<'_> {
    fn put(&mut self, step: TraceStep) {
        let step = match &self.rename {
            Some((names, mesh)) => names.rename(&step, mesh),
            None => step,
        };
        self.steps += 1;
        if self.json() {
            let sep = if self.steps == 1 { "\n    " } else { ",\n    " };
            // Through a value, as the app's steps are serialised (f32s written as the f64s they are).
            let value = serde_json::to_value(&step).expect("plain data serialises");
            let text = format!("{sep}{value}");
            self.write(&text);
            return;
        }
        let (depth, text) = (step.depth(), step.text());
        if let StepKind::Enter { depth, .. } = step.kind {
            self.entered = depth;
        }
        let depth = depth.unwrap_or(self.entered + 1);
        let level = if self.head.two_levels { format!("{:<10}", level_text(step.level)) } else { String::new() };
        let line = format!("{:>5}  {level}{}{text}\n", self.steps, crate::bvh::trace::indent(depth));
        self.write(&line);
    }
}
