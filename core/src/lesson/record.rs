//! Recording a lesson: the app turns what it shows into a `StepState` and keeps, as the step, only
//! what differs from the step before (`record`), so the file says what each step changes and
//! `Lesson::states` gives back the states recorded.

use super::{BuildEdit, RaysEdit, Show, Step, StepState};
use crate::bvh::TraceOptions;
use crate::render::{ColorMap, HeatRange, SecondarySpec, View};
use std::path::PathBuf;

/// The state `Lesson::states` starts from, before the first step.
pub fn start_state() -> StepState {
    StepState {
        scene: PathBuf::new(),
        build: BuildEdit::default(),
        trace: TraceOptions::default(),
        rays: SecondarySpec::default(),
        view: View::Normals,
        colormap: ColorMap::Viridis,
        range: HeatRange::Auto,
        camera: None,
        boxes: None,
        show: Show::Image,
    }
}

/// The step that, after `prev` (the previous step's state; `None` for the first step), shows
/// `now`: it names what differs, the scene always for the first step. What a step cannot unset (a
/// build option, a camera or a light named before and absent from `now`) stays as `prev` has it.
pub fn record(prev: Option<&StepState>, now: &StepState, caption: String) -> Step {
    let mut base = prev.cloned().unwrap_or_else(start_state);
    let scene = (prev.is_none() || base.scene != now.scene).then(|| now.scene.clone());
    if let Some(s) = &scene {
        if *s != base.scene {
            // As `states` reads a change of scene: its own camera, the image alone.
            base.camera = None;
            base.show = Show::Image;
        }
    }
    Step {
        caption,
        question: None,
        answer: None,
        scene,
        bvh: build_edit(&base.build, &now.build),
        order: differs(base.trace.order, now.trace.order),
        test: differs(base.trace.test, now.trace.test),
        rays: rays_edit(&base.rays, &now.rays),
        view: differs(base.view, now.view),
        colormap: differs(base.colormap, now.colormap),
        range: differs(base.range, now.range),
        camera: (base.camera != now.camera).then_some(now.camera).flatten(),
        boxes: differs(base.boxes, now.boxes),
        show: differs(base.show.clone(), now.show.clone()),
    }
}

/// `now` where it differs from `base`.
fn differs<T: PartialEq>(base: T, now: T) -> Option<T> {
    (base != now).then_some(now)
}

/// What `now` names differently from `base` (`base.then(edit)` names what `now` does).
fn build_edit(base: &BuildEdit, now: &BuildEdit) -> BuildEdit {
    let value = |p| base.params.iter().find(|(q, _)| *q == p).map(|(_, v)| *v);
    BuildEdit {
        strategy: now.strategy.filter(|s| base.strategy != Some(*s)),
        layout: now.layout.filter(|l| base.layout != Some(*l)),
        params: now.params.iter().filter(|(p, v)| value(*p) != Some(*v)).copied().collect(),
    }
}

