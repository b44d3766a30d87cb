//! The bonus builders in the app: LBVH and PLOC chosen in the strategy list, reinsertion asked for
//! in the build panel; the figures the app shows are `bvhscope stats`'s for the same settings.

mod support;

use bvhscope::app::{Action, Pick, SceneSource};
use bvhscope::bvh::Strategy;
use bvhscope::cli::{Cli, Command};
use egui_kittest::kittest::Queryable;
use std::path::{Path, PathBuf};
use support::*;

/// The app with `asset` open and `strategy` (its label) chosen from the strategy list.
fn open_with(asset: &str, strategy: &str) -> (egui_kittest::Harness<'static, bvhscope::app::BvhscopeApp>, PathBuf) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets").join(asset);
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::Picked(Pick::Open, path.clone()));
    run_until(&mut h, asset, |a| a.scene.source == SceneSource::File(path.clone()) && idle(a));
    h.get_by_role_and_label(egui::accesskit::Role::ComboBox, "Split strategy").click();
    h.run_steps(2);
    h.get_by_label(strategy).click();
    h.run_steps(1);
    (h, path)
}

#[test]
fn ploc_with_reinsertion_shows_what_stats_prints() {
    // PLOC from the list, then two passes of reinsertion and the binary layout.
    let (mut h, torus) = open_with("torus.obj", "PLOC");
    let mut s = h.state().settings.clone();
    (s.build.reinsert_passes, s.build.layout) = (2, bvhscope::bvh::Layout::Binary);
    h.state_mut().act(Action::Edit(Box::new(s)));
    run_until(&mut h, "PLOC with reinsertion", |a| {
        idle(a)
            && a.current_bvh()
                .is_some_and(|b| b.bvh.build_params().bvh.strategy == Strategy::Ploc && b.stats.reinsertion.is_some())
    });
    let (stats, r) = {
        let b = h.state().current_bvh().unwrap();
        (b.stats.clone(), b.stats.reinsertion.unwrap())
    };
    h.get_by_label_contains(&format!("Reinsertion: SAH cost {:.3} to {:.3}", r.sah_before, r.sah_after));
    let words = [
        "bvhscope",
        "stats",
        torus.to_str().unwrap(),
        "--strategy",
        "ploc",
        "--reinsert-passes",
        "2",
        "--layout",
        "binary",
        "--no-rays",
        "--format",
        "json",
    ];
    let Some(Command::Stats(args)) = Cli::from_words(words).unwrap().command else { panic!("stats") };
    let v: serde_json::Value = serde_json::from_str(&bvhscope::cli::stats::output(&args).unwrap()).unwrap();
    let cli = &v["stats"];
    assert_eq!(cli["nodes"], stats.nodes);
    assert_eq!(cli["sah_cost"].as_f64().unwrap(), stats.sah_cost);
    assert_eq!(cli["reinsertion"]["moves"], r.moves);
    assert_eq!(cli["reinsertion"]["sah_before"].as_f64().unwrap(), r.sah_before);
    assert!(r.sah_after <= r.sah_before);

    // LBVH from the list: the node inspector says it prices no plane.
    h.get_by_role_and_label(egui::accesskit::Role::ComboBox, "Split strategy").click();
    h.run_steps(2);
    h.get_by_label("LBVH (Morton)").click();
    run_until(&mut h, "LBVH", |a| {
        idle(a) && a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == Strategy::Lbvh)
    });
    h.state_mut().act(Action::SelectNode(0));
    run_until(&mut h, "the root's inspection", |a| a.nodes.inspection.is_some() && idle(a));
    // (One footnote under the table for both rows: issue 59.)
    h.get_by_label_contains("LBVH (Morton), PLOC: no plane priced here");
}

