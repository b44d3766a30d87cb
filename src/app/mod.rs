//! The desktop app (eframe/egui): a thin layer of state and panels over the core. The state is
//! here; the panels only read and change it; long work runs in `jobs` and comes back as events.
//! Data flows one way: mesh → BVH → renderer → image → screen.

mod export;
mod jobs;
mod orbit;
mod overlay;
mod panels;
mod scene;
mod settings;
mod shortcuts;
mod viewport;

pub use jobs::Pick;
pub use orbit::OrbitCamera;
pub use overlay::OverlayBox;
pub use scene::{BuiltBvh, Scene, SceneSource};
pub use settings::{BoxLevel, Settings};

use crate::bvh::{SceneBuild, SceneBvh, SplitStrategy, TreeStats};
use crate::render::{Camera, ColorMap, Frame, Legend, RaySummary, View};
use jobs::{JobEvent, Jobs, PassOutput, ViewStyle};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// "SAH binned, 4-wide SIMD": the strategy and layout of a build, for the statistics columns.
fn figures_label(p: &SceneBuild) -> String {
    let one = format!("{}, {}", p.bvh.strategy.label(), p.bvh.layout.short_name());
    match p.top {
        Some(top) => format!("top {} / {one}", top.strategy.label()),
        None => one,
    }
}

/// How the app starts.
#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// A mesh to open at start (the built-in scene shows until it is loaded).
    pub file: Option<PathBuf>,
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
    /// Rays per second of the last pass.
    pub rays_per_s: f64,
}

/// One strategy's figures for the statistics panel (the current one and the one before).
#[derive(Clone, Debug)]
pub struct StrategyFigures {
    pub label: String,
    pub stats: TreeStats,
    pub rays: Option<RaySummary>,
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
}

pub struct BvhscopeApp {
    pub settings: Settings,
    pub scene: Scene,
    /// Increases with every scene loaded; a BVH belongs to the scene it was built for.
    pub scene_id: u64,
    pub built: Option<BuiltBvh>,
    /// Work per ray in the latest full frame of the current BVH.
    pub rays: Option<RaySummary>,
    /// The figures of the strategy shown before the current one.
    pub previous: Option<StrategyFigures>,
    pub orbit: OrbitCamera,
    pub jobs: Jobs,
    pub shown: Option<Shown>,
    pub last_full_frame: Option<Duration>,
    pub messages: Vec<Message>,
    pub show_help: bool,
    pub path_window: Option<PathWindow>,
    /// Boxes drawn by the overlay in the last frame.
    pub boxes_drawn: usize,
    box_cache: Option<BoxCache>,
    overlay_cache: Option<OverlayCache>,
    /// Aspect of the viewport, for framing the camera.
    viewport_aspect: f32,
}

/// The overlay's triangles for one camera and viewport rectangle (redrawn only when they change).
struct OverlayCache {
    boxes: Arc<Vec<OverlayBox>>,
    camera: Camera,
    rect: egui::Rect,
    mesh: Arc<egui::Mesh>,
}

struct BoxCache {
    bvh: Arc<SceneBvh>,
    /// (level, top depth, bottom depth, leaves above)
    key: (BoxLevel, u32, u32, bool),
    boxes: Arc<Vec<OverlayBox>>,
}

impl BvhscopeApp {
    pub fn new(cc: &eframe::CreationContext<'_>, options: AppOptions) -> Self {
        let settings: Settings = cc.storage.and_then(|s| eframe::get_value(s, eframe::APP_KEY)).unwrap_or_default();
        let scene = Scene::builtin();
        let aspect = 1.6;
        let mut app = Self {
            settings,
            orbit: OrbitCamera::home(&scene.mesh.bounds(), aspect),
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
            boxes_drawn: 0,
            box_cache: None,
            overlay_cache: None,
            viewport_aspect: aspect,
        };
        if let Some(file) = options.file {
            app.open(file);
        }
        app.ensure_build();
        app
    }

    /// Load a mesh in the background; the current scene stays until it has loaded.
    pub fn open(&mut self, path: PathBuf) {
        self.jobs.load(path);
    }

    pub fn show_builtin(&mut self) {
        self.set_scene(Scene::builtin());
    }

    pub fn message(&mut self, kind: MessageKind, text: impl Into<String>) {
        self.messages.push(Message { kind, text: text.into(), at: Instant::now() });
        if self.messages.len() > 5 {
            self.messages.remove(0);
        }
    }

    fn set_scene(&mut self, scene: Scene) {
        for w in &scene.warnings {
            self.message(MessageKind::Warning, format!("{}: {w}", scene.title()));
        }
        // A scene file brings its camera and the BVH settings to start with.
        self.orbit = match &scene.camera {
            Some(c) => OrbitCamera::from_camera(c),
            None => OrbitCamera::home(&scene.mesh.bounds(), self.viewport_aspect),
        };
        if let Some(b) = scene.build {
            self.settings.build = b;
        }
        if let Some(note) = scene.desc.as_ref().and_then(|d| d.note.as_ref()) {
            self.message(MessageKind::Info, format!("{}: {note}", scene.title()));
        }
        self.scene = scene;
        self.scene_id += 1;
        self.previous = None;
        self.rays = None;
        self.ensure_build();
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
        self.scene.instances.is_some()
    }

