//! The Node window: the selected node of the binary tree explained (`explain::inspect`, the same
//! figures as `bvhscope inspect`): its breadcrumb, its figures, and per axis the SAH cost of
//! splitting its triangles at every candidate plane (the exact sweep as a line, the binned SAH's
//! bins as steps), with where each strategy puts its plane and the cost of a leaf.

use crate::app::state::{Action, Actions, BvhscopeApp};
use crate::app::views::NodeStep;
use crate::bvh::Strategy;
use crate::explain::inspect::{CurvePoint, Inspection};
use egui::Color32;
use egui_plot::{HLine, Line, LineStyle, Plot, PlotPoints, VLine};

mod table;

const AXES: [&str; 3] = ["x", "y", "z"];

/// Each strategy's marker colour: the strategies' table order picks it, so a strategy added to
/// the table has its own without naming it here.
pub fn strategy_color(s: Strategy) -> Color32 {
    const PALETTE: [Color32; 8] = [
        Color32::from_rgb(240, 120, 60),
        Color32::from_rgb(200, 120, 230),
        Color32::from_rgb(90, 200, 250),
        Color32::from_rgb(120, 230, 120),
        Color32::from_rgb(240, 120, 200),
        Color32::from_rgb(160, 140, 255),
        Color32::from_rgb(250, 220, 80),
        Color32::from_rgb(110, 220, 200),
    ];
    let k = Strategy::ALL.iter().position(|&x| x == s).unwrap_or(0);
    PALETTE[k % PALETTE.len()]
}

/// Whether the view is open (its tile shown).
pub fn is_open(app: &BvhscopeApp) -> bool {
    app.nodes.window && app.nodes.selected.is_some()
}

