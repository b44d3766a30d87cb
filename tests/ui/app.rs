//! The desktop app driven through egui_kittest, without a display: what a user sees and does.
//! Built by the `ui-tests` package (see its Cargo.toml); snapshots live in `tests/snapshots/`.

#[path = "../common/mod.rs"]
mod common;
mod support;
use support::*;

use bvhscope::app::{Action, AppOptions, BvhscopeApp, MessageKind, SceneSource};
use bvhscope::bvh::SplitStrategy;
use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

#[test]
fn starts_on_the_builtin_scene_and_shows_its_triangle_count() {
    let mut h = harness();
    run_until(&mut h, "the first full frame", idle);
    assert_eq!(h.state().scene.source, SceneSource::Builtin);
    let triangles = h.state().scene.report.triangles;
    assert!(triangles > 20_000);
    h.get_by_label("Triangles");
    h.get_by_label(&triangles.to_string());
    h.get_by_label_contains("full resolution");
}

#[test]
fn choosing_another_strategy_rebuilds_and_changes_the_node_count() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    let before = h.state().current_bvh().unwrap().stats.nodes;
    h.get_by_label(&before.to_string());

    h.get_by_role_and_label(Role::ComboBox, "Split strategy").click();
    h.run_steps(3);
    h.get_by_label("Midpoint").click();
    run_until(&mut h, "the midpoint build", |a| {
        a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == SplitStrategy::Midpoint) && idle(a)
    });
    let after = h.state().current_bvh().unwrap().stats.nodes;
    assert_ne!(before, after, "midpoint and SAH trees differ in size here");
    h.get_by_label(&after.to_string());
    // The previous strategy's figures stay next to the new ones.
    h.get_by_label("before: SAH binned, wide4");
    h.get_by_label(&before.to_string());
}

#[test]
fn switching_back_before_a_build_finishes_cancels_it() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    let sah_nodes = h.state().current_bvh().unwrap().stats.nodes;
    // Choose midpoint, then SAH again before the midpoint build can finish (it takes
    // milliseconds; these two requests are microseconds apart).
    let choose = |h: &mut Harness<'_, BvhscopeApp>, strategy| {
        let mut s = h.state().settings.clone();
        s.build.strategy = strategy;
        h.state_mut().act(Action::Edit(Box::new(s)));
        h.state_mut().reconcile();
    };
    choose(&mut h, SplitStrategy::Midpoint);
    assert!(h.state().jobs.build.is_some(), "the midpoint build runs");
    choose(&mut h, SplitStrategy::SahBinned);
    assert!(h.state().jobs.build.is_none(), "the midpoint build is cancelled");
    run_until(&mut h, "quiet", idle);
    for _ in 0..20 {
        h.step();
        std::thread::sleep(Duration::from_millis(5));
    }
    let b = h.state().current_bvh().unwrap();
    assert_eq!(b.bvh.build_params().bvh.strategy, SplitStrategy::SahBinned);
    assert_eq!(b.stats.nodes, sah_nodes);
    assert!(h.state().previous.is_none(), "no strategy the user did not keep appears as 'before'");
}

/// Panels only emit actions; the reconciler alone decides from the state what work follows: a
/// new view re-renders the BVH there is, a new strategy rebuilds, the same settings do nothing.
#[test]
fn the_reconciler_re_renders_for_a_view_and_rebuilds_for_a_strategy() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    let edit = |h: &mut Harness<'_, BvhscopeApp>, change: &dyn Fn(&mut bvhscope::app::Settings)| {
        let mut s = h.state().settings.clone();
        change(&mut s);
        h.state_mut().act(Action::Edit(Box::new(s)));
        h.state_mut().reconcile();
    };
    edit(&mut h, &|_| {});
    assert!(!h.state().jobs.is_busy(), "unchanged settings start nothing");
    edit(&mut h, &|s| s.view = bvhscope::render::View::Visits);
    assert!(h.state().jobs.build.is_none() && h.state().jobs.render.is_some(), "a view re-renders only");
    run_until(&mut h, "the heatmap", idle);
    edit(&mut h, &|s| s.build.strategy = SplitStrategy::Midpoint);
    assert!(h.state().jobs.build.is_some(), "a strategy rebuilds");
}

#[test]
fn moving_the_depth_slider_changes_the_number_of_boxes_drawn() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    assert_eq!(h.state().settings.box_depth, 3, "the default depth survives the first frames, built or not");
    h.get_by_label("Show node boxes").click();
    h.get_by_role_and_label(Role::Slider, "Box depth").set_value_accesskit(0.0);
    h.step();
    h.step();
    h.get_by_label("1 boxes drawn"); // depth 0: the root
    h.get_by_role_and_label(Role::Slider, "Box depth").set_value_accesskit(6.0);
    h.step();
    h.step();
    assert_eq!(h.state().settings.box_depth, 6);
    let drawn = h.state().boxes_drawn();
    // The default layout is 4-wide: depth 6 holds at most 4^6 nodes.
    assert!(drawn > 64 && drawn <= 4096, "depth 6 of a 4-wide tree, drew {drawn}");
    h.get_by_label(&format!("{drawn} boxes drawn"));
    // The ] key goes one level deeper.
    h.key_press(egui::Key::CloseBracket);
    h.step();
    h.step();
    assert_eq!(h.state().settings.box_depth, 7);
    assert!(h.state().boxes_drawn() > drawn);
}

#[test]
fn switching_to_a_heatmap_view_shows_the_legend() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    assert!(h.query_by_label_contains("Legend:").is_none(), "no legend on the normals view");
    h.get_by_label("Nodes visited").click();
    run_until(&mut h, "the heatmap frame", |a| idle(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some()));
    h.get_by_label_contains("Legend: nodes visited per ray");
    let legend = h.state().shown.as_ref().unwrap().legend.clone().unwrap();
    assert!(legend.max > legend.min && legend.mean > 0.0);
    h.get_by_label_contains(&format!("mean {:.2}", legend.mean));
}

#[test]
fn opening_a_broken_obj_shows_an_error_and_keeps_the_old_scene() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    let triangles = h.state().scene.report.triangles;
    let nodes = h.state().current_bvh().unwrap().stats.nodes;
    let broken = temp_file("broken.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
    h.input_mut().dropped_files.push(Arc::new(Dropped(broken.clone())));
    run_until(&mut h, "the error", |a| a.messages.iter().any(|m| m.kind == MessageKind::Error));
    h.get_by_label_contains("broken.obj: line 3");
    assert_eq!(h.state().scene.source, SceneSource::Builtin);
    h.get_by_label(&triangles.to_string());
    h.get_by_label(&nodes.to_string());
}