/// The SBVH chosen in the list, its growth bound set in the build panel: the references per
/// triangle and the spatial splits the statistics panel shows are `bvhscope stats`'s, and the Node
/// window says what the SBVH did at the root, with `inspect`'s line.
#[test]
fn sbvh_shows_its_references_as_stats_and_inspect_print_them() {
    let (mut h, rods) = open_with("diagonal-rods.obj", "SBVH (spatial splits)");
    let mut s = h.state().settings.clone();
    (s.build.sbvh_growth, s.build.layout) = (50, bvhscope::bvh::Layout::Binary);
    h.state_mut().act(Action::Edit(Box::new(s)));
    run_until(&mut h, "the SBVH", |a| {
        idle(a)
            && a.current_bvh().is_some_and(|b| {
                let p = b.bvh.build_params().bvh;
                p.strategy == Strategy::Sbvh && p.sbvh_growth == 50
            })
    });
    let stats = h.state().current_bvh().unwrap().stats.clone();
    assert!(stats.references > stats.triangles, "spatial splits cut triangles");
    h.get_by_label(&format!("{:.3} ({})", stats.references_per_triangle(), stats.spatial_splits));
    let words = [
        "bvhscope",
        "stats",
        rods.to_str().unwrap(),
        "--strategy",
        "sbvh",
        "--sbvh-growth",
        "50",
        "--layout",
        "binary",
        "--no-rays",
        "--format",
        "json",
    ];
    let Some(Command::Stats(args)) = Cli::from_words(words).unwrap().command else { panic!("stats") };
    let v: serde_json::Value = serde_json::from_str(&bvhscope::cli::stats::output(&args).unwrap()).unwrap();
    let cli = &v["stats"];
    assert_eq!((cli["nodes"].clone(), cli["references"].clone()), (stats.nodes.into(), stats.references.into()));
    assert_eq!(cli["spatial_splits"], stats.spatial_splits);
    assert_eq!(cli["sah_cost"].as_f64().unwrap(), stats.sah_cost);

    h.state_mut().act(Action::SelectNode(0));
    run_until(&mut h, "the root's inspection", |a| a.nodes.inspection.is_some() && idle(a));
    let ins = h.state().nodes.inspection.clone().unwrap();
    let line = bvhscope::explain::inspect::text::sbvh_text(&ins).expect("the SBVH's line");
    h.get_by_label(&line);
    let words = ["bvhscope", "inspect", rods.to_str().unwrap(), "--strategy", "sbvh", "--sbvh-growth", "50"];
    let Some(Command::Inspect(args)) =
        Cli::from_words(words.into_iter().chain(["--layout", "binary", "--node", "0"])).unwrap().command
    else {
        panic!("inspect")
    };
    assert!(bvhscope::cli::inspect::output(&args).unwrap().contains(&line), "inspect prints the same line");
}

/// LBVH's build replay shows its Morton order: the Replay window names the newest split by the
/// Morton bit where its slots' codes flip, in the words `bvhscope replay` prints for that step.
#[test]
fn the_lbvh_replay_names_each_split_by_its_morton_bit_as_replay_prints_it() {
    let (mut h, torus) = open_with("torus.obj", "LBVH (Morton)");
    let mut s = h.state().settings.clone();
    s.build.layout = bvhscope::bvh::Layout::Binary;
    h.state_mut().act(Action::Edit(Box::new(s)));
    run_until(&mut h, "LBVH", |a| {
        idle(a)
            && a.current_bvh().is_some_and(|b| {
                b.bvh.build_params().bvh.strategy == Strategy::Lbvh
                    && b.bvh.build_params().bvh.layout == bvhscope::bvh::Layout::Binary
            })
    });
    h.state_mut().act(Action::ShowReplay(true));
    run_until(&mut h, "the replay", |a| a.replay.replay.is_some() && a.replay.morton.is_some() && idle(a));
    let apng = temp_file("lbvh-replay.png", "");
    let words =
        ["bvhscope", "replay", torus.to_str().unwrap(), "--strategy", "lbvh", "--size", "32x24", "--frames", "5"];
    let Some(Command::Replay(args)) =
        Cli::from_words(words.into_iter().chain(["-o", apng.to_str().unwrap()])).unwrap().command
    else {
        panic!("replay")
    };
    let table = bvhscope::cli::replay::output(&args).unwrap();
    // A step past the first few splits, as the CLI played it.
    let line = table.lines().skip(3).find(|l| l.contains("Morton bit")).expect("a step named by its Morton bit");
    let k: usize = line.split_whitespace().next().unwrap().parse().unwrap();
    let text = line.split_once(": ").unwrap().1.to_string();
    h.state_mut().act(Action::ReplayStep(k));
    run_until(&mut h, "the step", |a| a.replay.k == k && idle(a));
    assert!(h.query_all_by_label_contains(&text).count() == 1, "the Replay window says {text}");
}

