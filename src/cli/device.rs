//! `--device gpu`: how the commands use the GPU crate (`bvhscope-gpu`). The GPU is opened once per
//! command; without an adapter the command fails with the crate's message (what to install), and
//! nothing falls back to the CPU unasked. The GPU walks the binary tree as built (core's nodes,
//! byte for byte) or its CWBVH form, with the watertight test, over one level; its per-ray counts
//! are the CPU's for the binary layout. The strategies lbvh and ploc are built on the GPU too
//! (core's trees node for node), with the build's phases timed.

use super::args::{BuildArgs, DeviceArgs, GpuNodes};
use super::{progress, CliError};
use crate::bvh::{AnyBvh, BuildParams, Bvh, Layout, RayCounters, SceneBuild, SceneBvh, SplitStrategy, TraceOptions};
use crate::geometry::{Ray, TriangleTest};
use crate::mesh::Mesh;
use crate::render::{Camera, Frame};
use crate::scene::Scene;
use bvhscope_gpu::{Cwbvh, Gpu, GpuBinaryBvh, GpuBuildTimings, GpuCwbvh, GpuError, GpuLbvh, GpuPloc, GpuTrace, Rays};
use rayon::prelude::*;
use std::sync::Arc;

/// A GPU error as the command line reports it: one line, exit 2.
pub fn gpu_error(e: GpuError) -> CliError {
    CliError::Usage(format!("--device gpu: {e}"))
}

/// The GPU for `--device gpu`, `None` for the CPU. `--gpu-nodes` without `--device gpu` is refused:
/// it would change nothing, silently.
pub fn open(d: &DeviceArgs) -> Result<Option<Gpu>, CliError> {
    if !d.gpu() {
        if d.gpu_nodes.is_some() {
            return Err(CliError::Usage("--gpu-nodes is the GPU's node format: add --device gpu".into()));
        }
        return Ok(None);
    }
    let gpu = progress::with_spinner("opening the GPU", Gpu::new).map_err(gpu_error)?;
    if gpu.is_software() {
        eprintln!("note: {} is a software adapter: its counts are right, its times are no GPU's", gpu.name());
    }
    Ok(Some(gpu))
}

/// The build parameters a GPU trace needs: the binary layout (the GPU walks binary nodes, or CWBVH
/// nodes made from them). A wide layout given on the command line is refused; one that came from
/// a preset or a scene file (`scene`) is replaced, with a note; the default one silently.
pub fn gpu_params(build: &BuildArgs, scene: Option<&BuildParams>, p: BuildParams) -> Result<BuildParams, CliError> {
    if p.layout == Layout::Binary {
        return Ok(p);
    }
    if build.layout.is_some() {
        return Err(CliError::Usage(format!(
            "--layout {}: the GPU walks binary nodes (or CWBVH nodes made from them, --gpu-nodes cwbvh); \
             leave out --layout, or trace the {} layout with --device cpu",
            p.layout.name(),
            p.layout.name()
        )));
    }
    let from = match (build.preset, scene) {
        (Some(preset), _) => Some(format!("the preset {}", preset.name())),
        (None, Some(_)) => Some("the scene file".to_string()),
        (None, None) => None,
    };
    if let Some(from) = from {
        eprintln!("note: the GPU walks the binary tree; the {} layout of {from} is for the CPU", p.layout.name());
    }
    Ok(BuildParams { layout: Layout::Binary, ..p })
}

/// Refuse what the GPU does not trace: two levels, the Möller–Trumbore test.
pub fn check_traceable(build: &SceneBuild, trace: TraceOptions) -> Result<(), CliError> {
    if build.top.is_some() {
        return Err(CliError::Usage(
            "--two-level: the GPU traces one BVH over the scene's triangles; leave out --two-level or use --device cpu"
                .into(),
        ));
    }
    if trace.test != TriangleTest::Watertight {
        return Err(CliError::Usage(
            "--triangle-test moller-trumbore: the GPU runs the watertight test only; use --device cpu for Möller–Trumbore"
                .into(),
        ));
    }
    Ok(())
}

/// A build made on the GPU: which builder, and how long each phase took.
#[derive(Clone, Copy, Debug)]
pub struct GpuBuild {
    pub strategy: SplitStrategy,
    pub timings: GpuBuildTimings,
}

impl GpuBuild {
    /// The phases as `stats` prints them (PLOC's emission is its clustering, its boxes the host's
    /// layout of the leaves).
    pub fn text(&self) -> String {
        let t = &self.timings;
        let ms = |d: std::time::Duration| format!("{:.2}", d.as_secs_f64() * 1e3);
        let (emission, boxes) = match self.strategy {
            SplitStrategy::Ploc => {
                (format!("clustering {} ({} rounds)", ms(t.emission), t.rounds), "layout on the host")
            }
            _ => (format!("emission {}", ms(t.emission)), "boxes"),
        };
        format!(
            "{} ms (upload {}, codes {}, sort {}, {emission}, {boxes} {}, download {})",
            ms(t.total()),
            ms(t.upload),
            ms(t.codes),
            ms(t.sort),
            ms(t.boxes),
            ms(t.download)
        )
    }