/// Type `text` as a keyboard does: per character a key press (when the character has a key),
/// its text, and the key release, one frame each, with nothing focused by the test.
#[test]
fn a_typed_path_goes_into_the_field_and_fires_no_shortcut() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    let settings = h.state().settings.clone();
    let orbit = h.state().orbit;
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::L);
    h.run_steps(2);
    assert!(h.get_by_label("Path").is_focused(), "the field takes the keyboard when it opens");
    // s: next strategy, r: reset camera, b: boxes, c: colour map, f: frame, 1..5: views, ]: depth.
    let typed = "meshes/scrubbed-fbc-12345].obj";
    type_keys(&mut h, typed);
    assert_eq!(h.state().path_window.as_ref().map(|w| w.text.as_str()), Some(typed));
    assert_eq!(h.state().settings, settings, "no setting changed while typing");
    assert_eq!(h.state().orbit, orbit, "the camera did not move");
    assert!(h.state().jobs.build.is_none(), "no build started");
    h.key_press(egui::Key::Enter);
    run_until(&mut h, "the error", |a| a.messages.iter().any(|m| m.kind == MessageKind::Error));
    assert!(h.state().path_window.is_none(), "Enter opens the path");
    h.get_by_label_contains("scrubbed-fbc-12345].obj");
    // With the field gone, the same keys are shortcuts again.
    h.key_press(egui::Key::B);
    h.step();
    assert!(h.state().settings.show_boxes);
}

#[test]
fn escape_closes_the_path_window() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    h.state_mut().act(Action::OpenPath);
    h.run_steps(2);
    type_keys(&mut h, "x");
    h.key_press(egui::Key::Escape);
    h.run_steps(2);
    assert!(h.state().path_window.is_none());
}

#[test]
fn a_mesh_opened_by_typing_its_path_replaces_the_scene() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    let tent =
        temp_file("tent.obj", "v -1 0 -1\nv 1 0 -1\nv 0 1 0\nv -1 0 1\nv 1 0 1\nf 1 2 3\nf 3 4 5\nf 1 3 4\nf 2 5 3\n");
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::L);
    h.run_steps(2);
    h.get_by_label("Path").type_text(tent.to_str().unwrap());
    h.run_steps(2);
    h.get_by_label("Open").click();
    run_until(&mut h, "the tent", |a| a.scene.report.triangles == 4 && idle(a));
    h.get_by_label("tent.obj");
    assert!(h.state().settings.recent_files.iter().any(|p| p.ends_with("tent.obj")), "remembered as recent");
}

#[test]
fn the_view_and_the_statistics_can_be_exported() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    h.get_by_label("Triangle tests").click();
    run_until(&mut h, "the heatmap", |a| idle(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some()));
    let dir = temp_file("x", "").parent().unwrap().to_path_buf();
    let png = dir.join("view.png");
    let csv = dir.join("stats.csv");
    let json = dir.join("stats.json");
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::SavePng, png.clone()));
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::SaveStatsCsv, csv.clone()));
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::SaveStatsJson, json.clone()));
    h.run_steps(3); // a new egui Area is measured, unseen, in its first frame
    let frame = h.state().shown.as_ref().unwrap().frame.clone();
    let img = image::open(&png).expect("PNG written").to_rgb8();
    assert_eq!(img.width(), frame.width().max(176));
    assert!(img.height() > frame.height(), "the heatmap PNG carries its legend below the image");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let header = reader.headers().unwrap().clone();
    assert_eq!(header.iter().take(3).collect::<Vec<_>>(), ["which", "strategy", "triangles"]);
    let rec = reader.records().next().unwrap().unwrap();
    assert_eq!(rec.len(), header.len());
    assert_eq!((&rec[0], &rec[1]), ("current", "SAH binned, wide4"), "{text}");
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["strategies"][0]["tree"]["nodes"], h.state().current_bvh().unwrap().stats.nodes);
    assert_eq!(h.query_all_by_label_contains("Note: Saved").count(), 3, "each save is confirmed on screen");
}

#[test]
fn a_scene_file_brings_its_camera_and_settings_and_can_be_saved_back() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    let tent = temp_file(
        "scene-tent.obj",
        "v -1 0 -1\nv 1 0 -1\nv 0 1 0\nv -1 0 1\nv 1 0 1\nf 1 2 3\nf 3 4 5\nf 1 3 4\nf 2 5 3\n",
    );
    let scene = temp_file(
        "tents.json",
        &format!(
            r#"{{"camera": {{"position": [3, 2, 6], "look_at": [0, 0.5, 0], "vertical_fov": 40, "size": [320, 200]}},
                "meshes": [{{"file": "{0}"}}, {{"file": "{0}", "transform": {{"translate": [3, 0, 0]}}}}],
                "bvh": {{"strategy": "midpoint", "layout": "binary"}}}}"#,
            tent.display()
        ),
    );
    h.input_mut().dropped_files.push(Arc::new(Dropped(scene.clone())));
    run_until(&mut h, "the scene", |a| a.scene.report.triangles == 8 && idle(a));
    let app = h.state();
    assert_eq!(app.settings.build.strategy, SplitStrategy::Midpoint, "the scene's BVH settings");
    assert_eq!(app.settings.build.layout, bvhscope::bvh::Layout::Binary);
    let cam = app.orbit.camera(320, 200);
    assert!((cam.position - glam::Vec3::new(3.0, 2.0, 6.0)).length() < 1e-4, "the scene's camera: {}", cam.position);
    assert_eq!(cam.vfov_deg, 40.0);

    let saved = scene.with_file_name("saved.json");
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::SaveScene, saved.clone()));
    let back = bvhscope::scene::load_any(&saved).expect("the saved scene loads");
    assert_eq!(back.placed_triangles(), 8);
    assert_eq!(back.build.unwrap().strategy, SplitStrategy::Midpoint);
    assert!((back.camera.unwrap().position - cam.position).length() < 1e-4);
}

