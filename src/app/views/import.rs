//! Bring your own BVH, in the app: a dump read for the current scene's mesh and checked
//! (`explain::check`, as `bvhscope check` does), one more entry in the strategy list ("imported:
//! FILE") that every view traces like a built tree, the checker's findings (the Imported BVH
//! window), and the pixels of the frame on screen whose hit differs from the linear scan's (a red
//! mask, `explain::check::wrong_rays` over the frame's primary rays).

use crate::bvh::{SceneBvh, TraceOptions};
use crate::explain::check::Finding;
use crate::render::Camera;
use std::path::PathBuf;
use std::sync::Arc;

/// Random rays the app's check traces besides the frame's (the CLI's default is a million; the
/// app keeps the wait short and says how many it traced).
pub const CHECK_RAYS: u64 = 100_000;

/// A dump read and checked for one scene.
pub struct ImportedTree {
    pub path: PathBuf,
    /// The scene it was read for (`BvhscopeApp::scene_id`).
    pub scene_id: u64,
    /// The tree as traced; `None` when its structure has defects (or it has nodes of more than 8
    /// children), with the reason.
    pub bvh: Result<Arc<SceneBvh>, String>,
    pub findings: Vec<Finding>,
    /// Random rays traced against the linear scan, besides the frame's.
    pub rays: u64,
    /// What the rays were checked against (kept for the wrong pixels of every view).
    pub reference: Option<Arc<crate::explain::check::Reference>>,
}

impl ImportedTree {
    pub fn name(&self) -> String {
        crate::files::file_name(&self.path)
    }

    pub fn defects(&self) -> usize {
        self.findings.iter().filter(|f| f.defect).count()
    }
}

/// The frame's pixels whose hit through the imported tree differs from the linear scan's.
pub struct WrongPixels {
    pub bvh: Arc<SceneBvh>,
    pub camera: Camera,
    pub trace: TraceOptions,
    pub pixels: Vec<(u32, u32)>,
}

#[derive(Default)]
pub struct ImportView {
    pub tree: Option<ImportedTree>,
    /// The imported tree is the one shown (chosen in the strategy list).
    pub on: bool,
    /// The Imported BVH window (the findings) is open.
    pub window: bool,
    /// Draw the wrong pixels' red mask over the image.
    pub mask: bool,
    pub wrong: Option<WrongPixels>,
}

impl ImportView {
    /// The imported tree of scene `scene_id`, when there is one that can be traced.
    pub fn traced(&self, scene_id: u64) -> Option<&Arc<SceneBvh>> {
        self.tree.as_ref().filter(|t| t.scene_id == scene_id).and_then(|t| t.bvh.as_ref().ok())
    }

    /// The imported tree to show instead of a build, when it is chosen.
    pub fn shown(&self, scene_id: u64) -> Option<&Arc<SceneBvh>> {
        self.traced(scene_id).filter(|_| self.on)
    }

    /// The wrong pixels of a frame traced by `bvh` on `camera` with `trace`, if computed.
    pub fn wrong_for(&self, bvh: &Arc<SceneBvh>, camera: &Camera, trace: &TraceOptions) -> Option<&WrongPixels> {
        self.wrong.as_ref().filter(|w| Arc::ptr_eq(&w.bvh, bvh) && w.camera == *camera && w.trace == *trace)
    }
}