/// The view's contents, in its tile (`panels::tiles`).
pub fn ui(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let nodes = &app.nodes;
    let (Some(node), true) = (nodes.selected, nodes.window) else { return };
    // The tile's width, before a wide line widens the scrolled contents: the table and the plots
    // fit in it (they were laid out in the widened width and ran off the tile).
    let width = ui.available_width();
    let bvh = app.current_bvh().map(|b| b.bvh.clone());
    let Some(e) = nodes.current(bvh.as_ref()) else {
        ui.weak("Preparing the tree…");
        return;
    };
    // The breadcrumb: the root down to the node, each a button.
    let path = e.hierarchy.path(node);
    ui.horizontal_wrapped(|ui| {
        ui.label("Path:");
        let skip = path.len().saturating_sub(14);
        if skip > 0 {
            ui.weak("0 > … >");
        }
        for &a in &path[skip..] {
            if ui.selectable_label(a == node, a.to_string()).on_hover_text(format!("Select node {a}")).clicked() {
                out.push(Action::SelectNode(a));
            }
        }
    });
    ui.horizontal(|ui| {
        for (label, step, key) in [
            ("Parent", NodeStep::Parent, "Up"),
            ("Left child", NodeStep::Left, "Left"),
            ("Right child", NodeStep::Right, "Right"),
            ("Sibling", NodeStep::Sibling, "Down"),
        ] {
            let enabled = nodes.step(step).is_some();
            let b = ui.add_enabled(enabled, egui::Button::new(label));
            if b.on_hover_text(format!("Key: Alt+{key}")).clicked() {
                out.push(Action::NodeStep(step));
            }
        }
    });
    ui.separator();
    let Some(ins) = nodes.inspection.as_ref().filter(|i| i.node == node) else {
        ui.weak(format!("Inspecting node {node}…"));
        return;
    };
    let visits = nodes.visits.as_ref().filter(|v| std::sync::Arc::ptr_eq(&v.explained, e));
    let visits = visits.map(|v| (v.counts[node as usize], v.camera.width, v.camera.height));
    figures(ui, ins, ins.epo_share, visits);
    let imported = e.bvh.import();
    if let Some(names) = imported {
        let d = crate::explain::inspect::text::dump_text(names.dump_of_binary_node(node));
        ui.label(format!("Imported from {}: dump node {d}.", names.name))
            .on_hover_text("The node's id in the dump; bvhscope inspect MESH --bvh DUMP --node ID takes that id");
    }
    let layout = e.bvh.build_params().bvh.layout;
    if imported.is_none() {
        if let Some(g) = crate::bvh::wide::wide_group_in(layout, &e.tree.nodes, &e.hierarchy, node) {
            ui.label(crate::explain::inspect::text::wide_group_text(node, &g)).on_hover_text(
                "A wide layout collapses the binary tree: a wide node takes binary nodes below one of them as its up to four (or eight) children, grouped so that the wide nodes' summed surface area (their SAH cost) is least",
            );
        }
    }
    ui.separator();
    // An imported tree has no strategy of bvhscope's: its own split is drawn as its cost.
    let own = imported.is_none().then_some(e.tree.params.strategy);
    if ins.triangles >= 2 {
        table::planes(ui, ins, own, width);
        ui.separator();
    }
    // Presenting, each plot is half the tile tall (a back row reads its curves).
    let present = app.settings.present;
    let height = if present { (ui.clip_rect().height() * 0.5).max(PLOT_HEIGHT) } else { PLOT_HEIGHT };
    if ins.triangles < 2 {
        ui.weak("One triangle: nothing to split.");
    } else {
        let whose = match (own, ins.own_cost) {
            (Some(s), _) => format!("this tree's strategy is {}", s.label()),
            (None, Some(c)) => format!("this tree's own split costs {c:.3} (the red line)"),
            (None, None) => "this imported node is a leaf".into(),
        };
        ui.label(format!(
            "SAH cost of splitting these {} triangles at each plane (C_trav + C_isect (A_L n_L + A_R n_R) / A); {whose}.",
            ins.triangles
        ));
        if let Some(line) = crate::explain::inspect::text::sbvh_text(ins) {
            ui.label(line).on_hover_text(
                "Stich et al. 2009: the SBVH prices spatial splits (which cut triangles straddling the plane) only where the object split's two boxes overlap by more than α of the root's area, while its budget of extra references lasts",
            );
        }
        let mut shared = app.nodes.shared_scale;
        if ui
            .checkbox(&mut shared, "One cost scale for the three axes")
            .on_hover_text("Draw x, y and z on the same cost range, so their costs compare across plots")
            .changed()
        {
            out.push(Action::SharedCostScale(shared));
        }
        let range = shared.then(|| cost_range(ins));
        for axis in 0..3 {
            curve_plot(ui, ins, axis, own, range, Size { height, width, present });
        }
    }
}

/// What closing the view's tile asks for.
pub fn close() -> Action {
    Action::ShowTree(false)
}

fn figures(ui: &mut egui::Ui, ins: &Inspection, epo: f64, visits: Option<(u32, u32, u32)>) {
    egui::Grid::new("node-figures").num_columns(2).striped(true).show(ui, |ui| {
        let mut row = |k: &str, v: String, tip: &str| {
            ui.label(k).on_hover_text(tip);
            ui.add(egui::Label::new(v).wrap());
            ui.end_row();
        };
        let kind = match (ins.children, ins.split_axis) {
            (Some([l, r]), Some(a)) => format!("interior: children {l} and {r}, split on {}", AXES[a as usize]),
            _ => "leaf".to_string(),
        };
        row("Node", format!("{} (depth {})", ins.node, ins.depth), "Its id in the binary tree as built (as `bvhscope inspect --node` takes it)");
        row("Kind", kind, "");
        row("Triangles", ins.triangles.to_string(), "Triangles in its subtree");
        let ratio = ins.area_ratio.map_or(String::new(), |r| format!(" ({:.1}% of its parent's)", 100.0 * r));
        row("Surface area", format!("{:.4}{ratio}", ins.area), "The surface area of its box; a ray enters it with probability area / parent's area");
        row("Subtree SAH", format!("{:.3}", ins.subtree_sah), "The SAH cost of its subtree, relative to its own area: the expected cost of a ray that enters its box");
        if let Some(o) = ins.child_overlap {
            row("Children overlap", format!("volume {:.4}, area {:.4}", o.volume, o.area), "The box the two children's boxes share: rays there must visit both");
        }
        row("EPO share", format!("{epo:.4}"), "Its term of the tree's end-point overlap (Aila, Karras & Laine 2013): the surface of other subtrees' triangles inside its box, weighted by its cost and over the total surface");
        row("As a leaf", format!("{:.3}", ins.leaf_cost), "What making it a leaf would cost: C_isect × triangles");
        let visits = visits.map_or("…".into(), |(v, w, h)| format!("{v} of the {w}×{h} frame's primary rays"));
        row("Visits", visits, "Primary rays of the frame on screen that entered it (a binary traversal of the same rays; `bvhscope inspect --size WxH` counts the same frame)");
    });
}

