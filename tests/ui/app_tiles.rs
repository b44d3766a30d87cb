//! The explain views readable in a tile (issue 59, points 3, 4 and the icicle's scale), and one
//! pinned ray across the Ray view, the tree and the icicle.

use super::*;

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
    for present in [false, true] {
        h.state_mut().act(Action::Present(present));
        for _ in 0..6 {
            h.step();
        }
        let img = h.render().expect("a wgpu adapter");
        img.save(format!("{dir}/tiles-720-{present}.png")).unwrap();
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

/// Presenting at 1280×720, each axis's plot names its lines in a legend that lies inside the
/// Node tile (its names wrap rather than run off the tile's edge) (issue 59, point 3).
#[test]
fn presenting_each_cost_plot_has_its_legend_inside_the_tile() {
    let mut h = at_720();
    explaining(&mut h);
    h.state_mut().act(Action::UnpinAll);
    h.state_mut().act(Action::Present(true));
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
            assert!(r.min.x >= left && r.max.x <= right + 0.5, "{entry} {r:?} inside the tile from x {left}");
        }
    }
}