#[test]
fn a_scene_with_placements_builds_two_levels_shown_level_by_level() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    assert!(h.query_by_label("Top-level nodes visited").is_none(), "no levels for one mesh");
    let tent = temp_file(
        "levels-tent.obj",
        "v -1 0 -1\nv 1 0 -1\nv 0 1 0\nv -1 0 1\nv 1 0 1\nf 1 2 3\nf 3 4 5\nf 1 3 4\nf 2 5 3\n",
    );
    let placements: Vec<String> = (0..6)
        .map(|i| {
            format!(
                r#"{{"file": "{}", "transform": {{"translate": [{}, 0, {}]}}}}"#,
                tent.display(),
                (i % 3) * 3,
                (i / 3) * 3
            )
        })
        .collect();
    let scene = temp_file(
        "levels.json",
        &format!(
            r#"{{"note": "six tents", "camera": {{"position": [3, 6, 12], "look_at": [3, 0, 1.5], "size": [320, 200]}},
                "meshes": [{}]}}"#,
            placements.join(",")
        ),
    );
    h.input_mut().dropped_files.push(Arc::new(Dropped(scene)));
    let two_level = |a: &BvhscopeApp| a.current_bvh().is_some_and(|b| b.bvh.two_level().is_some());
    run_until(&mut h, "the two-level build", |a| a.scene.report.triangles == 24 && two_level(a) && idle(a));
    h.get_by_label("Two levels: 6 placements of 1 meshes");
    h.get_by_label("six tents");
    {
        let t = h.state().current_bvh().unwrap().bvh.two_level().unwrap();
        assert_eq!((t.instances.len(), t.bottom.len()), (6, 1), "the tent's BVH is built once");
    }

    // The top level's own heatmap.
    h.get_by_label("Top-level nodes visited").click_accesskit();
    run_until(&mut h, "the top-level heatmap", |a| idle(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some()));
    h.get_by_label_contains("Legend: top-level nodes visited per ray");
    let rays = h.state().rays.expect("per-ray figures").summary;
    assert!(rays.mean_top_nodes_visited > 0.0 && rays.mean_instances_entered > 0.0);

    // Boxes (their controls are below the fold of the left panel, so accessibility actions click
    // them): the top level alone at depth 0 is its root; the bottom level adds a root per tent.
    h.get_by_label("Show node boxes").click_accesskit();
    h.step();
    h.get_by_label("Top level").click_accesskit();
    h.step();
    h.get_by_role_and_label(Role::Slider, "Top-level depth").set_value_accesskit(0.0);
    h.get_by_role_and_label(Role::Slider, "Bottom-level depth").set_value_accesskit(0.0);
    h.step();
    h.step();
    assert_eq!(h.state().settings.box_level, bvhscope::app::BoxLevel::Top);
    assert_eq!(h.state().boxes_drawn(), 1);
    h.get_by_label("Both").click_accesskit();
    h.step();
    h.step();
    assert_eq!(h.state().boxes_drawn(), 1 + 6, "the top root and each placement's mesh root");

    // One level again: the scene flattened into one BVH, and no per-level views.
    h.get_by_label("Two levels: 6 placements of 1 meshes").click();
    run_until(&mut h, "the single-level build", |a| !two_level(a) && a.current_bvh().is_some() && idle(a));
    assert!(h.query_by_label("Top-level nodes visited").is_none());
    assert_eq!(h.state().settings.view, bvhscope::render::View::Visits);
}

#[test]
fn the_builtin_scene_cannot_be_saved_as_a_scene_file() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    let path = std::env::temp_dir().join(format!("bvhscope-ui-builtin-{}.json", std::process::id()));
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::SaveScene, path.clone()));
    assert!(!path.exists());
    assert!(h.state().messages.iter().any(|m| m.kind == MessageKind::Error && m.text.contains("built-in")));
}

#[test]
fn default_view_snapshot() {
    let mut h = Harness::builder()
        .with_size(egui::vec2(1200.0, 760.0))
        .wgpu()
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()));
    // The first full frame, and the prepared tree behind it (its EPO shows in the statistics).
    run_until(&mut h, "the first full frame", |a| idle(a) && a.nodes.explained.is_some());
    // Timings in the status line and statistics differ run to run; allow those few pixels.
    let options = egui_kittest::SnapshotOptions::default()
        .max_failed_pixels(4000)
        .output_path(concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/snapshots"));
    h.snapshot_options("default_view", &options);
}

#[test]
fn a_coarse_pass_is_shown_in_place_at_its_resolution_snapshot() {
    use bvhscope::render::{render_passes, view_image, RenderSettings};
    let mut h = Harness::builder()
        .with_size(egui::vec2(1200.0, 760.0))
        .wgpu()
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()));
    run_until(&mut h, "the first full frame", idle);
    // The 1/8 pass of the frame on screen, put where the render job would put it.
    let app = h.state();
    let (bvh, shown) = (app.current_bvh().unwrap().bvh.clone(), app.shown.as_ref().unwrap());
    let (camera, style) = (shown.camera, shown.style);
    assert_ne!(camera.width % 8, 0, "a partly covered last column is part of the test");
    let settings = RenderSettings { count: true, progressive: true, ..Default::default() };
    let mut coarse = None;
    render_passes(&*bvh, &*bvh, &camera, &settings, &Default::default(), &Default::default(), |f, _| {
        if f.stride() == 8 {
            coarse = Some(f);
        }
    })
    .unwrap();
    let coarse = coarse.unwrap();
    let (img, _) = view_image(&coarse, style.view, style.colormap, style.range, style.cost);
    assert_eq!(img.width(), camera.width.div_ceil(8));
    let image = egui::ColorImage::from_rgb([img.width() as usize, img.height() as usize], img.as_raw());
    let shown = h.state_mut().shown.as_mut().unwrap();
    shown.texture.set(image, egui::TextureOptions::NEAREST);
    shown.frame = Arc::new(coarse);
    h.step();
    h.step();
    assert!(h.query_by_label_contains("1/8 resolution").is_some(), "the status line names the pass");
    let options = egui_kittest::SnapshotOptions::default()
        .max_failed_pixels(4000)
        .output_path(concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/snapshots"));
    h.snapshot_options("coarse_pass", &options);
}

