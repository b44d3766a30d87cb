//! The lesson open in the app: a teacher's steps (`crate::lesson`), the step on screen, whether
//! its answer is shown, and the step being applied. Applying a step takes a few frames (its scene
//! loads, its tree builds, its frame renders before a ray can be pinned on it), so it is kept here
//! as `Applying` and moved on each frame by `update::lesson` through the same actions the menus
//! emit.

use crate::lesson::{Lesson, StepState};
use std::path::PathBuf;

pub struct LessonState {
    pub lesson: Lesson,
    /// The state at each step (`Lesson::states`), kept in step with `lesson`.
    pub states: Vec<StepState>,
    /// The file it was read from or saved to (`None`: a new lesson, never saved).
    pub path: Option<PathBuf>,
    /// The step on screen (0-based; 0 with no steps yet).
    pub step: usize,
    /// The step's answer is shown (its question is asked first).
    pub revealed: bool,
    /// The band shows the caption, question and answer as fields to type in.
    pub editing: bool,
    /// Changed since it was read or saved.
    pub changed: bool,
    /// The step being applied, and how far it has got.
    pub applying: Option<Applying>,
    /// The state of the last step applied in full: what the view shows while nothing has moved
    /// (a recorded step keeps its choices, Tree or Node, the scene's camera or its own).
    pub applied: Option<StepState>,
}

/// A step's state on its way to the screen.
pub struct Applying {
    pub state: StepState,
    pub stage: Stage,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Its scene is opened (`asked`: File ▸ Open's load has been asked for).
    Scene { asked: bool },
    /// The settings, the camera and the views are set.
    Settings,
    /// The view's target, once what it needs is there: the tree (a node), its replay (the
    /// splits), its frame (a pixel's ray).
    Target,
}

impl LessonState {
    pub fn new(lesson: Lesson, path: Option<PathBuf>) -> Self {
        let states = lesson.states();
        LessonState {
            lesson,
            states,
            path,
            step: 0,
            revealed: false,
            editing: false,
            changed: false,
            applying: None,
            applied: None,
        }
    }

    pub fn len(&self) -> usize {
        self.lesson.steps.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lesson.steps.is_empty()
    }

    /// The step on screen.
    pub fn current(&self) -> Option<&crate::lesson::Step> {
        self.lesson.steps.get(self.step)
    }

    /// Whether the next key press shows the answer rather than the next step.
    pub fn answer_next(&self) -> bool {
        !self.revealed && self.current().is_some_and(|s| s.answer.is_some())
    }

    /// `lesson.states()` again after its steps changed.
    pub fn restate(&mut self) {
        self.states = self.lesson.states();
        self.changed = true;
    }
}
