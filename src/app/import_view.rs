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

impl super::BvhscopeApp {
    /// Select the node the dump calls `dump` in the tree view (showing the imported tree first).
    pub(super) fn select_dump_node(&mut self, dump: u32) {
        use super::{Action, MessageKind};
        let Some(bvh) = self.import.traced(self.scene_id).cloned() else {
            let why = "the imported tree cannot be shown (its structure has defects)";
            return self.message(MessageKind::Info, format!("node {dump}: {why}"));
        };
        self.import.on = true;
        let Some(names) = bvh.import() else { return };
        match names.binary_node_of_dump(dump) {
            Some(n) => self.act(Action::SelectNode(n)),
            None => self.message(MessageKind::Info, format!("node {dump} is never reached from the root")),
        }
    }

    /// Select the leaf that holds the triangle the file numbers `t` (the leaf reached first, for
    /// a triangle in several), or say that none does.
    pub(super) fn select_triangle(&mut self, t: u32) {
        use super::{Action, MessageKind};
        let Some(bvh) = self.import.traced(self.scene_id).cloned() else {
            return self.message(MessageKind::Info, format!("triangle {t}: the imported tree cannot be shown"));
        };
        self.import.on = true;
        let SceneBvh::Single { mesh, .. } = &*bvh else { return };
        let Some(Some(m)) = mesh.triangles_by_file_number().get(t as usize).copied() else {
            return self.message(MessageKind::Info, format!("triangle {t} has zero area: no ray can hit it"));
        };
        let leaf = self.nodes.current(Some(&bvh)).and_then(|e| e.hierarchy.leaf_of_prim(m));
        match leaf {
            Some(leaf) => {
                self.message(MessageKind::Info, format!("triangle {t}: in the leaf selected"));
                self.act(Action::SelectNode(leaf));
            }
            None if self.nodes.current(Some(&bvh)).is_none() => {
                self.message(MessageKind::Info, "The tree view is still being prepared: click again in a moment.")
            }
            None => self.message(MessageKind::Info, format!("triangle {t} is in no leaf of the imported tree")),
        }
    }

    /// The red mask over the frame on screen: its pixels whose hit is wrong (cached per result).
    pub fn wrong_mask(&self, ctx: &egui::Context) -> Option<(egui::TextureHandle, usize)> {
        let s = self.shown.as_ref().filter(|s| self.import.mask && s.frame.is_complete())?;
        let w = self.import.wrong_for(&s.bvh, &s.camera, &s.trace)?;
        let mut cache = self.wrong_cache.borrow_mut();
        if let Some((bvh, camera, trace, tex)) = cache.as_ref() {
            if self.import.wrong_for(bvh, camera, trace).is_some_and(|c| std::ptr::eq(c, w)) {
                return Some((tex.clone(), w.pixels.len()));
            }
        }
        let (width, height) = (s.camera.width as usize, s.camera.height as usize);
        let mut image = egui::ColorImage::new([width, height], vec![egui::Color32::TRANSPARENT; width * height]);
        for &(x, y) in &w.pixels {
            image.pixels[y as usize * width + x as usize] = egui::Color32::from_rgba_unmultiplied(255, 0, 0, 200);
        }
        let tex = ctx.load_texture("wrong-pixels", image, egui::TextureOptions::NEAREST);
        *cache = Some((w.bvh.clone(), w.camera, w.trace, tex.clone()));
        Some((tex, w.pixels.len()))
    }
}
