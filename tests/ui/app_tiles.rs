//! The explain views readable in a tile (issue 59, points 3, 4 and the icicle's scale), and one
//! pinned ray across the Ray view, the tree and the icicle.

use super::*;
use egui_kittest::kittest::NodeT;

/// The app at 1280×720 (a projector's size).
fn at_720() -> Harness<'static, BvhscopeApp> {
    Harness::builder()
        .with_size(egui::vec2(1280.0, 720.0))
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()))
}

/// The same, drawn by wgpu (to look at).
fn at_720_drawn() -> Harness<'static, BvhscopeApp> {
    Harness::builder()
        .with_size(egui::vec2(1280.0, 720.0))
        .wgpu()
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()))
}

/// The built-in scene with a ray pinned and the Tree and Node views open on the root.
fn explaining(h: &mut Harness<'_, BvhscopeApp>) {
    run_until(h, "the first frame", idle);
    h.state_mut().act(Action::ShowTree(true));
    h.state_mut().act(Action::SelectNode(0));
    run_until(h, "the prepared tree", |a| {
        idle(a) && a.nodes.current(a.current_bvh().map(|b| &b.bvh)).is_some() && a.nodes.inspection.is_some()
    });
    pin_first_hit(h);
    h.run_steps(3);
}

#[test]
#[ignore]
fn look_tiles_at_720() {
    let mut h = at_720_drawn();
    explaining(&mut h);
    let dir = std::env::var("BVHSCOPE_LOOK").unwrap_or("/tmp".into());
    // A step deep in the walk: the tree shows where the ray is.
    let n = h.state().pins.current().unwrap().len();
    h.state_mut().act(Action::RayStep(n * 2 / 3));
    for present in [false, true] {
        if h.state().pins.pinned.is_empty() {
            pin_first_hit(&mut h);
        }
        h.state_mut().act(Action::Present(present));
        for _ in 0..6 {
            h.step();
        }
        let img = h.render().expect("a wgpu adapter");
        img.save(format!("{dir}/tiles-720-{present}.png")).unwrap();
        // The Node view's table (the Ray view closed for the room) and its first plot's legend.
        h.state_mut().act(Action::UnpinAll);
        h.run_steps(2);
        h.get_by_label("Cost").scroll_to_me();
        for _ in 0..4 {
            h.step();
        }
        h.render().unwrap().save(format!("{dir}/tiles-720-{present}-table.png")).unwrap();
        h.get_all_by_label("as a leaf").next().unwrap().scroll_to_me();
        for _ in 0..4 {
            h.step();
        }
        h.render().unwrap().save(format!("{dir}/tiles-720-{present}-legend.png")).unwrap();
    }
}

/// The topmost widget labelled `label` (a tile's tab is above anything in its tile).
fn topmost(h: &Harness<'_, BvhscopeApp>, label: &str) -> egui::Rect {
    h.get_all_by_label(label).map(|n| n.rect()).min_by(|a, b| a.min.y.total_cmp(&b.min.y)).unwrap()
}

/// The Ray tile's rectangle below its tab: the right column, down to the Node tile's tab.
fn ray_tile(h: &Harness<'_, BvhscopeApp>) -> egui::Rect {
    let (ray, node) = (topmost(h, "Ray"), topmost(h, "Node"));
    egui::Rect::from_min_max(egui::pos2(ray.min.x - 8.0, ray.max.y), egui::pos2(h.ctx.content_rect().max.x, node.min.y))
}

