//! Lessons in the app: a teacher's steps opened from their file and stepped through with a
//! clicker's keys (PageDown / PageUp, Right / Left), each step's state applied (scene, build,
//! view, range, boxes, camera, the explain view and its target), its caption in a band of its own
//! below the image; a lesson recorded in the app, saved and opened again.

use super::support::*;
use bvhscope::app::{caption_text, Action, AppOptions, BvhscopeApp, Pick};
use bvhscope::lesson::{read_lesson, Lesson, Show, StepState};
use bvhscope::render::View;
use egui::Key;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use std::path::PathBuf;
use std::sync::Arc;

fn shipped(name: &str) -> PathBuf {
    root().join("lessons").join(name)
}

/// The step `k` of the lesson open is on screen: applied in full, its frame there, nothing
/// running (and, for Compare, B traced beside A).
fn on_step(a: &BvhscopeApp, k: usize) -> bool {
    let Some(l) = &a.lesson else { return false };
    let pair = !a.compare.on || pair_shown(a);
    l.step == k && l.applying.is_none() && idle(a) && pair
}

fn step_to(h: &mut Harness<'_, BvhscopeApp>, k: usize) {
    run_until(h, &format!("step {}", k + 1), |a| on_step(a, k));
}

/// What the app shows is `state`, as the lesson's step names it.
fn assert_shows(a: &BvhscopeApp, state: &StepState, k: usize) {
    let at = format!("step {}", k + 1);
    assert!(a.shows_scene(&state.scene), "{at}: the scene {}", state.scene.display());
    let build = state.build_params(a.scene.build.as_ref());
    assert_eq!(a.settings.build, build, "{at}: the build options");
    assert_eq!(a.current_bvh().unwrap().bvh.build_params().bvh, build, "{at}: the tree on screen");
    assert_eq!(a.settings.trace, state.trace, "{at}");
    assert_eq!(a.settings.rays, state.rays, "{at}");
    assert_eq!(a.settings.view, state.view, "{at}: the view");
    assert_eq!(a.settings.colormap, state.colormap, "{at}");
    assert_eq!(a.settings.heat_range(), state.range, "{at}: the range");
    assert_eq!(a.settings.show_boxes.then_some(a.settings.box_depth), state.boxes, "{at}: the boxes");
    // A mesh without a camera of its own shows its default view (the orbit's home).
    if let Some(camera) = state.camera.or(a.scene.camera) {
        assert_eq!(a.orbit.camera(camera.width, camera.height), camera, "{at}: the camera");
    }
    let views = (a.compare.on, a.replay.window, !a.pins.pinned.is_empty(), a.nodes.window);
    match &state.show {
        Show::Image => assert_eq!(views, (false, false, false, false), "{at}: the image alone"),
        Show::Ray { pixel, step } => {
            assert_eq!(views, (false, false, true, false), "{at}: the Ray view alone");
            let r = a.pins.current().unwrap();
            assert_eq!(r.pixel, Some(*pixel), "{at}: the pixel (the film is the step's camera's size)");
            let last = r.len() - 1;
            assert_eq!(a.pins.step, step.map_or(last, |s| (s as usize).min(last)), "{at}: the step of the walk");
            assert!(Arc::ptr_eq(&r.bvh, &a.current_bvh().unwrap().bvh), "{at}: through this step's tree");
        }
        Show::Node(n) | Show::Tree(n) => {
            assert_eq!(views, (false, false, false, true), "{at}: the Tree and Node views");
            assert_eq!(a.nodes.selected, Some(*n), "{at}: the node");
        }
        Show::Compare { b, mode } => {
            assert_eq!(views, (true, false, false, false), "{at}: Compare");
            let b = b.apply(&build);
            assert_eq!(
                (a.compare.strategy, a.compare.layout, a.compare.max_leaf_size),
                (b.strategy, b.layout, b.max_leaf_size)
            );
            assert_eq!(a.compare.mode, *mode, "{at}");
        }
        Show::Replay { splits } => {
            assert_eq!(views, (false, true, false, false), "{at}: Replay");
            assert_eq!(a.replay.k, *splits as usize, "{at}: the splits");
        }
    }
}

