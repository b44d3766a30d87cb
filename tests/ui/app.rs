//! The desktop app driven through egui_kittest, without a display: what a user sees and does.
//! Built by the `ui-tests` package (see its Cargo.toml); snapshots live in `tests/snapshots/`.

use bvhscope::app::{AppOptions, BvhscopeApp, MessageKind, SceneSource};
use bvhscope::bvh::SplitStrategy;
use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

fn harness() -> Harness<'static, BvhscopeApp> {
    Harness::builder()
        .with_size(egui::vec2(1400.0, 860.0))
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()))
}

/// Step the app until `done` holds (background jobs report asynchronously).
fn run_until(h: &mut Harness<'_, BvhscopeApp>, what: &str, done: impl Fn(&BvhscopeApp) -> bool) {
    let start = Instant::now();
    while !done(h.state()) {
        assert!(start.elapsed() < Duration::from_secs(120), "timed out waiting for {what}");
        h.step();
        std::thread::sleep(Duration::from_millis(5));
    }
    h.step();
    h.step();
}

fn idle(app: &BvhscopeApp) -> bool {
    app.current_bvh().is_some() && !app.jobs.is_busy() && app.shown.as_ref().is_some_and(|s| s.frame.is_complete())
}

fn temp_file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("bvhscope-ui-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[derive(Debug)]
struct Dropped(PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &Path {
        &self.0
    }
    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

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
    h.state_mut().settings.build.strategy = SplitStrategy::Midpoint;
    h.state_mut().ensure_build();
    assert!(h.state().jobs.build.is_some(), "the midpoint build runs");
    h.state_mut().settings.build.strategy = SplitStrategy::SahBinned;
    h.state_mut().ensure_build();
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

#[test]
fn moving_the_depth_slider_changes_the_number_of_boxes_drawn() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    h.get_by_label("Show node boxes").click();
    h.step();
    h.step();
    h.get_by_label("1 boxes drawn"); // depth 0: the root
    h.get_by_role_and_label(Role::Slider, "Box depth").set_value_accesskit(6.0);
    h.step();
    h.step();
    assert_eq!(h.state().settings.box_depth, 6);
    let drawn = h.state().boxes_drawn;
    // The default layout is 4-wide: depth 6 holds at most 4^6 nodes.
    assert!(drawn > 64 && drawn <= 4096, "depth 6 of a 4-wide tree, drew {drawn}");
    h.get_by_label(&format!("{drawn} boxes drawn"));
    // The ] key goes one level deeper.
    h.key_press(egui::Key::CloseBracket);
    h.step();
    h.step();
    assert_eq!(h.state().settings.box_depth, 7);
    assert!(h.state().boxes_drawn > drawn);
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

#[test]
fn a_mesh_opened_by_typing_its_path_replaces_the_scene() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    let tent =
        temp_file("tent.obj", "v -1 0 -1\nv 1 0 -1\nv 0 1 0\nv -1 0 1\nv 1 0 1\nf 1 2 3\nf 3 4 5\nf 1 3 4\nf 2 5 3\n");
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::L);
    h.run_steps(2);
    h.get_by_label("Path").focus();
    h.step();
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
    h.state_mut().picked(bvhscope::app::Pick::SavePng, png.clone());
    h.state_mut().picked(bvhscope::app::Pick::SaveStatsCsv, csv.clone());
    h.state_mut().picked(bvhscope::app::Pick::SaveStatsJson, json.clone());
    h.run_steps(3); // a new egui Area is measured, unseen, in its first frame
    let frame = h.state().shown.as_ref().unwrap().frame.clone();
    let img = image::open(&png).expect("PNG written").to_rgb8();
    assert_eq!(img.width(), frame.width().max(176));
    assert!(img.height() > frame.height(), "the heatmap PNG carries its legend below the image");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("which,strategy,triangles"), "{text}");
    assert!(text.lines().nth(1).unwrap().starts_with("current,SAH binned,"), "{text}");
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
    h.state_mut().picked(bvhscope::app::Pick::SaveScene, saved.clone());
    let back = bvhscope::scene::load_any(&saved).expect("the saved scene loads");
    assert_eq!(back.mesh.triangle_count(), 8);
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
    let rays = h.state().rays.expect("per-ray figures");
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
    assert_eq!(h.state().boxes_drawn, 1);
    h.get_by_label("Both").click_accesskit();
    h.step();
    h.step();
    assert_eq!(h.state().boxes_drawn, 1 + 6, "the top root and each placement's mesh root");

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
    h.state_mut().picked(bvhscope::app::Pick::SaveScene, path.clone());
    assert!(!path.exists());
    assert!(h.state().messages.iter().any(|m| m.kind == MessageKind::Error && m.text.contains("built-in")));
}

#[test]
fn default_view_snapshot() {
    let mut h = Harness::builder()
        .with_size(egui::vec2(1200.0, 760.0))
        .wgpu()
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()));
    run_until(&mut h, "the first full frame", idle);
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
    let (bvh, mesh, shown) =
        (app.current_bvh().unwrap().bvh.clone(), app.scene.mesh.clone(), app.shown.as_ref().unwrap());
    let (camera, style) = (shown.camera, shown.style);
    assert_ne!(camera.width % 8, 0, "a partly covered last column is part of the test");
    let settings = RenderSettings { count: true, progressive: true, ..Default::default() };
    let mut coarse = None;
    render_passes(&*bvh, &mesh, &camera, &settings, &Default::default(), |f, _| {
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
