//! The README's pictures of the app, made from the app itself: each sets the app up as the
//! picture shows it and writes a PNG rendered on the software GPU. Not a check (a picture must be
//! looked at): `BVHSCOPE_LOOK=DIR cargo test -p bvhscope-ui-tests --test app_ui look_ -- --ignored
//! --test-threads 1` writes them into DIR, to be looked at and copied to assets/screenshots/.

use super::support::*;
use bvhscope::app::{Action, AppOptions, BvhscopeApp};
use egui_kittest::Harness;
use std::path::PathBuf;

fn out_dir() -> PathBuf {
    let dir =
        PathBuf::from(std::env::var("BVHSCOPE_LOOK").unwrap_or_else(|_| std::env::temp_dir().display().to_string()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The app at a projector's 1280×720, drawn by wgpu.
fn projector() -> Harness<'static, BvhscopeApp> {
    Harness::builder()
        .with_size(egui::vec2(1280.0, 720.0))
        .wgpu()
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()))
}

/// The app at the README's window size, drawn by wgpu.
fn looking() -> Harness<'static, BvhscopeApp> {
    Harness::builder()
        .with_size(egui::vec2(1400.0, 860.0))
        .wgpu()
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()))
}

fn save(h: &mut Harness<'_, BvhscopeApp>, name: &str) {
    for _ in 0..4 {
        h.step();
    }
    let img = h.render().expect("a wgpu adapter (Mesa's lavapipe)");
    let path = out_dir().join(format!("{name}.png"));
    img.save(&path).unwrap();
    eprintln!("wrote {}", path.display());
}

/// The Node window on the monkey's root: the three axes' curves, the legend beside them, the cost
/// of this tree's split term by term.
#[test]
#[ignore]
fn look_node_inspector() {
    let mut h = looking();
    open(&mut h, &root().join("scenes/monkey.json"));
    h.state_mut().act(Action::ShowTree(true));
    h.state_mut().act(Action::SelectNode(0));
    run_until(&mut h, "the root's inspection", |a| {
        a.nodes.inspection.as_ref().is_some_and(|i| i.node == 0) && a.nodes.visits.is_some()
    });
    save(&mut h, "app-node-inspector");
    h.state_mut().act(Action::SharedCostScale(true));
    save(&mut h, "app-node-inspector-shared");
}

/// The Ray window on a deep walk: the knot on the floor, a pixel on the knot, midpoint's binary
/// tree (deep), at the last step.
#[test]
#[ignore]
fn look_ray_window() {
    let mut h = looking();
    open(&mut h, &root().join("scenes/knot-on-floor.json"));
    let (w, hgt) = h.state().viewport_pixels();
    h.state_mut().act(Action::PinPixel(w / 2, hgt / 3));
    for _ in 0..10 {
        h.step();
    }
    let n = h.state().pins.current().map_or(0, |r| r.trace.steps.len());
    h.state_mut().act(Action::RayStep(n.saturating_sub(1)));
    save(&mut h, "app-ray-trace");
}

/// The Grade report window over a class of three on the torus, ada chosen: her midpoint tree (A)
/// against SAH binned (B) on the report's camera, nodes visited per ray on one scale, with the
/// Imported BVH and Compare windows.
#[test]
#[ignore]
fn look_grade_report() {
    let report = super::app_grade::graded_class("look");
    let mut h = looking();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::OpenGradeReportFile(report));
    run_until(&mut h, "the report", |a| a.grade.report.is_some());
    h.state_mut().act(Action::View(2));
    h.state_mut().act(Action::ChooseStudent(0));
    run_until(&mut h, "ada against SAH binned", |a| {
        super::app_grade::student_shown(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some())
    });
    save(&mut h, "app-grade-report");
}

