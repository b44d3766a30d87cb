//! The desktop app (eframe/egui): a thin layer of state and panels over the core. The state is
//! here; the panels only read it and emit `Action`s, which `act` applies; `reconcile` then
//! decides what to rebuild and re-render. Long work runs in `jobs` and comes back as events.
//! Data flows one way: mesh → BVH → renderer → image → screen.

mod action;
mod compare_view;
mod derived;
mod explain_overlay;
mod export;
mod import_view;
mod jobs;
mod node_view;
mod orbit;
mod overlay;
mod panels;
mod ray_view;
mod replay_view;
mod scene;
mod settings;
mod shortcuts;
mod viewport;

pub use crate::scene::{Scene, SceneSource};
pub use action::{Action, Actions};
pub use compare_view::{CompareMode, CompareView};
pub use import_view::{ImportView, ImportedTree};
pub use jobs::Pick;
pub use node_view::{Metric, NodeView, Step as NodeStep};
pub use orbit::OrbitCamera;
pub use overlay::OverlayBox;
pub use ray_view::{PinnedRay, RayView};
pub use replay_view::ReplayView;
pub use scene::BuiltBvh;
pub use settings::{BoxLevel, Settings};

use crate::bvh::dump::BvhDump;
use crate::bvh::{SceneBuild, SceneBvh, TraceOptions, TreeStats};
use crate::render::{Camera, Frame, Legend, RaySummary, UpAxis, View};
use crate::scene::SceneBuildError;
use jobs::{JobEvent, Jobs, PassOutput, ViewStyle};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How the app starts.
#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// A mesh to open at start (the built-in scene shows until it is loaded).
    pub file: Option<PathBuf>,
    /// A BVH dump to import for it once it is loaded.
    pub bvh: Option<PathBuf>,
}

/// Open the window and run until it is closed.
pub fn run(options: AppOptions) -> Result<(), String> {
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("bvhscope")
            .with_app_id("bvhscope")
            .with_inner_size([1400.0, 860.0])
            .with_min_inner_size([800.0, 500.0])
            .with_drag_and_drop(true),
        ..Default::default()
    };
    eframe::run_native("bvhscope", native, Box::new(move |cc| Ok(Box::new(BvhscopeApp::new(cc, options)))))
        .map_err(|e| format!("cannot open the window: {e}"))
}