#[test]
fn the_viewport_keeps_its_width_when_the_figures_change() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    let before = h.state().viewport_rect;
    assert!(before.width() > 500.0, "{before:?}");
    // A second strategy adds the "before" column and its figures to the statistics.
    h.get_by_role_and_label(Role::ComboBox, "Split strategy").click();
    h.run_steps(3);
    h.get_by_label("Equal count").click();
    run_until(&mut h, "the equal-count build", |a| a.previous.is_some() && idle(a));
    h.get_by_label("before: SAH binned, wide4");
    assert_eq!(h.state().viewport_rect, before, "the side panels did not widen");
    // Two levels and back.
    let scene = temp_file(
        "width.json",
        &format!(
            r#"{{"note": "{}", "meshes": [{{"file": "{t}"}}, {{"file": "{t}", "transform": {{"translate": [3, 0, 0]}}}}]}}"#,
            "a long note that goes on and on to be wider than any panel ".repeat(4),
            t = temp_file("width-tent.obj", "v -1 0 -1\nv 1 0 -1\nv 0 1 0\nf 1 2 3\n").display()
        ),
    );
    h.input_mut().dropped_files.push(Arc::new(Dropped(scene)));
    let two = |a: &BvhscopeApp| a.current_bvh().is_some_and(|b| b.bvh.two_level().is_some());
    run_until(&mut h, "the two-level build", |a| a.scene.report.triangles == 2 && two(a) && idle(a));
    assert_eq!(h.state().viewport_rect, before);
    h.get_by_label("Two levels: 2 placements of 1 meshes").click();
    run_until(&mut h, "one level", |a| a.current_bvh().is_some_and(|b| b.bvh.two_level().is_none()) && idle(a));
    assert_eq!(h.state().viewport_rect, before);
}

#[test]
fn before_figures_from_another_camera_are_marked_stale() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    h.state_mut().settings.build.strategy = SplitStrategy::Midpoint;
    run_until(&mut h, "the midpoint build", |a| a.previous.is_some() && a.rays.is_some() && idle(a));
    assert!(h.query_by_label("stale").is_none(), "same camera: the figures compare");
    // Orbit: the next frame's rays are others; the figures from before are not comparable.
    h.state_mut().orbit.orbit(120.0, 0.0);
    run_until(&mut h, "the new frame", |a| {
        idle(a) && a.rays.is_some_and(|r| r.camera != a.previous.as_ref().unwrap().rays.unwrap().camera)
    });
    assert_eq!(h.query_all_by_label("stale").count(), 7, "every per-ray row of the before column");
}

#[test]
fn a_long_scene_note_wraps_inside_the_viewport_and_can_be_dismissed() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/many-instances.json");
    h.input_mut().dropped_files.push(Arc::new(Dropped(scene)));
    run_until(&mut h, "the scene", |a| a.scene.instances().is_some() && idle(a));
    let viewport = h.state().viewport_rect;
    let note = h.get_by_label_contains("Note: many-instances.json: 144 placements").rect();
    assert!(viewport.contains_rect(note), "the note {note:?} inside the viewport {viewport:?}");
    assert!(note.height() > 30.0, "it wraps over several lines");
    // "Opened …" and the note, each with its own button, all on screen; the note's is the last.
    let buttons: Vec<_> = h.query_all_by_label("Dismiss").collect();
    assert_eq!(buttons.len(), 2);
    for b in &buttons {
        assert!(viewport.contains_rect(b.rect()), "Dismiss {:?} on screen", b.rect());
    }
    assert!(buttons[1].rect().min.y > note.max.y - 1.0, "below its note");
    buttons[1].click();
    h.run_steps(2);
    assert!(h.query_by_label_contains("Note: many-instances.json").is_none());
}

#[test]
fn two_level_figures_show_the_whole_build_time_and_one_placement_shows_the_mesh() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/many-instances.json");
    h.input_mut().dropped_files.push(Arc::new(Dropped(scene)));
    let two = |a: &BvhscopeApp| a.current_bvh().is_some_and(|b| b.bvh.two_level().is_some());
    run_until(&mut h, "the two-level build", |a| two(a) && idle(a));
    assert!(h.state().settings.two_level, "a mesh placed 144 times starts as two levels");
    let (total, meshes, top) = {
        let b = h.state().current_bvh().unwrap();
        let t = b.bvh.two_level().unwrap();
        (b.bvh.build_time(), t.bottom_time, t.top_time)
    };
    assert_eq!(total, meshes + top);
    let figures = h.state().current_figures().unwrap();
    assert_eq!(figures.build_ms, total.as_secs_f64() * 1e3);
    assert!(figures.build_ms > 0.0);
    // (Another figure may read the same, so at least one label, not exactly one.)
    assert!(h.query_all_by_label(&bvhscope::bvh::fmt_ms(figures.build_ms)).count() >= 1, "the build time is shown");

    // A scene that places its one mesh once opens in one level; two levels describe the mesh.
    let one = temp_file(
        "one-placement.json",
        &format!(
            r#"{{"meshes": [{{"file": "{}"}}]}}"#,
            temp_file("one-tent.obj", "v -1 0 -1\nv 1 0 -1\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n").display()
        ),
    );
    h.input_mut().dropped_files.push(Arc::new(Dropped(one)));
    run_until(&mut h, "the one-placement scene", |a| {
        a.scene.report.triangles == 2 && a.current_bvh().is_some() && idle(a)
    });
    assert!(!h.state().settings.two_level, "one placement: one level, as the handout builds it");
    h.get_by_label("Two levels: 1 placements of 1 meshes").click();
    run_until(&mut h, "two levels", |a| two(a) && idle(a));
    let b = h.state().current_bvh().unwrap();
    assert!(b.rows_are_the_mesh());
    assert_eq!(b.stats.triangles, 2, "the rows count the mesh's triangles, not one placement");
    h.get_by_label_contains("the rows above describe the mesh's BVH");
}

#[test]
fn the_help_window_names_keys_by_their_symbols() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    h.key_press(egui::Key::F1);
    h.run_steps(2);
    h.get_by_label("]");
    h.get_by_label("[");
    assert!(h.query_by_label_contains("Bracket").is_none());
}

#[test]
fn a_fixed_range_stays_with_its_view_and_a_new_mesh_clears_it() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    h.get_by_label("Nodes visited").click();
    run_until(&mut h, "the heatmap", |a| idle(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some()));
    h.get_by_label("Fix the current range").click();
    h.run_steps(2);
    let view = bvhscope::render::View::Visits;
    let fixed = *h.state().settings.fixed_ranges.get(&view).expect("fixed for nodes visited");
    h.get_by_label("Combined cost").click();
    run_until(&mut h, "the cost heatmap", |a| {
        idle(a) && a.shown.as_ref().is_some_and(|s| s.style.view == bvhscope::render::View::Cost)
    });
    assert_eq!(h.state().settings.heat_range(), bvhscope::render::HeatRange::Auto, "another view, its own range");
    let legend = h.state().shown.as_ref().unwrap().legend.clone().unwrap();
    assert_eq!(
        (legend.range_min, legend.range_max),
        (legend.min, legend.max),
        "not saturated by the other view's scale"
    );
    h.get_by_label("Nodes visited").click();
    h.run_steps(2);
    assert_eq!(h.state().settings.heat_range(), bvhscope::render::HeatRange::Fixed { min: fixed.0, max: fixed.1 });
    let tent = temp_file("range-tent.obj", "v -1 0 -1\nv 1 0 -1\nv 0 1 0\nf 1 2 3\n");
    h.input_mut().dropped_files.push(Arc::new(Dropped(tent)));
    run_until(&mut h, "the tent", |a| a.scene.report.triangles == 1 && idle(a));
    assert!(h.state().settings.fixed_ranges.is_empty(), "a new mesh starts on its own scale");
}