    pub fn json(&self) -> serde_json::Value {
        let t = &self.timings;
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        serde_json::json!({
            "strategy": self.strategy.name(), "total_ms": ms(t.total()), "upload_ms": ms(t.upload),
            "codes_ms": ms(t.codes), "sort_ms": ms(t.sort), "emission_ms": ms(t.emission), "boxes_ms": ms(t.boxes),
            "download_ms": ms(t.download), "ploc_rounds": t.rounds,
        })
    }
}

/// Lay a built binary tree out as `layout` asks (as `AnyBvh::build` does after its build).
fn lay_out(bvh: Bvh, layout: Layout) -> AnyBvh {
    match layout {
        Layout::Binary => AnyBvh::Binary(bvh),
        Layout::Wide4 => AnyBvh::Wide(crate::bvh::WideBvh::from_binary(bvh)),
        Layout::Wide8 => AnyBvh::Wide8(crate::bvh::WideBvh::collapse(bvh)),
    }
}

/// Whether the GPU builds `strategy` (lbvh and ploc; the others are built on the CPU).
pub fn builds_on_gpu(strategy: SplitStrategy) -> bool {
    matches!(strategy, SplitStrategy::Lbvh | SplitStrategy::Ploc)
}

/// `gpu_build` without a spinner (the app's build job).
pub fn build_on_gpu(gpu: &Gpu, mesh: &Mesh, params: &BuildParams) -> Result<Option<(AnyBvh, GpuBuild)>, GpuError> {
    let strategy = params.strategy;
    let built = match strategy {
        SplitStrategy::Lbvh => GpuLbvh::new(gpu).and_then(|b| b.build(gpu, mesh, params)).map(Some),
        SplitStrategy::Ploc => GpuPloc::new(gpu).and_then(|b| b.build(gpu, mesh, params)).map(Some),
        _ => Ok(None),
    }?;
    Ok(built.map(|(mut bvh, timings)| {
        if params.reinsert_passes > 0 {
            bvh.report.reinsertion = Some(crate::bvh::reinsert::optimise(&mut bvh, params.reinsert_passes));
        }
        (lay_out(bvh, params.layout), GpuBuild { strategy, timings })
    }))
}

/// Build `params` over `mesh` with lbvh or ploc on the GPU (reinsertion, if asked for, then on the
/// CPU, as `Bvh::build` runs it after any builder); `None` for the other strategies, which only
/// the CPU builds.
pub fn gpu_build(gpu: &Gpu, mesh: &Mesh, params: &BuildParams) -> Result<Option<(AnyBvh, GpuBuild)>, CliError> {
    let label = format!("building the BVH ({} on the GPU)", params.strategy.label());
    progress::with_spinner(&label, || build_on_gpu(gpu, mesh, params)).map_err(gpu_error)
}

/// Build what `build` asks for: lbvh and ploc of one level on the GPU when there is one, anything
/// else on the CPU (`cli::build_scene`).
pub fn build_scene(
    gpu: Option<&Gpu>,
    scene: &Scene,
    build: &SceneBuild,
) -> Result<(SceneBvh, Option<GpuBuild>), CliError> {
    if let (Some(gpu), None) = (gpu, build.top) {
        let mesh = scene.flat_mesh()?;
        if let Some((bvh, phases)) = gpu_build(gpu, &mesh, &build.bvh)? {
            return Ok((SceneBvh::Single { bvh, mesh, imported: None }, Some(phases)));
        }
    }
    Ok((super::build_scene(scene, build)?, None))
}

/// A tree on the GPU in the node format asked for, with the mesh its hits are on.
pub enum GpuTree {
    Binary(GpuBinaryBvh),
    /// The CWBVH's CPU form too: its CPU walk is the reference for the GPU's counts.
    Cwbvh(Box<Cwbvh>, GpuCwbvh),
}

impl GpuTree {
    /// Upload the binary tree of `bvh` (one level: as built, or an imported dump's) as `nodes`.
    pub fn new(gpu: &Gpu, bvh: &SceneBvh, nodes: GpuNodes) -> Result<(GpuTree, Arc<Mesh>), GpuError> {
        let SceneBvh::Single { mesh, .. } = bvh else {
            return Err(GpuError::Input("the GPU traces one BVH, not two levels".into()));
        };
        let tree = bvh.binary_tree().ok_or_else(|| {
            GpuError::Input("this imported wide tree has no binary form the GPU could walk; trace it on the CPU".into())
        })?;
        let uploaded = match nodes {
            GpuNodes::Binary => GpuTree::Binary(GpuBinaryBvh::upload(gpu, &tree)?),
            GpuNodes::Cwbvh => {
                let cw = Cwbvh::from_bvh(&tree)?;
                let on_gpu = GpuCwbvh::upload(gpu, &cw)?;
                GpuTree::Cwbvh(Box::new(cw), on_gpu)
            }
        };
        Ok((uploaded, mesh.clone()))
    }