fn rays_edit(base: &SecondarySpec, now: &SecondarySpec) -> RaysEdit {
    RaysEdit {
        kind: (base.kind != now.kind).then_some(now.kind),
        samples: (base.samples != now.samples).then_some(now.samples),
        seed: (base.seed != now.seed).then_some(now.seed),
        ao_length: (base.ao_length != now.ao_length).then_some(now.ao_length),
        light: (base.light != now.light).then_some(now.light).flatten(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lesson::{parse_lesson, write_lesson, Lesson};
    use std::path::Path;

    const LESSON: &str = r#"{ "title": "Recorded",
      "steps": [
        { "caption": "one", "scene": "../scenes/knot-on-floor.json", "bvh": { "strategy": "midpoint", "max_leaf_size": 2 },
          "boxes": 3 },
        { "caption": "two", "view": "visits", "range": [0, 30], "boxes": "off",
          "show": { "ray": { "pixel": [64, 30], "step": 12 } }, "question": "Why?", "answer": "Deep." },
        { "caption": "three", "bvh": { "max_leaf_size": 4, "bins": 8 }, "rays": { "kind": "ao", "samples": 4, "seed": 7 },
          "show": { "compare": { "bvh": { "strategy": "sah" }, "mode": "difference" } } },
        { "caption": "four", "order": "split-axis", "test": "moller-trumbore", "colormap": "turbo", "show": { "node": 2 },
          "camera": { "position": [0, 6, 11], "look_at": [0, 1, 0], "size": [80, 60] } },
        { "caption": "five", "scene": "../scenes/monkey.json", "show": { "replay": { "splits": 40 } }, "range": "auto" },
        { "caption": "six", "bvh": { "strategy": "midpoint" }, "show": "image", "view": "normals" }
      ] }"#;

    #[test]
    fn the_start_is_where_states_starts() {
        let one = Lesson { title: String::new(), steps: vec![Step { scene: Some("a.obj".into()), ..Step::default() }] };
        assert_eq!(one.states()[0], StepState { scene: "a.obj".into(), ..start_state() });
    }

    #[test]
    fn recorded_states_read_back_as_the_same_states() {
        let path = Path::new("lessons/recorded.json");
        let lesson = parse_lesson(path, LESSON).unwrap();
        let states = lesson.states();
        let mut steps: Vec<Step> = Vec::new();
        for (i, now) in states.iter().enumerate() {
            let prev = i.checked_sub(1).map(|k| &states[k]);
            let mut step = record(prev, now, lesson.steps[i].caption.clone());
            (step.question, step.answer) = (lesson.steps[i].question.clone(), lesson.steps[i].answer.clone());
            steps.push(step);
        }
        let recorded = Lesson { title: lesson.title.clone(), steps };
        assert_eq!(recorded.states(), states);
        let text = write_lesson(&recorded, path);
        let again = parse_lesson(path, &text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(again.states(), states, "{text}");
        // Only what changes: the second step names no build, the sixth no scene.
        assert!(recorded.steps[1].bvh.is_empty() && recorded.steps[1].scene.is_none());
        assert_eq!(recorded.steps[5].scene, None);
        assert_eq!(recorded.steps[5].bvh.strategy, None, "midpoint since the first step");
        assert_eq!(recorded.steps[2].bvh.params.len(), 2, "{:?}", recorded.steps[2].bvh);
        assert_eq!(recorded.steps[4].camera, None, "another scene: its own camera");
    }

    #[test]
    fn the_first_step_names_the_scene_and_what_differs_from_the_start() {
        let now = StepState { scene: "m.obj".into(), view: View::Visits, ..start_state() };
        let step = record(None, &now, "first".into());
        assert_eq!(step.scene.as_deref(), Some(Path::new("m.obj")));
        assert_eq!(step.view, Some(View::Visits));
        assert_eq!((step.colormap, step.range, step.show), (None, None, None));
        let same = record(Some(&now), &now, "again".into());
        assert_eq!(same, Step { caption: "again".into(), ..Step::default() }, "nothing changed, nothing named");
    }

    #[test]
    fn a_lesson_is_told_from_a_scene_file() {
        let dir = crate::scratch::shared("is-lesson");
        let file = |name: &str, text: &str| {
            let p = dir.join(name);
            std::fs::write(&p, text).unwrap();
            p
        };
        assert!(crate::lesson::is_lesson(&file("l.json", LESSON)));
        assert!(crate::lesson::is_lesson(&file("bad.json", r#"{"steps": 3}"#)), "a broken lesson is a lesson");
        assert!(!crate::lesson::is_lesson(&file("s.json", r#"{"meshes": [{"file": "a.obj"}]}"#)));
        assert!(!crate::lesson::is_lesson(&file("a.obj", "v 0 0 0\n")));
        assert!(!crate::lesson::is_lesson(&dir.join("missing.json")));
        assert!(!crate::lesson::is_lesson(&file("list.json", r#"[{"steps": []}]"#)));
    }
}
