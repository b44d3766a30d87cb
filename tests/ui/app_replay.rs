//! The build replay and two strategies side by side, driven as a user drives them. A module of
//! the `app_ui` test binary (`app.rs`).

use super::*;

/// The Replay window traces the tree after k splits: at 0 every ray that enters the root box
/// tests every triangle; at the last split every pixel's counts are the finished binary tree's;
/// Play moves on; closing the window brings back the full tree, and the strategy's per-ray figures
/// are never those of a partial tree.
#[test]
fn the_build_replay_traces_the_partial_tree() {
    use bvhscope::bvh::{Accelerator, RayCounters};
    // A small mesh: at step 0 every ray tests every triangle.
    let torus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/torus.obj");
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::Open, torus.clone()));
    run_until(&mut h, "the torus and its tree", |a| {
        a.scene.source == SceneSource::File(torus.clone())
            && idle(a)
            && a.nodes.current(a.current_bvh().map(|b| &b.bvh)).is_some()
    });
    let rays_before = h.state().rays.map(|r| r.summary.mean_nodes_visited);
    h.get_by_role_and_label(Role::Button, "View").click();
    h.run_steps(2);
    h.get_by_label("Replay the build…").click();
    let step_done = |k: usize| {
        move |a: &BvhscopeApp| {
            idle(a)
                && a.shown
                    .as_ref()
                    .is_some_and(|s| s.partial.as_ref().is_some_and(|p| p.splits == k) && s.frame.is_complete())
        }
    };
    run_until(&mut h, "the replay", |a| a.replay.replay.is_some());
    h.get_by_label("First").click();
    run_until(&mut h, "the root alone", step_done(0));
    let n_tris = h.state().scene.report.triangles as u32;
    {
        let f = &h.state().shown.as_ref().unwrap().frame;
        let entered: Vec<RayCounters> = (0..f.height())
            .flat_map(|y| (0..f.width()).map(move |x| (x, y)))
            .map(|(x, y)| f.counters(x, y))
            .filter(|c| c.leaves_visited > 0)
            .collect();
        assert!(!entered.is_empty());
        assert!(
            entered.iter().all(|c| c.triangle_tests == n_tris && c.nodes_visited == 1),
            "one leaf of every triangle"
        );
    }
    h.get_by_label("Step").click();
    run_until(&mut h, "one split", step_done(1));
    h.get_by_label("Last").click();
    let n = h.state().replay.replay.as_ref().unwrap().splits();
    run_until(&mut h, "the finished tree", step_done(n));
    {
        let app = h.state();
        let s = app.shown.as_ref().unwrap();
        let tree = &app.nodes.explained.as_ref().unwrap().tree;
        let rays = s.camera.ray_gen();
        for (x, y) in
            (0..s.frame.height()).step_by(7).flat_map(|y| (0..s.frame.width()).step_by(5).map(move |x| (x, y)))
        {
            let mut c = RayCounters::default();
            tree.closest_hit(&mut rays.pixel_ray(x, y), s.trace, &mut c);
            assert_eq!(s.frame.counters(x, y), c, "pixel {x},{y}: the finished binary tree's counts");
        }
    }
    // The newest split's plane is the tree's own strategy's (the inspector's marker).
    {
        let app = h.state();
        let r = app.replay.replay.as_ref().unwrap();
        let newest = r.order[n - 1];
        let (node, marker, _) = app.replay.newest.as_ref().expect("the newest split");
        assert_eq!(*node, newest);
        let e = app.nodes.explained.as_ref().unwrap();
        let ins = bvhscope::explain::inspect::inspect(&e.tree, &e.hierarchy, newest).unwrap();
        let own = e.tree.params.strategy;
        assert_eq!(*marker, ins.markers.iter().find(|(s, _)| *s == own).unwrap().1);
    }
    h.get_by_label_contains("Newest split: node");
    h.get_by_label("Play").click();
    h.run_steps(2);
    run_until(&mut h, "a step of playing", |a| a.replay.k > 0 && a.replay.k < n);
    h.get_by_label("Pause").click();
    h.run_steps(2);
    assert!(!h.state().replay.playing);
    h.state_mut().act(Action::ShowReplay(false));
    run_until(&mut h, "the full tree again", |a| idle(a) && a.shown.as_ref().is_some_and(|s| s.partial.is_none()));
    assert_eq!(
        h.state().rays.map(|r| r.summary.mean_nodes_visited),
        rays_before,
        "the strategy's figures stay its own"
    );
}

