//! The GPU in the app's jobs: the look for an adapter (once, in the background, at start), the
//! tree uploaded for the render job (one at a time), a frame traced there at full resolution in
//! one pass, and lbvh and ploc built there by the build job. A ray whose GPU walk reaches the
//! step budget is finished on the CPU (`GpuTree::trace_rays`). When the app traces on the GPU is
//! `state::gpu`; its answers (`JobEvent::GpuProbed`, `GpuFailed`) are handled in `update`.
use super::messages::{GpuRender, JobEvent, PassOutput, RenderRequest};
use crate::bvh::{SceneBuild, SceneBvh};
use crate::gpu_path::{build_scene_on_gpu, GpuBuild, GpuBuildError, GpuNodes, GpuTree};
use crate::mesh::Mesh;
use crate::render::{view_image, Frame, PassInfo};
use crate::scene::{Scene, SceneBuildError};
use crate::work::WorkControl;
use bvhscope_gpu::{Gpu, Rays};
use std::sync::{Arc, Mutex, Weak};
use std::time::Instant;

/// What the look for an adapter found.
#[derive(Clone)]
pub enum Probe {
    Looking,
    Found(Arc<Gpu>),
    /// Why there is no GPU (the GPU crate's message: what to install).
    Missing(String),
}

/// The tree last uploaded: for which BVH and format (one at a time; a new one replaces it).
struct Uploaded {
    bvh: Weak<SceneBvh>,
    nodes: GpuNodes,
    tree: Arc<GpuTree>,
    mesh: Arc<Mesh>,
}

/// A build made on the GPU, with the tree it made (held weakly: the scene may drop it).
type BuiltOnGpu = (Weak<SceneBvh>, GpuBuild);

/// The GPU state the jobs share: the probe's result, the uploaded tree, the builds made on the
/// GPU with their phases.
#[derive(Clone)]
pub struct GpuJobs {
    pub probe: Probe,
    uploaded: Arc<Mutex<Option<Uploaded>>>,
    built: Arc<Mutex<Vec<BuiltOnGpu>>>,
    /// Whether the last build started was asked to build on the GPU.
    pub last_build_on_gpu: bool,
}

impl Default for GpuJobs {
    fn default() -> Self {
        GpuJobs {
            probe: Probe::Looking,
            uploaded: Default::default(),
            built: Default::default(),
            last_build_on_gpu: false,
        }
    }
}

impl GpuJobs {
    /// The phases of `bvh`'s build, when it was built on the GPU.
    pub fn build_of(&self, bvh: &Arc<SceneBvh>) -> Option<GpuBuild> {
        let built = self.built.lock().unwrap_or_else(|p| p.into_inner());
        built.iter().find(|(b, _)| b.as_ptr() == Arc::as_ptr(bvh)).map(|(_, g)| *g)
    }

    /// The tree of `bvh` on `gpu` in `nodes`' format: the one uploaded last if it is that, else
    /// uploaded now (in the calling job).
    fn tree(&self, gpu: &Gpu, bvh: &Arc<SceneBvh>, nodes: GpuNodes) -> Result<(Arc<GpuTree>, Arc<Mesh>), String> {
        let mut up = self.uploaded.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(u) = up.as_ref().filter(|u| u.nodes == nodes && u.bvh.as_ptr() == Arc::as_ptr(bvh)) {
            return Ok((u.tree.clone(), u.mesh.clone()));
        }
        *up = None;
        let (tree, mesh) = GpuTree::new(gpu, bvh, nodes).map_err(|e| e.to_string())?;
        let tree = Arc::new(tree);
        *up = Some(Uploaded { bvh: Arc::downgrade(bvh), nodes, tree: tree.clone(), mesh: mesh.clone() });
        Ok((tree, mesh))
    }

    /// The render job's work on the GPU: the request's frame at full resolution in one pass.
    pub fn render(
        &self,
        r: &RenderRequest,
        g: &GpuRender,
        control: &WorkControl,
    ) -> Result<Option<PassOutput>, String> {
        let start = Instant::now();
        let (tree, mesh) = self.tree(&g.gpu, &r.bvh, g.nodes)?;
        if control.is_cancelled() {
            return Ok(None);
        }
        let t = tree.trace_rays(&g.gpu, Rays::Camera(&r.camera), r.trace, true).map_err(|e| e.to_string())?;
        // While orbiting, a newer request has usually cancelled this one by now: skip its shading.
        if control.is_cancelled() {
            return Ok(None);
        }
        let frame = Frame::from_hits(&mesh, &r.camera, &t.hits, &t.counters).map_err(|e| e.to_string())?;
        let rays = t.hits.len() as u64;
        let (img, legend) = view_image(&frame, r.style.view, r.style.colormap, r.style.range, r.style.cost);
        let image = egui::ColorImage::from_rgb([img.width() as usize, img.height() as usize], img.as_raw());
        let info = PassInfo {
            stride: 1,
            rays,
            pass_time: start.elapsed(),
            elapsed: start.elapsed(),
            counts_only: false,
            counts_follow: false,
        };
        Ok(Some(PassOutput {
            bvh: r.bvh.clone(),
            frame: Arc::new(frame),
            image,
            legend,
            info,
            camera: r.camera,
            trace: r.trace,
            style: r.style,
            partial: None,
            gpu: Some(g.clone()),
            cpu_finished: t.cpu_finished,
        }))
    }

    /// The build job's work: lbvh and ploc on `gpu` (when given), the rest on the CPU. `Err`:
    /// the GPU failed, why (no tree; the CPU builds it next).
    pub fn build(
        &self,
        scene: &Scene,
        params: &SceneBuild,
        control: &WorkControl,
        gpu: Option<&Gpu>,
    ) -> Result<Result<Arc<SceneBvh>, SceneBuildError>, String> {
        let Some(gpu) = gpu else {
            return Ok(scene.build(params, control).map(Arc::new));
        };
        match build_scene_on_gpu(gpu, scene, params) {
            Ok(Some((bvh, phases))) => {
                let bvh = Arc::new(bvh);
                let mut built = self.built.lock().unwrap_or_else(|p| p.into_inner());
                built.retain(|(b, _)| b.strong_count() > 0);
                built.push((Arc::downgrade(&bvh), phases));
                Ok(Ok(bvh))
            }
            Ok(None) => Ok(scene.build(params, control).map(Arc::new)),
            Err(GpuBuildError::Scene(e)) => Ok(Err(SceneBuildError::Scene(e))),
            Err(GpuBuildError::Gpu(e)) => Err(format!("The GPU build failed: {e}")),
        }
    }
}

/// Look for an adapter on a thread of its own; the answer comes back as `JobEvent::GpuProbed`.
pub fn probe(send: impl Fn(JobEvent) + Send + 'static) {
    std::thread::spawn(move || {
        let found = std::panic::catch_unwind(Gpu::new)
            .map_err(|_| "looking for a GPU adapter panicked".to_string())
            .and_then(|r| r.map_err(|e| e.to_string()));
        send(JobEvent::GpuProbed(found.map(Arc::new)));
    });
}
