//! The app's state: `BvhscopeApp` and what it reads without changing it (the BVH of the scene,
//! the build wanted, the overlay's boxes, cached). Panels only read it and emit `Action`s, which
//! `update` applies.

use super::action::Action;
use super::built::{BuildCache, BuiltBvh};
use super::dock;
use super::figures::{MeasuredRays, Message, MessageKind, PathWindow, Shown, StrategyFigures};
use super::lesson::LessonState;
use super::orbit::{self, OrbitCamera};
use super::overlay::{self, OverlayBox};
use super::settings::{BoxLevel, Film, Settings};
use crate::app::jobs::{Jobs, Timed, ViewStyle};
use crate::app::views::{compare, node, CompareView, GradeView, ImportView, NodeView, RayView, ReplayView};
use crate::bvh::{SceneBuild, SceneBvh, TraceOptions};
use crate::render::{Camera, Frame, View};
use crate::scene::{Scene, SceneSource};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

/// How the app starts.
#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// A mesh or scene to open at start (the built-in scene shows until it is loaded), or a lesson
    /// (`lesson::is_lesson`), opened at its first step.
    pub file: Option<PathBuf>,
    /// A BVH dump to import for it once it is loaded.
    pub bvh: Option<PathBuf>,
}

pub struct BvhscopeApp {
    pub settings: Settings,
    pub scene: Arc<Scene>,
    /// Increases with every scene loaded; a BVH belongs to the scene it was built for.
    pub scene_id: u64,
    pub built: Option<BuiltBvh>,
    /// The last few trees built for this scene, by their options (a lesson's step back shows
    /// its tree at once).
    pub built_cache: BuildCache,
    /// The lesson open: its steps, the one on screen, the one being applied.
    pub lesson: Option<LessonState>,
    /// Work per ray in the latest full frame of the current BVH.
    pub rays: Option<MeasuredRays>,
    /// The figures of the strategy shown before the current one.
    pub previous: Option<StrategyFigures>,
    pub orbit: OrbitCamera,
    pub jobs: Jobs,
    pub shown: Option<Shown>,
    pub last_full_frame: Option<Duration>,
    pub messages: Vec<Message>,
    pub show_help: bool,
    pub path_window: Option<PathWindow>,
    /// Pinned rays and the step shown (the Ray window).
    pub pins: RayView,
    /// The Ray window is open with nothing pinned (to type a ray).
    pub ray_window: bool,
    /// The Tree and Node windows: the prepared tree, the node selected, its inspection.
    pub nodes: NodeView,
    /// The legend histogram's threshold: pixels whose heatmap value is above it are highlighted.
    pub threshold: Option<f32>,
    /// The Replay window: the build played back split by split.
    pub replay: ReplayView,
    /// Side by side: B, another strategy's build of the same scene on the same camera.
    pub compare: CompareView,
    /// Bring your own BVH: the imported dump, its findings, the wrong pixels.
    pub import: ImportView,
    /// A class's grade report: its students, the one chosen, how far showing them has got.
    pub grade: GradeView,
    /// The current BVH timed against the linear scan (the statistics panel, on demand).
    pub speedup: Option<Timed>,
    /// The rank of the last hottest pixel pinned (0: the hottest), for "Next".
    pub hottest: Option<usize>,
    /// A dump to import once the scene being loaded is there.
    pub(in crate::app) pending_import: Option<PathBuf>,
    /// Text to put on the clipboard at the end of this frame (the clipboard is the context's).
    pub clipboard: Option<String>,
    /// The docked layout (saved with the settings); out of the app only while it is drawn.
    pub dock: Option<dock::Layout>,
    /// Presenting: the layout before it, given back when presenting ends.
    pub dock_presenting: Option<dock::Presenting>,
    /// Derived from the state, kept while it is unchanged (the viewport reads them).
    pub(super) box_cache: std::cell::RefCell<Option<BoxCache>>,
    pub(super) overlay_cache: std::cell::RefCell<Option<OverlayCache>>,
    /// The selected node's mask over the frame on screen.
    pub(super) mask_cache: std::cell::RefCell<Option<MaskCache>>,
    /// The legend's histogram of the frame on screen, and the threshold's mask over it.
    pub(super) histogram_cache: std::cell::RefCell<Option<HistogramCache>>,
    /// The side-by-side images of the frames on screen.
    pub(super) compare_cache: std::cell::RefCell<Option<Arc<compare::CompareImages>>>,
    pub(super) threshold_cache: std::cell::RefCell<Option<ThresholdCache>>,
    /// The imported tree's wrong pixels' mask, for the result it was drawn from.
    pub(super) wrong_cache: std::cell::RefCell<Option<WrongCache>>,
    /// Aspect of the viewport, for framing the camera.
    pub(in crate::app) viewport_aspect: f32,
    /// Where the viewport was drawn in the last frame.
    pub viewport_rect: egui::Rect,
    /// Where the image was drawn in it: all of it, or a scene's film letterboxed.
    pub image_rect: egui::Rect,
    /// The image size the viewport asks for (0 × 0 before it is first laid out).
    pub(in crate::app) viewport_pixels: (u32, u32),
}