/// Trace on: GPU (issues 38 and 39): the default scene's heatmap of nodes visited, LBVH built and
/// traced on the GPU (lavapipe here), with the "Traced on" line and the GPU build's phases.
#[test]
#[ignore]
fn look_gpu_frame() {
    use bvhscope::app::Probe;
    let mut h = looking();
    run_until(&mut h, "the first frame", idle);
    run_until(&mut h, "the look for a GPU", |a| !matches!(a.jobs.gpu.probe, Probe::Looking));
    let mut s = h.state().settings.clone();
    s.view = bvhscope::render::View::Visits;
    s.build.strategy = bvhscope::bvh::Strategy::Lbvh;
    s.device = bvhscope::cli::Device::Gpu;
    h.state_mut().act(Action::Edit(Box::new(s)));
    h.state_mut().reconcile();
    run_until(&mut h, "lbvh built and traced on the GPU", |a| {
        idle(a)
            && a.shown.as_ref().is_some_and(|s| s.gpu.is_some())
            && a.current_bvh().is_some_and(|b| a.jobs.gpu.build_of(&b.bvh).is_some())
    });
    save(&mut h, "app-gpu-lbvh");
    // PLOC's rounds on the GPU too (its phases: clustering, the layout on the host).
    let mut s = h.state().settings.clone();
    s.build.strategy = bvhscope::bvh::Strategy::Ploc;
    h.state_mut().act(Action::Edit(Box::new(s)));
    h.state_mut().reconcile();
    run_until(&mut h, "ploc built and traced on the GPU", |a| {
        idle(a)
            && a.shown.as_ref().is_some_and(|s| s.gpu.is_some())
            && a.current_bvh().is_some_and(|b| b.bvh.label().contains("PLOC") && a.jobs.gpu.build_of(&b.bvh).is_some())
    });
    save(&mut h, "app-gpu-ploc");
}

/// The app as a room sees it (issue 48): at 1280×720, at scale 1 and presenting (150 %), the
/// Node view on the knot-on-floor's root, a ray walked through midpoint's tree, and Compare's
/// difference; every view a tile beside the image.
#[test]
#[ignore]
fn look_projector() {
    for present in [false, true] {
        let suffix = if present { "-present" } else { "" };
        let scene = root().join("scenes/knot-on-floor.json");
        // The Node view.
        let mut h = projector();
        h.state_mut().act(Action::Present(present));
        open(&mut h, &scene);
        h.state_mut().act(Action::ShowTree(true));
        h.state_mut().act(Action::SelectNode(0));
        run_until(&mut h, "the root's inspection", |a| {
            a.nodes.inspection.as_ref().is_some_and(|i| i.node == 0) && a.nodes.visits.is_some()
        });
        save(&mut h, &format!("projector-node{suffix}"));
        // A ray's walk through midpoint's tree.
        let mut h = projector();
        h.state_mut().act(Action::Present(present));
        open(&mut h, &scene);
        with_strategy(&mut h, bvhscope::bvh::Strategy::Midpoint);
        run_until(&mut h, "midpoint's frame", |a| {
            idle(a) && a.current_bvh().is_some_and(|b| b.bvh.label().starts_with("Midpoint"))
        });
        let (w, hgt) = h.state().viewport_pixels();
        h.state_mut().act(Action::PinPixel(w / 2, hgt / 3));
        for _ in 0..10 {
            h.step();
        }
        h.state_mut().act(Action::RayStep(12));
        save(&mut h, &format!("projector-ray{suffix}"));
        // Compare: midpoint against SAH binned, the difference of nodes visited.
        h.state_mut().act(Action::UnpinAll);
        h.state_mut().act(Action::View(2));
        h.state_mut().act(Action::Compare(true));
        h.state_mut().act(Action::CompareMode(bvhscope::render::PairView::Difference));
        run_until(&mut h, "B", pair_shown);
        save(&mut h, &format!("projector-compare{suffix}"));
        // The build's replay after 40 splits, midpoint's, nodes visited.
        h.state_mut().act(Action::Compare(false));
        h.state_mut().act(Action::ShowReplay(true));
        run_until(&mut h, "the replay", |a| a.replay.replay.is_some());
        h.state_mut().act(Action::ReplayStep(40));
        run_until(&mut h, "the tree after 40 splits", |a| {
            idle(a) && a.shown.as_ref().is_some_and(|s| s.partial.as_ref().is_some_and(|p| p.splits == 40))
        });
        save(&mut h, &format!("projector-replay{suffix}"));
    }
}

