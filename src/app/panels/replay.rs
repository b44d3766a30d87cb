//! The Replay window: the build played back split by split (`explain::replay`). A slider and play
//! button choose how many splits are made; the viewport traces the tree after them (its frontier
//! nodes acting as leaves) and draws the frontier's boxes with the newest split's two children
//! highlighted; a plot shows the partial tree's SAH cost against the number of splits.

use crate::app::state::{Action, Actions, BvhscopeApp};
use egui::Color32;
use egui_plot::{Line, Plot, PlotPoints, VLine};
use std::time::Duration;

/// How long a step shows while playing.
const PLAY_STEP: Duration = Duration::from_millis(250);

/// Whether the view is open (its tile shown).
pub fn is_open(app: &BvhscopeApp) -> bool {
    app.replay.window
}

/// The view's contents, in its tile (`panels::tiles`).
pub fn ui(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let view = &app.replay;
    if !view.window {
        return;
    }
    let Some(r) = view.replay.as_ref() else {
        let why = if app.built.as_ref().is_some_and(|b| b.top_stats.is_some()) {
            "The replay shows one BVH's build; this scene is built as two levels (uncheck Two levels)."
        } else {
            "Preparing the replay…"
        };
        ui.weak(why);
        return;
    };
    let n = r.splits();
    let k = view.k;
    ui.label(format!(
        "The binary tree as built ({}), split by split in breadth-first order: after {k} of {n} splits the image is traced through the partial tree, its frontier nodes acting as leaves.",
        app.current_bvh().map_or(r.tree.params.strategy.label().to_string(), |b| b.bvh.label())
    ));
    ui.horizontal(|ui| {
        if ui.button("First").on_hover_text("The root alone, one leaf of every triangle").clicked() {
            out.push(Action::ReplayStep(0));
        }
        if ui.button("Back").clicked() {
            out.push(Action::ReplayStep(k.saturating_sub(1)));
        }
        let (label, tip) = if view.playing { ("Pause", "Stop playing") } else { ("Play", "Split on, faster as the tree grows") };
        if ui.button(label).on_hover_text(tip).clicked() {
            out.push(Action::ReplayPlay(!view.playing));
        }
        if ui.button("Step").on_hover_text("One more split").clicked() {
            out.push(Action::ReplayStep(k + 1));
        }
        if ui.button("Last").on_hover_text("The finished tree").clicked() {
            out.push(Action::ReplayStep(n));
        }
        ui.separator();
        match &app.jobs.film {
            Some(job) => {
                ui.add(egui::ProgressBar::new(job.control.fraction()).desired_width(80.0).show_percentage());
                if ui.button("Cancel").on_hover_text("Stop writing the animation").clicked() {
                    out.push(Action::CancelFilm);
                }
            }
            None => {
                let tip = "Write the whole replay as an animation, 24 steps on one colour scale: .gif for slides, .png for an animated PNG (what bvhscope replay -o writes)";
                if ui.button("Export animation…").on_hover_text(tip).clicked() {
                    out.push(Action::ExportReplay);
                }
            }
        }
    });
    let mut kk = k;
    let slider = egui::Slider::new(&mut kk, 0..=n.max(1)).logarithmic(true).text(format!("of {n} splits"));
    if ui.add(slider).on_hover_text("Splits made (a logarithmic slider: the first splits change the most)").changed() {
        out.push(Action::ReplayStep(kk));
    }
    if view.playing {
        if view.last_tick.is_none_or(|t| t.elapsed() >= PLAY_STEP)
            && app.shown.as_ref().is_some_and(|s| s.frame.is_complete())
        {
            out.push(Action::ReplayStep(view.next_play_step()));
        }
        ui.ctx().request_repaint_after(PLAY_STEP);
    }
    match k.checked_sub(1).map(|i| r.order[i]) {
        Some(newest) => {
            let node = &r.tree.nodes[newest as usize];
            let (l, rr) = (node.index, node.index + 1);
            let axis = ["x", "y", "z"][node.axis as usize];
            let morton = view.morton.as_ref().and_then(|m| crate::explain::replay_film::morton_text(m, r, newest));
            let plane = match (view.newest.as_ref().filter(|(n, _, _)| *n == newest), &morton) {
                (_, Some(t)) => format!(" at {t},"),
                (Some((_, Some(m), _)), _) => {
                    format!(" on {axis} at {axis} = {:.4} (split cost {:.2})", m.position, m.cost)
                }
                _ => format!(" on {axis}"),
            };
            ui.label(format!(
                "Newest split: node {newest}{plane} into {l} ({} triangles) and {rr} ({}); SAH cost of the partial tree {:.2}",
                r.hierarchy.count[l as usize],
                r.hierarchy.count[rr as usize],
                r.sah[k]
            ));
            // The binned SAH: the cost at each of that node's bins' planes on the chosen axis.
            if let Some((_, Some(m), bins)) =
                view.newest.as_ref().filter(|(n, _, b)| *n == newest && !b[node.axis as usize].is_empty())
            {
                let a = node.axis as usize;
                let pts: PlotPoints = bins[a].iter().map(|p| [p.position as f64, p.cost as f64]).collect();
                Plot::new("replay-bins")
                    .height(90.0)
                    .allow_scroll(false)
                    .x_axis_label(format!("{axis}: the newest split's bins"))
                    .show(ui, |p| {
                        p.line(Line::new("cost at each bin plane", pts).color(Color32::from_rgb(90, 200, 250)));
                        p.vline(VLine::new("chosen plane", m.position as f64).color(Color32::from_rgb(250, 210, 80)));
                    });
            }
        }
        None => {
            ui.label(format!("No split yet: the root is one leaf; SAH cost {:.2}", r.sah[0]));
        }
    }
    if view.morton.is_some() {
        ui.weak("LBVH: the line is the Morton order, the order the build sorted the triangles in and its leaves keep, drawn through the frontier nodes (each at its triangles' mean centroid) from blue to yellow; each split cuts a node's stretch where a bit of the codes flips, so the curve refines in Z order as the tree grows.");
    }
    // The SAH cost against k, on a log scale of k + 1 (as the slider).
    let points: PlotPoints = thin(&r.sah).into_iter().map(|(i, c)| [((i + 1) as f64).log10(), c]).collect();
    Plot::new("replay-sah")
        .height(140.0)
        .allow_scroll(false)
        .x_axis_label("log10(splits + 1)")
        .y_axis_label("SAH cost")
        .show(ui, |p| {
            p.line(Line::new("SAH cost of the partial tree", points).color(Color32::from_rgb(90, 200, 250)));
            p.vline(VLine::new("now", ((k + 1) as f64).log10()).color(Color32::from_rgb(250, 210, 80)));
        });
}

/// What closing the view's tile asks for.
pub fn close() -> Action {
    Action::ShowReplay(false)
}

/// At most about 2,000 points of the cost curve, evenly spread on the log scale, the ends kept.
fn thin(sah: &[f64]) -> Vec<(usize, f64)> {
    let n = sah.len();
    if n <= 2000 {
        return sah.iter().copied().enumerate().collect();
    }
    let top = (n as f64).ln();
    let mut idx: Vec<usize> =
        (0..2000).map(|i| ((top * i as f64 / 1999.0).exp() as usize).saturating_sub(1).min(n - 1)).collect();
    idx.dedup();
    idx.into_iter().map(|i| (i, sah[i])).collect()
}