/// The overlay's triangles for one camera and viewport rectangle, and for the frame they were
/// depth-tested against if they were (redrawn only when these change).
pub(super) struct OverlayCache {
    boxes: Arc<Vec<OverlayBox>>,
    camera: Camera,
    rect: egui::Rect,
    depth: Option<Arc<Frame>>,
    mesh: Arc<egui::Mesh>,
}

/// The legend's histogram, for a frame and view.
pub(super) type HistogramCache = (Arc<Frame>, View, Vec<u32>);
/// The wrong pixels' mask, for the imported tree, camera and traversal it was traced with.
pub(super) type WrongCache = (Arc<SceneBvh>, Camera, TraceOptions, egui::TextureHandle);
/// The threshold's mask, for a frame, view and threshold.
pub(super) type ThresholdCache = (Arc<Frame>, View, f32, egui::TextureHandle);

/// A node's mask: for the frame, the prepared tree and the node it was made for.
pub(super) struct MaskCache {
    pub(super) frame: Arc<Frame>,
    pub(super) tree: Arc<node::Explained>,
    pub(super) node: u32,
    pub(super) texture: egui::TextureHandle,
}

pub(super) struct BoxCache {
    bvh: Arc<SceneBvh>,
    /// (level, top depth, bottom depth, leaves above)
    key: (BoxLevel, u32, u32, bool),
    boxes: Arc<Vec<OverlayBox>>,
}

impl BvhscopeApp {
    pub fn new(cc: &eframe::CreationContext<'_>, options: AppOptions) -> Self {
        let settings: Settings = cc.storage.and_then(|s| eframe::get_value(s, eframe::APP_KEY)).unwrap_or_default();
        let scene = Arc::new(Scene::builtin());
        let aspect = 1.6;
        let mut app = Self {
            orbit: OrbitCamera::home(&scene.bounds(), aspect, settings.up_axis),
            settings,
            scene,
            scene_id: 1,
            built: None,
            built_cache: BuildCache::default(),
            lesson: None,
            rays: None,
            previous: None,
            jobs: Jobs::new(cc.egui_ctx.clone()),
            shown: None,
            last_full_frame: None,
            messages: Vec::new(),
            clipboard: None,
            dock_presenting: None,
            dock: Some(
                cc.storage
                    .and_then(|s| eframe::get_value::<dock::Layout>(s, dock::DOCK_KEY))
                    .filter(dock::valid)
                    .unwrap_or_else(dock::default_layout),
            ),
            show_help: false,
            path_window: None,
            pins: RayView::default(),
            ray_window: false,
            nodes: NodeView::default(),
            threshold: None,
            replay: ReplayView::default(),
            compare: CompareView::default(),
            import: ImportView { mask: true, ..Default::default() },
            grade: GradeView::default(),
            speedup: None,
            hottest: None,
            pending_import: options.bvh.clone(),
            box_cache: Default::default(),
            overlay_cache: Default::default(),
            mask_cache: Default::default(),
            histogram_cache: Default::default(),
            compare_cache: Default::default(),
            threshold_cache: Default::default(),
            wrong_cache: Default::default(),
            viewport_aspect: aspect,
            viewport_rect: egui::Rect::NOTHING,
            image_rect: egui::Rect::NOTHING,
            viewport_pixels: (0, 0),
        };
        match (options.file, app.pending_import.take()) {
            (Some(file), bvh) => {
                app.pending_import = bvh;
                app.act(Action::OpenFile(file));
            }
            (None, Some(bvh)) => app.act(Action::ImportFile(bvh)),
            (None, None) => {}
        }
        app.jobs.probe_gpu();
        app.reconcile();
        app
    }