/// The README's pictures of the main views in the docked layout (each redrawn when the layout
/// changed): the knot on the floor's normals with midpoint's boxes at depth 7 in front of the
/// surface; its nodes-visited heatmap on 0..30 after switching from midpoint to SAH binned;
/// midpoint against SAH binned side by side and as the difference.
#[test]
#[ignore]
fn look_main_views() {
    use bvhscope::bvh::Strategy;
    let scene = root().join("scenes/knot-on-floor.json");
    let mut h = looking();
    open(&mut h, &scene);
    let mut s = h.state().settings.clone();
    (s.build.strategy, s.build.layout) = (Strategy::Midpoint, bvhscope::bvh::Layout::Binary);
    (s.show_boxes, s.box_depth, s.boxes_in_front) = (true, 7, true);
    h.state_mut().act(Action::Edit(Box::new(s)));
    run_until(&mut h, "midpoint's boxes", |a| {
        idle(a) && a.current_bvh().is_some_and(|b| b.bvh.label().starts_with("Midpoint"))
    });
    save(&mut h, "app-normals-boxes");
    let mut s = h.state().settings.clone();
    s.show_boxes = false;
    s.view = bvhscope::render::View::Visits;
    s.fixed_ranges.insert(bvhscope::render::View::Visits, (0.0, 30.0));
    h.state_mut().act(Action::Edit(Box::new(s)));
    run_until(&mut h, "midpoint's heatmap", midpoint_heatmap_shown);
    with_strategy(&mut h, Strategy::SahBinned);
    run_until(&mut h, "SAH binned's heatmap", |a| {
        idle(a) && a.previous.is_some() && a.current_bvh().is_some_and(|b| b.bvh.label().starts_with("SAH binned"))
    });
    save(&mut h, "app-heatmap-legend");
    with_strategy(&mut h, Strategy::Midpoint);
    run_until(&mut h, "midpoint's heatmap", midpoint_heatmap_shown);
    h.state_mut().act(Action::Compare(true));
    run_until(&mut h, "B", pair_shown);
    save(&mut h, "app-compare-halves");
    h.state_mut().act(Action::CompareMode(bvhscope::render::PairView::Difference));
    save(&mut h, "app-compare-difference");
}

/// The View menu presenting at 1280×720 (issue 59): taller than the window, it scrolls: as it
/// opens, and scrolled to its end (Present, Size, Reset the layout).
#[test]
#[ignore]
fn look_view_menu_presenting() {
    use egui::accesskit::Role;
    use egui_kittest::kittest::Queryable;
    let mut h = projector();
    h.state_mut().act(Action::Present(true));
    run_until(&mut h, "the first frame", idle);
    h.get_by_role_and_label(Role::Button, "View").click();
    h.run_steps(3);
    save(&mut h, "projector-view-menu-present");
    h.get_by_role_and_label(Role::Button, "View").get_by_label("Reset the layout").scroll_to_me();
    save(&mut h, "projector-view-menu-present-end");
}

/// The heatmap with its legend at 1280×720 (issue 59): beside the image at scale 1, below it
/// presenting, and folded to its colour bar.
#[test]
#[ignore]
fn look_legend() {
    for present in [false, true] {
        let suffix = if present { "-present" } else { "" };
        let mut h = projector();
        h.state_mut().act(Action::Present(present));
        open(&mut h, &root().join("scenes/knot-on-floor.json"));
        h.state_mut().act(Action::View(2));
        run_until(&mut h, "the heatmap", |a| idle(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some()));
        h.state_mut().message(bvhscope::app::MessageKind::Info, "Opened knot-on-floor.json: 20,480 triangles");
        save(&mut h, &format!("projector-heatmap{suffix}"));
        h.state_mut().act(Action::FoldLegend(true));
        run_until(&mut h, "the image at its new size", idle);
        save(&mut h, &format!("projector-heatmap-folded{suffix}"));
    }
}

/// The build panel at 1280×720, at scale 1 and presenting: the sliders' labels whole (beside the
/// slider, or above it where the panel is too narrow), and the triangle test's list open.
#[test]
#[ignore]
fn look_triangle_test_list() {
    use egui::accesskit::Role;
    use egui_kittest::kittest::Queryable;
    for present in [false, true] {
        let mut h = projector();
        h.state_mut().act(Action::Present(present));
        run_until(&mut h, "the first frame", idle);
        let name = if present { "triangle-test-present" } else { "triangle-test" };
        save(&mut h, name);
        h.get_by_role_and_label(Role::ComboBox, "Triangle test").scroll_to_me();
        h.get_by_role_and_label(Role::ComboBox, "Triangle test").click();
        h.run_steps(3);
        save(&mut h, &format!("{name}-open"));
    }
}