/// Side by side: B (another strategy) is built and traced on A's camera; the difference view is,
/// pixel by pixel, B's counts minus A's; the modes switch and the wipe line drags; with B's
/// strategy the same as A's the difference is zero everywhere; changing A rebuilds only A.
#[test]
fn two_strategies_side_by_side_and_their_difference() {
    let mut h = midpoint_against_sah();
    let ctx = h.ctx.clone();
    let b_bvh = {
        let app = h.state();
        let images = app.compare_images(&ctx).expect("both frames");
        let (a, b) = (&app.shown.as_ref().unwrap().frame, &app.compare.b.as_ref().unwrap().frame);
        let d = &images.diff.as_ref().expect("a heatmap has a difference").1;
        let mut differ = 0;
        for y in 0..a.height() {
            for x in 0..a.width() {
                let want = b.counters(x, y).nodes_visited as f32 - a.counters(x, y).nodes_visited as f32;
                assert_eq!(d[(y * a.width() + x) as usize], want);
                differ += (want != 0.0) as usize;
            }
        }
        assert!(differ > 0, "midpoint and SAH differ somewhere");
        let legend = images.legend.as_ref().unwrap();
        assert_eq!(
            legend.range_max as u32,
            a.ray_summary().max_nodes_visited.max(b.ray_summary().max_nodes_visited),
            "one scale"
        );
        app.compare.b.as_ref().unwrap().bvh.clone()
    };
    assert!(h.query_all_by_label("Nodes visited / ray").count() >= 2, "the Compare window's row beside the panel's");
    assert_eq!(h.query_all_by_label("B - A").count(), 2, "the Compare window's and the statistics panel's columns");
    assert!(h.query_all_by_label_contains("B: SAH binned").count() >= 1, "B in the statistics panel");

    // Modes: the wipe line drags; the difference mode.
    h.get_by_label("Wipe").click();
    h.run_steps(2);
    assert_eq!(h.state().compare.mode, bvhscope::render::PairView::Wipe);
    let line = h.get_by_label("Wipe line").rect();
    let (from, to) = (line.center(), line.center() - egui::vec2(120.0, 0.0));
    h.input_mut().events.push(egui::Event::PointerMoved(from));
    h.input_mut().events.push(egui::Event::PointerButton {
        pos: from,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: egui::Modifiers::NONE,
    });
    h.step();
    for k in 1..=6 {
        h.input_mut().events.push(egui::Event::PointerMoved(from + (to - from) * (k as f32 / 6.0)));
        h.step();
    }
    h.input_mut().events.push(egui::Event::PointerButton {
        pos: to,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: egui::Modifiers::NONE,
    });
    h.run_steps(2);
    assert!(h.state().compare.wipe < 0.45, "dragged left: {}", h.state().compare.wipe);
    h.get_by_label("Difference B - A").click();
    h.run_steps(2);
    assert_eq!(h.state().compare.mode, bvhscope::render::PairView::Difference);

    // A changes: only A is rebuilt, B is kept.
    let mut s = h.state().settings.clone();
    s.build.strategy = Strategy::EqualCount;
    h.state_mut().act(Action::Edit(Box::new(s)));
    run_until(&mut h, "equal count as A", |a| {
        idle(a)
            && a.jobs.compare.is_none()
            && a.shown.as_ref().is_some_and(|s| s.bvh.build_params().bvh.strategy == Strategy::EqualCount)
    });
    assert!(Arc::ptr_eq(&h.state().compare.b.as_ref().unwrap().bvh, &b_bvh), "B was not rebuilt");

    // B the same as A: no difference anywhere.
    h.state_mut().act(Action::CompareStrategy(Strategy::EqualCount));
    run_until(&mut h, "B as equal count", |a| {
        idle(a)
            && a.jobs.compare.is_none()
            && a.compare.b.as_ref().is_some_and(|b| b.build.bvh.strategy == Strategy::EqualCount)
    });
    {
        let app = h.state();
        let images = app.compare_images(&ctx).unwrap();
        assert!(images.diff.as_ref().unwrap().1.iter().all(|&v| v == 0.0), "two identical builds differ nowhere");
    }
    // B's own leaf size, layout and order: B is rebuilt with them, A stays.
    let trace =
        bvhscope::bvh::TraceOptions { order: bvhscope::bvh::TraversalOrder::SplitAxisSign, ..h.state().compare.trace };
    h.state_mut().act(Action::CompareB { max_leaf_size: 2, layout: bvhscope::bvh::Layout::Binary, trace });
    run_until(&mut h, "B with leaves of 2, binary", |a| {
        idle(a) && a.jobs.compare.is_none() && a.compare.b.as_ref().is_some_and(|b| b.build.bvh.max_leaf_size == 2)
    });
    let app = h.state();
    let b = app.compare.b.as_ref().unwrap();
    assert_eq!(
        (b.build.bvh.layout, b.trace.order),
        (bvhscope::bvh::Layout::Binary, bvhscope::bvh::TraversalOrder::SplitAxisSign)
    );
    assert_eq!(app.settings.build.max_leaf_size, 4, "A keeps its own");
    assert!(app.compare_images(&ctx).is_some());
}

