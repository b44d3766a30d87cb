//! When the app uses its GPU ("Trace on: CPU / GPU", issues 38 and 39). The adapter is looked for once,
//! in the background, at start; without one the GPU choice is greyed with the reason. With the GPU
//! chosen, frames are traced there at full resolution in one pass (counted: every heatmap, the
//! hover read-out and the statistics come from the GPU's counts, which are those of
//! `bvhscope render --device gpu`), the tree is built in the binary layout (the GPU walks binary
//! or CWBVH nodes made from it), and lbvh and ploc are built on the GPU. All of it runs in the
//! render and build jobs, never on the UI thread. Where the GPU cannot trace (two levels, the
//! build replay's partial trees) the CPU does, and the View panel's button and line say so; a
//! GPU error (device lost, a command rejected) switches back to the CPU with a message. A ray
//! whose GPU walk reaches the step budget is finished on the CPU (`GpuTree::trace_rays`), and the
//! statistics say how many were.

use super::app::BvhscopeApp;
use crate::app::jobs::{GpuRender, Probe};
use crate::bvh::{SceneBuild, SceneBvh};
use crate::gpu_path::{builds_on_gpu, Device};
use bvhscope_gpu::Gpu;
use std::sync::Arc;

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
        builds_on_gpu(build).then_some(g.gpu)
    }

    /// Whether the BVH was built where `build` should be now (on the GPU or not).
    pub fn built_where_wanted(&self, bvh: &Arc<SceneBvh>, build: &SceneBuild) -> bool {
        self.jobs.gpu.build_of(bvh).is_some() == self.gpu_for_building(build).is_some()
    }
}
