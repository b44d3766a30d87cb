//! The Compare window: side by side on or off, B's strategy, the mode (halves, wipe, difference),
//! and the figures of A, B and B − A: the trees' and the frame's per-ray work, as the statistics
//! panel gives them for A.

use super::stats::{difference, StatRow};
use crate::app::state::{Action, Actions, BvhscopeApp};
use crate::bvh::{Layout, Strategy, TraversalOrder};
use crate::options::Choice;
use crate::render::PairView;

/// Whether the view is open (its tile shown).
pub fn is_open(app: &BvhscopeApp) -> bool {
    app.compare.on
}

/// The view's contents, in its tile (`panels::tiles`).
pub fn ui(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let c = &app.compare;
    if !c.on {
        return;
    }
    // Every row wraps within the tile: a row wider than it made a sideways scroll bar, which
    // floated over the mode buttons when presenting (issue 59).
    ui.horizontal_wrapped(|ui| {
        ui.label("B: split by");
        egui::ComboBox::from_id_salt("compare-strategy").selected_text(c.strategy.label()).show_ui(ui, |ui| {
            for s in Strategy::ALL {
                if ui.selectable_label(c.strategy == s, s.label()).on_hover_text(s.named().help).clicked() {
                    out.push(Action::CompareStrategy(s));
                }
            }
        });
        ui.weak("(the rest as A)");
    });
    // B's leaf size, layout and traversal.
    let (mut leaf, mut layout, mut trace) = (c.max_leaf_size, c.layout, c.trace);
    let (n, l) = (crate::bvh::Param::MaxLeafSize.option(), crate::bvh::params::MAX_LEAF_SIZE);
    let mut changed =
        ui.add(egui::Slider::new(&mut leaf, l.min..=l.max).text("B's max leaf size")).on_hover_text(n.help).changed();
    ui.horizontal_wrapped(|ui| {
        for l in Layout::ALL {
            changed |= ui.radio_value(&mut layout, l, l.label()).changed();
        }
        ui.separator();
        for o in TraversalOrder::ALL {
            changed |= ui
                .radio_value(&mut trace.order, o, o.label())
                .on_hover_text("B's traversal order (binary layout)")
                .changed();
        }
    });
    if changed {
        out.push(Action::CompareB { max_leaf_size: leaf, layout, trace });
    }
    ui.horizontal_wrapped(|ui| {
        for m in PairView::ALL {
            if ui.radio(c.mode == m, m.label()).clicked() {
                out.push(Action::CompareMode(m));
            }
        }
    });
    let a = app.current_figures();
    let b = c.b.as_ref().filter(|b| b.scene_id == app.scene_id && b.build == c.build_for(app.wanted_build()));
    let (Some(a), Some(b)) = (a, b) else {
        ui.weak(
            app.jobs
                .compare
                .as_ref()
                .map_or("B follows once A's image is done…".to_string(), |j| format!("{}…", j.label)),
        );
        return;
    };
    let Some(bf) = app.compare_figures() else { return };
    // B's per-ray figures beside A's only where both are of the same rays (camera, kind, seed).
    let same_rays = a.rays.zip(bf.rays).is_some_and(|(ra, rb)| ra.camera == rb.camera && ra.secondary == rb.secondary);
    // The statistics panel's own rows: each figure, and B − A, reads as it does there.
    egui::Grid::new("compare-figures").num_columns(4).striped(true).show(ui, |ui| {
        for h in ["", "A", "B", "B - A"] {
            ui.strong(h);
        }
        ui.end_row();
        for name in ["Nodes", "SAH cost", "Nodes visited / ray", "Box tests / ray", "Triangle tests / ray"] {
            let row = StatRow::named(name);
            if row.per_ray && !same_rays {
                continue;
            }
            ui.label(row.name).on_hover_text(row.tip);
            ui.label(row.text(&a).unwrap_or_default());
            ui.label(row.text(&bf).unwrap_or_default());
            ui.label(difference(row, &a, &bf).unwrap_or_default());
            ui.end_row();
        }
    });
    ui.weak(format!(
        "A: {}. B: {}. Per-ray figures over the frame's rays that enter the root box, one camera, as in the statistics.",
        a.label,
        b.bvh.label()
    ));
}

/// What closing the view's tile asks for.
pub fn close() -> Action {
    Action::Compare(false)
}
