//! Saving what the app shows: the view as PNG (heatmaps with their legend), the statistics as CSV
//! or JSON (current strategy and the one before).

use crate::app::jobs::{FilmRequest, Pick, FILM_FRAMES};
use crate::app::state::{BvhscopeApp, Shown, StrategyFigures};
use crate::app::views::compare::CompareB;
use crate::render::{draw_legend, full_size, view_image};
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StatsFormat {
    Csv,
    Json,
}

/// A file name describing the current scene, strategy and view.
pub fn default_name(app: &BvhscopeApp, ext: &str) -> String {
    let scene: String = app.scene.title().chars().map(|c| if c.is_alphanumeric() { c } else { '-' }).collect();
    let strategy = app.settings.build.strategy.name();
    // Side by side, the name says both builds and how the pair is shown.
    if let Some((_, b)) = app.shown_pair() {
        let pair = format!("bvhscope-{scene}-{strategy}-vs-{}", b.build.bvh.strategy.name());
        match ext {
            "png" => return format!("{pair}-{}-{}.png", app.settings.view.name(), app.compare.mode.name()),
            "counts" => return format!("{pair}-{}-difference.csv", app.settings.view.name()),
            _ => {}
        }
    }
    match ext {
        "png" => format!("bvhscope-{scene}-{strategy}-{}.png", app.settings.view.name()),
        "counts" => format!("bvhscope-{scene}-{strategy}-counts.csv"),
        "bvh" => format!("{scene}-{strategy}-{}.json", app.settings.build.layout.name()),
        "gif" => format!("bvhscope-{scene}-{strategy}-replay.gif"),
        _ => format!("bvhscope-{scene}-stats.{ext}"),
    }
}

/// The name a save suggests for `pick` (the file dialog's), none for an open.
pub fn suggested_name(app: &BvhscopeApp, pick: Pick) -> String {
    match pick {
        Pick::Open | Pick::OpenBvh | Pick::OpenGradeReport | Pick::OpenLesson => String::new(),
        Pick::SavePng => default_name(app, "png"),
        Pick::SaveStatsCsv => default_name(app, "csv"),
        Pick::SaveStatsJson => default_name(app, "json"),
        Pick::SaveCounts => default_name(app, "counts"),
        Pick::SaveBvh => default_name(app, "bvh"),
        Pick::SaveAnimation => default_name(app, "gif"),
        Pick::SaveScene => {
            format!("{}.json", app.scene.title().trim_end_matches(".obj").trim_end_matches(".json"))
        }
        Pick::SaveLesson => lesson_name(app),
    }
}

/// The lesson's file name: the one it was read from, else its title's words joined by dashes.
fn lesson_name(app: &BvhscopeApp) -> String {
    let Some(l) = &app.lesson else { return "lesson.json".into() };
    if let Some(name) = l.path.as_ref().and_then(|p| p.file_name()) {
        return name.to_string_lossy().into_owned();
    }
    let words: Vec<String> =
        l.lesson.title.split(|c: char| !c.is_alphanumeric()).filter(|w| !w.is_empty()).map(str::to_lowercase).collect();
    if words.is_empty() {
        "lesson.json".into()
    } else {
        format!("{}.json", words.join("-"))
    }
}

/// What the typed-path window starts with for `pick`: a save's suggested name in the folder a
/// relative path is written to (so the field says where the file goes, and Enter saves it there);
/// an open's field starts empty.
pub fn typed_path(app: &BvhscopeApp, pick: Pick) -> String {
    let name = suggested_name(app, pick);
    if name.is_empty() {
        return name;
    }
    match std::env::current_dir() {
        Ok(dir) => dir.join(name).display().to_string(),
        Err(_) => name,
    }
}