    pub(in crate::app) fn set_scene(&mut self, scene: Arc<Scene>) {
        for w in &scene.warnings {
            self.message(MessageKind::Warning, format!("{}: {w}", scene.title()));
        }
        // A scene file brings its camera (and with it the up axis) and the BVH settings to start
        // with; two levels are the start only where a mesh is placed more than once (the
        // Moer-lite lab scene places its monkey once: one level, as the handout builds it).
        if let Some(c) = &scene.camera {
            self.settings.up_axis = orbit::up_axis_of(c);
        }
        self.orbit = match &scene.camera {
            Some(c) => OrbitCamera::exactly(c, self.settings.up_axis),
            None => OrbitCamera::home(&scene.bounds(), self.viewport_aspect, self.settings.up_axis),
        };
        if let Some(b) = scene.build {
            self.settings.build = b;
        }
        if let Some(inst) = scene.instances() {
            self.settings.two_level = inst.placements.len() > inst.meshes.len();
        }
        // A new mesh has its own heatmap scale.
        self.settings.fixed_ranges.clear();
        self.settings.diff_ranges.clear();
        self.scene = scene;
        self.scene_id += 1;
        self.previous = None;
        self.rays = None;
        // Node ids are the old tree's: a selection kept would dim the new heatmap for nothing.
        self.nodes.deselect();
        self.hottest = None;
        // A dump numbers the triangles of the mesh it was written for.
        self.import = ImportView { mask: self.import.mask, ..Default::default() };
    }

    /// Read and check a dump for the current mesh (in the background; the view stays as it is).
    pub(in crate::app) fn import_file(&mut self, path: PathBuf) {
        let (w, h) = match self.viewport_pixels {
            (0, _) | (_, 0) => (640, 400),
            p => p,
        };
        let camera = self.orbit.camera(w, h);
        self.jobs.import(path, self.scene.clone(), self.scene_id, camera, self.settings.trace);
    }

    /// Make `bvh` the current BVH; the one it replaces gives the statistics' "before" column.
    pub(in crate::app) fn set_built(&mut self, bvh: Arc<SceneBvh>) {
        if let Some(old) = self.current_figures() {
            if self
                .current_bvh()
                .is_some_and(|b| b.bvh.label() != bvh.label() || b.bvh.build_params() != bvh.build_params())
            {
                self.previous = Some(old);
            }
        }
        let names: Vec<String> =
            self.scene.instances().iter().flat_map(|i| &i.meshes).map(|m| m.name.clone()).collect();
        // Node ids are the old binary tree's: kept only where the new BVH has the same one (the
        // same build in another layout, which is collapsed from it).
        let binary = |b: &SceneBvh| {
            let mut p = b.build_params();
            p.bvh.layout = crate::bvh::Layout::Binary;
            (p, b.import().map(|i| i.path.clone()))
        };
        if self.current_bvh().is_none_or(|b| binary(&b.bvh) != binary(&bvh)) {
            self.nodes.deselect();
        }
        self.built_cache.keep(self.scene_id, self.scene.report.triangles, &bvh);
        self.built = Some(BuiltBvh::new(bvh, &names, self.scene_id));
        self.rays = None;
    }

    /// The current camera, meshes and BVH settings as a scene file (not for the built-in scene,
    /// which has no file to refer to).
    pub fn scene_file_text(&self) -> Result<String, String> {
        let meshes = match (&self.scene.desc, &self.scene.source) {
            (Some(desc), _) => desc.meshes.clone(),
            (None, SceneSource::File(p)) => {
                let file = p.canonicalize().unwrap_or_else(|_| p.clone());
                vec![crate::scene::SceneMesh::new(file, glam::Affine3A::IDENTITY)]
            }
            (None, SceneSource::Builtin) => {
                return Err("the built-in scene has no mesh file a scene could refer to; open a mesh first".into())
            }
        };
        let (w, h) = self.shown.as_ref().map_or((1280, 720), |s| (s.camera.width, s.camera.height));
        let camera = self.orbit.camera(w, h);
        Ok(crate::scene::write_scene_file(&camera, &meshes, &self.settings.build))
    }

    /// The style the next render uses.
    pub fn view_style(&self) -> ViewStyle {
        ViewStyle {
            view: self.settings.view,
            colormap: self.settings.colormap,
            range: self.settings.heat_range(),
            cost: self.settings.build.cost,
        }
    }

    /// The BVH of the current scene, if built.
    pub fn current_bvh(&self) -> Option<&BuiltBvh> {
        self.built.as_ref().filter(|b| b.scene_id == self.scene_id)
    }

    /// Whether the scene can be built as two levels (it came from a scene file).
    pub fn has_instances(&self) -> bool {
        self.scene.instances().is_some()
    }