/// The image on screen and what produced it.
pub struct Shown {
    pub texture: egui::TextureHandle,
    pub frame: Arc<Frame>,
    pub camera: Camera,
    pub legend: Option<Legend>,
    pub style: ViewStyle,
    /// The build replay's partial tree that traced the image, if it was one.
    pub partial: Option<Arc<crate::bvh::replay::PartialBvh>>,
    /// Rays per second of the last pass.
    pub rays_per_s: f64,
    /// The build that traced it ("SAH binned, wide4"), for captions.
    pub build_label: String,
    /// The BVH and traversal that traced it: a pinned pixel is traced again through them.
    pub bvh: Arc<SceneBvh>,
    pub trace: TraceOptions,
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

pub struct BvhscopeApp {
    pub settings: Settings,
    pub scene: Arc<Scene>,
    /// Increases with every scene loaded; a BVH belongs to the scene it was built for.
    pub scene_id: u64,
    pub built: Option<BuiltBvh>,
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
    /// A dump to import once the scene being loaded is there.
    pending_import: Option<PathBuf>,
    /// Derived from the state, kept while it is unchanged (the viewport reads them).
    box_cache: std::cell::RefCell<Option<BoxCache>>,
    overlay_cache: std::cell::RefCell<Option<OverlayCache>>,
    /// The selected node's mask over the frame on screen.
    mask_cache: std::cell::RefCell<Option<MaskCache>>,
    /// The legend's histogram of the frame on screen, and the threshold's mask over it.
    histogram_cache: std::cell::RefCell<Option<HistogramCache>>,
    /// The side-by-side images of the frames on screen.
    compare_cache: std::cell::RefCell<Option<Arc<compare_view::CompareImages>>>,
    threshold_cache: std::cell::RefCell<Option<ThresholdCache>>,
    /// The imported tree's wrong pixels' mask, for the result it was drawn from.
    wrong_cache: std::cell::RefCell<Option<WrongCache>>,
    /// Aspect of the viewport, for framing the camera.
    viewport_aspect: f32,
    /// Where the viewport was drawn in the last frame (its size is the rendered image's).
    pub viewport_rect: egui::Rect,
    /// The image size the viewport asks for (0 × 0 before it is first laid out).
    viewport_pixels: (u32, u32),
}

/// The overlay's triangles for one camera and viewport rectangle, and for the frame they were
/// depth-tested against if they were (redrawn only when these change).
struct OverlayCache {
    boxes: Arc<Vec<OverlayBox>>,
    camera: Camera,
    rect: egui::Rect,
    depth: Option<Arc<Frame>>,
    mesh: Arc<egui::Mesh>,
}

/// The legend's histogram, for a frame and view.
type HistogramCache = (Arc<Frame>, View, Vec<u32>);
/// The wrong pixels' mask, for the imported tree, camera and traversal it was traced with.
type WrongCache = (Arc<SceneBvh>, Camera, TraceOptions, egui::TextureHandle);
/// The threshold's mask, for a frame, view and threshold.
type ThresholdCache = (Arc<Frame>, View, f32, egui::TextureHandle);

/// A node's mask: for the frame, the prepared tree and the node it was made for.
struct MaskCache {
    frame: Arc<Frame>,
    tree: Arc<node_view::Explained>,
    node: u32,
    texture: egui::TextureHandle,
}

struct BoxCache {
    bvh: Arc<SceneBvh>,
    /// (level, top depth, bottom depth, leaves above)
    key: (BoxLevel, u32, u32, bool),
    boxes: Arc<Vec<OverlayBox>>,
}

/// How a scene file's camera orbits: about the axis its up vector is nearest to (Y or Z).
fn up_axis_of(c: &Camera) -> UpAxis {
    if c.up.z.abs() > c.up.y.abs() && c.up.z.abs() >= c.up.x.abs() {
        UpAxis::Z
    } else {
        UpAxis::Y
    }
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
            rays: None,
            previous: None,
            jobs: Jobs::new(cc.egui_ctx.clone()),
            shown: None,
            last_full_frame: None,
            messages: Vec::new(),
            show_help: false,
            path_window: None,
            pins: RayView::default(),
            ray_window: false,
            nodes: NodeView::default(),
            threshold: None,
            replay: ReplayView::default(),
            compare: CompareView::default(),
            import: ImportView { mask: true, ..Default::default() },
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
        app.reconcile();
        app
    }

    pub fn message(&mut self, kind: MessageKind, text: impl Into<String>) {
        self.messages.push(Message { kind, text: text.into(), at: Instant::now() });
        if self.messages.len() > 5 {
            self.messages.remove(0);
        }
    }