/// Before anything is written: the file named for what it will hold, and none of the files the
/// app has open (the scene, its meshes, the imported dump).
pub fn check_output(app: &BvhscopeApp, pick: Pick, path: &Path) -> Result<(), String> {
    use crate::files::{CSV, JSON, PNG};
    let kind = match pick {
        Pick::Open | Pick::OpenBvh | Pick::OpenGradeReport | Pick::OpenLesson => return Ok(()),
        Pick::SavePng => PNG,
        Pick::SaveStatsCsv | Pick::SaveCounts => CSV,
        Pick::SaveStatsJson | Pick::SaveScene | Pick::SaveLesson => JSON,
        Pick::SaveBvh => return crate::dump::BvhDump::written_as(path).map(|_| ()),
        Pick::SaveAnimation => crate::render::animation::ANIMATION,
    };
    kind.check(path).map_err(|e| e.to_string())?;
    let mut inputs: Vec<(PathBuf, &str)> = Vec::new();
    if let crate::scene::SceneSource::File(p) = &app.scene.source {
        inputs.push((p.clone(), "the scene or mesh open"));
    }
    for m in app.scene.desc.iter().flat_map(|d| &d.meshes) {
        inputs.push((m.file.clone(), "a mesh of the scene open"));
    }
    if let Some(t) = &app.import.tree {
        inputs.push((t.path.clone(), "the imported BVH dump"));
    }
    let inputs: Vec<(&Path, &str)> = inputs.iter().map(|(p, w)| (p.as_path(), *w)).collect();
    crate::files::refuse_inputs(path, &inputs).map_err(|e| e.to_string())
}

/// Compare's pair, or why it cannot be written yet.
fn pair_on_screen(app: &BvhscopeApp) -> Result<(&Shown, &CompareB), String> {
    app.shown_pair().ok_or_else(|| "B is not traced yet: save once both builds are on screen".to_string())
}

/// The view as PNG: in Compare what is on screen (halves, wipe or difference, with its legend,
/// as `render --against … --pair-view` writes it), else the frame with its legend.
pub fn save_png(app: &BvhscopeApp, path: &Path) -> Result<(), String> {
    if app.compare.on {
        let (shown, b) = pair_on_screen(app)?;
        let subject = format!("{}: A {}, B {}", app.scene.title(), shown.build_label, b.bvh.label());
        let style = app.pair_style(shown);
        let (mode, wipe) = (app.compare.mode, app.compare.wipe);
        let img = crate::render::pair::pair_picture(&shown.frame, &b.frame, mode, wipe, &style, &subject)
            .ok_or("the difference is of heatmaps: choose a heatmap view")?;
        return crate::files::write_png(path, &img).map_err(|e| e.to_string());
    }
    let shown = app.shown.as_ref().ok_or("nothing rendered yet")?;
    let s = shown.style;
    let (img, mut legend) = view_image(&shown.frame, s.view, s.colormap, s.range, s.cost);
    if let Some(l) = &mut legend {
        l.subject = format!("{}, {}", app.scene.title(), shown.build_label);
    }
    // A coarse pass's image has a pixel per traced pixel; the file has the frame's size.
    let img = full_size(&img, &shown.frame);
    let img = match &legend {
        Some(l) => draw_legend(&img, l),
        None => img,
    };
    crate::files::write_png(path, &img).map_err(|e| e.to_string())
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

/// The statistics rows as CSV (RFC 4180, written by the `csv` crate, so a label with a comma is
/// quoted): one record per strategy; per-ray fields are empty while not yet measured.
pub fn stats_csv(rows: &[(&str, StrategyFigures)]) -> String {
    const HEADER: [&str; 24] = [
        "which",
        "strategy",
        "triangles",
        "build_ms",
        "nodes",
        "leaves",
        "max_depth",
        "mean_leaf_depth",
        "sah_cost",
        "bytes",
        "rays",
        "rays_in_root_box",
        "mean_nodes_visited",
        "max_nodes_visited",
        "mean_box_tests",
        "mean_triangle_tests",
        "max_triangle_tests",
        "root_box_mean_nodes_visited",
        "root_box_mean_box_tests",
        "root_box_mean_triangle_tests",
        "frame_ms",
        "one_thread_tree_ms",
        "one_thread_linear_ms",
        "speedup_over_linear",
    ];
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(HEADER).expect("writing CSV to memory");
    for (which, f) in rows {
        let s = &f.stats;
        let mut rec = vec![
            which.to_string(),
            f.label.clone(),
            s.triangles.to_string(),
            format!("{:.3}", f.build_ms),
            s.nodes.to_string(),
            s.leaves.to_string(),
            s.max_depth.to_string(),
            format!("{:.3}", s.mean_leaf_depth),
            format!("{:.4}", s.sah_cost),
            s.memory_bytes.to_string(),
        ];
        match f.rays.map(|r| r.summary) {
            Some(r) => rec.extend([
                r.rays.to_string(),
                r.root_rays.to_string(),
                format!("{:.3}", r.mean_nodes_visited),
                r.max_nodes_visited.to_string(),
                format!("{:.3}", r.mean_box_tests),
                format!("{:.3}", r.mean_triangle_tests),
                r.max_triangle_tests.to_string(),
                format!("{:.3}", r.root_mean_nodes_visited),
                format!("{:.3}", r.root_mean_box_tests),
                format!("{:.3}", r.root_mean_triangle_tests),
            ]),
            None => rec.resize(HEADER.len() - 4, String::new()),
        }
        // Measured or empty: the frame's time (every core), the lab's speed-up (one thread).
        rec.push(f.frame_ms.map_or(String::new(), |ms| format!("{ms:.3}")));
        match &f.speedup {
            Some(t) => {
                rec.extend([format!("{:.3}", t.tree_ms), format!("{:.3}", t.linear_ms), format!("{:.2}", t.speedup)])
            }
            None => rec.extend([String::new(), String::new(), String::new()]),
        }
        w.write_record(&rec).expect("writing CSV to memory");
    }
    String::from_utf8(w.into_inner().expect("writing CSV to memory")).expect("CSV of UTF-8 fields")
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
                .map(|(which, f)| {
                    let rays = f.rays.map(|r| serde_json::json!({ "summary": r.summary, "camera": r.camera, "trace": r.trace }));
                    let speedup = f.speedup.as_ref().map(|t| serde_json::json!({ "rays": t.rays, "one_thread_tree_ms": t.tree_ms, "one_thread_linear_ms": t.linear_ms, "linear_sampled": t.linear_sampled, "speedup_over_linear": t.speedup }));
                    serde_json::json!({ "which": which, "strategy": f.label, "build_ms": f.build_ms, "frame_ms": f.frame_ms, "speedup": speedup, "tree": f.stats, "rays": rays })
                })
                .collect();
            let v = serde_json::json!({ "scene": app.scene.title(), "triangles": app.scene.report.triangles, "strategies": items });
            serde_json::to_string_pretty(&v).map_err(|e| e.to_string())?
        }
        StatsFormat::Csv => stats_csv(&rows),
    })
}