/// The fastest preset is one click: the 8-wide layout, the SAH told a step costs three triangle
/// tests, one level; the tree's figures are `bvhscope stats --preset fastest`'s.
#[test]
fn fastest_traversal_is_one_click_and_stats_agrees() {
    let (mut h, torus) = open_with("torus.obj", "SAH binned");
    run_until(&mut h, "the SAH build", |a| {
        idle(a) && a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == Strategy::SahBinned)
    });
    h.get_by_label("Fastest traversal").click();
    run_until(&mut h, "the fastest build", |a| {
        idle(a) && a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.layout == bvhscope::bvh::Layout::Wide8)
    });
    let settings = &h.state().settings;
    assert!(settings.is_preset(bvhscope::bvh::Preset::Fastest));
    assert_eq!(settings.build.cost.traversal, bvhscope::bvh::Preset::Fastest.build().cost.traversal);
    assert!(!settings.two_level);
    h.get_by_label("Fastest traversal (on)");
    h.get_by_label("SAH binned, wide8");
    let stats = h.state().current_bvh().unwrap().stats.clone();
    let stats_words =
        ["bvhscope", "stats", torus.to_str().unwrap(), "--preset", "fastest", "--no-rays", "--format", "json"];
    let Some(Command::Stats(args)) = Cli::from_words(stats_words).unwrap().command else { panic!("stats") };
    let v: serde_json::Value = serde_json::from_str(&bvhscope::cli::stats::output(&args).unwrap()).unwrap();
    let cli = &v["stats"];
    assert_eq!(cli["nodes"], stats.nodes);
    assert_eq!(cli["leaves"], stats.leaves);
    assert_eq!(cli["sah_cost"].as_f64().unwrap(), stats.sah_cost);
    assert_eq!(cli["memory_bytes"], stats.memory_bytes);
    // The kernels the statistics panel names are the ones `stats` prints.
    let simd = stats.simd.expect("a wide layout's kernels");
    assert_eq!(cli["simd"], simd);
    assert!(h.query_all_by_label(simd).count() >= 1, "the SIMD kernels row shows {simd}");

    // The 8-wide heatmap's counts: `render --preset fastest` on the same camera gives them pixel for pixel.
    h.state_mut().act(Action::View(2));
    run_until(&mut h, "the visits heatmap", |a| idle(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some()));
    let camera = h.state().shown.as_ref().unwrap().camera;
    let csv = temp_file("fastest-counts.csv", "");
    let mut args = vec![s("render"), s(torus.display()), s("--preset"), s("fastest"), s("--view"), s("visits")];
    args.extend(camera_words(&camera));
    args.extend([s("--counts"), s(csv.display()), s("-o"), s(temp_file("fastest.png", "").display())]);
    bvhscope::cli::run(words(&args)).unwrap();
    let app_counts = h.state().shown.as_ref().unwrap().frame.counts_csv().unwrap();
    assert_eq!(app_counts, std::fs::read_to_string(&csv).unwrap(), "the app's 8-wide counts are render's");
}

/// With the stored-edges triangle test on the 8-wide layout, "Bytes / triangle" counts the leaves
/// that test keeps beside the tree (48 bytes a triangle), as `stats --triangle-test
/// moller-trumbore-stored` does; with the watertight test, the tree's own.
#[test]
fn the_stored_tests_leaves_count_in_bytes_per_triangle_as_stats_counts_them() {
    use bvhscope::geometry::TriangleTest;
    let (mut h, torus) = open_with("torus.obj", "SAH binned");
    h.get_by_label("Fastest traversal").click();
    run_until(&mut h, "the fastest build", |a| {
        idle(a) && a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.layout == bvhscope::bvh::Layout::Wide8)
    });
    let mut s = h.state().settings.clone();
    s.trace.test = TriangleTest::MollerTrumboreStored;
    h.state_mut().act(Action::Edit(Box::new(s)));
    run_until(&mut h, "the frame with the stored test", |a| {
        idle(a) && a.shown.as_ref().is_some_and(|s| s.trace.test == TriangleTest::MollerTrumboreStored)
    });
    h.run_steps(2);
    let stats = |test: &str| {
        let w = ["bvhscope", "stats", torus.to_str().unwrap(), "--preset", "fastest", "--triangle-test", test];
        let Some(Command::Stats(args)) = Cli::from_words(w.iter().copied().chain(["--no-rays"])).unwrap().command
        else {
            panic!("stats")
        };
        bvhscope::cli::stats::output(&args).unwrap()
    };
    let text = stats("moller-trumbore-stored");
    let line = text.lines().find(|l| l.contains("of leaves kept for")).unwrap_or_else(|| panic!("{text}"));
    let total = line.rsplit(", ").next().unwrap().trim_end_matches(" per triangle");
    let tree = h.state().current_bvh().unwrap().stats.clone();
    let want = (tree.memory_bytes + 48 * tree.triangles) as f64 / tree.triangles as f64;
    assert_eq!(total, format!("{want:.1}"), "{line}");
    assert!(h.query_all_by_label(total).count() >= 1, "the statistics show {total} bytes a triangle");
    // The watertight test keeps nothing beside the tree: the line is not printed.
    assert!(!stats("watertight").contains("of leaves kept for"));
}