/// The band says where the lesson is and what the step says.
fn assert_band(h: &Harness<'_, BvhscopeApp>, lesson: &Lesson, k: usize, revealed: bool) {
    let step = &lesson.steps[k];
    h.get_by_label(&format!("Step {} / {}", k + 1, lesson.steps.len()));
    h.get_by_label(&caption_text(&step.caption));
    if let Some(q) = &step.question {
        h.get_by_label(&format!("Question: {}", caption_text(q)));
    }
    if let Some(a) = &step.answer {
        let shown = h.query_by_label(&format!("Answer: {}", caption_text(a))).is_some();
        assert_eq!(shown, revealed, "step {}: the answer shown only once asked for", k + 1);
    }
}

/// (a) The shipped lesson, PageDown by PageDown: every step's view, build, explain view and its
/// target, and its caption; a question's answer on the extra key press.
#[test]
fn a_shipped_lesson_steps_through_with_the_clicker() {
    step_through(&shipped("why-sah-wins.json"));
}

/// The course's lab lesson too, where the lab's models are checked out beside the repository.
#[test]
fn the_course_lab_lesson_steps_through_with_the_clicker() {
    if !root().join("../shared/models/moer-lite-lab1-bvh").is_dir() {
        eprintln!("skipped: the lab's models (../shared/models/moer-lite-lab1-bvh) are not here");
        return;
    }
    step_through(&shipped("course-lab.json"));
}

/// Open `path` as File ▸ Open lesson… does and press PageDown through it, checking each step
/// against the file's own states (so the test follows the lesson's content).
fn step_through(path: &std::path::Path) {
    let lesson = read_lesson(path).unwrap();
    let states = lesson.states();
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::Picked(Pick::OpenLesson, path.to_path_buf()));
    for (k, state) in states.iter().enumerate() {
        if k > 0 {
            h.key_press(Key::PageDown);
        }
        step_to(&mut h, k);
        assert_shows(h.state(), state, k);
        assert_band(&h, &lesson, k, false);
        if lesson.steps[k].answer.is_some() {
            h.key_press(Key::PageDown);
            h.run_steps(2);
            assert_eq!(h.state().lesson.as_ref().unwrap().step, k, "the answer first, the same step");
            assert_band(&h, &lesson, k, true);
        }
    }
    // Past the last step: nothing more.
    h.key_press(Key::PageDown);
    h.run_steps(2);
    assert_eq!(h.state().lesson.as_ref().unwrap().step, states.len() - 1);
}

/// A lesson of three steps on the torus (absolute paths), the second with a question.
fn small_lesson() -> PathBuf {
    let torus = root().join("assets/torus.obj");
    let text = format!(
        r#"{{ "title": "Three steps", "steps": [
          {{ "caption": "The *torus*", "scene": "{t}" }},
          {{ "caption": "Its `midpoint` tree", "bvh": {{ "strategy": "midpoint" }}, "view": "visits",
             "question": "Where is it hot?", "answer": "Where rays graze it." }},
          {{ "caption": "The root", "show": {{ "node": 0 }} }} ] }}"#,
        t = torus.display()
    );
    temp_file("three-steps.json", &text)
}

