//! Two builds side by side: A is the app's build, B the same scene and settings split by another
//! strategy, both traced on the same camera. The viewport shows them as two halves, with a
//! draggable wipe line, or as the difference B − A of the heatmap (`render::diff`), all on one
//! colour scale; the Compare window gives both builds' figures and their difference. B is built
//! and traced in the background; it is kept, so flipping modes is instant and changing A's
//! strategy rebuilds only A.

use crate::bvh::{Layout, SceneBuild, SceneBvh, Strategy, TraceOptions, TreeStats};
use crate::render::{Camera, Frame, Legend, PairView, RaySummary};
use std::sync::Arc;

/// B: its build and its frame of one camera.
pub struct CompareB {
    pub scene_id: u64,
    pub build: SceneBuild,
    pub bvh: Arc<SceneBvh>,
    pub stats: TreeStats,
    pub frame: Arc<Frame>,
    pub camera: Camera,
    pub trace: TraceOptions,
    /// The secondary rays it traced, as A's frame did (`None`: camera rays).
    pub secondary: Option<crate::render::SecondaryRays>,
    pub summary: RaySummary,
}

/// The images shown in compare mode, for one pair of frames and one view.
pub struct CompareImages {
    pub a_frame: Arc<Frame>,
    pub b_frame: Arc<Frame>,
    pub view: crate::render::View,
    pub colormap: crate::render::ColorMap,
    /// The range asked for (`HeatRange`) and the difference's fixed ±range, if any: the images
    /// are made again when either changes.
    pub range: crate::render::HeatRange,
    pub diff_range: Option<f32>,
    pub a: egui::TextureHandle,
    pub b: egui::TextureHandle,
    /// The difference (heatmaps only), its values and legend.
    pub diff: Option<(egui::TextureHandle, Vec<f32>, Legend)>,
    /// The one scale of both heatmaps.
    pub legend: Option<Legend>,
}

pub struct CompareView {
    pub on: bool,
    /// B's own choices; the rest of B's build is A's.
    pub strategy: Strategy,
    pub max_leaf_size: u32,
    pub layout: crate::bvh::Layout,
    /// How B is traversed (order and triangle test).
    pub trace: TraceOptions,
    pub mode: PairView,
    /// Where the wipe line is, from 0 (left) to 1 (right).
    pub wipe: f32,
    pub b: Option<CompareB>,
}

impl Default for CompareView {
    fn default() -> Self {
        let p = crate::bvh::BuildParams::default();
        Self {
            on: false,
            strategy: Strategy::SahBinned,
            max_leaf_size: p.max_leaf_size,
            layout: p.layout,
            trace: TraceOptions::default(),
            mode: PairView::Halves,
            wipe: 0.5,
            b: None,
        }
    }
}

impl CompareView {
    /// B's build for A's `build`: A's with B's strategy, leaf size and layout.
    pub fn build_for(&self, build: SceneBuild) -> SceneBuild {
        let bvh = crate::bvh::BuildParams {
            strategy: self.strategy,
            max_leaf_size: self.max_leaf_size,
            layout: self.layout,
            ..build.bvh
        };
        SceneBuild { bvh, ..build }
    }

    /// Start from A's build and traversal, with another strategy than A's; against an imported
    /// tree (`imported`: its layout), the reference: SAH binned in that layout.
    pub fn start_from(&mut self, a: &crate::bvh::BuildParams, trace: TraceOptions, imported: Option<Layout>) {
        self.strategy = if a.strategy == Strategy::SahBinned && imported.is_none() {
            Strategy::Midpoint
        } else {
            Strategy::SahBinned
        };
        (self.max_leaf_size, self.layout, self.trace) = (a.max_leaf_size, imported.unwrap_or(a.layout), trace);
    }
}
