//! Recording a lesson in the app: what it shows turned into a `StepState` (`shown_state`) and
//! kept as a step of only what differs from the step before (`lesson::record`); the lesson saved
//! as its file.

use super::lesson::{same_file, scale_pixel};
use crate::app::state::{BvhscopeApp, MessageKind, OrbitCamera};
use crate::lesson::{record, BuildEdit, Show, StepState};
use crate::options::BUILD_PARAMS;
use crate::scene::SceneSource;
use std::path::Path;

impl BvhscopeApp {
    /// What the app shows as a lesson's state after `prev` (the step before; `None` for the
    /// first): the build options named as `prev` named them plus what differs from those, the
    /// camera `prev`'s while it has not moved, the explain view open and its target.
    pub(in crate::app) fn shown_state(&self, prev: Option<&StepState>) -> Result<StepState, String> {
        let SceneSource::File(file) = &self.scene.source else {
            return Err("The built-in scene has no file a lesson could name: open a mesh or a scene first".into());
        };
        let same_scene = prev.is_some_and(|p| same_file(&p.scene, file));
        // The build options carry over from scene to scene (`Lesson::states`).
        let base = prev.map(|p| p.build.clone()).unwrap_or_default();
        let build = base.then(&self.build_edit_over(&base));
        let scene = match prev {
            Some(p) if same_scene => p.scene.clone(),
            // Named by its full path, `..` folded (the file writes it relative to the lesson's).
            _ => file.canonicalize().unwrap_or_else(|_| file.clone()),
        };
        let camera = self.shown_camera(prev.and_then(|p| p.camera), same_scene);
        let state = StepState {
            scene,
            build,
            trace: self.settings.trace,
            rays: self.settings.rays,
            view: self.settings.view,
            colormap: self.settings.colormap,
            range: self.settings.heat_range(),
            camera,
            boxes: self.settings.show_boxes.then_some(self.settings.box_depth),
            show: crate::lesson::Show::Image,
        };
        let show = self.shown_view(&state);
        Ok(StepState { show, ..state })
    }

    /// The build options that differ from what `base` makes of the scene's own.
    fn build_edit_over(&self, base: &BuildEdit) -> BuildEdit {
        let own = base.apply(&self.scene.build.unwrap_or_default());
        let b = self.settings.build;
        BuildEdit {
            strategy: (b.strategy != own.strategy).then_some(b.strategy),
            layout: (b.layout != own.layout).then_some(b.layout),
            params: BUILD_PARAMS
                .iter()
                .filter(|o| o.param.get(&b) != o.param.get(&own))
                .map(|o| (o.param, o.param.get(&b)))
                .collect(),
        }
    }

    /// The camera on screen, as a step names it: `prev` (the step before's, on the same scene)
    /// while the view has not moved from it, else the camera at the size of the frame on screen.
    fn shown_camera(&self, prev: Option<crate::render::Camera>, same_scene: bool) -> Option<crate::render::Camera> {
        let prev = prev.filter(|_| same_scene);
        let implied = match prev.or(self.scene.camera) {
            Some(c) => OrbitCamera::exactly(&c, crate::app::state::orbit::up_axis_of(&c)),
            None => OrbitCamera::home(&self.scene.bounds(), self.viewport_aspect, self.settings.up_axis),
        };
        if implied.camera(16, 9) == self.orbit.camera(16, 9) {
            return prev;
        }
        let (w, h) = match (&self.shown, self.viewport_pixels()) {
            (Some(s), _) => (s.camera.width, s.camera.height),
            (None, (0, _) | (_, 0)) => (1280, 720),
            (None, p) => p,
        };
        Some(self.orbit.camera(w, h))
    }

