//! The app's GPU path ("Trace on: CPU / GPU", issues 38 and 39). The adapter is looked for once,
//! in the background, at start; without one the GPU choice is greyed with the reason. With the GPU
//! chosen, frames are traced there at full resolution in one pass (counted: every heatmap, the
//! hover read-out and the statistics come from the GPU's counts, which are those of
//! `bvhscope render --device gpu`), the tree is built in the binary layout (the GPU walks binary
//! or CWBVH nodes made from it), and lbvh and ploc are built on the GPU. All of it runs in the
//! render and build jobs, never on the UI thread. Where the GPU cannot trace (two levels, the
//! build replay's partial trees) the CPU does, and the View panel's button and line say so; a
//! GPU error (device lost, a command rejected) switches back to the CPU with a message. A ray
//! whose GPU walk reaches the step budget is finished on the CPU (`GpuTree::walk`), and the
//! statistics say how many were.

use super::jobs::messages::{GpuRender, JobEvent, PassOutput, RenderRequest};
use super::{BvhscopeApp, MessageKind};
use crate::bvh::{SceneBuild, SceneBvh};
use crate::gpu_path::{build_on_gpu, builds_on_gpu, Device, GpuBuild, GpuNodes, GpuTree};
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
        let t = tree.walk(&g.gpu, Rays::Camera(&r.camera), r.trace, true).map_err(|e| e.to_string())?;
        // While orbiting, a newer request has usually cancelled this one by now: skip its shading.
        if control.is_cancelled() {
            return Ok(None);
        }
        let frame = Frame::from_hits(&mesh, &r.camera, &t.hits, &t.counters).map_err(|e| e.to_string())?;
        let rays = t.hits.len() as u64;
        let (img, legend) = view_image(&frame, r.style.view, r.style.colormap, r.style.range, r.style.cost);
        let image = egui::ColorImage::from_rgb([img.width() as usize, img.height() as usize], img.as_raw());
        let info = PassInfo { stride: 1, rays, pass_time: start.elapsed(), elapsed: start.elapsed() };
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
        let Some(gpu) = gpu.filter(|_| params.top.is_none()) else {
            return Ok(scene.build(params, control).map(Arc::new));
        };
        let mesh = match scene.flat_mesh() {
            Ok(m) => m,
            Err(e) => return Ok(Err(SceneBuildError::Scene(e))),
        };
        match build_on_gpu(gpu, &mesh, &params.bvh) {
            Ok(Some((bvh, phases))) => {
                let bvh = Arc::new(SceneBvh::Single { bvh, mesh, imported: None });
                let mut built = self.built.lock().unwrap_or_else(|p| p.into_inner());
                built.retain(|(b, _)| b.strong_count() > 0);
                built.push((Arc::downgrade(&bvh), phases));
                Ok(Ok(bvh))
            }
            Ok(None) => Ok(scene.build(params, control).map(Arc::new)),
            Err(e) => Err(format!("The GPU build failed: {e}")),
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

impl BvhscopeApp {
    /// Why the GPU, though chosen, does not trace the frames now (`None`: it does, or the CPU is
    /// chosen).
    pub fn gpu_blocked(&self) -> Option<String> {
        if self.settings.device != Device::Gpu {
            return None;
        }
        Some(match &self.jobs.gpu.probe {
            Probe::Looking => "looking for a GPU adapter…".into(),
            Probe::Missing(why) => why.clone(),
            Probe::Found(_) if self.settings.two_level && self.has_instances() => {
                "two levels are traced on the CPU (the GPU traces one BVH)".into()
            }
            Probe::Found(_) if self.replay.window => "the build replay's partial trees are traced on the CPU".into(),
            Probe::Found(_) if self.settings.rays.kind.is_secondary() => format!(
                "{} rays are traced on the CPU (the GPU's walks are of camera rays)",
                self.settings.rays.kind.label().to_lowercase()
            ),
            Probe::Found(_) => return None,
        })
    }

    /// The GPU frames are traced on, when it is chosen and can trace them.
    pub fn gpu_for_frames(&self) -> Option<GpuRender> {
        match (&self.jobs.gpu.probe, self.settings.device, self.gpu_blocked()) {
            (Probe::Found(gpu), Device::Gpu, None) => {
                Some(GpuRender { gpu: gpu.clone(), nodes: self.settings.gpu_nodes })
            }
            _ => None,
        }
    }

    /// The GPU that builds `build`: when frames are traced on it and it builds the strategy.
    pub fn gpu_for_building(&self, build: &SceneBuild) -> Option<Arc<Gpu>> {
        let g = self.gpu_for_frames()?;
        (build.top.is_none() && builds_on_gpu(build.bvh.strategy)).then_some(g.gpu)
    }

    /// Whether the BVH was built where `build` should be now (on the GPU or not).
    pub fn built_where_wanted(&self, bvh: &Arc<SceneBvh>, build: &SceneBuild) -> bool {
        self.jobs.gpu.build_of(bvh).is_some() == self.gpu_for_building(build).is_some()
    }

    /// The GPU's answers: the adapter found or not, a GPU job that failed (back to the CPU).
    pub(super) fn gpu_event(&mut self, event: JobEvent) {
        match event {
            JobEvent::GpuProbed(Ok(gpu)) => self.jobs.gpu.probe = Probe::Found(gpu),
            JobEvent::GpuProbed(Err(why)) => {
                if self.settings.device == Device::Gpu {
                    self.message(MessageKind::Warning, format!("No GPU: {why}. Tracing on the CPU."));
                    self.settings.device = Device::Cpu;
                }
                self.jobs.gpu.probe = Probe::Missing(why);
            }
            JobEvent::GpuFailed(why) => {
                self.message(MessageKind::Error, format!("{why}. Switched back to the CPU."));
                self.settings.device = Device::Cpu;
                // The last render and build asked for the GPU: ask again, on the CPU.
                self.jobs.last_render = None;
                self.jobs.last_build = None;
            }
            _ => {}
        }
    }
}

/// The statistics panel's GPU lines: where the frame on screen was traced, and the GPU build's
/// phases of the current BVH when it was built there (what `bvhscope stats --device gpu` prints).
pub fn show_in_statistics(app: &BvhscopeApp, ui: &mut egui::Ui) {
    let built = app.current_bvh().and_then(|b| app.jobs.gpu.build_of(&b.bvh));
    let traced = app.shown.as_ref().filter(|s| s.gpu.is_some());
    if built.is_none() && traced.is_none() {
        return;
    }
    egui::Grid::new("gpu-stats").num_columns(2).striped(true).show(ui, |ui| {
        if let Some(s) = traced {
            let nodes = s.gpu.as_ref().map_or("", |g| g.nodes.name());
            ui.label("Traced on").on_hover_text("The frame on screen was traced on this GPU, in one pass at full resolution; its counts are those of bvhscope render --device gpu");
            ui.label(format!("GPU, {nodes} nodes"))
                .on_hover_text(s.gpu.as_ref().map_or(String::new(), |g| g.gpu.name()));
            ui.end_row();
            if s.cpu_finished > 0 {
                ui.label("Finished on the CPU").on_hover_text(format!(
                    "Rays whose GPU walk reached the step budget ({} steps a walk: nodes, stack pops and triangle tests) and were finished by the same walk on the CPU: every hit and count is the CPU walk's",
                    bvhscope_gpu::STEP_BUDGET
                ));
                ui.label(format!("{} of {} rays", s.cpu_finished, s.frame.width() as u64 * s.frame.height() as u64));
                ui.end_row();
            }
        }
        if let Some(b) = built {
            ui.label("GPU build").on_hover_text("lbvh and ploc built on the GPU: the phases, as bvhscope stats --device gpu prints them (PLOC: emission is its clustering, boxes the host's layout)");
            ui.add(egui::Label::new(b.text()).wrap());
            ui.end_row();
        }
    });
    ui.add_space(6.0);
}