    fn set_scene(&mut self, scene: Arc<Scene>) {
        for w in &scene.warnings {
            self.message(MessageKind::Warning, format!("{}: {w}", scene.title()));
        }
        // A scene file brings its camera (and with it the up axis) and the BVH settings to start
        // with; two levels are the start only where a mesh is placed more than once (the
        // Moer-lite lab scene places its monkey once: one level, as the handout builds it).
        if let Some(c) = &scene.camera {
            self.settings.up_axis = up_axis_of(c);
        }
        self.orbit = match &scene.camera {
            Some(c) => OrbitCamera::from_camera(c, self.settings.up_axis),
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
        if let Some(note) = scene.desc.as_ref().and_then(|d| d.note.as_ref()) {
            self.message(MessageKind::Info, format!("{}: {note}", scene.title()));
        }
        self.scene = scene;
        self.scene_id += 1;
        self.previous = None;
        self.rays = None;
        // A dump numbers the triangles of the mesh it was written for.
        self.import = ImportView { mask: self.import.mask, ..Default::default() };
    }

    /// Read and check a dump for the current mesh (in the background; the view stays as it is).
    fn import_file(&mut self, path: PathBuf) {
        let (w, h) = match self.viewport_pixels {
            (0, _) | (_, 0) => (640, 400),
            p => p,
        };
        let camera = self.orbit.camera(w, h);
        self.jobs.import(path, self.scene.clone(), self.scene_id, camera, self.settings.trace);
    }

    /// Make `bvh` the current BVH; the one it replaces gives the statistics' "before" column.
    fn set_built(&mut self, bvh: Arc<SceneBvh>) {
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
        SceneBuild { bvh: self.settings.build, top }
    }

    /// Bring the background work in line with the state: settings that depend on the BVH are
    /// kept within it, a build starts when the settings or the scene differ from what was built
    /// or is building, and a render when what the viewport would show differs from the last
    /// render asked for. The one place that decides what to rebuild and re-render.
    pub fn reconcile(&mut self) {
        self.fit_settings_to_bvh();
        self.fit_levels_to_scene();
        self.ensure_build();
        self.ensure_render();
        self.ensure_explained();
        self.ensure_compare();
        self.ensure_wrong();
    }

    /// The red mask's pixels: once an image of the imported tree is done, the frame's primary
    /// rays are traced against the linear scan (unless they were for this camera).
    fn ensure_wrong(&mut self) {
        if !self.import.on || self.jobs.is_busy() || self.jobs.wrong.is_some() {
            return;
        }
        let Some(s) = self.shown.as_ref().filter(|s| s.frame.is_complete() && s.partial.is_none()) else { return };
        let Some(reference) = self.import.tree.as_ref().and_then(|t| t.reference.clone()) else { return };
        if s.bvh.import().is_some() && self.import.wrong_for(&s.bvh, &s.camera, &s.trace).is_none() {
            self.jobs.wrong(s.bvh.clone(), reference, s.camera, s.trace);
        }
    }

    /// B of the side-by-side view: once A's image is done, B is built (or kept) and traced on the
    /// same camera and traversal, unless it already was.
    fn ensure_compare(&mut self) {
        if !self.compare.on || self.jobs.is_busy() {
            return;
        }
        let Some(shown) = self.shown.as_ref().filter(|s| s.frame.is_complete() && s.partial.is_none()) else { return };
        if !self.current_bvh().is_some_and(|b| Arc::ptr_eq(&b.bvh, &shown.bvh)) {
            return;
        }
        let build = self.compare.build_for(self.wanted_build());
        let wanted = (build, self.scene_id, shown.camera, self.compare.trace);
        let have = self.compare.b.as_ref().is_some_and(|b| (b.build, b.scene_id, b.camera, b.trace) == wanted);
        if !have && self.jobs.last_compare != Some(wanted) {
            let keep = self.compare.b.as_ref().filter(|b| b.scene_id == self.scene_id).map(|b| b.bvh.clone());
            self.jobs.compare(self.scene.clone(), self.scene_id, build, keep, shown.camera, self.compare.trace);
        }
    }

    /// The node explainer's background work, each started only when the image is done (it must
    /// not slow a build or a render): the binary tree behind the current single BVH, the frame's
    /// visits per node while the Tree window is open, and the selected node's inspection.
    fn ensure_explained(&mut self) {
        if self.jobs.is_busy() {
            return;
        }
        let Some(bvh) = self.current_bvh().map(|b| b.bvh.clone()) else { return };
        if !matches!(*bvh, SceneBvh::Single { .. }) {
            return;
        }
        let Some(explained) = self.nodes.current(Some(&bvh)).cloned() else {
            if self.jobs.explain.is_none() {
                self.jobs.explain(bvh);
            }
            return;
        };
        if self.replay.window {
            let before = self.replay.partial.clone();
            self.replay.fit(&explained);
            let changed = match (&before, &self.replay.partial) {
                (Some(a), Some(b)) => !Arc::ptr_eq(a, b),
                _ => true,
            };
            if changed {
                self.ensure_render();
            }
        }
        if let Some(node) = self.nodes.selected.filter(|_| self.nodes.inspection.is_none()) {
            if self.jobs.inspect.as_ref().is_none_or(|(_, n)| *n != node) {
                self.jobs.inspect(explained.clone(), node);
            }
        }
        if self.nodes.window && self.jobs.visits.is_none() {
            let Some(shown) = self.shown.as_ref().filter(|s| Arc::ptr_eq(&s.bvh, &bvh)) else { return };
            let fresh = self.nodes.visits.as_ref().is_some_and(|v| {
                Arc::ptr_eq(&v.explained, &explained) && v.camera == shown.camera && v.trace == shown.trace
            });
            if !fresh {
                self.jobs.visits(explained, shown.camera, shown.trace);
            }
        }
    }

    /// Box depths within the tree's depth (once it is known: until a BVH is built the chosen
    /// depth is kept), and no per-level view for a single BVH, which has no levels to tell apart.
    fn fit_settings_to_bvh(&mut self) {
        let Some(built) = self.current_bvh() else { return };
        let (max, top) = (built.bottom_max_depth(), built.top_stats.as_ref().map(|s| s.max_depth));
        let s = &mut self.settings;
        s.box_depth = s.box_depth.min(max);
        match top {
            Some(top) => s.top_box_depth = s.top_box_depth.min(top),
            None if s.view.is_per_level() => s.view = View::Visits,
            None => {}
        }
    }

    /// One level over a scene too large to flatten is not built: the app switches to two levels
    /// and says why (the CLI refuses with the same sentence).
    fn fit_levels_to_scene(&mut self) {
        if self.settings.two_level || !self.has_instances() {
            return;
        }
        if let Err(e) = self.scene.check_one_level() {
            self.settings.two_level = true;
            self.message(MessageKind::Warning, format!("{e}. Switched to two levels."));
        }
    }

    /// Start a build when the settings or the scene differ from what was built or is building.
    fn ensure_build(&mut self) {
        // The imported tree, when it is chosen, is the current BVH: nothing to build.
        if let Some(bvh) = self.import.shown(self.scene_id).cloned() {
            self.jobs.cancel_build();
            self.jobs.last_build = None;
            if !self.current_bvh().is_some_and(|b| Arc::ptr_eq(&b.bvh, &bvh)) {
                self.set_built(bvh);
            }
            return;
        }
        let build = self.wanted_build();
        let wanted = (build, self.scene_id);
        let have = self.current_bvh().is_some_and(|b| b.bvh.import().is_none() && b.bvh.build_params() == build);
        if have {
            // Switched back to what is built while another build ran: that build is not wanted.
            self.jobs.cancel_build();
        } else if self.jobs.last_build != Some(wanted) {
            self.jobs.build(self.scene.clone(), build, self.scene_id);
        }
    }

    /// Start a render when what the viewport would show (camera, image size, BVH, view)
    /// differs from the last render asked for.
    fn ensure_render(&mut self) {
        let (w, h) = self.viewport_pixels;
        let Some(built) = self.current_bvh().filter(|_| w > 0 && h > 0) else { return };
        let req = jobs::RenderRequest {
            bvh: built.bvh.clone(),
            camera: self.orbit.camera(w, h),
            trace: self.settings.trace,
            style: self.view_style(),
            progressive: self.settings.progressive,
            partial: self.replay_partial(),
        };
        if req.camera.validate().is_ok() && !self.jobs.last_render.as_ref().is_some_and(|last| last.same_as(&req)) {
            self.jobs.render(req);
        }
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
    pub fn replay_partial(&self) -> Option<Arc<crate::bvh::replay::PartialBvh>> {
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
        let test = depth.as_deref().map(|frame| overlay::DepthTest { frame, rect });
        let mesh = Arc::new(overlay::boxes_mesh(&boxes, &camera, rect, 1.2, test));
        *cache = Some(OverlayCache { boxes, camera, rect, depth, mesh: mesh.clone() });
        mesh
    }

    /// Figures of the current strategy for the statistics panel.
    pub fn current_figures(&self) -> Option<StrategyFigures> {
        self.current_bvh().map(|b| StrategyFigures {
            label: b.bvh.label(),
            // The end-point overlap comes with the prepared tree, a moment after the image.
            stats: TreeStats { epo: self.nodes.current(Some(&b.bvh)).map(|e| e.epo), ..b.stats.clone() },
            build_ms: b.bvh.build_time().as_secs_f64() * 1e3,
            rays: self.rays,
        })
    }

    /// B's figures for the statistics panel's second column, while comparing side by side.
    pub fn compare_figures(&self) -> Option<StrategyFigures> {
        let b = self.compare.b.as_ref().filter(|b| self.compare.on && b.scene_id == self.scene_id)?;
        Some(StrategyFigures {
            label: format!("B: {}", b.bvh.label()),
            stats: b.stats.clone(),
            build_ms: b.bvh.build_time().as_secs_f64() * 1e3,
            rays: Some(MeasuredRays { summary: b.summary, camera: b.camera, trace: b.trace }),
        })
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

    fn reset_view(&mut self) {
        self.orbit = OrbitCamera::home(&self.scene.bounds(), self.viewport_aspect, self.settings.up_axis);
    }

    fn apply(&mut self, ctx: &egui::Context, event: JobEvent) {
        match event {
            JobEvent::Loaded(Ok(scene)) => {
                if let SceneSource::File(p) = &scene.source {
                    self.settings.remember(p.clone());
                }
                let r = &scene.report;
                let mut text = format!("Opened {}: {} triangles", scene.title(), r.triangles);
                if r.degenerate_skipped > 0 {
                    text += &format!(" ({} degenerate triangles skipped)", r.degenerate_skipped);
                }
                self.message(MessageKind::Info, text);
                self.set_scene(scene);
                if let Some(dump) = self.pending_import.take() {
                    self.import_file(dump);
                }
            }
            JobEvent::Loaded(Err(e)) => self.message(MessageKind::Error, e),
            JobEvent::Explained(e) => {
                // A new tree: keep the selection where the id still exists, and its open rows.
                let n = e.tree.nodes.len() as u32;
                self.nodes.selected = self.nodes.selected.filter(|&s| s < n);
                self.nodes.open.retain(|&o| o < n);
                self.nodes.inspection = None;
                self.nodes.explained = Some(e);
                if let Some(s) = self.nodes.selected {
                    self.nodes.select(s);
                }
            }
            JobEvent::Visits(v) => self.nodes.visits = Some(v),
            JobEvent::Compared(b) => {
                if b.scene_id == self.scene_id {
                    self.compare.b = Some(*b);
                }
            }
            JobEvent::Inspected { node, explained, inspection } => {
                let current = self.nodes.explained.as_ref().is_some_and(|e| Arc::ptr_eq(e, &explained));
                if current && self.nodes.selected == Some(node) {
                    self.nodes.inspection = Some(inspection);
                }
            }
            JobEvent::Built { scene_id, result: Ok(bvh), .. }
                if scene_id == self.scene_id && self.import.shown(scene_id).is_none() =>
            {
                self.set_built(bvh)
            }
            JobEvent::Imported(Err(e)) => self.message(MessageKind::Error, e),
            JobEvent::Imported(Ok(tree)) if tree.scene_id == self.scene_id => {
                let (d, w) = (tree.defects(), tree.findings.len() - tree.defects());
                let kind = if d > 0 { MessageKind::Warning } else { MessageKind::Info };
                let shown = match &tree.bvh {
                    Ok(_) => "shown as \"imported\" in the strategy list".to_string(),
                    Err(why) => format!("not traced: {why}"),
                };
                self.message(kind, format!("Checked {}: {d} defects, {w} warnings; {shown}", tree.name()));
                self.import.on = tree.bvh.is_ok();
                self.import.window = true;
                self.import.wrong = None;
                self.import.tree = Some(*tree);
            }
            JobEvent::Imported(_) => {}
            JobEvent::Wrong(w) => self.import.wrong = Some(w),
            JobEvent::Built { scene_id, result: Err(SceneBuildError::Scene(e)), .. } if scene_id == self.scene_id => {
                self.message(MessageKind::Error, e.to_string());
            }
            JobEvent::Built { .. } => {}
            JobEvent::Pass(pass) => self.show_pass(ctx, pass),
            JobEvent::Picked { pick, path: Some(path), .. } => self.act(Action::Picked(pick, path)),
            JobEvent::Picked { pick, path: None, took } => {
                // rfd answers None at once when it has no portal or zenity to ask; a person who
                // cancels a real dialog takes longer than that.
                if took < Duration::from_millis(300) {
                    let note = "No file dialog is available on this system (no desktop portal or zenity). Type the path instead.";
                    self.path_window = Some(PathWindow::new(pick, String::new(), Some(note.into())));
                }
            }
        }
    }

    /// Act on a chosen file.
    fn picked(&mut self, pick: Pick, path: PathBuf) {
        let result = match pick {
            Pick::Open => {
                self.jobs.load(path);
                return;
            }
            Pick::SavePng => export::save_png(self, &path),
            Pick::SaveStatsCsv => export::save_stats(self, &path, export::StatsFormat::Csv),
            Pick::SaveStatsJson => export::save_stats(self, &path, export::StatsFormat::Json),
            Pick::SaveCounts => export::save_counts(self, &path),
            Pick::OpenBvh => {
                self.import_file(path);
                return;
            }
            Pick::SaveBvh => export::save_bvh(self, &path),
            Pick::SaveScene => self
                .scene_file_text()
                .and_then(|t| std::fs::write(&path, t).map_err(|e| format!("{}: cannot write: {e}", path.display()))),
        };
        match result {
            Ok(()) => self.message(MessageKind::Info, format!("Saved {}", path.display())),
            Err(e) => self.message(MessageKind::Error, e),
        }
    }

    fn show_pass(&mut self, ctx: &egui::Context, p: PassOutput) {
        let options = egui::TextureOptions::NEAREST;
        let rays_per_s = p.info.rays as f64 / p.info.pass_time.as_secs_f64().max(1e-9);
        if p.info.stride == 1 {
            self.last_full_frame = Some(p.info.elapsed);
            // Per-ray figures belong to the BVH that traced them; a pass of an older BVH that
            // arrives after a rebuild must not be shown (or remembered) under the new strategy.
            // A replay's partial tree is not the strategy's tree: its figures are not recorded.
            if p.partial.is_none() && self.current_bvh().is_some_and(|b| Arc::ptr_eq(&b.bvh, &p.bvh)) {
                self.rays = Some(MeasuredRays { summary: p.frame.ray_summary(), camera: p.camera, trace: p.trace });
            }
        }
        let texture = match self.shown.take() {
            Some(mut s) => {
                s.texture.set(p.image, options);
                s.texture
            }
            None => ctx.load_texture("bvhscope-view", p.image, options),
        };
        let build_label = p.bvh.label();
        self.shown = Some(Shown {
            texture,
            frame: p.frame,
            camera: p.camera,
            legend: p.legend,
            style: p.style,
            rays_per_s,
            build_label,
            bvh: p.bvh,
            trace: p.trace,
            partial: p.partial,
        });
    }

    /// Job results, and the actions of input outside the panels: dropped files and keys.
    fn handle_input(&mut self, ctx: &egui::Context, actions: &mut Actions) {
        for event in self.jobs.poll() {
            self.apply(ctx, event);
        }
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw.dropped_files.iter().map(|f| f.path().to_path_buf()).filter(|p| !p.as_os_str().is_empty()).collect()
        });
        // A dump dropped is imported for the current mesh; anything else is opened.
        let open = |p: PathBuf| if BvhDump::sniff(&p) { Action::ImportFile(p) } else { Action::OpenFile(p) };
        actions.extend(dropped.into_iter().take(1).map(open));
        actions.extend(shortcuts::pressed(ctx));
        // Info messages fade out; errors stay until dismissed.
        self.messages.retain(|m| m.kind != MessageKind::Info || m.at.elapsed() < Duration::from_secs(6));
    }
}

impl eframe::App for BvhscopeApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        let mut actions = Actions::new();
        self.handle_input(&ctx, &mut actions);
        // The panels see the state as it is after the input's actions.
        for action in actions.drain(..) {
            self.act(action);
        }
        self.reconcile();
        let out = &mut actions;
        egui::Panel::top("menu").show(ui, |ui| panels::menu::show(self, ui, out));
        egui::Panel::bottom("status").show(ui, |ui| panels::status::show(self, ui));
        // The side panels keep the width they have (the user's, remembered by egui's memory):
        // their contents wrap, scroll or clip inside it and never widen them, so the viewport,
        // and with it the camera's aspect, stays as it is when the figures change.
        egui::Panel::left("controls").resizable(true).default_size(290.0).size_range(200.0..=640.0).show(ui, |ui| {
            panels::fixed_width(ui, |ui| {
                panels::build::show(self, ui, out);
                ui.separator();
                panels::view::show(self, ui, out);
            })
        });
        egui::Panel::right("statistics")
            .resizable(true)
            .default_size(340.0)
            .size_range(220.0..=720.0)
            .show(ui, |ui| panels::fixed_width(ui, |ui| panels::stats::show(self, ui)));
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE.fill(egui::Color32::from_gray(12)))
            .show(ui, |ui| viewport::show(self, ui, out));
        panels::windows::show(self, &ctx, out);
        panels::ray::show(self, &ctx, out);
        panels::tree::show(self, &ctx, out);
        panels::node::show(self, &ctx, out);
        panels::replay::show(self, &ctx, out);
        panels::compare::show(self, &ctx, out);
        panels::imported::show(self, &ctx, out);
        // What the panels asked for takes effect now, and shows in the next frame.
        if !actions.is_empty() {
            for action in actions {
                self.act(action);
            }
            self.reconcile();
            ctx.request_repaint();
        }
        if self.jobs.is_busy() {
            // Keep progress indicators moving; results also wake the UI themselves.
            ctx.request_repaint_after(Duration::from_millis(100));
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, eframe::APP_KEY, &self.settings);
    }
}