    /// The explain view open, as a step names it (one of them: Compare, else Replay, else the
    /// Ray view's pinned pixel, else the Tree and Node views' node).
    fn shown_view(&self, state: &StepState) -> Show {
        let applied = self.lesson.as_ref().and_then(|l| l.applied.as_ref()).map(|a| &a.show);
        if self.compare.on {
            let a = self.settings.build;
            let c = &self.compare;
            let b =
                crate::bvh::BuildParams { strategy: c.strategy, max_leaf_size: c.max_leaf_size, layout: c.layout, ..a };
            let b = BuildEdit {
                strategy: (b.strategy != a.strategy).then_some(b.strategy),
                layout: (b.layout != a.layout).then_some(b.layout),
                params: BUILD_PARAMS
                    .iter()
                    .filter(|o| o.param.get(&b) != o.param.get(&a))
                    .map(|o| (o.param, o.param.get(&b)))
                    .collect(),
            };
            return Show::Compare { b, mode: c.mode };
        }
        if self.replay.window {
            return Show::Replay { splits: self.replay.k as u32 };
        }
        if let Some((r, p)) = self.pins.current().and_then(|r| r.pixel.map(|p| (r, p))) {
            let frame = self.shown.as_ref().map_or(self.reference_size(state), |s| (s.camera.width, s.camera.height));
            let pixel = scale_pixel(p, frame, self.reference_size(state));
            let step = (self.pins.step + 1 < r.len()).then_some(self.pins.step as u32);
            return Show::Ray { pixel, step };
        }
        match self.nodes.selected.filter(|_| self.nodes.window) {
            Some(n) if applied == Some(&Show::Tree(n)) => Show::Tree(n),
            Some(n) => Show::Node(n),
            None => Show::Image,
        }
    }

    /// Lesson ▸ Add this view as a step (after the step on screen) or Replace this step (its
    /// caption, question and answer kept). The steps after it are recorded again over it, so
    /// they show what they showed before.
    pub(in crate::app) fn record_step(&mut self, replace: bool) {
        let Some(l) = &self.lesson else { return };
        let replace = replace && !l.is_empty();
        let at = if replace || l.is_empty() { l.step } else { l.step + 1 };
        let prev = at.checked_sub(1).and_then(|k| l.states.get(k)).cloned();
        let now = match self.shown_state(prev.as_ref()) {
            Ok(s) => s,
            Err(e) => return self.message(MessageKind::Error, e),
        };
        let Some(l) = &mut self.lesson else { return };
        let old = l.states.clone();
        let mut step = record(prev.as_ref(), &now, String::new());
        // The states the later steps showed, each after the one before it.
        let later: Vec<StepState> = old.iter().skip(if replace { at + 1 } else { at }).cloned().collect();
        if replace {
            let was = &l.lesson.steps[at];
            (step.caption, step.question, step.answer) =
                (was.caption.clone(), was.question.clone(), was.answer.clone());
            l.lesson.steps[at] = step;
        } else {
            l.lesson.steps.insert(at, step);
        }
        let mut before = now.clone();
        for (i, target) in later.iter().enumerate() {
            let k = at + 1 + i;
            let was = &l.lesson.steps[k];
            let mut again = record(Some(&before), target, was.caption.clone());
            (again.question, again.answer) = (was.question.clone(), was.answer.clone());
            l.lesson.steps[k] = again;
            before = target.clone();
        }
        l.step = at;
        l.revealed = false;
        l.applying = None;
        l.applied = Some(now);
        l.editing = true;
        l.restate();
        let text = format!("Step {} of {} recorded", at + 1, l.len());
        self.message(MessageKind::Info, text);
    }

    /// Write the lesson to `path` (its scenes named relative to its folder).
    pub(in crate::app) fn save_lesson(&mut self, path: &Path) -> Result<(), String> {
        let Some(l) = &mut self.lesson else { return Err("No lesson is open".into()) };
        let text = crate::lesson::write_lesson(&l.lesson, path);
        crate::files::write_bytes(path, text.as_bytes()).map_err(|e| e.to_string())?;
        l.path = Some(path.to_path_buf());
        l.changed = false;
        Ok(())
    }
}