/// The rows of the step list ("   3  box of node 1: hit …") drawn inside `tile`'s height.
fn step_rows_in(h: &Harness<'_, BvhscopeApp>, tile: egui::Rect) -> usize {
    let row = |l: &str| {
        let t = l.trim_start();
        t.chars().next().is_some_and(|c| c.is_ascii_digit())
            && t.split_once("  ").is_some_and(|(n, _)| n.parse::<u32>().is_ok())
    };
    let by = egui_kittest::kittest::by().predicate(move |n| n.label().is_some_and(|l| row(&l)));
    // (A row's rectangle is as wide as its text, which scrolls sideways past the tile.)
    let (top, bottom) = (tile.min.y, tile.max.y);
    h.query_all(by)
        .filter(|n| n.rect().min.y >= top && n.rect().max.y <= bottom && n.rect().min.x >= tile.min.x)
        .count()
}

/// At 1280×720 with the Tree and Node views open too, the Ray tile shows eight rows of steps
/// or more, and its First, Last and step slider lie inside it; presenting (F5), the controls
/// still do (they were off its right edge) (issue 59, point 4).
#[test]
fn the_ray_tile_shows_eight_steps_and_its_controls_at_720() {
    let mut h = at_720();
    explaining(&mut h);
    let n = h.state().pins.current().unwrap().len();
    assert!(n > 8, "{n} steps");
    // A step deep in the walk: the tree shows where the ray is.
    let n = h.state().pins.current().unwrap().len();
    h.state_mut().act(Action::RayStep(n * 2 / 3));
    for present in [false, true] {
        h.state_mut().act(Action::Present(present));
        h.run_steps(4);
        let tile = ray_tile(&h);
        for b in ["First", "Back", "Step", "Last"] {
            let r = h.get_by_label(b).rect();
            assert!(tile.contains_rect(r), "presenting {present}: {b} {r:?} inside the Ray tile {tile:?}");
        }
        let slider = h.get_by_role_and_label(Role::Slider, &format!("of {n}")).rect();
        assert!(tile.contains_rect(slider), "presenting {present}: the slider {slider:?} inside {tile:?}");
        let rows = step_rows_in(&h, tile);
        eprintln!("presenting {present}: the Ray tile {tile:?} ({} points tall) shows {rows} step rows", tile.height());
        if !present {
            assert!(rows >= 8, "{rows} rows of steps in the Ray tile {tile:?}");
        }
    }
}

/// The Node table on LBVH's root in the right column at 1280×720: LBVH and PLOC price no plane,
/// and say why under the table, not in a cell as wide as the table; scrolled sideways to its
/// Cost column, the strategies' names stay in the tile (issue 59, point 3).
#[test]
fn the_node_table_keeps_its_names_in_view_and_its_notes_below() {
    let mut h = at_720();
    run_until(&mut h, "the first frame", idle);
    with_strategy(&mut h, bvhscope::bvh::Strategy::Lbvh);
    h.state_mut().act(Action::ShowTree(true));
    run_until(&mut h, "LBVH", |a| {
        idle(a) && a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == bvhscope::bvh::Strategy::Lbvh)
    });
    h.state_mut().act(Action::SelectNode(0));
    run_until(&mut h, "the root's inspection", |a| a.nodes.inspection.as_ref().is_some_and(|i| i.node == 0));
    h.run_steps(3);
    let (names, cost) = (h.get_by_label("Strategy").rect(), h.get_by_label("Cost").rect());
    assert!(cost.max.x - names.min.x < 560.0, "the table is as wide as its figures: {names:?} to {cost:?}");
    let note = h.get_by_label("¹ LBVH (Morton), PLOC: no plane priced here: it builds from the Morton order").rect();
    assert!(note.min.y > cost.max.y, "the note {note:?} is under the table");
    assert_eq!(h.query_all_by_label("— ¹").count(), 2, "LBVH's and PLOC's rows mark the note");
    let left = topmost(&h, "Node").min.x - 8.0;
    h.get_by_label("Cost").scroll_to_me();
    h.run_steps(3);
    let right = h.ctx.content_rect().max.x;
    let inside = |r: egui::Rect| r.min.x >= left && r.max.x <= right + 0.5;
    let cost = h.get_by_label("Cost").rect();
    assert!(inside(cost), "Cost {cost:?} in the tile, from x {left}");
    for name in ["Strategy", "LBVH (Morton) (this tree)", "SAH binned", "PLOC"] {
        let r = h.get_by_label(name).rect();
        assert!(inside(r), "{name} {r:?} stays in the tile (from x {left}) with Cost in view");
    }
}

