//! The statistics panel: the current strategy's tree and per-ray figures, next to the strategy
//! shown before it, and the leaf-size histogram.

use crate::app::{BvhscopeApp, StrategyFigures};
use egui_plot::{Bar, BarChart, Plot};

type Row = (&'static str, fn(&StrategyFigures) -> String);

const ROWS: &[Row] = &[
    ("Build ms", |f| format!("{:.1}", f.stats.build_total_ms)),
    ("Nodes", |f| f.stats.nodes.to_string()),
    ("Leaves", |f| f.stats.leaves.to_string()),
    ("Depth max / mean", |f| format!("{} / {:.1}", f.stats.max_depth, f.stats.mean_leaf_depth)),
    ("SAH cost", |f| format!("{:.2}", f.stats.sah_cost)),
    ("Bytes / triangle", |f| format!("{:.1}", f.stats.memory_bytes as f64 / f.stats.triangles.max(1) as f64)),
    ("Fallback splits", |f| f.stats.fallback_splits.to_string()),
    ("Nodes visited / ray", |f| {
        f.rays.map_or("…".into(), |r| format!("{:.2} (max {})", r.mean_nodes_visited, r.max_nodes_visited))
    }),
    ("Box tests / ray", |f| f.rays.map_or("…".into(), |r| format!("{:.2}", r.mean_box_tests))),
    ("Triangle tests / ray", |f| {
        f.rays.map_or("…".into(), |r| format!("{:.2} (max {})", r.mean_triangle_tests, r.max_triangle_tests))
    }),
];

pub fn show(app: &mut BvhscopeApp, ui: &mut egui::Ui) {
    ui.heading("Statistics");
    let r = &app.scene.report;
    egui::Grid::new("scene-stats").num_columns(2).striped(true).show(ui, |ui| {
        ui.label("Triangles");
        ui.label(r.triangles.to_string());
        ui.end_row();
        if r.degenerate_skipped > 0 {
            ui.label("Degenerate skipped");
            ui.label(r.degenerate_skipped.to_string());
            ui.end_row();
        }
        ui.label("Vertices");
        ui.label(r.vertices.to_string());
        ui.end_row();
        ui.label("Groups");
        ui.label(r.groups.to_string());
        ui.end_row();
    });
    ui.add_space(6.0);
    let Some(current) = app.current_figures() else {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label("Building…");
        });
        return;
    };
    let previous = app.previous.clone();
    egui::Grid::new("bvh-stats").num_columns(3).striped(true).show(ui, |ui| {
        ui.label("");
        ui.strong(&current.label);
        match &previous {
            Some(p) => ui.weak(format!("before: {}", p.label)),
            None => ui.weak("before: —"),
        };
        ui.end_row();
        for (name, value) in ROWS {
            ui.label(*name);
            ui.label(value(&current));
            ui.weak(previous.as_ref().map_or(String::new(), value));
            ui.end_row();
        }
    });
    ui.weak(format!(
        "Per-ray figures: all primary rays of the last full frame. SAH cost with C_trav = {}, C_isect = {}.",
        current.stats.sah_constants.traversal, current.stats.sah_constants.intersection
    ));

    ui.add_space(6.0);
    ui.label("Leaf sizes (triangles per leaf)");
    let bars: Vec<Bar> = current
        .stats
        .leaf_size_histogram
        .iter()
        .enumerate()
        .filter(|(_, &n)| n > 0)
        .map(|(k, &n)| Bar::new(k as f64, n as f64).width(0.8))
        .collect();
    Plot::new("leaf-histogram").height(140.0).allow_drag(false).allow_zoom(false).allow_scroll(false).show(ui, |p| {
        p.bar_chart(BarChart::new("leaves", bars));
    });
}
