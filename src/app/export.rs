//! Saving what the app shows: the view as PNG (heatmaps with their legend), the statistics as CSV
//! or JSON (current strategy and the one before).

use super::{BvhscopeApp, StrategyFigures};
use crate::render::{draw_legend, full_size, view_image};
use std::fmt::Write;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StatsFormat {
    Csv,
    Json,
}

/// A file name describing the current scene, strategy and view.
pub fn default_name(app: &BvhscopeApp, ext: &str) -> String {
    let scene: String = app.scene.title().chars().map(|c| if c.is_alphanumeric() { c } else { '-' }).collect();
    let strategy = app.settings.build.strategy.short_name();
    match ext {
        "png" => format!("bvhscope-{scene}-{strategy}-{}.png", app.settings.view.short_name()),
        _ => format!("bvhscope-{scene}-stats.{ext}"),
    }
}

pub fn save_png(app: &BvhscopeApp, path: &Path) -> Result<(), String> {
    let shown = app.shown.as_ref().ok_or("nothing rendered yet")?;
    let s = shown.style;
    let (img, legend) = view_image(&shown.frame, s.view, s.colormap, s.range, s.cost);
    // A coarse pass's image has a pixel per traced pixel; the file has the frame's size.
    let img = full_size(&img, &shown.frame);
    let img = match &legend {
        Some(l) => draw_legend(&img, l),
        None => img,
    };
    img.save(path).map_err(|e| format!("{}: cannot write: {e}", path.display()))
}

fn rows(app: &BvhscopeApp) -> Vec<(&'static str, StrategyFigures)> {
    let mut v = Vec::new();
    if let Some(c) = app.current_figures() {
        v.push(("current", c));
    }
    if let Some(p) = &app.previous {
        v.push(("previous", p.clone()));
    }
    v
}

pub fn stats_text(app: &BvhscopeApp, format: StatsFormat) -> Result<String, String> {
    let rows = rows(app);
    if rows.is_empty() {
        return Err("no BVH built yet".into());
    }
    Ok(match format {
        StatsFormat::Json => {
            let items: Vec<_> = rows
                .iter()
                .map(|(which, f)| serde_json::json!({ "which": which, "strategy": f.label, "tree": f.stats, "rays": f.rays }))
                .collect();
            let v = serde_json::json!({ "scene": app.scene.title(), "triangles": app.scene.report.triangles, "strategies": items });
            serde_json::to_string_pretty(&v).map_err(|e| e.to_string())?
        }
        StatsFormat::Csv => {
            let mut o = String::from("which,strategy,triangles,build_ms,nodes,leaves,max_depth,mean_leaf_depth,sah_cost,bytes,mean_nodes_visited,max_nodes_visited,mean_box_tests,mean_triangle_tests,max_triangle_tests\n");
            for (which, f) in rows {
                let s = &f.stats;
                let r = f.rays.unwrap_or_default();
                let _ = writeln!(
                    o,
                    "{which},{},{},{:.3},{},{},{},{:.3},{:.4},{},{:.3},{},{:.3},{:.3},{}",
                    f.label,
                    s.triangles,
                    s.build_total_ms,
                    s.nodes,
                    s.leaves,
                    s.max_depth,
                    s.mean_leaf_depth,
                    s.sah_cost,
                    s.memory_bytes,
                    r.mean_nodes_visited,
                    r.max_nodes_visited,
                    r.mean_box_tests,
                    r.mean_triangle_tests,
                    r.max_triangle_tests
                );
            }
            o
        }
    })
}

pub fn save_stats(app: &BvhscopeApp, path: &Path, format: StatsFormat) -> Result<(), String> {
    let text = stats_text(app, format)?;
    std::fs::write(path, text).map_err(|e| format!("{}: cannot write: {e}", path.display()))
}
