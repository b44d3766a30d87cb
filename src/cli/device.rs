//! `--device gpu`: how the commands use the GPU crate (`bvhscope-gpu`). The GPU is opened once per
//! command; without an adapter the command fails with the crate's message (what to install), and
//! nothing falls back to the CPU unasked. The GPU walks the binary tree as built (core's nodes,
//! byte for byte) or its CWBVH form, with either triangle test, over one level; its per-ray counts
//! are the CPU's for the binary layout. A walk that reaches the GPU's step budget is finished on
//! the CPU (`GpuTree::trace_rays`), and every command says how many rays were (`finished_note`). The strategies lbvh and ploc are built on the GPU too
//! (core's trees node for node), with the build's phases timed.

use super::args::{BuildArgs, DeviceArgs};
use super::progress;
use crate::bvh::{AnyBvh, BuildParams, Layout, SceneBuild, SceneBvh, TraceOptions};
use crate::cli::error::CliError;
pub use crate::gpu_path::{
    build_on_gpu, build_scene_on_gpu, builds_on_gpu, GpuBuild, GpuBuildError, GpuNodes, GpuTree,
};
use crate::mesh::Mesh;
use crate::render::{Camera, Frame};
use crate::scene::Scene;
use bvhscope_gpu::{Gpu, GpuError, GpuTrace, Rays};
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

/// Refuse what the GPU does not trace: two levels. (Both triangle tests and both child orders run
/// there.)
pub fn check_traceable(build: &SceneBuild, _trace: TraceOptions) -> Result<(), CliError> {
    if build.top.is_some() {
        return Err(CliError::Usage(
            "--two-level: the GPU traces one BVH over the scene's triangles; leave out --two-level or use --device cpu"
                .into(),
        ));
    }
    Ok(())
}

/// What a command prints of the rays a GPU walk left to the CPU ("" when none): every hit and
/// count is the CPU walk's either way, but where the GPU's time went is then only partly the GPU's.
pub fn finished_note(t: &GpuTrace) -> Option<String> {
    (t.cpu_finished > 0).then(|| {
        format!(
            "{} of {} rays reached the GPU's step budget ({} steps a walk) and were finished on the CPU",
            t.cpu_finished,
            t.hits.len(),
            bvhscope_gpu::STEP_BUDGET
        )
    })
}

/// Build `params` over `mesh` with lbvh or ploc on the GPU (reinsertion, if asked for, then on the
/// CPU, as `Bvh::build` runs it after any builder); `None` for the other strategies, which only
/// the CPU builds.
pub fn gpu_build(gpu: &Gpu, mesh: &Mesh, params: &BuildParams) -> Result<Option<(AnyBvh, GpuBuild)>, CliError> {
    let label = format!("building the BVH ({} on the GPU)", params.strategy.label());
    progress::with_spinner(&label, || build_on_gpu(gpu, mesh, params)).map_err(gpu_error)
}

/// `build` on the GPU with a spinner, when the GPU builds it (`gpu_path::builds_on_gpu`); `None`:
/// the CPU builds it (`cli::build_scene`).
pub fn gpu_build_scene(gpu: &Gpu, scene: &Scene, build: &SceneBuild) -> Result<Option<(SceneBvh, GpuBuild)>, CliError> {
    if !builds_on_gpu(build) {
        return Ok(None);
    }
    let label = format!("building the BVH ({} on the GPU)", build.bvh.strategy.label());
    progress::with_spinner(&label, || build_scene_on_gpu(gpu, scene, build)).map_err(|e| match e {
        GpuBuildError::Scene(e) => e.into(),
        GpuBuildError::Gpu(e) => gpu_error(e),
    })
}

/// The command line's spinners and errors over the GPU path's tree.
impl GpuTree {
    /// `new`, with a spinner while it takes long and the command line's error.
    pub fn upload(gpu: &Gpu, bvh: &SceneBvh, nodes: GpuNodes) -> Result<(GpuTree, Arc<Mesh>), CliError> {
        progress::with_spinner("uploading the tree to the GPU", || Self::new(gpu, bvh, nodes)).map_err(gpu_error)
    }

    /// `walk`, with the command line's error.
    pub fn trace(&self, gpu: &Gpu, rays: Rays, trace: TraceOptions, counted: bool) -> Result<GpuTrace, CliError> {
        self.trace_rays(gpu, rays, trace, counted).map_err(gpu_error)
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
        if let Some(note) = finished_note(&t) {
            eprintln!("note: {note}");
        }
        let frame = Frame::from_hits(mesh, camera, &t.hits, &t.counters)
            .map_err(|e| CliError::Usage(format!("--device gpu: {e}")))?;
        Ok((frame, t))
    }
}