    /// What the settings ask to build for the current scene.
    pub fn wanted_build(&self) -> SceneBuild {
        let top = (self.settings.two_level && self.has_instances())
            .then_some(crate::bvh::BuildParams { layout: crate::bvh::Layout::Binary, ..self.settings.top_build });
        let mut bvh = self.settings.build;
        if self.gpu_for_frames().is_some() {
            // The GPU walks binary nodes (or CWBVH nodes made from them), as `--device gpu` does.
            bvh.layout = crate::bvh::Layout::Binary;
        }
        SceneBuild { bvh, top }
    }

    /// The boxes of the overlay for the current BVH and settings (cached): the single BVH's at
    /// the box depth, or for two levels the top level's and/or the bottom level's, each at its
    /// own depth.
    pub fn overlay_boxes(&self) -> Option<Arc<Vec<OverlayBox>>> {
        let bvh = self.current_bvh()?.bvh.clone();
        let s = &self.settings;
        let key = (s.box_level, s.top_box_depth, s.box_depth, s.boxes_leaves_above);
        let mut cache = self.box_cache.borrow_mut();
        let fresh = cache.as_ref().is_some_and(|c| Arc::ptr_eq(&c.bvh, &bvh) && c.key == key);
        if !fresh {
            let (level, top_depth, depth, leaves_above) = key;
            let boxes = overlay::boxes_of(&bvh, level, top_depth, depth, leaves_above);
            *cache = Some(BoxCache { bvh, key, boxes: Arc::new(boxes) });
        }
        cache.as_ref().map(|c| c.boxes.clone())
    }

    /// The partial tree the viewport shows while the Replay window is open (of the current BVH).
    pub fn replay_partial(&self) -> Option<Arc<crate::explain::replay::PartialBvh>> {
        let bvh = self.current_bvh()?.bvh.clone();
        let e = self.nodes.current(Some(&bvh))?;
        let p = self.replay.partial.as_ref().filter(|_| self.replay.window)?;
        Arc::ptr_eq(&p.tree, &e.tree).then(|| p.clone())
    }

    /// How many boxes the overlay draws (0 when it is off).
    pub fn boxes_drawn(&self) -> usize {
        let boxes = self.settings.show_boxes.then(|| self.overlay_boxes()).flatten();
        boxes.map_or(0, |b| b.len())
    }

    /// The overlay mesh of `boxes` seen by `camera` in `rect` (cached), depth-tested against
    /// `depth` (the frame on screen) when given.
    pub fn overlay_mesh(
        &self,
        boxes: Arc<Vec<OverlayBox>>,
        camera: Camera,
        rect: egui::Rect,
        depth: Option<Arc<Frame>>,
    ) -> Arc<egui::Mesh> {
        let mut cache = self.overlay_cache.borrow_mut();
        if let Some(c) = &*cache {
            let same_depth = match (&c.depth, &depth) {
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                (None, None) => true,
                _ => false,
            };
            if Arc::ptr_eq(&c.boxes, &boxes) && c.camera == camera && c.rect == rect && same_depth {
                return c.mesh.clone();
            }
        }
        let mesh = Arc::new(overlay::boxes_mesh(&boxes, &camera, rect, 1.2, depth.as_deref()));
        *cache = Some(OverlayCache { boxes, camera, rect, depth, mesh: mesh.clone() });
        mesh
    }

    /// The camera and traversal the current per-ray figures come from (or, before the first
    /// full frame, the ones the image on screen was made with).
    pub fn rays_key(&self) -> Option<(Camera, TraceOptions)> {
        match (&self.rays, &self.shown) {
            (Some(r), _) => Some((r.camera, r.trace)),
            (None, Some(s)) => Some((s.camera, self.settings.trace)),
            (None, None) => None,
        }
    }

    /// The image size the viewport renders at.
    pub fn viewport_pixels(&self) -> (u32, u32) {
        self.viewport_pixels
    }

    /// The film the image is rendered at, when it is a scene file's (its camera's size): the
    /// statistics are then of the scene's frame, as `bvhscope stats SCENE` counts them.
    pub fn film(&self) -> Option<(u32, u32)> {
        let c = self.scene.camera.as_ref().filter(|_| self.settings.film == Film::Scene)?;
        Some((c.width, c.height))
    }

    pub(in crate::app) fn reset_view(&mut self) {
        self.orbit = OrbitCamera::home(&self.scene.bounds(), self.viewport_aspect, self.settings.up_axis);
    }
}
