//! What goes to the app's jobs and what comes back from them: the render request and its pass,
//! the events on the one channel, what a file dialog was opened for.

use crate::app::views::compare::CompareB;
use crate::app::views::import::{ImportedTree, WrongPixels};
use crate::app::views::node::{Explained, FrameVisits};
use crate::bvh::{SahCost, SceneBuild, SceneBvh, TraceOptions};
use crate::explain::inspect::Inspection;
use crate::explain::replay::PartialBvh;
use crate::gpu_path::GpuNodes;
use crate::render::{Camera, ColorMap, Frame, HeatRange, Legend, PassInfo, View};
use crate::scene::{Scene, SceneBuildError};
use bvhscope_gpu::Gpu;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

/// How a frame is turned into colours (the parts of the view that need no re-trace are here too,
/// since any change of view restarts the refinement anyway).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewStyle {
    pub view: View,
    pub colormap: ColorMap,
    pub range: HeatRange,
    pub cost: SahCost,
}

#[derive(Clone)]
pub struct RenderRequest {
    /// What is traced, and what shades its hits.
    pub bvh: Arc<SceneBvh>,
    pub camera: Camera,
    pub trace: TraceOptions,
    pub style: ViewStyle,
    pub progressive: bool,
    /// The build replay's partial tree of `bvh` (a single BVH) to trace instead of it.
    pub partial: Option<Arc<PartialBvh>>,
    /// Trace on this GPU instead of the CPU (`jobs::gpu`).
    pub gpu: Option<GpuRender>,
    /// Secondary rays from each hit, resolved for the scene and camera (`None`: camera rays).
    pub secondary: Option<crate::render::SecondaryRays>,
}

impl RenderRequest {
    /// Whether two requests would produce the same image.
    pub fn same_as(&self, o: &RenderRequest) -> bool {
        Arc::ptr_eq(&self.bvh, &o.bvh)
            && self.camera == o.camera
            && self.trace == o.trace
            && self.style == o.style
            && self.progressive == o.progressive
            && self.secondary == o.secondary
            && match (&self.partial, &o.partial) {
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                (None, None) => true,
                _ => false,
            }
            && match (&self.gpu, &o.gpu) {
                (Some(a), Some(b)) => a.same_as(b),
                (None, None) => true,
                _ => false,
            }
    }
}

/// One finished render pass, ready to show.
pub struct PassOutput {
    /// The BVH that traced the frame.
    pub bvh: Arc<SceneBvh>,
    pub frame: Arc<Frame>,
    pub image: egui::ColorImage,
    pub legend: Option<Legend>,
    pub info: PassInfo,
    pub camera: Camera,
    pub trace: TraceOptions,
    pub style: ViewStyle,
    /// The partial tree of a build replay that traced the frame, if it was one.
    pub partial: Option<Arc<PartialBvh>>,
    /// The GPU that traced it, if one did.
    pub gpu: Option<GpuRender>,
    /// Rays of it whose GPU walk reached the step budget and were finished on the CPU.
    pub cpu_finished: usize,
}

/// What a file dialog was opened for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pick {
    Open,
    SavePng,
    SaveStatsCsv,
    SaveStatsJson,
    SaveScene,
    SaveCounts,
    /// A BVH dump to import for the current mesh.
    OpenBvh,
    /// Where to write the current tree as a dump.
    SaveBvh,
    /// Where to write the build replay's animation (.gif or .png).
    SaveAnimation,
    /// A class's grade report (`bvhscope grade`'s grade.json) to list.
    OpenGradeReport,
    /// A lesson file to open, and where to save the lesson.
    OpenLesson,
    SaveLesson,
}

pub enum JobEvent {
    Loaded(Result<Arc<Scene>, String>),
    Explained(Arc<Explained>),
    /// B of the side-by-side view, built (or reused) and traced.
    Compared(Box<CompareB>),
    Visits(FrameVisits),
    Inspected {
        node: u32,
        explained: Arc<Explained>,
        inspection: Arc<Inspection>,
    },
    Built {
        scene_id: u64,
        params: SceneBuild,
        result: Result<Arc<SceneBvh>, SceneBuildError>,
    },
    /// The build ended without a tree because the GPU failed (`GpuFailed` says why, and the CPU
    /// builds it next): not a cancellation, which it used to be reported as.
    NotBuilt,
    Pass(PassOutput),
    /// A dump read and checked for scene `scene_id`, or why it cannot be read.
    Imported(Result<Box<ImportedTree>, String>),
    /// A frame's pixels whose hit through the imported tree is wrong.
    Wrong(WrongPixels),
    /// A grade report read, its files looked for, or why it cannot be read.
    GradeReport(Result<Box<crate::explain::grade::GradeReport>, String>),
    Picked {
        pick: Pick,
        path: Option<PathBuf>,
        took: Duration,
    },
    /// The job panicked (`Jobs::spawn`): what to tell the user.
    Failed(String),
    /// The BVH timed against the linear scan.
    Speedup(Box<Timed>),
    /// The look for a GPU adapter at start: the GPU, or why there is none.
    GpuProbed(Result<Arc<bvhscope_gpu::Gpu>, String>),
    /// The replay's animation written: what to tell the user (saved, or why not).
    Filmed(Result<String, String>),
    /// A GPU render or build failed: what to tell the user (the app goes back to the CPU).
    GpuFailed(String),
}

/// The linear scan's time budget for a frame: past it, a spread sample is timed (as `compare`).
pub const LINEAR_BUDGET: Duration = Duration::from_secs(10);

/// A speed-up over the linear scan, for the BVH, camera and traversal it was timed with.
pub struct Timed {
    pub bvh: Arc<SceneBvh>,
    pub camera: Camera,
    pub trace: TraceOptions,
    pub speedup: crate::explain::timing::Speedup,
}

/// The GPU to trace a frame on, and in which node format (part of a render request).
#[derive(Clone)]
pub struct GpuRender {
    pub gpu: Arc<Gpu>,
    pub nodes: GpuNodes,
}

impl GpuRender {
    pub fn same_as(&self, o: &GpuRender) -> bool {
        Arc::ptr_eq(&self.gpu, &o.gpu) && self.nodes == o.nodes
    }
}

/// Frames of the app's replay animation and how long each shows (`bvhscope replay`'s defaults).
pub const FILM_FRAMES: u32 = 24;
pub const FILM_DELAY_MS: u16 = 400;

/// The replay's animation to write (`update::export::film_request`).
pub struct FilmRequest {
    pub replay: std::sync::Arc<crate::explain::replay::Replay>,
    pub mesh: std::sync::Arc<crate::mesh::Mesh>,
    pub camera: crate::render::Camera,
    pub settings: crate::explain::replay_film::FilmSettings,
    pub subject: String,
}