/// At 1280×720, and presenting, each axis's plot names its lines in a legend that lies inside
/// the Node tile (its names wrap rather than run off the tile's edge) (issue 59, point 3).
#[test]
fn each_cost_plot_has_its_legend_inside_the_tile() {
    let mut h = at_720();
    explaining(&mut h);
    h.state_mut().act(Action::UnpinAll);
    for present in [false, true] {
        h.state_mut().act(Action::Present(present));
        h.run_steps(4);
        let left = topmost(&h, "Node").min.x - 8.0;
        let right = h.ctx.content_rect().max.x;
        let sweep = format!("{}: every plane", bvhscope::bvh::Strategy::SahSweep.label());
        assert_eq!(h.query_all_by_label(&sweep).count(), 3, "one legend per axis");
        for entry in [sweep.as_str(), "as a leaf", "| SAH binned (this tree)"] {
            let n = h.query_all_by_label(entry).count();
            assert!(n >= 1, "{entry}");
            for k in 0..n {
                h.query_all_by_label(entry).nth(k).unwrap().scroll_to_me();
                h.run_steps(2);
                let r = h.query_all_by_label(entry).nth(k).unwrap().rect();
                assert!(
                    r.min.x >= left && r.max.x <= right + 0.5,
                    "presenting {present}: {entry} {r:?} inside the tile from x {left}"
                );
            }
        }
    }
}