    /// What the settings ask to build for the current scene.
    pub fn wanted_build(&self) -> SceneBuild {
        let top = (self.settings.two_level && self.has_instances())
            .then_some(crate::bvh::BuildParams { layout: crate::bvh::Layout::Binary, ..self.settings.top_build });
        SceneBuild { bvh: self.settings.build, top }
    }

    /// Start a build when the settings or the scene differ from what was built or is building.
    pub fn ensure_build(&mut self) {
        let build = self.wanted_build();
        let wanted = (build, self.scene_id);
        let have = self.current_bvh().is_some_and(|b| b.bvh.build_params() == build);
        if have {
            // Switched back to what is built while another build ran: that build is not wanted.
            self.jobs.cancel_build();
        } else if self.jobs.last_build != Some(wanted) {
            let instances = if build.top.is_some() { self.scene.instances.clone() } else { None };
            self.jobs.build(self.scene.mesh.clone(), instances, build, self.scene_id);
        }
    }

    /// The boxes of the overlay for the current BVH and settings (cached): the single BVH's at
    /// the box depth, or for two levels the top level's and/or the bottom level's, each at its
    /// own depth.
    pub fn overlay_boxes(&mut self) -> Option<Arc<Vec<OverlayBox>>> {
        let bvh = self.current_bvh()?.bvh.clone();
        let s = &self.settings;
        let key = (s.box_level, s.top_box_depth, s.box_depth, s.boxes_leaves_above);
        let fresh = self.box_cache.as_ref().is_some_and(|c| Arc::ptr_eq(&c.bvh, &bvh) && c.key == key);
        if !fresh {
            let (level, top_depth, depth, leaves_above) = key;
            let boxes = overlay::boxes_of(&bvh, level, top_depth, depth, leaves_above);
            self.box_cache = Some(BoxCache { bvh, key, boxes: Arc::new(boxes) });
        }
        self.box_cache.as_ref().map(|c| c.boxes.clone())
    }

    /// The overlay mesh of `boxes` seen by `camera` in `rect` (cached).
    pub fn overlay_mesh(&mut self, boxes: Arc<Vec<OverlayBox>>, camera: Camera, rect: egui::Rect) -> Arc<egui::Mesh> {
        if let Some(c) = &self.overlay_cache {
            if Arc::ptr_eq(&c.boxes, &boxes) && c.camera == camera && c.rect == rect {
                return c.mesh.clone();
            }
        }
        let mesh = Arc::new(overlay::boxes_mesh(&boxes, &camera, rect, 1.2));
        self.overlay_cache = Some(OverlayCache { boxes, camera, rect, mesh: mesh.clone() });
        mesh
    }

    /// Figures of the current strategy for the statistics panel.
    pub fn current_figures(&self) -> Option<StrategyFigures> {
        self.current_bvh().map(|b| StrategyFigures {
            label: figures_label(&b.bvh.build_params()),
            stats: b.stats.clone(),
            rays: self.rays,
        })
    }

    pub fn frame_mesh(&mut self) {
        self.orbit.frame(&self.scene.mesh.bounds(), self.viewport_aspect);
    }