#[test]
fn the_exported_png_names_the_mesh_the_strategy_and_the_view() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    h.get_by_label("Nodes visited").click();
    run_until(&mut h, "the heatmap", |a| idle(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some()));
    let png = temp_file("named.png", "");
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::SavePng, png.clone()));
    let img = image::open(&png).unwrap().to_rgb8();
    let frame = h.state().shown.as_ref().unwrap().frame.clone();
    let mut legend = h.state().shown.as_ref().unwrap().legend.clone().unwrap();
    legend.subject = format!("{}, SAH binned, wide4", h.state().scene.title());
    assert_eq!(img.height(), frame.height() + bvhscope::render::legend_height(&legend), "a line for the subject");
    // The same strip drawn here from the expected words matches the file's, pixel for pixel.
    let base = image::RgbImage::from_fn(frame.width(), frame.height(), |x, y| *img.get_pixel(x, y));
    assert!(bvhscope::render::draw_legend(&base, &legend) == img, "the strip says what the image shows");
}

#[test]
fn handout_mode_is_one_click() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    h.get_by_label("Handout mode").click();
    run_until(&mut h, "the handout build", |a| {
        a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == SplitStrategy::Midpoint) && idle(a)
    });
    let s = &h.state().settings;
    assert!(s.is_preset(bvhscope::bvh::Preset::Handout));
    assert_eq!(s.build.layout, bvhscope::bvh::Layout::Binary);
    assert_eq!(s.trace, bvhscope::bvh::Preset::Handout.trace());
    h.get_by_label("Handout mode (on)");
    h.get_by_label("Midpoint, binary");
}

#[test]
fn a_z_up_mesh_is_seen_from_the_front() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    h.get_by_label("Z up").click();
    h.run_steps(2);
    let cam = h.state().orbit.camera(800, 600);
    assert_eq!(cam.up, glam::Vec3::Z);
    assert!(cam.position.z > cam.look_at.z && cam.position.y < cam.look_at.y, "front (-y), above (+z): {cam:?}");
    run_until(&mut h, "a frame from the new camera", |a| {
        idle(a) && a.shown.as_ref().is_some_and(|s| s.camera.up == glam::Vec3::Z)
    });
}

#[test]
fn the_moer_lite_lab_scene_opens_in_one_level() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/models/moer-lite-lab1-bvh");
    if !dir.is_dir() {
        assert!(std::env::var("CI").map_or(true, |v| v != "true"), "CI=true but {} is missing", dir.display());
        use std::io::Write;
        let _ = writeln!(std::io::stderr(), "notice: {} not found; skipping the Moer-lite scene test", dir.display());
        return;
    }
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    h.state_mut().settings.two_level = true;
    h.input_mut().dropped_files.push(Arc::new(Dropped(dir.join("scene.json"))));
    run_until(&mut h, "the lab's monkey", |a| a.scene.report.triangles == 968 && a.current_bvh().is_some() && idle(a));
    assert!(!h.state().settings.two_level, "one placement of one mesh: one level");
    assert!(h.state().current_bvh().unwrap().bvh.two_level().is_none());
    h.get_by_label("Two levels: 1 placements of 1 meshes");
}

