//! Every figure the app shows is the command line's (issue 35): the build time is the build's
//! alone, the per-ray figures are of the scene's film, B's EPO is shown, a threshold or a node
//! selection never outlives the scale or the tree it was made for, and messages never hide a window.

use super::support::*;
use bvhscope::app::{Action, BvhscopeApp, Film, MessageKind};
use bvhscope::bvh::Strategy;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use std::path::PathBuf;

/// A scene's film: the image is its camera's 1200×800, letterboxed, traced with its camera as
/// written; the statistics panel's per-ray figures are then `bvhscope stats SCENE`'s, exactly.
/// With the viewport's film the frame is the viewport's, and the figures differ.
#[test]
fn the_scenes_film_gives_the_command_lines_figures() {
    let mut h = harness();
    let scene = root().join("scenes/monkey.json");
    open(&mut h, &scene);
    let shown = h.state().shown.as_ref().unwrap().camera;
    assert_eq!((shown.width, shown.height), (1200, 800), "the scene's film");
    assert_eq!(Some(shown), h.state().scene.camera, "its camera as written");
    let rays = h.state().rays.unwrap().summary;
    let args = words(&[s("stats"), s(scene.display()), s("--format"), s("json")]);
    let bvhscope::cli::Command::Stats(a) = args else { panic!("stats") };
    let v: serde_json::Value = serde_json::from_str(&bvhscope::cli::stats::output(&a).unwrap()).unwrap();
    let cli = &v["rays"]["summary"];
    assert_eq!(cli["rays"], rays.rays);
    assert_eq!(cli["root_rays"], rays.root_rays);
    assert_eq!(cli["mean_nodes_visited"].as_f64().unwrap(), rays.mean_nodes_visited);
    assert_eq!(cli["mean_triangle_tests"].as_f64().unwrap(), rays.mean_triangle_tests);
    h.get_by_label_contains("film 1200×800");
    // The viewport's own film: another frame, other figures.
    let mut settings = h.state().settings.clone();
    settings.film = Film::Viewport;
    h.state_mut().act(Action::Edit(Box::new(settings)));
    run_until(&mut h, "the viewport's frame", |a| idle(a) && a.shown.as_ref().unwrap().camera.width != 1200);
    assert_ne!(h.state().rays.unwrap().summary.rays, rays.rays);
}

/// B of the side-by-side view has its EPO in the statistics, as A has.
#[test]
fn bs_epo_is_shown() {
    let mut h = harness();
    open(&mut h, &root().join("assets/torus.obj"));
    h.state_mut().act(Action::Compare(true));
    run_until(&mut h, "B", |a| pair_shown(a) && a.jobs.compare.is_none());
    let b = h.state().compare_figures().unwrap();
    let epo = b.stats.epo.expect("B's EPO");
    let tree = h.state().compare.b.as_ref().unwrap().bvh.binary_tree().unwrap();
    assert_eq!(epo, bvhscope::bvh::epo::of(&tree));
}

/// A threshold is of the scale it was set on: another view clears it, and so does a scale that no
/// longer holds it. A node selected in one tree is cleared when another tree or mesh comes.
#[test]
fn a_threshold_and_a_selection_never_outlive_their_scale_or_tree() {
    let mut h = harness();
    open(&mut h, &root().join("assets/torus.obj"));
    h.state_mut().act(Action::View(4));
    run_until(&mut h, "the cost heatmap", |a| idle(a) && a.shown.as_ref().unwrap().legend.is_some());
    let top = h.state().shown.as_ref().unwrap().legend.as_ref().unwrap().range_max;
    h.state_mut().act(Action::SetThreshold(Some(top * 0.9)));
    h.step();
    // A fixed range of 0..1 no longer holds it.
    let mut settings = h.state().settings.clone();
    settings.fixed_ranges.insert(bvhscope::render::View::Cost, (0.0, 1.0));
    h.state_mut().act(Action::Edit(Box::new(settings)));
    run_until(&mut h, "the 0..1 scale", |a| {
        idle(a) && a.shown.as_ref().unwrap().legend.as_ref().unwrap().range_max == 1.0
    });
    assert_eq!(h.state().threshold, None);
    assert!(h.query_by_label_contains("Pixels above").is_none());

    h.state_mut().act(Action::SelectNode(2));
    run_until(&mut h, "the selection", |a| a.nodes.selected == Some(2));
    with_strategy(&mut h, Strategy::EqualCount);
    run_until(&mut h, "the equal-count tree", |a| {
        a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == Strategy::EqualCount) && idle(a)
    });
    assert_eq!(h.state().nodes.selected, None, "another tree: its node 2 is another node");
    h.state_mut().act(Action::SelectNode(1));
    run_until(&mut h, "the selection", |a| a.nodes.selected == Some(1));
    open(&mut h, &root().join("scenes/monkey.json"));
    assert_eq!(h.state().nodes.selected, None, "another mesh");
}