    pub fn reset_view(&mut self) {
        self.orbit = OrbitCamera::home(&self.scene.mesh.bounds(), self.viewport_aspect);
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
            }
            JobEvent::Loaded(Err(e)) => self.message(MessageKind::Error, e),
            JobEvent::Built { scene_id, result: Ok(bvh), .. } if scene_id == self.scene_id => {
                if let Some(old) = self.current_figures() {
                    if self.current_bvh().is_some_and(|b| b.bvh.build_params() != bvh.build_params()) {
                        self.previous = Some(old);
                    }
                }
                let stats = TreeStats::of(bvh.tree());
                let bottom = match (bvh.two_level(), &self.scene.instances) {
                    (Some(t), Some(inst)) => {
                        t.bottom.iter().zip(&inst.meshes).map(|(b, m)| (m.name.clone(), TreeStats::of(b))).collect()
                    }
                    _ => Vec::new(),
                };
                self.built = Some(BuiltBvh { bvh, stats, bottom, scene_id });
                self.rays = None;
            }
            JobEvent::Built { .. } => {}
            JobEvent::Pass(pass) => self.show_pass(ctx, pass),
            JobEvent::Picked { pick, path: Some(path), .. } => self.picked(pick, path),
            JobEvent::Picked { pick, path: None, took } => {
                // rfd answers None at once when it has no portal or zenity to ask; a person who
                // cancels a real dialog takes longer than that.
                if took < Duration::from_millis(300) {
                    self.path_window = Some(PathWindow {
                        pick,
                        text: String::new(),
                        note: Some("No file dialog is available on this system (no desktop portal or zenity). Type the path instead.".into()),
                    });
                }
            }
        }
    }

    /// Act on a chosen file.
    pub fn picked(&mut self, pick: Pick, path: PathBuf) {
        let result = match pick {
            Pick::Open => {
                self.open(path);
                return;
            }
            Pick::SavePng => export::save_png(self, &path),
            Pick::SaveStatsCsv => export::save_stats(self, &path, export::StatsFormat::Csv),
            Pick::SaveStatsJson => export::save_stats(self, &path, export::StatsFormat::Json),
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
            if self.current_bvh().is_some_and(|b| Arc::ptr_eq(&b.bvh, &p.bvh)) {
                self.rays = Some(p.frame.ray_summary());
            }
        }
        let texture = match self.shown.take() {
            Some(mut s) => {
                s.texture.set(p.image, options);
                s.texture
            }
            None => ctx.load_texture("bvhscope-view", p.image, options),
        };
        self.shown =
            Some(Shown { texture, frame: p.frame, camera: p.camera, legend: p.legend, style: p.style, rays_per_s });
    }

    /// Everything that happens before the panels are drawn: job results, dropped files, keys.
    fn handle_input(&mut self, ctx: &egui::Context) {
        for event in self.jobs.poll() {
            self.apply(ctx, event);
        }
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw.dropped_files.iter().map(|f| f.path().to_path_buf()).filter(|p| !p.as_os_str().is_empty()).collect()
        });
        if let Some(path) = dropped.into_iter().next() {
            self.open(path);
        }
        for action in shortcuts::pressed(ctx) {
            self.act(action);
        }
        // Info messages fade out; errors stay until dismissed.
        self.messages.retain(|m| m.kind != MessageKind::Info || m.at.elapsed() < Duration::from_secs(6));
    }

    pub fn act(&mut self, action: shortcuts::Action) {
        use shortcuts::Action as A;
        match action {
            A::Open => self.jobs.pick_file(Pick::Open, ""),
            A::OpenPath => self.path_window = Some(PathWindow { pick: Pick::Open, text: String::new(), note: None }),
            A::SavePng => self.jobs.pick_file(Pick::SavePng, &export::default_name(self, "png")),
            A::ExportStats => self.jobs.pick_file(Pick::SaveStatsCsv, &export::default_name(self, "csv")),
            A::FrameMesh => self.frame_mesh(),
            A::ResetView => self.reset_view(),
            A::View(i) => self.settings.view = View::ALL[i.min(View::ALL.len() - 1)],
            A::ToggleBoxes => self.settings.show_boxes = !self.settings.show_boxes,
            A::DepthUp => {
                let max = self.current_bvh().map_or(0, |b| b.bottom_max_depth());
                self.settings.box_depth = (self.settings.box_depth + 1).min(max);
                self.settings.show_boxes = true;
            }
            A::DepthDown => {
                self.settings.box_depth = self.settings.box_depth.saturating_sub(1);
                self.settings.show_boxes = true;
            }
            A::NextStrategy => {
                let i = SplitStrategy::ALL.iter().position(|s| *s == self.settings.build.strategy).unwrap_or(0);
                self.settings.build.strategy = SplitStrategy::ALL[(i + 1) % SplitStrategy::ALL.len()];
            }
            A::NextColormap => {
                let i = ColorMap::ALL.iter().position(|c| *c == self.settings.colormap).unwrap_or(0);
                self.settings.colormap = ColorMap::ALL[(i + 1) % ColorMap::ALL.len()];
            }
            A::Help => self.show_help = !self.show_help,
        }
    }
}

impl eframe::App for BvhscopeApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.handle_input(&ctx);
        egui::Panel::top("menu").show(ui, |ui| panels::menu::show(self, ui));
        egui::Panel::bottom("status").show(ui, |ui| panels::status::show(self, ui));
        egui::Panel::left("controls").resizable(true).default_size(290.0).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                panels::build::show(self, ui);
                ui.separator();
                panels::view::show(self, ui);
            });
        });
        egui::Panel::right("statistics").resizable(true).default_size(330.0).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| panels::stats::show(self, ui));
        });
        egui::CentralPanel::default().frame(egui::Frame::NONE.fill(egui::Color32::from_gray(12))).show(ui, |ui| {
            self.viewport_aspect = ui.available_width() / ui.available_height().max(1.0);
            viewport::show(self, ui);
        });
        panels::windows::show(self, &ctx);
        self.ensure_build();
        if self.jobs.is_busy() {
            // Keep progress indicators moving; results also wake the UI themselves.
            ctx.request_repaint_after(Duration::from_millis(100));
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, eframe::APP_KEY, &self.settings);
    }
}