/// Unticking Two levels on a scene too large to flatten keeps two levels and says why.
#[test]
fn one_level_past_the_budget_switches_back_to_two_levels_and_says_why() {
    let dir = std::env::temp_dir().join(format!("bvhscope-ui-many-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = common::many_placements(&dir, 21_000);
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    h.input_mut().dropped_files.push(Arc::new(Dropped(scene)));
    run_until(&mut h, "the placements", |a| a.scene.report.triangles == 21_000_000 && idle(a));
    assert!(h.state().settings.two_level);
    h.get_by_label("Two levels: 21000 placements of 1 meshes").click();
    h.run_steps(3);
    assert!(h.state().settings.two_level, "one level would flatten 21M triangles");
    let m = h.state().messages.iter().find(|m| m.kind == MessageKind::Warning).expect("a warning says why");
    assert!(m.text.contains("21000000 triangles") && m.text.contains("Switched to two levels"), "{}", m.text);
    assert!(h.state().current_bvh().unwrap().bvh.two_level().is_some());
}

/// A click (press and release without moving) at a screen position.
fn click_at(h: &mut Harness<'_, BvhscopeApp>, pos: egui::Pos2) {
    let input = h.input_mut();
    input.events.push(egui::Event::PointerMoved(pos));
    let button = |pressed| egui::Event::PointerButton {
        pos,
        button: egui::PointerButton::Primary,
        pressed,
        modifiers: egui::Modifiers::NONE,
    };
    input.events.push(button(true));
    h.step();
    h.input_mut().events.push(button(false));
    h.run_steps(3);
}

/// The frame pixel under a screen position of the viewport (as the viewport maps it).
fn pixel_under(app: &BvhscopeApp, pos: egui::Pos2) -> (u32, u32) {
    let (r, f) = (app.viewport_rect, &app.shown.as_ref().unwrap().frame);
    let (u, v) = ((pos.x - r.min.x) / r.width(), (pos.y - r.min.y) / r.height());
    ((u * f.width() as f32) as u32, (v * f.height() as f32) as u32)
}

/// Clicking a pixel of a heatmap pins its ray: its counts and hit are the heatmap's and the hover
/// read-out's for that pixel (the frame's counters), and the Ray window steps through it.
#[test]
fn clicking_a_pixel_pins_its_ray_and_the_ray_window_steps_through_it() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.get_by_label("Nodes visited").click();
    run_until(&mut h, "the heatmap", |a| idle(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some()));
    // The hottest pixel of the heatmap (the knot's view has a hole in its middle).
    let pos = {
        let app = h.state();
        let (r, f) = (app.viewport_rect, &app.shown.as_ref().unwrap().frame);
        let (w, hh) = (f.width(), f.height());
        let (x, y) = (0..hh)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter(|&(x, y)| f.sample(x, y).is_hit())
            .max_by_key(|&(x, y)| f.counters(x, y).nodes_visited)
            .unwrap();
        r.min + egui::vec2((x as f32 + 0.5) / w as f32 * r.width(), (y as f32 + 0.5) / hh as f32 * r.height())
    };
    click_at(&mut h, pos);
    let app = h.state();
    assert_eq!(app.pins.pinned.len(), 1, "the click pinned a ray");
    let r = &app.pins.pinned[0];
    let (x, y) = pixel_under(app, pos);
    assert_eq!(r.pixel, Some((x, y)));
    let frame = &app.shown.as_ref().unwrap().frame;
    let c = frame.counters(x, y);
    assert_eq!(r.counts.nodes_visited, c.nodes_visited, "the heatmap's count for the pixel");
    assert_eq!(
        (r.counts.box_tests, r.counts.leaves_visited, r.counts.triangle_tests),
        (c.box_tests, c.leaves_visited, c.triangle_tests)
    );
    assert_eq!(r.hit.map(|h| h.prim), frame.sample(x, y).is_hit().then(|| frame.sample(x, y).prim));
    assert!(r.hit.is_some(), "the hottest pixel is on the knot");
    let n = r.len();
    assert!(n > 10, "{n} steps");
    assert!(app.orbit == h.state().orbit, "a click does not orbit");

    // The window lists the steps and steps through them.
    h.get_by_label_contains("box of node 0: hit");
    assert_eq!(h.state().pins.step, 0);
    // The pointer goes to the window first, as a hand would: the hover read-out it left over the
    // image goes with it.
    h.get_by_label("Step").hover();
    h.run_steps(2);
    h.get_by_label("Step").click();
    h.run_steps(2);
    assert_eq!(h.state().pins.step, 1);
    h.get_by_label("Last").click();
    h.run_steps(2);
    assert_eq!(h.state().pins.step, n - 1);
    h.get_by_label_contains("Stack (bottom first)");
    h.get_by_label("Back").click();
    h.run_steps(2);
    assert_eq!(h.state().pins.step, n - 2);
    // First goes back to the start; Play from four steps before the end runs to the end.
    h.get_by_label("First").click();
    h.run_steps(2);
    assert_eq!(h.state().pins.step, 0);
    h.state_mut().act(Action::RayStep(n - 5));
    h.run_steps(2);
    h.get_by_label("Play").click();
    run_until(&mut h, "the last step", |a| a.pins.step + 1 == a.pins.pinned[0].len());
    assert!(!h.state().pins.playing, "playing stops at the last step");

    // A neighbouring pixel, pinned too: both are listed to compare; the newer one is selected.
    click_at(&mut h, pos + egui::vec2(1.0, 0.0));
    assert_eq!(h.state().pins.pinned.len(), 2);
    assert_eq!(h.state().pins.selected, 1);
    h.get_by_label("Pinned ray");
    // Exported counts carry the same numbers for the pinned pixel.
    let path = std::env::temp_dir().join(format!("bvhscope-ui-counts-{}.csv", std::process::id()));
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::SaveCounts, path.clone()));
    let text = std::fs::read_to_string(&path).expect("the counts file is written");
    let row = text.lines().find(|l| l.starts_with(&format!("{x},{y},"))).expect("the pixel's row");
    let hit = h.state().pins.pinned[0].hit.unwrap().prim;
    let c = h.state().pins.pinned[0].counts;
    let expected =
        format!("{x},{y},{},{},{},{},{hit}", c.nodes_visited, c.box_tests, c.leaves_visited, c.triangle_tests);
    assert_eq!(row, expected);
}

/// A ray typed as an origin and a direction is pinned and traced through the current BVH; a bad
/// one is refused with a message naming the field.
#[test]
fn a_typed_ray_is_pinned_and_a_bad_one_is_refused() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    let (view, boxes, strategy) =
        (h.state().settings.view, h.state().settings.show_boxes, h.state().settings.build.strategy);
    h.state_mut().act(Action::ShowRayWindow);
    h.run_steps(2);
    h.get_by_label("Origin").click();
    h.run_steps(1);
    type_keys(&mut h, "0, 0.3, 10");
    h.get_by_label("Direction").click();
    h.run_steps(1);
    type_keys(&mut h, "0 0 -1");
    h.get_by_label("Pin typed ray").click();
    h.run_steps(3);
    let app = h.state();
    // "3" (the nodes-visited view's key) typed into a field fires no shortcut.
    assert_eq!((app.settings.view, app.settings.show_boxes, app.settings.build.strategy), (view, boxes, strategy));
    assert_eq!(app.pins.pinned.len(), 1);
    let r = &app.pins.pinned[0];
    assert_eq!(r.pixel, None);
    assert!(r.label.starts_with("typed ray"), "{}", r.label);
    assert_eq!((r.ray.origin(), r.ray.dir()), (glam::Vec3::new(0.0, 0.3, 10.0), glam::Vec3::new(0.0, 0.0, -1.0)));
    h.state_mut().act(Action::RayText { origin: "1, 2".into(), dir: "0, 0, -1".into() });
    h.state_mut().act(Action::PinTyped);
    h.run_steps(2);
    assert_eq!(h.state().pins.pinned.len(), 1, "not pinned");
    assert!(h.state().messages.iter().any(|m| m.kind == MessageKind::Error && m.text.contains("origin")));
}

