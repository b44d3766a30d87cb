//! A lesson in the app: opened from its file, stepped through with a clicker's keys, each step
//! applied through the actions the menus emit (`Edit` for the build, trace, rays, view, colour
//! map, range and boxes; `SetCamera`; `Compare`, `ShowReplay`, `ShowTree`, `UnpinAll` for the
//! views; then, once what it needs is there, `SelectNode`, `ReplayStep` or `PinPixel` and
//! `RayStep` for its target), so that what a step does is what a user's clicks do.

use crate::app::jobs::Pick;
use crate::app::state::{Action, Applying, BvhscopeApp, LessonState, MessageKind, OrbitCamera, PathWindow, Stage};
use crate::bvh::SceneBvh;
use crate::lesson::{Lesson, Show, StepState};
use crate::render::{Camera, HeatRange};
use crate::scene::SceneSource;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How a stage of applying a step ends this frame.
enum Outcome {
    /// Go on to this stage (or stay in it) next frame.
    Next(Stage),
    Done,
    /// Its scene could not be opened (the load's message says why).
    Failed,
}

impl BvhscopeApp {
    /// The lesson actions (`Action::OpenLesson` …).
    pub(super) fn act_lesson(&mut self, action: Action) {
        use Action as A;
        match action {
            A::OpenLesson => self.jobs.pick_file(Pick::OpenLesson, ""),
            A::OpenLessonPath => self.path_window = Some(PathWindow::new(Pick::OpenLesson, String::new(), None)),
            A::OpenLessonFile(path) => self.open_lesson(path),
            A::LessonGo(k) => self.lesson_go(k, false),
            A::LessonNext => self.lesson_next(),
            A::LessonPrevious => self.lesson_previous(),
            A::NewLesson => {
                let mut l = LessonState::new(Lesson { title: String::new(), steps: Vec::new() }, None);
                l.editing = true;
                self.lesson = Some(l);
            }
            A::AddStep => self.record_step(false),
            A::ReplaceStep => self.record_step(true),
            A::LessonText { title, caption, question, answer } => {
                let Some(l) = &mut self.lesson else { return };
                l.lesson.title = title;
                let k = l.step;
                if let Some(step) = l.lesson.steps.get_mut(k) {
                    let text = |t: String| Some(t).filter(|t| !t.trim().is_empty());
                    step.caption = caption;
                    step.question = text(question);
                    // An answer needs its question (the reader refuses one without).
                    step.answer = text(answer).filter(|_| step.question.is_some());
                }
                l.changed = true;
            }
            A::LessonEditing(on) => {
                if let Some(l) = &mut self.lesson {
                    l.editing = on;
                }
            }
            A::SaveLesson => match &self.lesson {
                Some(l) if l.is_empty() => {
                    self.message(MessageKind::Error, "The lesson has no steps yet: Lesson › Add this view as a step")
                }
                Some(_) => {
                    self.jobs.pick_file(Pick::SaveLesson, &super::export::suggested_name(self, Pick::SaveLesson))
                }
                None => {}
            },
            A::CloseLesson => self.lesson = None,
            _ => {}
        }
    }

    /// Open the lesson file `path` at its first step. One that cannot be read leaves everything
    /// as it was (the lesson open, if any, and the scene) with one message naming the file, the
    /// step and the field.
    pub(in crate::app) fn open_lesson(&mut self, path: PathBuf) {
        match crate::lesson::read_lesson(&path) {
            Ok(lesson) => {
                let text = format!("Lesson {}: {} steps", lesson_title(&lesson, &path), lesson.steps.len());
                self.lesson = Some(LessonState::new(lesson, Some(path)));
                self.message(MessageKind::Info, text);
                self.lesson_go(0, false);
            }
            Err(e) => self.message(MessageKind::Error, e.to_string()),
        }
    }

    /// Show step `k` (its answer too when `revealed` and it has one).
    pub(in crate::app) fn lesson_go(&mut self, k: usize, revealed: bool) {
        let Some(l) = &mut self.lesson else { return };
        let Some(state) = l.states.get(k).cloned() else { return };
        l.step = k;
        l.revealed = revealed && l.lesson.steps[k].answer.is_some();
        l.applying = Some(Applying { state, stage: Stage::Scene { asked: false } });
    }