/// Most points a curve is drawn with: a root of millions of triangles has a candidate plane per
/// centroid, more than a plot can redraw each frame.
const MAX_PLOTTED: usize = 4000;

/// The curve for drawing: all of it when short; else, for each of `MAX_PLOTTED / 2` runs of
/// neighbouring planes, its cheapest and its dearest point in order, so the shape, and the minimum
/// the sweep takes, stay exactly where they are.
fn thinned(points: &[CurvePoint]) -> Vec<CurvePoint> {
    if points.len() <= MAX_PLOTTED {
        return points.to_vec();
    }
    let run = points.len().div_ceil(MAX_PLOTTED / 2);
    let mut out = Vec::with_capacity(MAX_PLOTTED);
    for chunk in points.chunks(run) {
        let lo = chunk.iter().min_by(|a, b| a.cost.total_cmp(&b.cost)).copied();
        let hi = chunk.iter().max_by(|a, b| a.cost.total_cmp(&b.cost)).copied();
        if let (Some(lo), Some(hi)) = (lo, hi) {
            let (a, b) = if lo.position <= hi.position { (lo, hi) } else { (hi, lo) };
            out.push(a);
            if b != a {
                out.push(b);
            }
        }
    }
    out
}

/// Points of a staircase through the binned planes: each plane's cost held until the next one.
fn steps(points: &[CurvePoint]) -> Vec<[f64; 2]> {
    let mut out = Vec::with_capacity(points.len() * 2);
    for (i, p) in points.iter().enumerate() {
        out.push([p.position as f64, p.cost as f64]);
        if let Some(next) = points.get(i + 1) {
            out.push([next.position as f64, p.cost as f64]);
        }
    }
    out
}

/// Height of each axis's plot: tall enough for tick labels on both axes at the default window size.
const PLOT_HEIGHT: f32 = 170.0;
/// Width of the legend beside each plot (the curves stay uncovered).
const LEGEND_WIDTH: f32 = 150.0;

/// How large a plot is drawn: its height, and whether its notes are full size (presenting).
#[derive(Clone, Copy)]
struct Size {
    height: f32,
    width: f32,
    present: bool,
}

impl Size {
    fn note(self, text: String) -> egui::RichText {
        if self.present {
            egui::RichText::new(text)
        } else {
            egui::RichText::new(text).small()
        }
    }
}

/// The lowest and highest cost drawn on any axis's plot: the shared scale.
fn cost_range(ins: &Inspection) -> (f32, f32) {
    let mut lo = ins.leaf_cost.min(ins.own_cost.unwrap_or(f32::INFINITY));
    let mut hi = ins.leaf_cost.max(ins.own_cost.unwrap_or(f32::NEG_INFINITY));
    for a in 0..3 {
        for p in ins.sweep[a].iter().chain(&ins.binned[a]).chain(&ins.spatial[a]) {
            lo = lo.min(p.cost);
            hi = hi.max(p.cost);
        }
    }
    (lo, hi)
}