/// The Ray window's "Copy trace command" names the `bvhscope trace` command line that reproduces
/// the pinned ray: run through the CLI's own code, it prints the same steps, counts and hit as
/// the window shows (a non-default build and traversal, so every option must carry over).
#[test]
fn the_pinned_rays_trace_command_prints_the_same_walk() {
    use bvhscope::bvh::{Layout, TraversalOrder};
    use bvhscope::geometry::TriangleTest;
    let torus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/torus.obj");
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::Open, torus.clone()));
    run_until(&mut h, "the torus", |a| a.scene.source == SceneSource::File(torus.clone()) && idle(a));
    let mut s = h.state().settings.clone();
    s.build.strategy = SplitStrategy::Midpoint;
    s.build.layout = Layout::Binary;
    s.build.max_leaf_size = 2;
    s.trace.order = TraversalOrder::SplitAxisSign;
    s.trace.test = TriangleTest::MollerTrumbore;
    h.state_mut().act(Action::Edit(Box::new(s)));
    run_until(&mut h, "the midpoint build", |a| {
        idle(a) && a.shown.as_ref().is_some_and(|s| s.bvh.build_params().bvh.strategy == SplitStrategy::Midpoint)
    });
    // The pixel of the frame's first hit, near its middle row.
    let (x, y) = {
        let f = &h.state().shown.as_ref().unwrap().frame;
        let y = f.height() / 2;
        (0..f.width()).map(|x| (x, y)).find(|&(x, y)| f.sample(x, y).is_hit()).expect("the torus is in view")
    };
    h.state_mut().act(Action::PinPixel(x, y));
    h.run_steps(2);
    h.get_by_label("Copy trace command");
    let r = &h.state().pins.pinned[0];
    let cmd = r.command.clone().expect("a file's ray has a command");
    assert!(cmd.starts_with("bvhscope trace "), "{cmd}");
    let words: Vec<&str> = cmd.split_whitespace().chain(["--format", "json"]).collect();
    let cli = bvhscope::cli::Cli::from_words(&words).unwrap_or_else(|e| panic!("{cmd}: {e}"));
    let Some(bvhscope::cli::Command::Trace(args)) = cli.command else { panic!("{cmd}: not a trace") };
    let json: serde_json::Value = serde_json::from_str(&bvhscope::cli::trace::output(&args).unwrap()).unwrap();
    let c = r.counts;
    assert_eq!(
        json["counts"],
        serde_json::json!({"nodes_visited": c.nodes_visited, "box_tests": c.box_tests, "leaves_visited": c.leaves_visited, "triangle_tests": c.triangle_tests}),
        "{cmd}"
    );
    let hit = r.hit.expect("a hit pixel");
    assert_eq!(json["hit"]["triangle"], hit.prim);
    assert_eq!(json["hit"]["t"].as_f64().unwrap() as f32, hit.t);
    assert_eq!(json["steps"], serde_json::to_value(&r.trace.steps).unwrap(), "step by step");
    assert_eq!(json["build"], "Midpoint, binary");
}

/// A click with modifiers held (the viewport's shift-click).
fn click_at_with(h: &mut Harness<'_, BvhscopeApp>, pos: egui::Pos2, modifiers: egui::Modifiers) {
    let input = h.input_mut();
    input.events.push(egui::Event::ModifiersChanged(modifiers));
    input.events.push(egui::Event::PointerMoved(pos));
    let button = |pressed| egui::Event::PointerButton { pos, button: egui::PointerButton::Primary, pressed, modifiers };
    input.events.push(button(true));
    h.step();
    h.input_mut().events.push(button(false));
    h.run_steps(3);
    h.input_mut().events.push(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.step();
}

/// The Tree and Node windows select the same node from the tree's rows, the icicle and the
/// viewport (shift-click: the pixel's leaf, with its ancestors as the breadcrumb), and the
/// inspector shows that node's figures and curves, computed by the core's inspector.
#[test]
fn a_node_is_selected_from_the_tree_the_icicle_and_the_viewport() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.get_by_role_and_label(Role::Button, "View").click();
    h.run_steps(2);
    h.get_by_label("Tree and node…").click();
    run_until(&mut h, "the prepared tree", |a| {
        idle(a) && a.nodes.current(a.current_bvh().map(|b| &b.bvh)).is_some() && a.nodes.inspection.is_some()
    });
    assert_eq!(h.state().nodes.selected, Some(0), "opening the windows selects the root");
    h.get_by_label_contains("Subtree SAH");
    h.get_by_label_contains("Axis x: ");

    // The tree's rows: open the root, select its right child.
    h.get_by_label("+").click();
    h.run_steps(2);
    h.get_by_label_contains("node 2 · d1").click();
    run_until(&mut h, "node 2's inspection", |a| a.nodes.inspection.as_ref().is_some_and(|i| i.node == 2));
    {
        let app = h.state();
        let e = app.nodes.explained.as_ref().unwrap();
        let want = bvhscope::bvh::inspect::inspect(&e.tree, &e.hierarchy, 2).unwrap();
        let got = app.nodes.inspection.as_ref().unwrap();
        assert_eq!((got.triangles, got.markers.clone()), (want.triangles, want.markers), "the core's inspection");
    }
    // Keys move the selection: Alt+Up to the parent, Alt+Left to its left child.
    h.key_press_modifiers(egui::Modifiers::ALT, egui::Key::ArrowUp);
    h.run_steps(2);
    assert_eq!(h.state().nodes.selected, Some(0));
    h.key_press_modifiers(egui::Modifiers::ALT, egui::Key::ArrowLeft);
    h.run_steps(2);
    assert_eq!(h.state().nodes.selected, Some(1));

    // The icicle: the middle of the root's left child in the second row.
    let (rect, share) = {
        let app = h.state();
        let e = app.nodes.explained.as_ref().unwrap();
        let share = e.hierarchy.count[2] as f32 / e.tree.prim_ids.len() as f32;
        (h.get_by_label("Icicle of the tree").rect(), share)
    };
    // Node 2 is the root's right child: its cell ends at the right edge.
    let pos = egui::pos2(rect.right() - rect.width() * share * 0.5, rect.top() + 12.0 * 1.5);
    click_at_with(&mut h, pos, egui::Modifiers::NONE);
    assert_eq!(h.state().nodes.selected, Some(2), "the icicle's cell of node 2");

    // The viewport: shift-click a hit pixel selects the leaf holding its triangle.
    let (pos, leaf) = {
        let app = h.state();
        let (r, f) = (app.viewport_rect, &app.shown.as_ref().unwrap().frame);
        let (x, y) = (f.width() / 2, (0..f.height()).find(|&y| f.sample(f.width() / 2, y).is_hit()).unwrap());
        let pos = r.min
            + egui::vec2(
                (x as f32 + 0.5) / f.width() as f32 * r.width(),
                (y as f32 + 0.5) / f.height() as f32 * r.height(),
            );
        let e = app.nodes.explained.as_ref().unwrap();
        (pos, e.hierarchy.leaf_of_prim(f.sample(x, y).prim).unwrap())
    };
    let pinned = h.state().pins.pinned.len();
    click_at_with(&mut h, pos, egui::Modifiers::SHIFT);
    assert_eq!(h.state().nodes.selected, Some(leaf), "the pixel's leaf");
    assert_eq!(h.state().pins.pinned.len(), pinned, "a shift-click pins no ray");
    let path = h.state().nodes.explained.as_ref().unwrap().hierarchy.path(leaf);
    assert!(path.len() > 2);
    h.get_by_label("Path:");
    assert!(h.state().nodes.open.contains(&path[path.len() - 2]), "its ancestors are open in the tree view");
    // The statistics show the tree's end-point overlap.
    h.get_by_label("EPO");
}

