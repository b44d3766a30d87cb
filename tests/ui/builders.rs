//! The bonus builders in the app: LBVH and PLOC chosen in the strategy list, reinsertion asked for
//! in the build panel; the figures the app shows are `bvhscope stats`'s for the same settings.

mod support;

use bvhscope::app::{Action, Pick, SceneSource};
use bvhscope::bvh::SplitStrategy;
use bvhscope::cli::{Cli, Command};
use egui_kittest::kittest::Queryable;
use std::path::Path;
use support::*;

#[test]
fn ploc_with_reinsertion_shows_what_stats_prints() {
    let torus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/torus.obj");
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::Picked(Pick::Open, torus.clone()));
    run_until(&mut h, "the torus", |a| a.scene.source == SceneSource::File(torus.clone()) && idle(a));
    // PLOC from the list, then two passes of reinsertion and the binary layout.
    h.get_by_role_and_label(egui::accesskit::Role::ComboBox, "Split strategy").click();
    h.run_steps(2);
    h.get_by_label("PLOC").click();
    h.run_steps(1);
    let mut s = h.state().settings.clone();
    (s.build.reinsert_passes, s.build.layout) = (2, bvhscope::bvh::Layout::Binary);
    h.state_mut().act(Action::Edit(Box::new(s)));
    run_until(&mut h, "PLOC with reinsertion", |a| {
        idle(a)
            && a.current_bvh().is_some_and(|b| {
                b.bvh.build_params().bvh.strategy == SplitStrategy::Ploc && b.stats.reinsertion.is_some()
            })
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
        idle(a) && a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == SplitStrategy::Lbvh)
    });
    h.state_mut().act(Action::SelectNode(0));
    run_until(&mut h, "the root's inspection", |a| a.nodes.inspection.is_some() && idle(a));
    assert!(h.query_all_by_label_contains("no plane priced here").count() >= 2, "LBVH and PLOC rows");
}
