//! The app's build runs alone: a test binary of its own (cargo runs test binaries one after
//! another), so that no other test's work is mistaken for the app's.

mod support;
use support::*;

use bvhscope::app::Action;
use bvhscope::bvh::Strategy;

/// A build started while the previous frame still renders waits for the render to stop, and
/// nothing renders while it runs: its time is the build's alone, as `stats` measures it (with the
/// render beside it, it used to be 6 to 9 times the CLI's, and the Compare window once showed a
/// negative difference). The mechanism is what is checked; the times are the benchmarks' business.
#[test]
fn the_build_time_is_the_builds_alone() {
    let mut h = harness();
    open(&mut h, &root().join("scenes/knot-on-floor.json"));
    // A render starts (a new camera), then, at once, a new build.
    h.state_mut().act(Action::Orbit(40.0, 0.0));
    h.step();
    assert!(h.state().jobs.render.is_some(), "a render runs");
    assert_ne!(h.state().settings.build.strategy, Strategy::EqualCount);
    with_strategy(&mut h, Strategy::EqualCount);
    // The render stops for the build, and nothing renders while it runs.
    h.state_mut().reconcile();
    assert!(h.state().jobs.build.is_some() && h.state().jobs.render.is_none(), "the render was stopped for the build");
    while h.state().jobs.build.is_some() {
        assert!(h.state().jobs.render.is_none(), "no render while the build runs");
        h.step();
    }
    run_until(&mut h, "the equal-count build", |a| {
        a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == Strategy::EqualCount) && idle(a)
    });
    // What the build's clock measured is the build: a positive time, taken by the build job itself
    // (not compared with a timing here: the project measures speed in benchmarks, not tests).
    let app_ms = h.state().current_bvh().unwrap().bvh.build_time().as_secs_f64() * 1e3;
    assert!(app_ms > 0.0, "the build's own time is kept");
}