/// (d) PageUp goes back; the question first, its answer on the next press; the arrows as the
/// page keys; Alt+arrows stay the Node view's, and a text field keeps its arrows.
#[test]
fn page_up_goes_back_and_the_answer_waits_for_its_key() {
    let path = small_lesson();
    let lesson = read_lesson(&path).unwrap();
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::OpenLessonFile(path));
    step_to(&mut h, 0);
    assert_band(&h, &lesson, 0, false);
    h.key_press(Key::ArrowRight);
    step_to(&mut h, 1);
    assert_band(&h, &lesson, 1, false);
    h.get_by_label("Next: the answer");
    h.key_press(Key::PageDown);
    h.run_steps(2);
    assert_band(&h, &lesson, 1, true);
    h.key_press(Key::PageUp);
    h.run_steps(2);
    assert_band(&h, &lesson, 1, false);
    assert_eq!(h.state().lesson.as_ref().unwrap().step, 1, "back hides the answer first");
    h.key_press(Key::ArrowLeft);
    step_to(&mut h, 0);
    assert_eq!(h.state().settings.view, View::Normals, "step 1's view again");
    for _ in 0..3 {
        h.key_press(Key::PageDown);
        h.run_steps(2);
    }
    step_to(&mut h, 2);
    assert_shows(h.state(), &lesson.states()[2], 2);
    // Alt+Left is the Node view's (the left child), not the lesson's.
    h.key_press_modifiers(egui::Modifiers::ALT, Key::ArrowLeft);
    h.run_steps(2);
    let l = h.state().lesson.as_ref().unwrap();
    assert_eq!(l.step, 2, "Alt+Left does not step the lesson");
    assert_ne!(h.state().nodes.selected, Some(0), "it selected the root's left child");
    // Back: the step before as the room last saw it, its answer shown.
    h.key_press(Key::PageUp);
    step_to(&mut h, 1);
    assert_band(&h, &lesson, 1, true);
    // A text field with the keyboard keeps its arrows.
    h.state_mut().act(Action::LessonEditing(true));
    h.run_steps(2);
    focus_label(&mut h, "Caption");
    h.key_press(Key::ArrowLeft);
    h.key_press(Key::PageUp);
    h.run_steps(2);
    assert_eq!(h.state().lesson.as_ref().unwrap().step, 1, "typing, the keys are the field's");
}

/// A lesson that cannot be read: one message naming the file, the step and the field; the scene
/// on screen stays.
#[test]
fn a_broken_lesson_says_where_and_keeps_the_scene() {
    let broken = temp_file(
        "broken-lesson.json",
        r#"{ "steps": [ { "caption": "x", "scene": "a.obj" }, { "caption": "y", "view": "sideways" } ] }"#,
    );
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    let triangles = h.state().scene.report.triangles;
    h.input_mut().dropped_files.push(Arc::new(Dropped(broken)));
    run_until(&mut h, "the error", |a| a.messages.iter().any(|m| m.kind == bvhscope::app::MessageKind::Error));
    h.get_by_label_contains("broken-lesson.json: steps[1].view");
    assert!(h.state().lesson.is_none());
    assert_eq!(h.state().scene.report.triangles, triangles, "the scene stays");
}

/// `bvhscope LESSON`: the app starts on the lesson's first step.
#[test]
fn a_lesson_named_at_start_opens_at_its_first_step() {
    let path = small_lesson();
    let options = AppOptions { file: Some(path.clone()), bvh: None };
    let mut h = Harness::builder()
        .with_size(egui::vec2(1400.0, 860.0))
        .build_eframe(move |cc| BvhscopeApp::new(cc, options.clone()));
    step_to(&mut h, 0);
    assert_shows(h.state(), &read_lesson(&path).unwrap().states()[0], 0);
}

