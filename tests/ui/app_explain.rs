//! The app's explaining views driven as a user drives them: a pixel's ray pinned and stepped
//! through, nodes selected from the tree, the icicle and the viewport, the node inspector against
//! `bvhscope inspect`, the heatmap histogram's threshold, the build replay, two strategies side
//! by side. A module of the `app_ui` test binary (`app.rs`).

use super::*;

/// A click (press and release without moving) at a screen position.
fn click_at(h: &mut Harness<'_, BvhscopeApp>, pos: egui::Pos2) {
    click_with(h, pos, egui::Modifiers::NONE)
}

/// A click holding `modifiers`.
fn click_with(h: &mut Harness<'_, BvhscopeApp>, pos: egui::Pos2, modifiers: egui::Modifiers) {
    let input = h.input_mut();
    input.events.push(egui::Event::ModifiersChanged(modifiers));
    input.events.push(egui::Event::PointerMoved(pos));
    let button = |pressed| egui::Event::PointerButton { pos, button: egui::PointerButton::Primary, pressed, modifiers };
    input.events.push(button(true));
    h.step();
    h.input_mut().events.push(button(false));
    h.run_steps(3);
    h.input_mut().events.push(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
}

/// The frame pixel under a screen position of the viewport (as the viewport maps it).
fn pixel_under(app: &BvhscopeApp, pos: egui::Pos2) -> (u32, u32) {
    let (r, f) = (app.image_rect, &app.shown.as_ref().unwrap().frame);
    let (u, v) = ((pos.x - r.min.x) / r.width(), (pos.y - r.min.y) / r.height());
    ((u * f.width() as f32) as u32, (v * f.height() as f32) as u32)
}

/// Ctrl-clicking a pixel of a heatmap pins its ray (a plain click does not, until the Ray window
/// is open): its counts and hit are the heatmap's and the hover read-out's for that pixel (the
/// frame's counters), and the Ray window steps through it.
#[test]
fn clicking_a_pixel_pins_its_ray_and_the_ray_window_steps_through_it() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.get_by_label("Nodes visited").click();
    run_until(&mut h, "the heatmap", |a| idle(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some()));
    // The hottest pixel of the heatmap (the knot's view has a hole in its middle).
    let pos = {
        let app = h.state();
        let (r, f) = (app.image_rect, &app.shown.as_ref().unwrap().frame);
        let (w, hh) = (f.width(), f.height());
        let (x, y) = (0..hh)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter(|&(x, y)| f.sample(x, y).is_hit())
            .max_by_key(|&(x, y)| f.counters(x, y).nodes_visited)
            .unwrap();
        r.min + egui::vec2((x as f32 + 0.5) / w as f32 * r.width(), (y as f32 + 0.5) / hh as f32 * r.height())
    };
    click_at(&mut h, pos);
    assert!(h.state().pins.pinned.is_empty() && !h.state().ray_window, "a plain click pins nothing");
    click_with(&mut h, pos, egui::Modifiers::COMMAND);
    let app = h.state();
    assert_eq!(app.pins.pinned.len(), 1, "the Ctrl-click pinned a ray");
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

    // The window lists the steps (the chosen one also whole above the list) and steps through them.
    assert_eq!(
        h.get_all_by_label_contains("box of node 0: hit").count(),
        2,
        "the step chosen, and its line in the list"
    );
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

    // A neighbouring pixel, pinned too by a plain click now the Ray window is open (picking):
    // both are listed to compare; the newer one is selected.
    click_at(&mut h, pos + egui::vec2(1.0, 0.0));
    assert_eq!(h.state().pins.pinned.len(), 2);
    assert_eq!(h.state().pins.selected, 1);
    h.get_by_label("Pinned ray");
    // Exported counts carry the same numbers for the pinned pixel.
    let path = crate::support::scratch::shared("ui").join("counts.csv");
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
    focus_label(&mut h, "Origin");
    h.run_steps(1);
    type_keys(&mut h, "0, 0.3, 10");
    focus_label(&mut h, "Direction");
    h.run_steps(1);
    type_keys(&mut h, "0 0 -1");
    click_label(&mut h, "Pin typed ray");
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
    s.build.strategy = Strategy::Midpoint;
    s.build.layout = Layout::Binary;
    s.build.max_leaf_size = 2;
    s.trace.order = TraversalOrder::SplitAxisSign;
    s.trace.test = TriangleTest::MollerTrumbore;
    h.state_mut().act(Action::Edit(Box::new(s)));
    run_until(&mut h, "the midpoint build", |a| {
        idle(a) && a.shown.as_ref().is_some_and(|s| s.bvh.build_params().bvh.strategy == Strategy::Midpoint)
    });
    // The pixel of the frame's first hit, near its middle row.
    pin_first_hit(&mut h);
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
    click_label(&mut h, "+");
    h.run_steps(2);
    click_label_containing(&mut h, "node 2 · d1");
    run_until(&mut h, "node 2's inspection", |a| a.nodes.inspection.as_ref().is_some_and(|i| i.node == 2));
    {
        let app = h.state();
        let e = app.nodes.explained.as_ref().unwrap();
        let want = bvhscope::explain::inspect::inspect(&e.tree, &e.hierarchy, 2).unwrap();
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
        let (r, f) = (app.image_rect, &app.shown.as_ref().unwrap().frame);
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

/// The inspector's figures for a node are `bvhscope inspect`'s for the same node and build, its
/// EPO share included on a mesh of more than 4,096 triangles (where the tree's EPO is estimated:
/// the share of one node is still walked exactly, in both).
#[test]
fn the_node_inspector_and_bvhscope_inspect_agree() {
    let torus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/diagonal-rods.obj");
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
        if !s.splits_top_down() && *s != bvhscope::bvh::Strategy::Sbvh {
            assert!(m.is_none() && j.is_null(), "{s:?} prices no plane, in both");
            continue;
        }
        if m.is_none() && *s == bvhscope::bvh::Strategy::Sbvh {
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
    // (serde_json reads a float back to within an ulp: the printed figures are compared too.)
    let cli_share = v["epo_contribution"].as_f64().unwrap();
    assert!((cli_share - ins.epo_share).abs() <= 1e-15 * ins.epo_share.abs(), "{cli_share} vs {}", ins.epo_share);
    assert_eq!(format!("{cli_share:.4}"), format!("{:.4}", ins.epo_share), "the EPO share as both print it");
    assert!(ins.epo_share > 0.0, "node 3's share is not nothing");
    // The Node window prints that figure.
    h.step();
    h.step();
    h.get_by_label(&format!("{:.4}", ins.epo_share));
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

/// The statistics' EPO is `bvhscope stats`'s for the same mesh and build, to the last digit, and
/// so is its error where it is estimated (the bunny's 69,451 triangles are past what is summed
/// exactly within the budget): the same tree (the binary tree as built) and the same points.
#[test]
fn the_statistics_epo_is_bvhscope_stats_epo() {
    let Some(models) = common::shared_models() else { return };
    let bunny = models.join("stanford-bunny.obj");
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::Open, bunny.clone()));
    run_until(&mut h, "the bunny and its prepared tree", |a| {
        a.scene.source == SceneSource::File(bunny.clone())
            && idle(a)
            && a.nodes.current(a.current_bvh().map(|b| &b.bvh)).is_some()
    });
    let (epo, error) = {
        let a = h.state();
        let e = a.nodes.current(a.current_bvh().map(|b| &b.bvh)).unwrap();
        (e.epo, e.epo_error)
    };
    assert!(error.is_some(), "the bunny's EPO is estimated within the budget");
    let p = h.state().settings.build;
    let words = [
        "bvhscope".to_string(),
        "stats".into(),
        bunny.display().to_string(),
        "--strategy".into(),
        bvhscope::options::Choice::named(p.strategy).name.to_string(),
        "--layout".into(),
        bvhscope::options::Choice::named(p.layout).name.to_string(),
        "--no-rays".into(),
        "--format".into(),
        "json".into(),
    ];
    let cli = bvhscope::cli::Cli::from_words(&words).unwrap();
    let Some(bvhscope::cli::Command::Stats(args)) = cli.command else { panic!("not stats") };
    let v: serde_json::Value = serde_json::from_str(&bvhscope::cli::stats::output(&args).unwrap()).unwrap();
    assert_eq!(v["stats"]["epo"].as_f64(), Some(epo), "the same EPO");
    assert_eq!(v["stats"]["epo_error"].as_f64(), error, "the same error");
    // And the panel shows it as `stats` prints it.
    h.step();
    h.get_by_label(&bvhscope::bvh::epo::figure(epo, error));
}