/// The plane nearest `x` on a curve.
fn nearest(points: &[CurvePoint], x: f64) -> Option<&CurvePoint> {
    points.iter().min_by(|a, b| (a.position as f64 - x).abs().total_cmp(&(b.position as f64 - x).abs()))
}

/// One axis: the curves (each named by its strategy, as the options table names it), where each
/// strategy puts its plane, the cost of a leaf; the legend beside the plot; below it the cost of
/// the plane under the pointer (or of this tree's own split) term by term. `own`: the tree's
/// strategy, whose marker is "(this tree)"; `None` for an imported tree, whose own split is drawn
/// as a line at its cost. `shared`: the cost range all three axes are drawn on, when one scale is
/// asked for.
fn curve_plot(
    ui: &mut egui::Ui,
    ins: &Inspection,
    axis: usize,
    own: Option<Strategy>,
    shared: Option<(f32, f32)>,
    size: Size,
) {
    let (sweep, binned, spatial) = (&ins.sweep[axis], &ins.binned[axis], &ins.spatial[axis]);
    let cuts = if spatial.is_empty() { String::new() } else { format!(", {} spatial planes", spatial.len()) };
    ui.label(format!(
        "Axis {}: {} candidate planes, {} bins' planes ({} bins){cuts}",
        AXES[axis],
        sweep.len(),
        binned.len(),
        ins.bins
    ));
    if sweep.is_empty() {
        ui.weak("The centroids do not spread along this axis.");
        return;
    }
    let (sweep_name, binned_name, spatial_name) =
        (Strategy::SahSweep.label(), Strategy::SahBinned.label(), Strategy::Sbvh.label());
    let markers: Vec<(Strategy, crate::explain::inspect::Marker)> =
        ins.markers.iter().filter_map(|(s, m)| m.filter(|m| m.axis as usize == axis).map(|m| (*s, m))).collect();
    let mut hovered = None;
    // The legend beside the plot where the tile is wide enough, else below it (a narrow tile,
    // or a presenter's large text).
    let beside = size.width > 3.0 * LEGEND_WIDTH;
    let layout =
        if beside { egui::Layout::left_to_right(egui::Align::Min) } else { egui::Layout::top_down(egui::Align::Min) };
    ui.with_layout(layout, |ui| {
        let width = if beside { (size.width - LEGEND_WIDTH - 8.0).max(160.0) } else { size.width };
        let mut plot = Plot::new(("node-curve", axis))
            .height(size.height)
            .width(width)
            .allow_scroll(false)
            .show_axes(true)
            .y_axis_min_width(40.0)
            .x_axis_label(AXES[axis])
            .y_axis_label("cost");
        if let Some((lo, hi)) = shared {
            plot = plot.include_y(lo).include_y(hi);
        }
        plot.show(ui, |p| {
            let line: PlotPoints = thinned(sweep).into_iter().map(|q| [q.position as f64, q.cost as f64]).collect();
            p.line(Line::new(sweep_name, line).color(strategy_color(Strategy::SahSweep)).width(1.5));
            if !binned.is_empty() {
                p.line(
                    Line::new(binned_name, PlotPoints::from(steps(binned)))
                        .color(strategy_color(Strategy::SahBinned))
                        .width(1.0)
                        .style(LineStyle::dashed_loose()),
                );
            }
            if !spatial.is_empty() {
                p.line(
                    Line::new(spatial_name, PlotPoints::from(steps(spatial)))
                        .color(strategy_color(Strategy::Sbvh))
                        .width(1.0)
                        .style(LineStyle::dashed_dense()),
                );
            }
            p.hline(HLine::new("as a leaf", ins.leaf_cost as f64).color(LEAF_COLOR).style(LineStyle::dotted_dense()));
            if let (None, Some(c)) = (own, ins.own_cost) {
                p.hline(HLine::new("this tree's split", c as f64).color(OWN_COLOR).width(2.0));
            }
            for (s, m) in &markers {
                let width = if Some(*s) == own { 2.5 } else { 1.5 };
                p.vline(VLine::new(s.label(), m.position as f64).color(strategy_color(*s)).width(width));
            }
            hovered = p.pointer_coordinate().and_then(|c| nearest(sweep, c.x).copied());
        });
        // The legend, one line per name.
        ui.vertical(|ui| {
            if beside {
                ui.set_width(LEGEND_WIDTH);
            }
            let swatch = |ui: &mut egui::Ui, color: Color32, text: String| {
                ui.horizontal(|ui| {
                    let (r, _) = ui.allocate_exact_size(egui::vec2(14.0, 10.0), egui::Sense::hover());
                    ui.painter().rect_filled(r, 2.0, color);
                    // Wrapped at the tile's edge: a narrow tile (presenting) cuts no name.
                    ui.add(egui::Label::new(size.note(text)).wrap());
                });
            };
            swatch(ui, strategy_color(Strategy::SahSweep), format!("{sweep_name}: every plane"));
            if !binned.is_empty() {
                swatch(ui, strategy_color(Strategy::SahBinned), format!("{binned_name}: its bins"));
            }
            if !spatial.is_empty() {
                swatch(ui, strategy_color(Strategy::Sbvh), format!("{spatial_name}: spatial"));
            }
            swatch(ui, LEAF_COLOR, "as a leaf".into());
            if let (None, Some(_)) = (own, ins.own_cost) {
                swatch(ui, OWN_COLOR, "this tree's split".into());
            }
            for (s, _) in &markers {
                let chosen = if Some(*s) == own { " (this tree)" } else { "" };
                swatch(ui, strategy_color(*s), format!("| {}{chosen}", s.label()));
            }
        });
    });
    // The cost term by term: of the plane under the pointer, else of this tree's split here.
    let chosen = markers.iter().find(|(s, _)| Some(*s) == own).map(|(_, m)| (m.position, m.terms(ins.sah)));
    let shown = hovered
        .map(|p| (p.position, p.terms(ins.sah), "the plane under the pointer"))
        .or(chosen.map(|(x, t)| (x, t, "this tree's split")));
    if let Some((x, t, what)) = shown {
        ui.label(size.note(format!("At {} = {x:.4} ({what}): {}", AXES[axis], t.text())))
            .on_hover_text("C_trav + C_isect·(A_L/A)·n_L + C_isect·(A_R/A)·n_R: the traversal step, then each side's triangle tests weighted by the chance a ray entering the node enters that side");
    }
}