/// (b) A lesson recorded in the app: three steps added with their captions typed, one replaced,
/// saved, opened again: the same steps and states, and stepping through it shows them.
#[test]
fn a_lesson_recorded_in_the_app_reopens_as_the_same_steps() {
    let mut h = harness();
    open(&mut h, &root().join("scenes/knot-on-floor.json"));
    h.state_mut().act(Action::NewLesson);
    h.run_steps(2);
    let text = |h: &mut Harness<'_, BvhscopeApp>, caption: &str, question: &str, answer: &str| {
        let title = "Recorded".to_string();
        let (caption, question, answer) = (caption.to_string(), question.to_string(), answer.to_string());
        h.state_mut().act(Action::LessonText { title, caption, question, answer });
        h.run_steps(2);
    };
    // Step 1: the scene as it opens, its caption typed in the band.
    h.state_mut().act(Action::AddStep);
    h.run_steps(2);
    focus_label(&mut h, "Caption");
    h.get_by_label("Caption").type_text("The knot on the *floor*");
    h.run_steps(2);
    assert_eq!(h.state().lesson.as_ref().unwrap().lesson.steps[0].caption, "The knot on the *floor*");
    // Step 2: SAH, nodes visited, boxes at depth 2.
    with_strategy(&mut h, bvhscope::bvh::Strategy::SahBinned);
    h.state_mut().act(Action::View(2));
    h.state_mut().act(Action::ToggleBoxes);
    run_until(&mut h, "SAH's heatmap", idle);
    h.state_mut().act(Action::AddStep);
    text(&mut h, "SAH's `visits`", "Why cooler?", "The floor is split off.");
    // Step 3: the Tree and Node views on node 1.
    h.state_mut().act(Action::ShowTree(true));
    run_until(&mut h, "the tree", |a| a.nodes.explained.is_some() && idle(a));
    h.state_mut().act(Action::SelectNode(1));
    h.run_steps(2);
    h.state_mut().act(Action::AddStep);
    text(&mut h, "Node 1", "", "");
    // Step 2 again (the fields put away: while one has the keyboard, the keys are its own), now
    // with the next colour map: replaced, its text kept.
    h.state_mut().act(Action::LessonEditing(false));
    h.run_steps(2);
    h.key_press(Key::PageUp);
    step_to(&mut h, 1);
    h.state_mut().act(Action::NextColormap);
    h.run_steps(2);
    h.state_mut().act(Action::ReplaceStep);
    h.run_steps(2);
    let recorded = h.state().lesson.as_ref().unwrap().lesson.clone();
    assert_eq!(recorded.steps.len(), 3);
    assert_eq!(recorded.steps[1].caption, "SAH's `visits`", "replaced, the text kept");
    assert_eq!(recorded.steps[1].answer.as_deref(), Some("The floor is split off."));
    let states = recorded.states();
    assert_eq!(states[1].view, View::Visits);
    assert_eq!(states[1].colormap, bvhscope::render::ColorMap::ALL[1]);
    assert_eq!(states[1].boxes, Some(3));
    assert_eq!(states[2].show, Show::Node(1));
    // The step after the one replaced shows what it showed before: it names its colour map now.
    assert_eq!(states[2].colormap, bvhscope::render::ColorMap::ALL[0], "step 3 as recorded");
    assert_eq!(recorded.steps[2].colormap, Some(bvhscope::render::ColorMap::ALL[0]));
    // Only what changed: step 3 names no view, no build.
    assert!(recorded.steps[2].view.is_none() && recorded.steps[2].bvh.is_empty(), "{:?}", recorded.steps[2]);
    assert!(recorded.steps[1].scene.is_none());
    // Saved, opened again.
    let file = temp_file("recorded-lesson.json", "");
    h.state_mut().act(Action::Picked(Pick::SaveLesson, file.clone()));
    h.run_steps(2);
    h.get_by_label_contains("Saved");
    let again = read_lesson(&file).unwrap();
    assert_eq!(again.states(), states, "{}", std::fs::read_to_string(&file).unwrap());
    assert_eq!(states[0].scene, root().join("scenes/knot-on-floor.json").canonicalize().unwrap(), "named plainly");
    let texts = |l: &Lesson| {
        l.steps.iter().map(|s| (s.caption.clone(), s.question.clone(), s.answer.clone())).collect::<Vec<_>>()
    };
    assert_eq!(texts(&again), texts(&recorded));
    h.state_mut().act(Action::CloseLesson);
    h.state_mut().act(Action::OpenLessonFile(file));
    for (k, state) in states.iter().enumerate() {
        if k > 0 {
            h.key_press(Key::PageDown);
            if again.steps[k - 1].answer.is_some() {
                h.key_press(Key::PageDown);
            }
        }
        step_to(&mut h, k);
        assert_shows(h.state(), state, k);
    }
}

/// A harness at 1280×720, the projector's size.
fn projector() -> Harness<'static, BvhscopeApp> {
    Harness::builder()
        .with_size(egui::vec2(1280.0, 720.0))
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()))
}