    fn lesson_next(&mut self) {
        let Some(l) = &mut self.lesson else { return };
        if l.answer_next() {
            l.revealed = true;
        } else if l.step + 1 < l.len() {
            let k = l.step + 1;
            self.lesson_go(k, false);
        }
    }

    /// Back: the answer hidden again if it is shown, else the step before as the room last saw
    /// it (its answer shown).
    fn lesson_previous(&mut self) {
        let Some(l) = &mut self.lesson else { return };
        if l.revealed && l.current().is_some_and(|s| s.answer.is_some()) {
            l.revealed = false;
        } else if l.step > 0 {
            let k = l.step - 1;
            self.lesson_go(k, true);
        }
    }

    /// The actions that move the step being applied on: called every frame, before the panels.
    pub(in crate::app) fn lesson_actions(&mut self) -> Vec<Action> {
        let Some(a) = self.lesson.as_ref().and_then(|l| l.applying.as_ref()) else { return Vec::new() };
        let (state, stage) = (a.state.clone(), a.stage);
        let mut out = Vec::new();
        let outcome = match stage {
            Stage::Scene { asked } => self.scene_stage(&state, asked, &mut out),
            Stage::Settings => {
                self.settings_stage(&state, &mut out);
                Outcome::Next(Stage::Target)
            }
            Stage::Target => self.target_stage(&state, &mut out),
        };
        let Some(l) = &mut self.lesson else { return out };
        match outcome {
            Outcome::Next(stage) => {
                if let Some(a) = &mut l.applying {
                    a.stage = stage;
                }
            }
            Outcome::Done => l.applied = l.applying.take().map(|a| a.state),
            Outcome::Failed => l.applying = None,
        }
        out
    }

    /// The step's scene, opened as File ▸ Open opens it, unless it is the one on screen.
    fn scene_stage(&self, state: &StepState, asked: bool, out: &mut Vec<Action>) -> Outcome {
        if self.shows_scene(&state.scene) {
            // On to the settings in the same frame.
            self.settings_stage(state, out);
            return Outcome::Next(Stage::Target);
        }
        if !asked {
            out.push(Action::OpenFile(state.scene.clone()));
            return Outcome::Next(Stage::Scene { asked: true });
        }
        if self.jobs.load.is_none() {
            return Outcome::Failed;
        }
        Outcome::Next(Stage::Scene { asked: true })
    }

    /// Whether the scene on screen is the file `path`.
    pub fn shows_scene(&self, path: &Path) -> bool {
        matches!(&self.scene.source, SceneSource::File(p) if same_file(p, path))
    }

    /// The step's settings, camera and views.
    fn settings_stage(&self, state: &StepState, out: &mut Vec<Action>) {
        let mut s = self.settings.clone();
        s.build = state.build_params(self.scene.build.as_ref());
        s.trace = state.trace;
        s.rays = state.rays;
        s.view = state.view;
        s.colormap = state.colormap;
        match state.range {
            HeatRange::Fixed { min, max } => s.fixed_ranges.insert(state.view, (min, max)).map(|_| ()),
            HeatRange::Auto => s.fixed_ranges.remove(&state.view).map(|_| ()),
        };
        s.show_boxes = state.boxes.is_some();
        s.box_depth = state.boxes.unwrap_or(s.box_depth);
        if self.import.on {
            out.push(Action::UseImported(false));
        }
        out.push(Action::Edit(Box::new(s.clone())));
        out.push(Action::SetCamera(state.camera));
        let show = &state.show;
        if self.compare.on && !matches!(show, Show::Compare { .. }) {
            out.push(Action::Compare(false));
        }
        if self.replay.window && !matches!(show, Show::Replay { .. }) {
            out.push(Action::ShowReplay(false));
        }
        if !self.pins.pinned.is_empty() || self.ray_window {
            out.push(Action::UnpinAll);
        }
        if self.nodes.window && !matches!(show, Show::Node(_) | Show::Tree(_)) {
            out.push(Action::ShowTree(false));
        }
        match show {
            Show::Compare { b, mode } => {
                let b = b.apply(&s.build);
                out.push(Action::Compare(true));
                out.push(Action::CompareStrategy(b.strategy));
                out.push(Action::CompareB { max_leaf_size: b.max_leaf_size, layout: b.layout, trace: state.trace });
                out.push(Action::CompareMode(*mode));
            }
            Show::Replay { .. } => out.push(Action::ShowReplay(true)),
            _ => {}
        }
    }