const LEAF_COLOR: Color32 = Color32::from_rgb(200, 200, 200);
const OWN_COLOR: Color32 = Color32::from_rgb(240, 80, 70);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_strategy_has_a_colour_of_its_own() {
        let colours: Vec<Color32> = Strategy::ALL.iter().map(|&s| strategy_color(s)).collect();
        for (i, c) in colours.iter().enumerate() {
            assert!(!colours[..i].contains(c), "{:?} shares its colour", Strategy::ALL[i]);
        }
    }

    #[test]
    fn a_long_curve_is_thinned_keeping_its_minimum_and_order() {
        let points: Vec<CurvePoint> = (0..100_000)
            .map(|i| {
                let x = i as f32 / 1000.0;
                let cost = (x - 37.123).powi(2) + (x * 7.0).sin();
                CurvePoint { position: x, left: i, right: 100_000 - i, cost, area_left: 0.5, area_right: 0.5 }
            })
            .collect();
        let t = thinned(&points);
        assert!(t.len() <= MAX_PLOTTED);
        let min = |v: &[CurvePoint]| v.iter().map(|p| p.cost).fold(f32::INFINITY, f32::min);
        assert_eq!(min(&t), min(&points));
        assert!(t.windows(2).all(|w| w[0].position <= w[1].position));
        assert_eq!(thinned(&points[..10]), points[..10].to_vec());
    }
}