/// (c) The band never covers the image: at 1280×720, presenting (F5) and not, its words lie
/// below the image and inside the window.
#[test]
fn the_caption_band_is_below_the_image_at_1280_by_720() {
    let path = shipped("why-sah-wins.json");
    let lesson = read_lesson(&path).unwrap();
    let mut h = projector();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::OpenLessonFile(path));
    // The step with a question, its answer shown: the band's fullest.
    let k = lesson.steps.iter().position(|s| s.answer.is_some()).unwrap();
    for _ in 0..k {
        h.key_press(Key::PageDown);
        h.run_steps(2);
    }
    step_to(&mut h, k);
    h.key_press(Key::PageDown);
    h.run_steps(2);
    for presenting in [false, true] {
        h.state_mut().act(Action::Present(presenting));
        run_until(&mut h, "the frame", |a| on_step(a, k));
        let image = h.state().image_rect;
        let window = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 720.0) / h.state().settings.zoom());
        let step = &lesson.steps[k];
        let texts = [
            format!("Step {} / {}", k + 1, lesson.steps.len()),
            caption_text(&step.caption),
            format!("Question: {}", caption_text(step.question.as_ref().unwrap())),
            format!("Answer: {}", caption_text(step.answer.as_ref().unwrap())),
        ];
        let mut band = egui::Rect::NOTHING;
        for t in &texts {
            let r = h.get_by_label(t).rect();
            assert!(r.top() >= image.bottom() - 0.5, "presenting {presenting}: {t:?} at {r:?}, the image at {image:?}");
            assert!(window.contains_rect(r.shrink(0.5)), "presenting {presenting}: {t:?} at {r:?} in {window:?}");
            band = band.union(r);
        }
        eprintln!("presenting {presenting}: image {image:?}, the band's words {band:?}, window {window:?}");
        // A lesson presented is slides: the Build and view panel is the teacher's, hidden while
        // presenting (the image takes its room) and back afterwards.
        assert_eq!(h.query_by_label("Handout mode").is_some(), !presenting, "presenting {presenting}: the Build panel");
        assert!(
            band.height() < window.height() / 3.0,
            "presenting {presenting}: the band's words {band:?} take over a third"
        );
    }
}

/// Stepping back to a tree built before shows it at once: kept by its options, not rebuilt.
#[test]
fn a_step_back_to_a_tree_built_before_does_not_rebuild() {
    let path = small_lesson();
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::OpenLessonFile(path));
    step_to(&mut h, 0);
    let first = h.state().current_bvh().unwrap().bvh.clone();
    h.key_press(Key::PageDown);
    step_to(&mut h, 1);
    h.key_press(Key::PageUp);
    h.step();
    h.step();
    assert!(h.state().jobs.build.is_none(), "no build for a tree kept");
    assert!(Arc::ptr_eq(&h.state().current_bvh().unwrap().bvh, &first), "the same tree, at once");
    step_to(&mut h, 0);
}

/// The picture of a lesson presented: a step of `lessons/why-sah-wins.json` at 1280×720,
/// presenting (F5), for the README (`BVHSCOPE_LOOK=DIR`, as the other `look_` tests).
#[test]
#[ignore]
fn look_lesson_present() {
    let path = shipped("why-sah-wins.json");
    let lesson = read_lesson(&path).unwrap();
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 720.0))
        .wgpu()
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()));
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::Present(true));
    h.state_mut().act(Action::OpenLessonFile(path));
    let k = lesson.steps.iter().position(|s| s.answer.is_some()).unwrap();
    for _ in 0..k {
        h.key_press(Key::PageDown);
        h.run_steps(2);
    }
    step_to(&mut h, k);
    h.key_press(Key::PageDown);
    for _ in 0..6 {
        h.step();
    }
    let img = h.render().expect("a wgpu adapter (Mesa's lavapipe)");
    let dir =
        PathBuf::from(std::env::var("BVHSCOPE_LOOK").unwrap_or_else(|_| std::env::temp_dir().display().to_string()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("lesson-present.png");
    img.save(&out).unwrap();
    eprintln!("wrote {}", out.display());
}