/// Messages: the newest is shown on the status bar, the older fold behind one button that lists
/// them and dismisses them.
#[test]
fn messages_are_few() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().messages.clear();
    for i in 0..6 {
        h.state_mut().message(MessageKind::Info, format!("message number {i}"));
    }
    h.step();
    h.step();
    assert!(h.query_by_label_contains("message number 2").is_none(), "folded");
    h.get_by_label_contains("message number 5");
    h.get_by_label("5 earlier").click();
    h.step();
    h.step();
    h.get_by_label_contains("message number 2");
    h.get_by_label("Dismiss them").click();
    h.step();
    h.step();
    assert_eq!(h.state().messages.len(), 1);
    h.get_by_label_contains("message number 5");
}

/// "Hottest pixel" pins the ray with the most work of the heatmap on screen, "Next" the next one:
/// the pixels `bvhscope trace --hottest 1` and `--hottest 2` trace on the same camera.
#[test]
fn the_hottest_pixels_are_the_command_lines() {
    let mut h = harness();
    let torus = root().join("assets/torus.obj");
    open(&mut h, &torus);
    h.state_mut().act(Action::View(2));
    run_until(&mut h, "the visits heatmap", |a| idle(a) && a.shown.as_ref().unwrap().legend.is_some());
    let camera = h.state().shown.as_ref().unwrap().camera;
    h.get_by_label("Hottest pixel").click();
    h.step();
    let pinned = |h: &Harness<'_, BvhscopeApp>| h.state().pins.current().and_then(|r| r.pixel);
    let first = pinned(&h).expect("a pinned pixel");
    h.get_by_label("Next").click();
    h.step();
    let second = pinned(&h).unwrap();
    assert_ne!(first, second);
    for (k, want) in [(1, first), (2, second)] {
        let mut args = vec![s("trace"), s(torus.display()), s("--hottest"), s(k), s("--format"), s("json")];
        args.extend(camera_words(&camera));
        let bvhscope::cli::Command::Trace(a) = words(&args) else { panic!("trace") };
        let v: serde_json::Value = serde_json::from_str(&bvhscope::cli::trace::output(&a).unwrap()).unwrap();
        let p = &v["ray"]["from"]["pixel"];
        assert_eq!((p[0].as_u64().unwrap() as u32, p[1].as_u64().unwrap() as u32), want, "--hottest {k}");
    }
}

/// The statistics panel times the BVH against the linear scan on demand, single rays on one
/// thread, with a progress bar; the result is of the frame on screen.
#[test]
fn the_speedup_over_linear_search_is_timed_on_demand() {
    let mut h = harness();
    open(&mut h, &root().join("assets/torus.obj"));
    h.get_by_label("Time against the linear scan").click();
    h.step();
    assert!(h.state().jobs.speedup.is_some(), "timing");
    run_until(&mut h, "the speed-up", |a| a.speedup.is_some() && a.jobs.speedup.is_none());
    let t = h.state().speedup.as_ref().unwrap();
    let shown = h.state().shown.as_ref().unwrap();
    assert_eq!(t.speedup.rays, (shown.camera.width * shown.camera.height) as usize);
    assert!(t.speedup.speedup > 1.0, "{:?}", t.speedup);
    h.get_by_label_contains("× faster: this BVH");
}

