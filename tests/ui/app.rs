//! The desktop app driven through egui_kittest, without a display: what a user sees and does.
//! Built by the `ui-tests` package (see its Cargo.toml); snapshots live in `tests/snapshots/`.

#[path = "../common/mod.rs"]
mod common;
mod support;
use support::*;

// The explaining views (pinned rays, the tree and the node inspector, the histogram, the replay,
// two strategies side by side): the same binary, another file.
mod app_explain;
mod app_figures;
mod app_gpu;
mod app_grade;
mod app_legend;
mod app_lesson;
mod app_look;
mod app_rays;
mod app_replay;
mod app_room;
mod app_scenes;
mod app_small;
mod app_tiles;
mod app_truth;

use bvhscope::app::{Action, AppOptions, BvhscopeApp, MessageKind, SceneSource};
use bvhscope::bvh::Strategy;
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
        a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == Strategy::Midpoint) && idle(a)
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
    choose(&mut h, Strategy::Midpoint);
    assert!(h.state().jobs.build.is_some(), "the midpoint build runs");
    choose(&mut h, Strategy::SahBinned);
    assert!(h.state().jobs.build.is_none(), "the midpoint build is cancelled");
    run_until(&mut h, "quiet", idle);
    for _ in 0..20 {
        h.step();
        std::thread::sleep(Duration::from_millis(5));
    }
    let b = h.state().current_bvh().unwrap();
    assert_eq!(b.bvh.build_params().bvh.strategy, Strategy::SahBinned);
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
    edit(&mut h, &|s| s.build.strategy = Strategy::Midpoint);
    assert!(h.state().jobs.build.is_some(), "a strategy rebuilds");
}

#[test]
fn moving_the_depth_slider_changes_the_number_of_boxes_drawn() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    assert_eq!(h.state().settings.box_depth, 3, "the default depth survives the first frames, built or not");
    // By its accessibility action: the View panel's rows that do not apply stay, greyed (issue
    // 59), and the node boxes lie below the fold of this window.
    click_label(&mut h, "Show node boxes");
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
    // The lab's figures: the frame's time, and, once timed, the speed-up over linear search.
    let field = |rec: &csv::StringRecord, name: &str| rec[header.iter().position(|h| h == name).unwrap()].to_string();
    let frame_ms = h.state().last_full_frame.unwrap().as_secs_f64() * 1e3;
    assert_eq!(field(&rec, "frame_ms"), format!("{frame_ms:.3}"));
    assert_eq!(field(&rec, "speedup_over_linear"), "", "not timed yet");
    h.state_mut().act(Action::TimeLinear(true));
    run_until(&mut h, "the timing against the linear scan", |a| a.fresh_speedup().is_some());
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::SaveStatsCsv, csv.clone()));
    let timed = h.state().fresh_speedup().unwrap().speedup;
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let rec = reader.records().next().unwrap().unwrap();
    assert_eq!(field(&rec, "speedup_over_linear"), format!("{:.2}", timed.speedup), "{text}");
    assert_eq!(field(&rec, "one_thread_linear_ms"), format!("{:.3}", timed.linear_ms), "{text}");
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["strategies"][0]["tree"]["nodes"], h.state().current_bvh().unwrap().stats.nodes);
    h.run_steps(3);
    let saved = h.state().messages.iter().filter(|m| m.text.starts_with("Saved")).count();
    assert_eq!(saved, 3, "each file saved is confirmed, once");
    assert_eq!(h.query_all_by_label_contains("Note: Saved").count(), 1, "the newest on the status bar");
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
    h.state_mut().settings.build.strategy = Strategy::Midpoint;
    run_until(&mut h, "the midpoint build", |a| a.previous.is_some() && a.rays.is_some() && idle(a));
    assert!(h.query_by_label("stale").is_none(), "same camera: the figures compare");
    // Orbit: the next frame's rays are others; the figures from before are not comparable.
    h.state_mut().orbit.orbit(120.0, 0.0);
    run_until(&mut h, "the new frame", |a| {
        idle(a) && a.rays.is_some_and(|r| r.camera != a.previous.as_ref().unwrap().rays.unwrap().camera)
    });
    assert_eq!(h.query_all_by_label("stale").count(), 7, "every per-ray row of the before column");
}

/// A scene's long note is no message over the image (a paragraph there hid a third of it): the
/// statistics show its first sentence, the rest under "About this scene".
#[test]
fn a_long_scene_note_is_one_sentence_in_the_statistics_and_the_rest_on_asking() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/many-instances.json");
    h.input_mut().dropped_files.push(Arc::new(Dropped(scene)));
    run_until(&mut h, "the scene", |a| a.scene.instances().is_some() && idle(a));
    h.run_steps(2);
    assert!(h.query_by_label_contains("Note: many-instances.json: 144").is_none(), "no message over the image");
    h.get_by_label("144 placements of one torus.");
    assert!(h.query_by_label_contains("Flattened into one BVH").is_none(), "the rest folded away");
    click_label(&mut h, "About this scene");
    h.run_steps(2);
    h.get_by_label_contains("Flattened into one BVH");
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
        a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == Strategy::Midpoint) && idle(a)
    });
    let s = &h.state().settings;
    assert!(s.is_preset(bvhscope::bvh::Preset::Handout));
    assert_eq!(s.build.layout, bvhscope::bvh::Layout::Binary);
    assert_eq!(s.trace, bvhscope::bvh::Preset::Handout.trace_options());
    h.get_by_label("Handout mode (on)");
    h.get_by_label("Midpoint, binary");
}

#[test]
fn a_z_up_mesh_is_seen_from_the_front() {
    let mut h = harness();
    run_until(&mut h, "the first build", idle);
    click_label(&mut h, "Z up");
    h.run_steps(2);
    let cam = h.state().orbit.camera(800, 600);
    assert_eq!(cam.up, glam::Vec3::Z);
    assert!(cam.position.z > cam.look_at.z && cam.position.y < cam.look_at.y, "front (-y), above (+z): {cam:?}");
    run_until(&mut h, "a frame from the new camera", |a| {
        idle(a) && a.shown.as_ref().is_some_and(|s| s.camera.up == glam::Vec3::Z)
    });
}
