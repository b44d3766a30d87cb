//! The plain data the app's state is made of: the image on screen and what produced it, the
//! per-ray figures and what they depend on, a strategy's figures for the statistics panel, the
//! messages, the path-typing window; and the figures of the current build and of B, as the
//! statistics panel and its exports read them.

use super::*;

/// The image on screen and what produced it.
pub struct Shown {
    pub texture: egui::TextureHandle,
    pub frame: Arc<Frame>,
    pub camera: Camera,
    pub legend: Option<Legend>,
    pub style: ViewStyle,
    /// The build replay's partial tree that traced the image, if it was one.
    pub partial: Option<Arc<crate::explain::replay::PartialBvh>>,
    /// Rays per second of the last pass.
    pub rays_per_s: f64,
    /// The build that traced it ("SAH binned, wide4"), for captions.
    pub build_label: String,
    /// The BVH and traversal that traced it: a pinned pixel is traced again through them.
    pub bvh: Arc<SceneBvh>,
    pub trace: TraceOptions,
    /// The GPU that traced it, if one did (`app::gpu`).
    pub gpu: Option<super::jobs::GpuRender>,
    /// Rays of it whose GPU walk reached the step budget and were finished on the CPU.
    pub cpu_finished: usize,
}

/// Per-ray figures of a full frame, with what they depend on besides the BVH: the camera (and
/// image size) and the traversal options. Figures measured under other ones are not comparable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeasuredRays {
    pub summary: RaySummary,
    pub camera: Camera,
    pub trace: TraceOptions,
}

impl MeasuredRays {
    /// Whether these figures and `other` come from the same rays (camera, image size, traversal).
    pub fn comparable(&self, camera: &Camera, trace: &TraceOptions) -> bool {
        self.camera == *camera && self.trace == *trace
    }
}

/// One strategy's figures for the statistics panel (the current one and the one before).
#[derive(Clone, Debug)]
pub struct StrategyFigures {
    pub label: String,
    /// Of the tree the statistics rows describe (`BuiltBvh::stats`).
    pub stats: TreeStats,
    /// The whole build, every level.
    pub build_ms: f64,
    pub rays: Option<MeasuredRays>,
    /// The last full frame's time (ms, every core), where it was of this tree.
    pub frame_ms: Option<f64>,
    /// This tree timed against the linear scan on the frame (one thread), where it was.
    pub speedup: Option<crate::explain::timing::Speedup>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MessageKind {
    Info,
    Warning,
    Error,
}

#[derive(Clone, Debug)]
pub struct Message {
    pub kind: MessageKind,
    pub text: String,
    pub at: Instant,
}

/// The path-typing window: the way in when no file dialog is available, and always offered.
pub struct PathWindow {
    pub pick: Pick,
    pub text: String,
    pub note: Option<String>,
    /// Its text field takes the keyboard when it first shows (then single-key shortcuts stop).
    pub focus: bool,
}

impl PathWindow {
    pub fn new(pick: Pick, text: String, note: Option<String>) -> Self {
        Self { pick, text, note, focus: true }
    }
}

impl super::BvhscopeApp {
    /// Figures of the current strategy for the statistics panel.
    pub fn current_figures(&self) -> Option<StrategyFigures> {
        self.current_bvh().map(|b| StrategyFigures {
            label: b.bvh.label(),
            // The end-point overlap comes with the prepared tree, a moment after the image.
            stats: {
                let e = self.nodes.current(Some(&b.bvh));
                TreeStats { epo: e.map(|e| e.epo), epo_error: e.and_then(|e| e.epo_error), ..b.stats.clone() }
            },
            build_ms: b.bvh.build_time().as_secs_f64() * 1e3,
            rays: self.rays,
            frame_ms: self
                .last_full_frame
                .filter(|_| self.shown.as_ref().is_some_and(|s| Arc::ptr_eq(&s.bvh, &b.bvh)))
                .map(|d| d.as_secs_f64() * 1e3),
            speedup: self.fresh_speedup().map(|t| t.speedup),
        })
    }

    /// The timing against the linear scan of the tree, camera and traversal on screen, if there
    /// is one (an older tree's or camera's is stale).
    pub fn fresh_speedup(&self) -> Option<&jobs::Timed> {
        let shown = self.shown.as_ref()?;
        self.speedup
            .as_ref()
            .filter(|t| Arc::ptr_eq(&t.bvh, &shown.bvh) && t.camera == shown.camera && t.trace == shown.trace)
    }

    /// B's figures for the statistics panel's second column, while comparing side by side.
    pub fn compare_figures(&self) -> Option<StrategyFigures> {
        let b = self.compare.b.as_ref().filter(|b| self.compare.on && b.scene_id == self.scene_id)?;
        Some(StrategyFigures {
            label: format!("B: {}", b.bvh.label()),
            stats: b.stats.clone(),
            build_ms: b.bvh.build_time().as_secs_f64() * 1e3,
            rays: Some(MeasuredRays { summary: b.summary, camera: b.camera, trace: b.trace }),
            frame_ms: None,
            speedup: None,
        })
    }
}