/// A click of the pointer at `pos`.
fn click_at(h: &mut Harness<'_, BvhscopeApp>, pos: egui::Pos2) {
    h.input_mut().events.push(egui::Event::PointerMoved(pos));
    h.step();
    for pressed in [true, false] {
        h.input_mut().events.push(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
        h.step();
    }
    h.run_steps(2);
}

/// The tree row of `node` ("leaf 17 · d5 · …" or "node 17 · …").
fn row_of(h: &Harness<'_, BvhscopeApp>, node: u32) -> String {
    let (a, b) = (format!("leaf {node} · "), format!("node {node} · "));
    let by = egui_kittest::kittest::by()
        .predicate(move |n| n.label().is_some_and(|l| l.starts_with(&a) || l.starts_with(&b)));
    h.query_all(by).next().and_then(|n| n.accesskit_node().label()).unwrap_or_else(|| panic!("no row of node {node}"))
}

/// One ray across the views (Madan & Nobre's synchronised query view): the pinned ray's entered
/// nodes are marked in the tree's rows with the step that entered them; stepping in the Ray view
/// moves the tree to the node the walk is at (its row shown, the ancestors opened), the leaf of
/// the closest hit at the step that finds it; a click on a marked row or on the icicle's root
/// takes the Ray view to the step that entered that node (issue 59).
#[test]
fn one_pinned_ray_across_the_ray_view_the_tree_and_the_icicle() {
    use bvhscope::bvh::StepKind;
    let mut h = harness();
    explaining(&mut h);
    h.get_by_label_contains("at step 1: the root's box test");
    // Step 2 enters the root.
    h.state_mut().act(Action::RayStep(1));
    h.run_steps(3);
    h.get_by_label_contains("at step 2: node 0");
    assert!(row_of(&h, 0).ends_with(" · ray @ step 2"), "{}", row_of(&h, 0));
    // The step that finds the closest hit: the walk is at the leaf holding that triangle.
    let (k, leaf) = {
        let a = h.state();
        let r = a.pins.current().unwrap();
        let hit = r.hit.expect("the pixel's ray hits");
        let k = r.trace.steps.iter().rposition(|s| matches!(s.kind, StepKind::ClosestHit { .. })).unwrap();
        (k, a.nodes.explained.as_ref().unwrap().hierarchy.leaf_of_prim(hit.prim).unwrap())
    };
    h.state_mut().act(Action::RayStep(k));
    h.run_steps(3);
    h.get_by_label_contains(&format!("at step {}: node {leaf}", k + 1));
    let row = row_of(&h, leaf);
    assert!(row.starts_with("leaf ") && row.contains(" · ray @ step "), "{row}");
    // Back to the start, the leaf selected (its row stays open): a click on it goes to its step.
    h.state_mut().act(Action::SelectNode(leaf));
    h.state_mut().act(Action::RayStep(0));
    h.run_steps(3);
    let entered: usize = row_of(&h, leaf).rsplit("ray @ step ").next().unwrap().parse().unwrap();
    click_label_containing(&mut h, &format!("leaf {leaf} · "));
    h.run_steps(2);
    let step = h.state().pins.step;
    assert_eq!(step + 1, entered, "the Ray view at the step that entered leaf {leaf}");
    let kind = &h.state().pins.current().unwrap().trace.steps[step].kind;
    assert!(matches!(kind, StepKind::Leaf { .. } | StepKind::Enter { .. }), "{kind:?}");
    assert!(step <= k, "the hit's leaf is entered before its hit is found");
    h.get_by_label_contains(&format!("at step {}: node {leaf}", step + 1));
    // The icicle's top row is the root: a click there goes to the step entering it.
    let icicle = h.get_by_label("Icicle of the tree").rect();
    click_at(&mut h, egui::pos2(icicle.center().x, icicle.top() + 6.0));
    assert_eq!(h.state().nodes.selected, Some(0));
    assert_eq!(h.state().pins.step, 1, "the root is entered at step 2");
}

/// The icicle coloured by EPO share names its colour scale and its two ends (the scale was
/// nowhere, and a square root to the largest share left most nodes dark) (issue 59, point 8).
#[test]
fn the_icicle_shows_its_colour_scale() {
    let mut h = harness();
    explaining(&mut h);
    h.get_by_label_contains("Colour scale: visits, log, ");
    h.state_mut().act(Action::SetMetric(bvhscope::app::Metric::Epo));
    h.run_steps(3);
    let label = {
        let n = h.get_by_label_contains("Colour scale: EPO share, log, ").accesskit_node();
        n.label().or_else(|| n.value()).unwrap()
    };
    let hi = {
        let e = h.state().nodes.explained.clone().unwrap();
        e.epo_terms.iter().copied().fold(0.0, f64::max)
    };
    assert!(
        label.ends_with(&format!(" to {hi:.4}")) || label.ends_with(&format!(" to {hi:.2e}")),
        "{label} (largest {hi})"
    );
    h.state_mut().act(Action::SetMetric(bvhscope::app::Metric::Depth));
    h.run_steps(3);
    h.get_by_label_contains("Colour scale: depth, linear, 0 to ");
}

/// The Node view's table on LBVH's root in a tall window (to look at its footnote).
#[test]
#[ignore]
fn look_node_table_tall() {
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 1700.0))
        .wgpu()
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()));
    run_until(&mut h, "the first frame", idle);
    with_strategy(&mut h, bvhscope::bvh::Strategy::Lbvh);
    h.state_mut().act(Action::ShowTree(true));
    run_until(&mut h, "LBVH", |a| {
        idle(a) && a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == bvhscope::bvh::Strategy::Lbvh)
    });
    h.state_mut().act(Action::SelectNode(0));
    run_until(&mut h, "the root's inspection", |a| a.nodes.inspection.as_ref().is_some_and(|i| i.node == 0));
    for _ in 0..6 {
        h.step();
    }
    let dir = std::env::var("BVHSCOPE_LOOK").unwrap_or("/tmp".into());
    h.render().unwrap().save(format!("{dir}/node-table-tall.png")).unwrap();
}