    /// The view's target, once the step's tree is built (and for a ray, its frame is there).
    fn target_stage(&self, state: &StepState, out: &mut Vec<Action>) -> Outcome {
        let wanted = self.wanted_build();
        let built = self.current_bvh().filter(|b| b.bvh.build_params() == wanted && self.jobs.build.is_none());
        let Some(bvh) = built.map(|b| b.bvh.clone()) else { return Outcome::Next(Stage::Target) };
        // Boxes deeper than the tree before this step's went to that tree's depth.
        if let Some(d) = state.boxes.filter(|&d| d != self.settings.box_depth) {
            let max = self.current_bvh().map_or(0, |b| b.bottom_max_depth());
            let s = crate::app::state::Settings { box_depth: d.min(max), ..self.settings.clone() };
            if s != self.settings {
                out.push(Action::Edit(Box::new(s)));
            }
        }
        // The Tree, Node and Replay views explain a single tree (not two levels).
        let single = matches!(*bvh, SceneBvh::Single { .. });
        let explained = self.nodes.current(Some(&bvh));
        match &state.show {
            Show::Image | Show::Compare { .. } => {}
            Show::Node(n) | Show::Tree(n) if single => {
                if explained.is_none() {
                    return Outcome::Next(Stage::Target);
                }
                out.push(Action::SelectNode(*n));
            }
            Show::Replay { splits } if single => {
                let ready = explained
                    .is_some_and(|e| self.replay.replay.as_ref().is_some_and(|r| Arc::ptr_eq(&r.tree, &e.tree)));
                if !ready {
                    return Outcome::Next(Stage::Target);
                }
                out.push(Action::ReplayStep(*splits as usize));
            }
            Show::Ray { pixel, step } => {
                let ready = self.shown.as_ref().filter(|s| {
                    Arc::ptr_eq(&s.bvh, &bvh)
                        && s.partial.is_none()
                        && s.frame.is_complete()
                        && self.jobs.render.is_none()
                        && s.camera == self.orbit.camera(s.camera.width, s.camera.height)
                });
                let Some(s) = ready else { return Outcome::Next(Stage::Target) };
                let (x, y) = scale_pixel(*pixel, self.reference_size(state), (s.camera.width, s.camera.height));
                out.push(Action::PinPixel(x, y));
                out.push(Action::RayStep(step.map_or(usize::MAX, |k| k as usize)));
            }
            _ => {}
        }
        Outcome::Done
    }

    /// The image size a step's pixels are counted in: its camera's, else its scene's, else the
    /// 1280×720 `render` frames a mesh at (`lesson::step_camera`).
    pub(in crate::app) fn reference_size(&self, state: &StepState) -> (u32, u32) {
        state.camera.or(self.scene.camera).map_or((1280, 720), |c| (c.width, c.height))
    }

    /// The camera of a step (`None`: the scene's own, or the mesh's default view).
    pub(super) fn set_camera(&mut self, camera: Option<Camera>) {
        match camera.or(self.scene.camera) {
            Some(c) => {
                self.settings.up_axis = crate::app::state::orbit::up_axis_of(&c);
                self.orbit = OrbitCamera::exactly(&c, self.settings.up_axis);
            }
            None => self.reset_view(),
        }
    }
}

/// A pixel of an image of size `from`, in an image of size `to` (the same place on the film).
pub(in crate::app) fn scale_pixel(p: (u32, u32), from: (u32, u32), to: (u32, u32)) -> (u32, u32) {
    let one = |x: u32, f: u32, t: u32| {
        let x =
            if f == t || f == 0 { x } else { ((x as f64 + 0.5) * t as f64 / f as f64 - 0.5).round().max(0.0) as u32 };
        x.min(t.saturating_sub(1))
    };
    (one(p.0, from.0, to.0), one(p.1, from.1, to.1))
}

/// Whether two paths name the same file (as written, or once resolved).
pub(in crate::app) fn same_file(a: &Path, b: &Path) -> bool {
    a == b || matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
}

/// The lesson's title, or its file's name.
fn lesson_title(l: &Lesson, path: &Path) -> String {
    if l.title.is_empty() {
        path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned())
    } else {
        format!("\"{}\"", l.title)
    }
}