/// The counts behind the heatmap of the full frame on screen, one row per pixel (the format of
/// `bvhscope render --counts`); in Compare the pair's, x, y, a, b, b_minus_a (`render --against
/// … --difference`).
pub fn save_counts(app: &BvhscopeApp, path: &Path) -> Result<(), String> {
    if app.compare.on {
        let (shown, b) = pair_on_screen(app)?;
        let s = shown.style;
        let text = crate::render::pair::difference_csv(&shown.frame, &b.frame, s.view, s.cost)
            .ok_or("the pair's counts are of heatmaps: choose a heatmap view")?;
        return crate::files::write_bytes(path, text.as_bytes()).map_err(|e| e.to_string());
    }
    let shown = app.shown.as_ref().ok_or("nothing rendered yet")?;
    let text = shown.frame.counts_csv().ok_or("the frame is still refining; export once it is complete")?;
    crate::files::write_bytes(path, text.as_bytes()).map_err(|e| e.to_string())
}

/// The current single BVH as a bvhscope-bvh dump (`bvhscope export-bvh` writes the same), JSON or
/// the text form by the file's extension.
pub fn save_bvh(app: &BvhscopeApp, path: &Path) -> Result<(), String> {
    let built = app.current_bvh().ok_or("no BVH is built yet")?;
    let crate::bvh::SceneBvh::Single { bvh, mesh, .. } = &*built.bvh else {
        return Err("a two-level BVH is not written as one dump: turn two levels off in the Build panel".into());
    };
    let name = match &app.scene.source {
        crate::scene::SceneSource::File(p) => p.file_name().map(|n| n.to_string_lossy().into_owned()),
        crate::scene::SceneSource::Builtin => None,
    };
    let dump = crate::dump::BvhDump::of_any(bvh, mesh, name);
    dump.write(path).map_err(|e| e.to_string())
}