/// The Replay window's "Export animation…" writes what `bvhscope replay -o` writes: a real GIF
/// for a .gif name (24 frames, or one per step of a smaller tree), in the background with its
/// progress; any other name is refused before anything is traced, and nothing is written.
#[test]
fn the_replay_window_exports_the_animation() {
    let torus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/torus.obj");
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::Open, torus.clone()));
    run_until(&mut h, "the torus", |a| a.scene.source == SceneSource::File(torus.clone()) && idle(a));
    h.state_mut().act(Action::ShowReplay(true));
    run_until(&mut h, "the replay", |a| a.replay.replay.is_some() && idle(a));
    h.get_by_label("Export animation…");
    let dir = crate::support::scratch::shared("ui-film");
    let wrong = dir.join("replay.txt");
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::SaveAnimation, wrong.clone()));
    run_until(&mut h, "the refusal", |a| a.messages.iter().any(|m| m.kind == MessageKind::Error));
    assert!(h.state().messages.iter().any(|m| m.text.contains(".gif")), "the message names what is allowed");
    assert!(!wrong.exists() && h.state().jobs.film.is_none(), "nothing traced, nothing written");

    let gif = dir.join("replay.gif");
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::SaveAnimation, gif.clone()));
    assert!(h.state().jobs.film.is_some(), "written in the background");
    run_until(&mut h, "the animation", |a| a.jobs.film.is_none());
    let splits = h.state().replay.replay.as_ref().unwrap().splits();
    let frames = bvhscope::explain::replay_film::steps(splits, 24).len();
    let saved = format!("Saved {} ({frames} frames", gif.display());
    assert!(
        h.state().messages.iter().any(|m| m.kind == MessageKind::Info && m.text.starts_with(&saved)),
        "{:?}",
        h.state().messages.iter().map(|m| &m.text).collect::<Vec<_>>()
    );
    let bytes = std::fs::read(&gif).unwrap();
    assert_eq!(&bytes[..6], b"GIF89a", "a GIF, not a PNG under a .gif name");
    let mut d = gif::DecodeOptions::new().read_info(&bytes[..]).unwrap();
    let mut n = 0;
    while d.read_next_frame().unwrap().is_some() {
        n += 1;
    }
    assert_eq!(n, frames, "one frame per step");
    std::fs::remove_dir_all(&dir).ok();
}
