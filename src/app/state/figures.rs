//! The plain data the app's state is made of: the image on screen and what produced it, the
//! per-ray figures and what they depend on, a strategy's figures for the statistics panel, the
//! messages, the path-typing window.

use crate::app::jobs::{GpuRender, Pick, ViewStyle};
use crate::bvh::{SceneBvh, TraceOptions, TreeStats};
use crate::render::{Camera, Frame, Legend, RayKind, RaySummary, SecondarySpec};
use std::sync::Arc;
use std::time::Instant;

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
    /// The GPU that traced it, if one did (`jobs::gpu`).
    pub gpu: Option<GpuRender>,
    /// Rays of it whose GPU walk reached the step budget and were finished on the CPU.
    pub cpu_finished: usize,
}

impl Shown {
    /// The rays the image on screen traced.
    pub fn rays_key(&self) -> RaysKey {
        RaysKey { camera: self.camera, trace: self.trace, secondary: self.frame.secondary().copied() }
    }
}

/// Per-ray figures of a full frame, with what they depend on besides the BVH: the camera (and
/// image size), the traversal options and the secondary rays. Figures measured under other ones
/// are not comparable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeasuredRays {
    pub summary: RaySummary,
    pub camera: Camera,
    pub trace: TraceOptions,
    /// The secondary rays counted (kind, seed, light, length; `None`: the camera's rays).
    pub secondary: Option<SecondarySpec>,
}

impl MeasuredRays {
    /// What these figures were measured on.
    pub fn key(&self) -> RaysKey {
        RaysKey { camera: self.camera, trace: self.trace, secondary: self.secondary }
    }

    /// Whether these figures and `other` come from the same rays (camera, image size, traversal,
    /// ray kind and seed).
    pub fn comparable(&self, other: &RaysKey) -> bool {
        self.key().stale_because(other).is_none()
    }
}

/// What per-ray figures depend on besides the tree: the rays (camera, image size, kind, seed) and
/// the traversal. The figures on screen are stale when theirs is not the image's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RaysKey {
    pub camera: Camera,
    pub trace: TraceOptions,
    pub secondary: Option<SecondarySpec>,
}

impl RaysKey {
    /// The rays' kind (camera rays when no secondary rays).
    pub fn kind(&self) -> RayKind {
        self.secondary.map_or(RayKind::Primary, |s| s.kind)
    }

    /// Why figures measured on `self` are not figures of `now` (a phrase for a tooltip: "of a
    /// 703×646 image; the image is 703×459"), or `None` when they are of the same rays.
    pub fn stale_because(&self, now: &RaysKey) -> Option<String> {
        let describe = |k: &RaysKey| k.secondary.map_or("primary rays".to_string(), |s| s.describe());
        let (a, b) = (&self.camera, &now.camera);
        if self.kind() != now.kind() {
            Some(format!("of {}; the image shows {}", describe(self), describe(now)))
        } else if (a.width, a.height) != (b.width, b.height) {
            Some(format!("of a {}×{} image; the image is {}×{}", a.width, a.height, b.width, b.height))
        } else if a != b {
            Some("of another camera (the view moved since)".to_string())
        } else if let Some((x, y)) = self.secondary.zip(now.secondary).filter(|(x, y)| x.seed != y.seed) {
            Some(format!("of seed {}; the image's rays are of seed {}", x.seed, y.seed))
        } else if self.secondary != now.secondary {
            Some(format!("of {}; the image shows {}", describe(self), describe(now)))
        } else if self.trace != now.trace {
            Some("of another traversal order or triangle test".to_string())
        } else {
            None
        }
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
