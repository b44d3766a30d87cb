//! The statistics panel: the current strategy's tree and per-ray figures, next to the strategy
//! shown before it, and the leaf-size histogram.

use crate::app::{BuiltBvh, BvhscopeApp, StrategyFigures};
use crate::bvh::TreeView;
use crate::render::RaySummary;
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

/// The two levels: the tree rows above are the top level's; here each mesh's BVH, and the
/// per-ray work split by level.
fn two_level(ui: &mut egui::Ui, built: &BuiltBvh, rays: Option<RaySummary>) {
    let Some(t) = built.bvh.two_level() else { return };
    ui.add_space(6.0);
    ui.strong("Two levels");
    ui.weak("The tree rows above describe the top level, whose leaves hold placements.");
    egui::Grid::new("two-level").num_columns(2).striped(true).show(ui, |ui| {
        ui.label("Placements / meshes");
        ui.label(format!("{} / {}", t.instances.len(), t.bottom.len()));
        ui.end_row();
        ui.label("Triangles placed / stored");
        ui.label(format!(
            "{} / {}",
            t.instanced_triangle_count(),
            t.bottom.iter().map(|b| b.triangle_count()).sum::<usize>()
        ));
        ui.end_row();
        ui.label("Build ms (meshes + top)");
        ui.label(format!("{:.1} + {:.2}", t.bottom_time.as_secs_f64() * 1e3, t.top_time.as_secs_f64() * 1e3));
        ui.end_row();
        ui.label("Memory, all levels");
        ui.label(format!("{:.1} KiB", t.memory_bytes() as f64 / 1024.0));
        ui.end_row();
        if let Some(r) = rays {
            ui.label("Top-level nodes / ray");
            ui.label(format!("{:.2}", r.mean_top_nodes_visited));
            ui.end_row();
            ui.label("Bottom-level nodes / ray");
            ui.label(format!("{:.2}", r.mean_nodes_visited - r.mean_top_nodes_visited));
            ui.end_row();
            ui.label("Placements entered / ray");
            ui.label(format!("{:.2}", r.mean_instances_entered));
            ui.end_row();
        }
    });
    ui.label("Each mesh's BVH (built once)");
    egui::Grid::new("bottom-level").num_columns(5).striped(true).show(ui, |ui| {
        for h in ["Mesh", "Triangles", "Nodes", "Depth", "SAH cost"] {
            ui.strong(h);
        }
        ui.end_row();
        for (name, s) in &built.bottom {
            ui.label(name);
            ui.label(s.triangles.to_string());
            ui.label(s.nodes.to_string());
            ui.label(s.max_depth.to_string());
            ui.label(format!("{:.2}", s.sah_cost));
            ui.end_row();
        }
    });
}

pub fn show(app: &mut BvhscopeApp, ui: &mut egui::Ui) {
    ui.heading("Statistics");
    if let Some(note) = app.scene.desc.as_ref().and_then(|d| d.note.as_ref()) {
        ui.label(egui::RichText::new(note).italics());
        ui.add_space(4.0);
    }
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
    if let Some(built) = app.current_bvh().filter(|b| b.bvh.two_level().is_some()) {
        two_level(ui, built, current.rays);
    }

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