    /// `new`, with a spinner while it takes long and the command line's error.
    pub fn upload(gpu: &Gpu, bvh: &SceneBvh, nodes: GpuNodes) -> Result<(GpuTree, Arc<Mesh>), CliError> {
        progress::with_spinner("uploading the tree to the GPU", || Self::new(gpu, bvh, nodes)).map_err(gpu_error)
    }

    pub fn nodes(&self) -> GpuNodes {
        match self {
            GpuTree::Binary(_) => GpuNodes::Binary,
            GpuTree::Cwbvh(..) => GpuNodes::Cwbvh,
        }
    }

    /// Trace `rays` (closest hits), counting when `counted`, in `trace`'s order (binary nodes;
    /// CWBVH orders its children by octant).
    pub fn walk(&self, gpu: &Gpu, rays: Rays, trace: TraceOptions, counted: bool) -> Result<GpuTrace, GpuError> {
        let opts = bvhscope_gpu::GpuTraceOptions { order: trace.order, counted, exact: true };
        match self {
            GpuTree::Binary(t) => t.trace(gpu, rays, opts),
            GpuTree::Cwbvh(_, t) => t.trace(gpu, rays, opts),
        }
    }

    /// `walk`, with the command line's error.
    pub fn trace(&self, gpu: &Gpu, rays: Rays, trace: TraceOptions, counted: bool) -> Result<GpuTrace, CliError> {
        self.walk(gpu, rays, trace, counted).map_err(gpu_error)
    }

    /// `camera`'s frame traced on the GPU, as a frame the views, legends and CSVs read.
    pub fn frame(
        &self,
        gpu: &Gpu,
        mesh: &Mesh,
        camera: &Camera,
        trace: TraceOptions,
        counted: bool,
    ) -> Result<(Frame, GpuTrace), CliError> {
        let label = format!("tracing the {}x{} frame on the GPU", camera.width, camera.height);
        let t = progress::with_spinner(&label, || self.trace(gpu, Rays::Camera(camera), trace, counted))?;
        let frame = Frame::from_hits(mesh, camera, &t.hits, &t.counters)
            .map_err(|e| CliError::Usage(format!("--device gpu: {e}")))?;
        Ok((frame, t))
    }

    /// The per-pixel counts of the same walk on the CPU (row by row): core's renderer for binary
    /// nodes (`cpu` is the binary tree's `SceneBvh`), the CWBVH's own CPU walk for CWBVH nodes.
    pub fn cpu_counts(&self, cpu: &SceneBvh, camera: &Camera, trace: TraceOptions) -> Vec<RayCounters> {
        match self {
            GpuTree::Binary(_) => {
                let settings = crate::render::RenderSettings { trace, count: true, progressive: false };
                let frame = crate::render::render(cpu, cpu, camera, &settings);
                frame.traced().map(|(_, c)| c).collect()
            }
            GpuTree::Cwbvh(cw, _) => {
                let gen = camera.ray_gen();
                (0..camera.width * camera.height)
                    .into_par_iter()
                    .map(|i| cw.trace_cpu(&mut gen.pixel_ray(i % camera.width, i / camera.width)).1)
                    .collect()
            }
        }
    }
}

/// `n` incoherent rays: from random points on random triangles of `mesh` in random directions, a
/// hair off the surface (gpu_bench's and benches/versus's construction), from a fixed seed.
pub fn incoherent_rays(mesh: &Mesh, n: usize) -> Vec<Ray> {
    let count = mesh.triangle_count() as u64;
    if count == 0 {
        return Vec::new();
    }
    let eps = mesh.bounds().extent().length() * 1e-4;
    let mut rng = crate::random::Rng::new(1);
    (0..n)
        .map(|_| {
            let tri = mesh.triangle(rng.below(count) as u32);
            let (mut u, mut v) = (rng.unit(), rng.unit());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let p = tri[0] * (1.0 - u - v) + tri[1] * u + tri[2] * v;
            let z = 2.0 * rng.unit() - 1.0;
            let phi = rng.unit() * std::f32::consts::TAU;
            let s = (1.0 - z * z).max(0.0).sqrt();
            let dir = glam::Vec3::new(s * phi.cos(), s * phi.sin(), z);
            Ray::new(p + dir * eps, dir)
        })
        .collect()
}