pub fn save_stats(app: &BvhscopeApp, path: &Path, format: StatsFormat) -> Result<(), String> {
    let text = stats_text(app, format)?;
    crate::files::write_bytes(path, text.as_bytes()).map_err(|e| e.to_string())
}

/// What the replay's animation is made of, as `bvhscope replay` makes it: the replay shown, its
/// mesh, the view's camera, and the view if it is a heatmap (else the combined cost, the
/// command's default), 24 frames.
pub fn film_request(app: &BvhscopeApp) -> Result<FilmRequest, String> {
    use crate::bvh::SceneBvh;
    let replay = app.replay.replay.clone().ok_or("the replay is not ready yet")?;
    let built = app.current_bvh().ok_or("build a BVH first")?;
    let SceneBvh::Single { mesh, .. } = &*built.bvh else {
        return Err("the replay shows one BVH's build; this scene is built as two levels".into());
    };
    let camera = app.shown.as_ref().map(|s| s.camera).ok_or("nothing rendered yet")?;
    let view = if app.settings.view.is_heatmap() { app.settings.view } else { crate::render::View::Cost };
    let settings = crate::explain::replay_film::FilmSettings {
        view,
        colormap: app.settings.colormap,
        frames: FILM_FRAMES,
        trace: app.settings.trace,
        cost: app.settings.build.cost,
    };
    let subject = format!("{}, {}, log scale", app.scene.title(), replay.tree.params.strategy.label());
    Ok(FilmRequest { replay, mesh: mesh.clone(), camera, settings, subject })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::state::MeasuredRays;
    use crate::bvh::TreeStats;
    use crate::render::{Camera, RaySummary};

    #[test]
    fn the_csv_parses_with_a_real_reader_and_leaves_unmeasured_rays_empty() {
        let stats = TreeStats { triangles: 10, nodes: 7, leaves: 4, ..Default::default() };
        let camera = Camera::framing(&crate::geometry::Aabb::new(glam::Vec3::ZERO, glam::Vec3::ONE), 64, 48);
        let summary = RaySummary {
            rays: 3072,
            root_rays: 1000,
            mean_nodes_visited: 1.5,
            root_mean_nodes_visited: 4.5,
            ..Default::default()
        };
        let measured = MeasuredRays { summary, camera, trace: Default::default(), secondary: None };
        let rows = [
            (
                "current",
                StrategyFigures {
                    label: "Equal count, binary".into(),
                    stats: stats.clone(),
                    build_ms: 1.25,
                    rays: Some(measured),
                    frame_ms: Some(41.5),
                    speedup: Some(crate::explain::timing::Speedup {
                        rays: 3072,
                        tree_ms: 2.0,
                        tree_runs: 5,
                        linear_ms: 90.0,
                        linear_sampled: None,
                        speedup: 45.0,
                    }),
                },
            ),
            (
                "previous",
                StrategyFigures {
                    label: "top SAH binned / Midpoint, \"wide4\"".into(),
                    stats,
                    build_ms: 0.5,
                    rays: None,
                    frame_ms: None,
                    speedup: None,
                },
            ),
        ];
        let text = stats_csv(&rows);
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        let header = reader.headers().unwrap().clone();
        let records: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
        assert_eq!(records.len(), 2);
        for r in &records {
            assert_eq!(r.len(), header.len(), "every record has the header's fields:\n{text}");
        }
        let field = |r: &csv::StringRecord, name: &str| r[header.iter().position(|h| h == name).unwrap()].to_string();
        assert_eq!(field(&records[0], "strategy"), "Equal count, binary");
        assert_eq!(field(&records[1], "strategy"), "top SAH binned / Midpoint, \"wide4\"");
        assert_eq!(field(&records[0], "root_box_mean_nodes_visited"), "4.500");
        assert_eq!(field(&records[0], "rays_in_root_box"), "1000");
        assert_eq!(field(&records[1], "mean_nodes_visited"), "", "not measured is empty, not 0");
        assert_eq!(field(&records[1], "build_ms"), "0.500");
        assert_eq!(field(&records[0], "frame_ms"), "41.500");
        assert_eq!(field(&records[0], "speedup_over_linear"), "45.00");
        assert_eq!(field(&records[0], "one_thread_linear_ms"), "90.000");
        assert_eq!(field(&records[1], "speedup_over_linear"), "", "not timed is empty");
    }
}