/// The inspector's figures for a node are `bvhscope inspect`'s for the same node and build.
#[test]
fn the_node_inspector_and_bvhscope_inspect_agree() {
    let torus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/torus.obj");
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::Open, torus.clone()));
    run_until(&mut h, "the torus", |a| a.scene.source == SceneSource::File(torus.clone()) && idle(a));
    h.state_mut().act(Action::SelectNode(3));
    run_until(&mut h, "node 3's inspection and the frame's visits", |a| {
        a.nodes.inspection.as_ref().is_some_and(|i| i.node == 3) && a.nodes.visits.is_some()
    });
    let ins = h.state().nodes.inspection.clone().unwrap();
    let p = h.state().settings.build;
    let (c, visits) = {
        let v = h.state().nodes.visits.as_ref().unwrap();
        (v.camera, v.counts[3])
    };
    let v3 = |v: glam::Vec3| format!("{},{},{}", v.x, v.y, v.z);
    let words = [
        "bvhscope".to_string(),
        "inspect".into(),
        torus.display().to_string(),
        "--node".into(),
        "3".into(),
        "--strategy".into(),
        bvhscope::options::Choice::named(p.strategy).name.to_string(),
        "--camera".into(),
        format!("{}:{}:{}", v3(c.position), v3(c.look_at), v3(c.up)),
        "--fov".into(),
        c.vfov_deg.to_string(),
        "--size".into(),
        format!("{}x{}", c.width, c.height),
        "--format".into(),
        "json".into(),
    ];
    let cli = bvhscope::cli::Cli::from_words(&words).unwrap();
    let Some(bvhscope::cli::Command::Inspect(args)) = cli.command else { panic!("not inspect") };
    let v: serde_json::Value = serde_json::from_str(&bvhscope::cli::inspect::output(&args).unwrap()).unwrap();
    assert_eq!(v["triangles"], ins.triangles);
    for (s, m) in &ins.markers {
        let j = &v["markers"][bvhscope::options::Choice::named(*s).name];
        // LBVH and PLOC price no plane at a node; the SBVH (its own driver) does.
        if !s.splits_top_down() && *s != bvhscope::bvh::SplitStrategy::Sbvh {
            assert!(m.is_none() && j.is_null(), "{s:?} prices no plane, in both");
            continue;
        }
        if m.is_none() && *s == bvhscope::bvh::SplitStrategy::Sbvh {
            assert!(j.is_null(), "the SBVH makes a leaf here, in both");
            continue;
        }
        let m = m.expect("a split");
        assert_eq!((j["cost"].as_f64().unwrap() as f32, j["left_count"].as_u64().unwrap() as u32), (m.cost, m.left));
    }
    assert_eq!(v["curves"]["x"]["sweep"].as_array().unwrap().len(), ins.sweep[0].len());
    for (a, axis) in ["x", "y", "z"].iter().enumerate() {
        assert_eq!(
            v["curves"][axis]["spatial"].as_array().unwrap().len(),
            ins.spatial[a].len(),
            "spatial curve {axis}"
        );
    }
    assert_eq!(v["visits"], visits, "the Tree window's visits of node 3 for the same camera");
    assert!(visits > 0);
}

/// The legend's histogram counts every pixel of the heatmap; a click on it sets the threshold
/// above which pixels are highlighted, a double click clears it, and another view drops it.
#[test]
fn the_heatmap_histogram_sets_a_threshold() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::View(2));
    run_until(&mut h, "the heatmap", |a| idle(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some()));
    let (counts, pixels, legend) = {
        let app = h.state();
        let s = app.shown.as_ref().unwrap();
        (app.legend_histogram().unwrap(), s.frame.width() * s.frame.height(), s.legend.clone().unwrap())
    };
    assert_eq!(counts.iter().sum::<u32>(), pixels, "every pixel in a bin");
    let rect = h.get_by_label("Histogram of the heatmap").rect();
    // The bars span the colour bar: a click in the middle of the widget lands near the range's middle.
    click_at_with(&mut h, rect.center(), egui::Modifiers::NONE);
    let t = h.state().threshold.expect("a threshold");
    assert!(t > legend.range_min && t < legend.range_max, "{t} in {}..{}", legend.range_min, legend.range_max);
    h.get_by_label_contains("highlighted");
    assert!(h.state().pins.pinned.is_empty(), "a click on the legend pins no ray");
    h.state_mut().act(Action::View(3));
    h.run_steps(2);
    assert_eq!(h.state().threshold, None, "another view, another scale: the threshold goes");
}

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
        let ins = bvhscope::bvh::inspect::inspect(&e.tree, &e.hierarchy, newest).unwrap();
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
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    let mut s = h.state().settings.clone();
    s.build.strategy = SplitStrategy::Midpoint;
    h.state_mut().act(Action::Edit(Box::new(s)));
    h.state_mut().act(Action::View(2));
    run_until(&mut h, "midpoint's heatmap", |a| {
        idle(a)
            && a.shown
                .as_ref()
                .is_some_and(|s| s.legend.is_some() && s.bvh.build_params().bvh.strategy == SplitStrategy::Midpoint)
    });
    h.get_by_role_and_label(Role::Button, "View").click();
    h.run_steps(2);
    h.get_by_label("Compare side by side…").click();
    run_until(&mut h, "B", |a| a.compare.b.is_some() && idle(a));
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
    assert_eq!(h.state().compare.mode, bvhscope::app::CompareMode::Wipe);
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
    assert_eq!(h.state().compare.mode, bvhscope::app::CompareMode::Difference);

    // A changes: only A is rebuilt, B is kept.
    let mut s = h.state().settings.clone();
    s.build.strategy = SplitStrategy::EqualCount;
    h.state_mut().act(Action::Edit(Box::new(s)));
    run_until(&mut h, "equal count as A", |a| {
        idle(a)
            && a.jobs.compare.is_none()
            && a.shown.as_ref().is_some_and(|s| s.bvh.build_params().bvh.strategy == SplitStrategy::EqualCount)
    });
    assert!(Arc::ptr_eq(&h.state().compare.b.as_ref().unwrap().bvh, &b_bvh), "B was not rebuilt");

    // B the same as A: no difference anywhere.
    h.state_mut().act(Action::CompareStrategy(SplitStrategy::EqualCount));
    run_until(&mut h, "B as equal count", |a| {
        idle(a)
            && a.jobs.compare.is_none()
            && a.compare.b.as_ref().is_some_and(|b| b.build.bvh.strategy == SplitStrategy::EqualCount)
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
