//! "Trace on: GPU" (issues 38 and 39): turned on by a click, the frames come from the GPU with the
//! CPU's per-pixel counts for the same camera, lbvh is built on the GPU (the CPU's tree, with its
//! phases in the statistics), and without an adapter the choice is greyed with the reason. The
//! GPU's part needs an adapter (lavapipe in CI): without one it prints a notice and passes, except
//! under `CI=true`.

use super::support::*;
use bvhscope::app::Probe;
use bvhscope::app::{Action, BvhscopeApp};
use bvhscope::bvh::{BuildParams, Bvh, Layout, Strategy};
use bvhscope::cli::Device;
use bvhscope::render::{render, RenderSettings, View};
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;

fn edit(h: &mut Harness<'_, BvhscopeApp>, change: impl Fn(&mut bvhscope::app::Settings)) {
    let mut s = h.state().settings.clone();
    change(&mut s);
    h.state_mut().act(Action::Edit(Box::new(s)));
    h.state_mut().reconcile();
}

/// The frame on screen, traced on the GPU, and the same BVH rendered on the CPU for its camera:
/// every pixel's hit and counts are equal.
fn assert_gpu_frame_is_the_cpus(h: &Harness<'_, BvhscopeApp>) {
    let s = h.state().shown.as_ref().expect("a frame on screen");
    assert!(s.gpu.is_some() && s.frame.is_complete() && s.frame.counted(), "a complete counted GPU frame");
    assert_eq!(s.bvh.build_params().bvh.layout, Layout::Binary, "the GPU walks the binary tree");
    let settings = RenderSettings { trace: s.trace, count: true, progressive: false, secondary: None };
    let cpu = render(&*s.bvh, &*s.bvh, &s.camera, &settings);
    let (w, h) = (s.camera.width, s.camera.height);
    assert!(w * h > 100_000, "a full-resolution frame ({w}x{h})");
    let hits = s.frame.full_samples().unwrap().iter().filter(|p| p.is_hit()).count();
    assert!(hits > 1000, "{hits} pixels hit");
    assert!(s.frame.counts_csv() == cpu.counts_csv(), "the GPU's counts CSV differs from the CPU's");
    assert_eq!(s.frame.full_samples(), cpu.full_samples(), "the same hits and normals");
}

#[test]
fn the_gpu_toggle_traces_frames_with_the_cpus_counts_and_builds_lbvh_there() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    run_until(&mut h, "the look for a GPU", |a| !matches!(a.jobs.gpu.probe, Probe::Looking));
    if let Probe::Missing(why) = &h.state().jobs.gpu.probe {
        assert!(std::env::var("CI").as_deref() != Ok("true"), "CI=true needs a GPU adapter: {why}");
        use std::io::Write;
        let _ = writeln!(std::io::stderr(), "notice: {why}; skipping the app's GPU test");
        return;
    }
    edit(&mut h, |s| s.view = View::Visits);
    run_until(&mut h, "the CPU heatmap", idle);
    assert!(h.state().shown.as_ref().unwrap().gpu.is_none());

    // A user's click on "GPU" in the View panel.
    h.get_by_label("GPU").click();
    h.step();
    assert_eq!(h.state().settings.device, Device::Gpu);
    let on_gpu = |a: &BvhscopeApp| idle(a) && a.shown.as_ref().is_some_and(|s| s.gpu.is_some());
    run_until(&mut h, "a frame traced on the GPU", on_gpu);
    assert_gpu_frame_is_the_cpus(&h);
    h.get_by_label("Traced on");
    let summary = h.state().shown.as_ref().unwrap().frame.ray_summary();
    assert_eq!(h.state().rays.map(|r| r.summary), Some(summary), "the statistics are the GPU frame's");

    // The warp view comes from the same counts.
    edit(&mut h, |s| s.view = View::WarpCost(bvhscope::render::warp::WarpSize::W32));
    run_until(&mut h, "the warp view on the GPU", |a| {
        on_gpu(a) && a.shown.as_ref().unwrap().style.view != View::Visits
    });
    assert_gpu_frame_is_the_cpus(&h);

    // LBVH is built on the GPU: core's tree node for node, with its phases in the statistics.
    edit(&mut h, |s| s.build.strategy = Strategy::Lbvh);
    let lbvh_on_gpu =
        |a: &BvhscopeApp| on_gpu(a) && a.current_bvh().is_some_and(|b| a.jobs.gpu.build_of(&b.bvh).is_some());
    run_until(&mut h, "lbvh built and traced on the GPU", lbvh_on_gpu);
    assert_gpu_frame_is_the_cpus(&h);
    let bvh = h.state().current_bvh().unwrap().bvh.clone();
    let bvhscope::bvh::SceneBvh::Single { bvh: bvhscope::bvh::AnyBvh::Binary(gpu_tree), mesh, .. } = &*bvh else {
        panic!("one binary BVH")
    };
    let params = BuildParams { strategy: Strategy::Lbvh, layout: Layout::Binary, ..gpu_tree.params };
    let cpu_tree = Bvh::build(mesh, &params);
    assert!(gpu_tree.nodes == cpu_tree.nodes && gpu_tree.prim_ids == cpu_tree.prim_ids, "the CPU's LBVH");
    h.get_by_label("GPU build");
    h.get_by_label_contains("sort");

    // Back to the CPU: its own frame again, and lbvh rebuilt on the CPU.
    h.get_by_label("CPU").click();
    h.step();
    let on_cpu = |a: &BvhscopeApp| {
        idle(a)
            && a.shown.as_ref().is_some_and(|s| s.gpu.is_none())
            && a.current_bvh().is_some_and(|b| a.jobs.gpu.build_of(&b.bvh).is_none())
    };
    run_until(&mut h, "the CPU's frame", on_cpu);
}

#[test]
fn without_an_adapter_the_gpu_choice_is_greyed_with_the_reason() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    run_until(&mut h, "the look for a GPU", |a| !matches!(a.jobs.gpu.probe, Probe::Looking));
    // What the probe reports on a machine without one (the GPU crate's message).
    let why = "no GPU adapter that runs compute shaders was found (backends: test)";
    h.state_mut().jobs.gpu.probe = Probe::Missing(why.into());
    h.step();
    // The reason shows on hovering the greyed choice.
    h.get_by_label("GPU").hover();
    // egui shows a tooltip after a delay; the harness steps time on by a frame each step.
    for _ in 0..60 {
        h.step();
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    h.get_by_label_contains(&format!("No GPU: {why}"));
    h.get_by_label("GPU").click();
    h.step();
    h.step();
    assert_eq!(h.state().settings.device, Device::Cpu, "a greyed choice cannot be taken");
    assert!(h.state().gpu_for_frames().is_none());
}
