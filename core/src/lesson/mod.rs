//! Lessons: a teacher's walk through a BVH as an ordered list of steps, each a caption and the
//! state it shows (scene, build and trace options, rays, view, colour map and range, camera, node
//! boxes, the explain view open and its target). A step names only what changes; the rest carries
//! over from the step before (`Lesson::states`). The app steps through a lesson with a clicker's
//! keys and records one; the CLI renders it to a handout. The file is JSON, read as strictly as a
//! scene file (`read.rs`), written back by `write.rs` (a recorded lesson reopens as the same steps).

mod check;
mod command;
mod handout;
mod read;
mod record;
mod text;
mod write;

#[cfg(test)]
mod lesson_tests;

pub use check::{check, step_camera, Problem};
pub use command::{explain_words, folded, render_words, shown};
pub use handout::{caption_html, handout_html, HandoutStep};
pub use read::{is_lesson, parse_lesson, read_lesson, LessonError, MAX_LESSON_BYTES};
pub use record::{record, start_state};
pub use text::{spans, Span};
pub use write::write_lesson;

use crate::bvh::{BuildParams, Layout, Param, ParamValue, Strategy, TraceOptions, TraversalOrder};
use crate::geometry::TriangleTest;
use crate::render::{Camera, ColorMap, HeatRange, PairView, RayKind, SecondarySpec, View};
use glam::Vec3;
use std::path::PathBuf;

/// A lesson as its file describes it.
#[derive(Clone, Debug, PartialEq)]
pub struct Lesson {
    pub title: String,
    pub steps: Vec<Step>,
}

/// One step: what it says and what it changes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Step {
    /// A few lines; `*emphasis*` and `` `code` `` as Markdown writes them.
    pub caption: String,
    /// A question to the room, and its answer (shown on the next key press).
    pub question: Option<String>,
    pub answer: Option<String>,
    /// The scene or mesh file (relative paths are the lesson file's folder's).
    pub scene: Option<PathBuf>,
    pub bvh: BuildEdit,
    pub order: Option<TraversalOrder>,
    pub test: Option<TriangleTest>,
    pub rays: RaysEdit,
    pub view: Option<View>,
    pub colormap: Option<ColorMap>,
    pub range: Option<HeatRange>,
    pub camera: Option<Camera>,
    /// Node boxes at a depth (`Some(None)`: no boxes).
    pub boxes: Option<Option<u32>>,
    pub show: Option<Show>,
}

/// The build options a step names, applied over the previous step's.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BuildEdit {
    pub strategy: Option<Strategy>,
    pub layout: Option<Layout>,
    /// The numeric parameters named (`crate::options::BUILD_PARAMS`), in the file's order.
    pub params: Vec<(Param, ParamValue)>,
}

impl BuildEdit {
    pub fn is_empty(&self) -> bool {
        self.strategy.is_none() && self.layout.is_none() && self.params.is_empty()
    }

    /// This edit with what `later` names changed (a parameter named again keeps its first place).
    pub fn then(&self, later: &BuildEdit) -> BuildEdit {
        let mut out = self.clone();
        out.strategy = later.strategy.or(out.strategy);
        out.layout = later.layout.or(out.layout);
        for &(param, v) in &later.params {
            match out.params.iter_mut().find(|(p, _)| *p == param) {
                Some(slot) => slot.1 = v,
                None => out.params.push((param, v)),
            }
        }
        out
    }

    /// `p` with what this names changed.
    pub fn apply(&self, p: &BuildParams) -> BuildParams {
        let mut out = *p;
        if let Some(s) = self.strategy {
            out.strategy = s;
        }
        if let Some(l) = self.layout {
            out.layout = l;
        }
        for &(param, v) in &self.params {
            param.set(&mut out, v);
        }
        out
    }
}

/// The rays options a step names (the CLI's `--ray-kind`, `--samples`, `--seed`, `--ao-length`,
/// `--light`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RaysEdit {
    pub kind: Option<RayKind>,
    pub samples: Option<u32>,
    pub seed: Option<u64>,
    pub ao_length: Option<f32>,
    pub light: Option<Vec3>,
}

impl RaysEdit {
    pub fn is_empty(&self) -> bool {
        *self == RaysEdit::default()
    }

    pub fn apply(&self, s: &SecondarySpec) -> SecondarySpec {
        let mut out = *s;
        out.kind = self.kind.unwrap_or(out.kind);
        out.samples = self.samples.unwrap_or(out.samples);
        out.seed = self.seed.unwrap_or(out.seed);
        out.ao_length = self.ao_length.unwrap_or(out.ao_length);
        if self.light.is_some() {
            out.light = self.light;
        }
        out
    }
}

/// The explain view a step opens, with its target.
#[derive(Clone, Debug, PartialEq)]
pub enum Show {
    /// The image alone: every explain view closed.
    Image,
    /// The Ray view on the ray of pixel `(x, y)`, at step `step` of its walk (its last when
    /// `None`).
    Ray { pixel: (u32, u32), step: Option<u32> },
    /// The Node view on a node of the binary tree (0: the root).
    Node(u32),
    /// The Tree view with a node selected.
    Tree(u32),
    /// Side by side with a second build (the step's, with `b` changed) in a mode.
    Compare { b: BuildEdit, mode: PairView },
    /// The build's replay after a number of splits.
    Replay { splits: u32 },
}

/// What the screen shows at a step: every step before it applied in turn.
#[derive(Clone, Debug, PartialEq)]
pub struct StepState {
    pub scene: PathBuf,
    /// The build options named since the lesson began; the rest are the scene's own (its file's
    /// `bvh`), as `render` takes them when its flags leave them out (`StepState::build_params`).
    pub build: BuildEdit,
    pub trace: TraceOptions,
    pub rays: SecondarySpec,
    pub view: View,
    pub colormap: ColorMap,
    pub range: HeatRange,
    /// The scene's own camera (or the mesh's default) until a step sets one.
    pub camera: Option<Camera>,
    pub boxes: Option<u32>,
    pub show: Show,
}

impl StepState {
    /// The build this step shows, over the scene's own settings (`None`: a mesh, the defaults).
    pub fn build_params(&self, scene: Option<&BuildParams>) -> BuildParams {
        self.build.apply(&scene.copied().unwrap_or_default())
    }
}

impl Lesson {
    /// The state at each step. The reader makes sure the first step names a scene.
    pub fn states(&self) -> Vec<StepState> {
        let mut out: Vec<StepState> = Vec::with_capacity(self.steps.len());
        for step in &self.steps {
            let mut s = out.last().cloned().unwrap_or_else(start_state);
            if let Some(scene) = &step.scene {
                if *scene != s.scene {
                    // Another scene: its own camera, and a view's target no longer means anything.
                    s.camera = None;
                    s.show = Show::Image;
                }
                s.scene = scene.clone();
            }
            s.build = s.build.then(&step.bvh);
            s.trace.order = step.order.unwrap_or(s.trace.order);
            s.trace.test = step.test.unwrap_or(s.trace.test);
            s.rays = step.rays.apply(&s.rays);
            s.view = step.view.unwrap_or(s.view);
            s.colormap = step.colormap.unwrap_or(s.colormap);
            s.range = step.range.unwrap_or(s.range);
            if step.camera.is_some() {
                s.camera = step.camera;
            }
            s.boxes = step.boxes.unwrap_or(s.boxes);
            if let Some(show) = &step.show {
                s.show = show.clone();
            }
            out.push(s);
        }
        out
    }
}