/// A chain of `n` stacked triangles and a correct chain-shaped dump (depth n - 1), in files;
/// triangle 7 twice in its leaf: the Tree window says so.
fn chain(n: u32, name: &str) -> (PathBuf, PathBuf) {
    let (o, d) = crate::common::chain_texts(n, Some(7));
    (temp_file(&format!("{name}.obj"), &o), temp_file(&format!("{name}.json"), &d))
}

/// A deep walk in the Ray window: its steps' indent is capped (the depth written out past it),
/// a line keeps the step without its stack, and the step chosen is shown whole above the list.
/// The Tree window names a triangle referenced twice in one leaf, not as a spatial split.
#[test]
fn a_deep_walk_is_readable_and_a_duplicate_is_named() {
    let (obj, dump) = chain(120, "deep-chain");
    let mut h = harness();
    open(&mut h, &obj);
    h.state_mut().act(Action::ImportFile(dump));
    run_until(&mut h, "the chain imported", |a| a.import.shown(a.scene_id).is_some() && idle(a));
    // A typed ray down the stack: through every level to the top triangle.
    h.state_mut().pins.origin_text = "0.25,0.25,130".into();
    h.state_mut().pins.dir_text = "0,0,-1".into();
    h.state_mut().act(Action::PinTyped);
    h.step();
    let steps = h.state().pins.current().unwrap().named.clone();
    let deep = steps.iter().position(|s| matches!(s.kind, bvhscope::bvh::StepKind::Enter { depth: 100, .. })).unwrap();
    h.state_mut().act(Action::RayStep(deep));
    // The list scrolls to the step chosen.
    for _ in 0..6 {
        h.step();
    }
    let whole = format!("Step {}: {}", deep + 1, steps[deep].brief());
    h.get_by_label(&whole);
    h.get_by_label_contains("[depth 100] enter");
    assert!(h.query_by_label_contains(&" ".repeat(40)).is_none(), "no line is indented past the cap");
    // The Tree window.
    h.state_mut().act(Action::ShowTree(true));
    run_until(&mut h, "the tree view", |a| a.nodes.explained.is_some());
    // The window's figures come from a job: step until they are drawn (a loaded machine is slow).
    let warning = "Warning: triangle 7 is referenced twice (leaf 126)";
    let start = std::time::Instant::now();
    while h.query_all_by_label_contains(warning).count() == 0 && start.elapsed() < std::time::Duration::from_secs(60) {
        h.step();
    }
    assert!(h.query_all_by_label_contains(warning).count() >= 1, "the Tree window names the duplicate");
    assert!(h.query_by_label_contains("spatial splits cut").is_none());
}

/// The Node window gives this tree's split term by term (the terms `inspect` prints), and draws
/// the three axes on one cost scale when asked.
#[test]
fn the_node_window_gives_the_split_cost_term_by_term() {
    let mut h = harness();
    open(&mut h, &root().join("assets/torus.obj"));
    h.state_mut().act(Action::ShowTree(true));
    h.state_mut().act(Action::SelectNode(0));
    run_until(&mut h, "the root's inspection", |a| a.nodes.inspection.as_ref().is_some_and(|i| i.node == 0));
    h.run_steps(3);
    let ins = h.state().nodes.inspection.clone().unwrap();
    let own = h.state().settings.build.strategy;
    let m = ins.markers.iter().find(|(s, _)| *s == own).and_then(|(_, m)| *m).expect("this tree's split");
    let terms = m.terms(ins.sah).text();
    assert!(h.query_all_by_label_contains(&format!("(this tree's split): {terms}")).count() >= 1, "{terms}");
    click_label(&mut h, "One cost scale for the three axes");
    h.step();
    assert!(h.state().nodes.shared_scale);
}
