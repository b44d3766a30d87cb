//! The app's build time against the build's alone: a test binary of its own, so that no other
//! test shares the cores while it times (cargo runs test binaries one after another).

mod support;
use support::*;

use bvhscope::app::Action;
use bvhscope::bvh::SplitStrategy;

/// A build started while the previous frame still renders waits for the render to stop: its time
/// is the build's alone, as `stats` measures it (it used to be several times more, and the
/// Compare window once showed a negative difference). Generous bounds: timings are noisy, but
/// contention made it 6 to 9 times the CLI's.
#[test]
fn the_build_time_is_the_builds_alone() {
    let mut h = harness();
    open(&mut h, &root().join("scenes/knot-on-floor.json"));
    // A render starts (a new camera), then, at once, a new build.
    h.state_mut().act(Action::Orbit(40.0, 0.0));
    h.step();
    assert!(h.state().jobs.render.is_some(), "a render runs");
    assert_ne!(h.state().settings.build.strategy, SplitStrategy::EqualCount);
    with_strategy(&mut h, SplitStrategy::EqualCount);
    // The render stops for the build, and nothing renders while it runs.
    h.state_mut().reconcile();
    assert!(h.state().jobs.build.is_some() && h.state().jobs.render.is_none(), "the render was stopped for the build");
    while h.state().jobs.build.is_some() {
        assert!(h.state().jobs.render.is_none(), "no render while the build runs");
        h.step();
    }
    run_until(&mut h, "the equal-count build", |a| {
        a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == SplitStrategy::EqualCount) && idle(a)
    });
    let app_ms = h.state().current_bvh().unwrap().bvh.build_time().as_secs_f64() * 1e3;
    // The same build, alone, three times.
    let scene = h.state().scene.clone();
    let params = h.state().wanted_build();
    let alone = (0..3)
        .map(|_| {
            let b = scene.build(&params, &bvhscope::work::WorkControl::new()).unwrap();
            b.build_time().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min);
    assert!(app_ms <= 3.0 * alone + 5.0, "the app's build took {app_ms:.2} ms, alone it takes {alone:.2} ms");
}
