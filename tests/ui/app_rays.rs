//! Secondary rays in the app (issue 50): the ray kind beside the view; the app's ambient-occlusion
//! counts are `render --ray-kind ao --counts`'s, pixel for pixel (the same seed, the same rays);
//! the side by side traces B on A's rays; the statistics are `stats --ray-kind ao`'s.

use super::support::*;
use bvhscope::app::Action;
use bvhscope::render::{RayKind, SecondarySpec};
use egui_kittest::kittest::Queryable;

#[test]
fn the_apps_ao_counts_are_the_command_lines() {
    let mut h = harness();
    let torus = root().join("assets/torus.obj");
    open(&mut h, &torus);
    // The kind is chosen beside the view's colour map (a heatmap's): the combo box is there, and
    // choosing Ambient occlusion (as its list does, by an edit of the settings; the panel's lower
    // rows lie below the fold of the test's window) shows its rays per pixel beside it.
    h.state_mut().act(Action::View(2));
    h.run_steps(2);
    h.get_by_role_and_label(egui::accesskit::Role::ComboBox, "Rays");
    let mut settings = h.state().settings.clone();
    settings.rays.kind = RayKind::Ao;
    h.state_mut().act(Action::Edit(Box::new(settings)));
    h.run_steps(2);
    assert_eq!(h.state().settings.rays, SecondarySpec { kind: RayKind::Ao, ..SecondarySpec::default() });
    h.get_by_label_contains("rays per pixel");
    let ao_shown = |a: &bvhscope::app::BvhscopeApp| {
        idle(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some() && s.frame.ray_kind().0 == RayKind::Ao)
    };
    run_until(&mut h, "the ao heatmap", ao_shown);
    let (camera, app_counts, legend) = {
        let shown = h.state().shown.as_ref().unwrap();
        (shown.camera, shown.frame.counts_csv().unwrap(), shown.legend.clone().unwrap())
    };
    assert!(legend.note.contains("camera ray missed"), "{}", legend.note);
    let csv = temp_file("ao-counts.csv", "");
    let mut args = vec![s("render"), s(torus.display()), s("--view"), s("visits"), s("--ray-kind"), s("ao")];
    args.extend(camera_words(&camera));
    args.extend([s("--counts"), s(csv.display()), s("-o"), s(temp_file("ao.png", "").display())]);
    bvhscope::cli::run(words(&args)).unwrap();
    let cli = std::fs::read_to_string(&csv).unwrap();
    assert!(cli.starts_with("x,y,rays,"), "secondary counts: {}", &cli[..60]);
    assert_eq!(app_counts, cli, "the app's ao counts are render --ray-kind ao --counts'");

    // The statistics are stats --ray-kind ao's.
    let rays = h.state().rays.unwrap().summary;
    let mut args = vec![s("stats"), s(torus.display()), s("--ray-kind"), s("ao"), s("--format"), s("json")];
    args.extend(camera_words(&camera));
    let bvhscope::cli::Command::Stats(a) = words(&args) else { panic!("stats") };
    let v: serde_json::Value = serde_json::from_str(&bvhscope::cli::stats::output(&a).unwrap()).unwrap();
    let cli = &v["rays"]["summary"];
    assert_eq!(cli["rays"], rays.rays);
    assert_eq!(cli["mean_nodes_visited"].as_f64().unwrap(), rays.mean_nodes_visited);

    // The Ray window: a pixel's ao rays, one of them pinned and walked as `trace --ray-kind ao
    // --secondary 2` walks it (its command, run, gives the same steps and counts).
    let (x, y) = pin_first_hit(&mut h);
    h.get_by_label_contains(&format!("Pixel {x}, {y}'s ambient occlusion rays"));
    h.get_by_label("ray 2").click();
    h.run_steps(2);
    let r = h.state().pins.current().unwrap();
    assert!(r.any && r.label.contains("ao ray 2 of 4"), "{}", r.label);
    let cmd = r.command.clone().expect("a file's ray has a command");
    let words: Vec<&str> = cmd.split_whitespace().chain(["--format", "json"]).collect();
    let cli = bvhscope::cli::Cli::from_words(&words).unwrap_or_else(|e| panic!("{cmd}: {e}"));
    let Some(bvhscope::cli::Command::Trace(args)) = cli.command else { panic!("{cmd}: not a trace") };
    let json: serde_json::Value = serde_json::from_str(&bvhscope::cli::trace::output(&args).unwrap()).unwrap();
    assert_eq!(json["counts"]["nodes_visited"], r.counts.nodes_visited, "{cmd}");
    assert_eq!(json["counts"]["triangle_tests"], r.counts.triangle_tests, "{cmd}");
    // Both made a JSON value, written as text and read back, as the command's output is: serde_json's
    // reader may land a 17-digit number one ulp off, the same way on both sides.
    let app_steps = serde_json::to_string(&serde_json::to_value(&r.trace.steps).unwrap()).unwrap();
    let app_steps: serde_json::Value = serde_json::from_str(&app_steps).unwrap();
    assert_eq!(json["steps"], app_steps, "step by step");
    assert_eq!(json["ray"]["from"]["secondary"]["walked"], 2);

    // Side by side, B traces A's ao rays: its frame is of ao rays too, from the same hits.
    h.get_by_role_and_label(egui::accesskit::Role::Button, "View").click();
    h.run_steps(2);
    h.get_by_label("Compare side by side…").click();
    run_until(&mut h, "B", pair_shown);
    let b = h.state().compare.b.as_ref().unwrap().frame.clone();
    let a = h.state().shown.as_ref().unwrap().frame.clone();
    assert_eq!(b.ray_kind(), a.ray_kind());
    assert_eq!(b.ray_summary().rays, a.ray_summary().rays, "the same hits, the same number of rays");
}
