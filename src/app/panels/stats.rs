//! The statistics panel: the current strategy's tree and per-ray figures, next to the strategy
//! shown before it, and the leaf-size histogram. Every row says what it counts in its tooltip.

use crate::app::state::{Action, Actions, BuiltBvh, BvhscopeApp, RaysKey, StrategyFigures};
use crate::bvh::{fmt_ms, SahCost, TreeView};
use crate::render::RaySummary;
use egui_plot::{Bar, BarChart, Plot};

mod rows;
use rows::rays;
pub use rows::{difference, StatRow, ROWS};

/// The two levels: each mesh's BVH, and the per-ray work split by level.
fn two_level(ui: &mut egui::Ui, built: &BuiltBvh, rays: Option<&RaySummary>) {
    let Some(t) = built.bvh.two_level() else { return };
    ui.add_space(6.0);
    ui.strong("Two levels");
    if built.rows_are_the_mesh() {
        ui.weak("One placement of one mesh: the rows above describe the mesh's BVH (the top level is a single node).");
    } else {
        ui.weak("The tree rows above describe the top level, whose leaves hold placements.");
    }
    let width = super::layout::grid_column_width(ui, 2);
    egui::Grid::new("two-level").num_columns(2).striped(true).max_col_width(width).show(ui, |ui| {
        ui.label("Placements / meshes")
            .on_hover_text("Placements in the scene file, and the distinct meshes they place");
        ui.label(format!("{} / {}", t.instances.len(), t.bottom.len()));
        ui.end_row();
        ui.label("Triangles placed / stored").on_hover_text(
            "Triangles as the rays meet them (each placement counts its mesh's), and as stored (each mesh once)",
        );
        ui.label(format!(
            "{} / {}",
            t.instanced_triangle_count(),
            t.bottom.iter().map(|b| b.triangle_count()).sum::<usize>()
        ));
        ui.end_row();
        ui.label("Build ms (meshes + top)").on_hover_text(
            "The meshes' BVHs (each built once) and the top level over the placements; their sum is the Build ms row",
        );
        ui.label(format!("{} + {}", fmt_ms(t.bottom_time.as_secs_f64() * 1e3), fmt_ms(t.top_time.as_secs_f64() * 1e3)));
        ui.end_row();
        ui.label("Memory, all levels")
            .on_hover_text("Nodes and index arrays of the top level and of each mesh's BVH (once), and the placements");
        ui.label(format!("{:.1} KiB", t.memory_bytes() as f64 / 1024.0));
        ui.end_row();
        if let Some(r) = rays {
            ui.label("Top-level nodes / ray").on_hover_text("Nodes of the top level visited per ray (all rays)");
            ui.label(format!("{:.2}", r.mean_top_nodes_visited));
            ui.end_row();
            ui.label("Bottom-level nodes / ray").on_hover_text("Nodes of the meshes' BVHs visited per ray (all rays)");
            ui.label(format!("{:.2}", r.mean_nodes_visited - r.mean_top_nodes_visited));
            ui.end_row();
            ui.label("Placements entered / ray")
                .on_hover_text("Placements whose mesh BVH the ray entered, moved into object space (all rays)");
            ui.label(format!("{:.2}", r.mean_instances_entered));
            ui.end_row();
        }
    });
    ui.label("Each mesh's BVH (built once)");
    let width = super::layout::grid_column_width(ui, 5);
    egui::Grid::new("bottom-level").num_columns(5).striped(true).max_col_width(width).show(ui, |ui| {
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

/// Why a second column's per-ray figures are not set beside the current ones.
enum Second {
    /// Of another kind of ray: not shown.
    OtherKind(String),
    /// Of other rays of the same kind (camera, size, seed, traversal): marked stale.
    Stale(String),
}

/// What "combined cost" means with the constants in use (tooltips of the statistics and the
/// heatmap views).
pub fn combined_cost_text(c: SahCost) -> String {
    format!(
        "Combined cost = C_trav × nodes visited + C_isect × triangle tests, with C_trav = {} and C_isect = {} (the SAH constants of the build)",
        c.traversal, c.intersection
    )
}

pub fn show(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    ui.heading("Statistics");
    scene_note(app, ui);
    scene_counts(app, ui);
    ui.add_space(6.0);
    let Some(current) = app.current_figures() else {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label("Building…");
        });
        return;
    };
    gpu_lines(app, ui);
    figures_table(app, ui, &current);
    let c = current.stats.sah_constants;
    let spec = app.settings.rays;
    let which = match spec.kind.is_secondary() {
        true => format!("the {} from the hits of the last full frame", spec.describe()),
        false => "the primary rays of the last full frame".to_string(),
    };
    ui.weak(format!(
        "Per-ray figures: {which} that enter the root box, unless a row says all rays. SAH cost with C_trav = {}, C_isect = {}.",
        c.traversal, c.intersection
    ))
    .on_hover_text(combined_cost_text(c));
    if let Some(built) = app.current_bvh().filter(|b| b.bvh.two_level().is_some()) {
        two_level(ui, built, rays(&current));
    }
    warp_line(app, ui);
    speedup(app, ui, out);
    leaf_histogram(ui, &current);
}

/// The scene's note: its first sentence, the rest on asking (a paragraph pushed the figures out
/// of a projector's view).
fn scene_note(app: &BvhscopeApp, ui: &mut egui::Ui) {
    if let Some(note) = app.scene.desc.as_ref().and_then(|d| d.note.as_ref()) {
        match crate::explain::words::first_sentence(note) {
            Some(first) => {
                ui.label(egui::RichText::new(first).italics());
                egui::CollapsingHeader::new("About this scene").id_salt("scene-note").show(ui, |ui| {
                    ui.label(egui::RichText::new(&note[first.len()..]).italics());
                });
            }
            None => {
                ui.label(egui::RichText::new(note).italics());
            }
        }
        ui.add_space(4.0);
    }
}

/// What the scene holds: triangles, the degenerate ones skipped, vertices, groups.
fn scene_counts(app: &BvhscopeApp, ui: &mut egui::Ui) {
    let r = &app.scene.report;
    egui::Grid::new("scene-stats").num_columns(2).striped(true).show(ui, |ui| {
        ui.label("Triangles").on_hover_text("Triangles in the scene as the rays see it (polygons fan-triangulated, placements counted), zero-area ones left out");
        ui.label(r.triangles.to_string());
        ui.end_row();
        if r.degenerate_skipped > 0 {
            ui.label("Degenerate skipped").on_hover_text("Triangles of zero area, left out of the BVH");
            ui.label(r.degenerate_skipped.to_string());
            ui.end_row();
        }
        ui.label("Vertices").on_hover_text("Vertex positions of the loaded meshes");
        ui.label(r.vertices.to_string());
        ui.end_row();
        ui.label("Groups").on_hover_text("Objects and groups (o / g lines) of the file");
        ui.label(r.groups.to_string());
        ui.end_row();
    });
}

/// The tree's figures beside the strategy shown before (or, side by side, beside B with B − A),
/// each per-ray figure marked where it is not of the image on screen.
fn figures_table(app: &BvhscopeApp, ui: &mut egui::Ui, current: &StrategyFigures) {
    // Side by side, the second column is B and a third gives B − A; otherwise it is the strategy
    // shown before this one.
    let b = app.compare_figures();
    let comparing = b.is_some();
    let previous = b.or_else(|| app.previous.clone());
    let key = app.figures_key();
    // The current figures' per-ray rows, when they are not of the image on screen (another size,
    // camera, ray kind, seed or tree: Replay's smaller image, a new ray kind still rendering).
    let stale_now = app.stale_figures(current);
    // The second column's per-ray figures: not shown at all for another ray kind (AO figures
    // beside shadow figures read as a comparison), marked stale for other rays of the same kind
    // (B: the same camera and rays; its traversal is its own).
    let second = |f: &StrategyFigures| -> Option<Second> {
        let (r, key) = (f.rays.as_ref()?, key.as_ref()?);
        if r.key().kind() != key.kind() {
            return r.key().stale_because(key).map(Second::OtherKind);
        }
        let k = if comparing { RaysKey { trace: r.trace, ..*key } } else { *key };
        r.key().stale_because(&k).map(Second::Stale)
    };
    let columns = if comparing { 4 } else { 3 };
    // Four columns share the width (a long label such as an imported file's wraps within its own).
    let width = if comparing { super::layout::grid_column_width(ui, columns) } else { 0.4 * ui.available_width() };
    egui::Grid::new("bvh-stats").num_columns(columns).striped(true).max_col_width(width).show(ui, |ui| {
        ui.label("");
        ui.strong(&current.label);
        let other_kind = previous.as_ref().is_some_and(|p| matches!(second(p), Some(Second::OtherKind(_))));
        let other = if other_kind { " (other rays)" } else { "" };
        match &previous {
            Some(p) if comparing => ui.strong(format!("{}{other}", p.label)).on_hover_text("B, the build compared side by side"),
            Some(p) => ui
                .weak(format!("before: {}{other}", p.label))
                .on_hover_text("The strategy shown before this one, for comparison (its per-ray figures only where they are of the same kind of rays)"),
            None => ui.weak("before: —").on_hover_text("The strategy shown before this one, for comparison"),
        };
        if comparing {
            ui.strong("B - A");
        }
        ui.end_row();
        for row in ROWS {
            ui.label(row.name).on_hover_text(row.tip);
            let a = row.text(current);
            match (&a, &stale_now) {
                (Some(v), Some(why)) if row.per_ray => {
                    ui.weak(egui::RichText::new(format!("{v} (stale)")).italics())
                        .on_hover_text(format!("Measured {why}: not this image's figure (measured again with the next full frame of the tree)"));
                }
                _ => {
                    ui.label(a.clone().unwrap_or_else(|| "…".into()));
                }
            }
            let stale = previous.as_ref().filter(|_| row.per_ray).and_then(second);
            match (&previous, stale) {
                (Some(p), Some(Second::OtherKind(why))) => {
                    let was = row.text(p).unwrap_or_else(|| "not measured".into());
                    ui.weak(egui::RichText::new("other rays").italics()).on_hover_text(format!(
                        "Measured {why} (was {was}): figures of another kind of ray are not set beside these"
                    ));
                }
                (Some(p), Some(Second::Stale(why))) => {
                    let was = row.text(p).unwrap_or_else(|| "not measured".into());
                    ui.weak(egui::RichText::new("stale").italics()).on_hover_text(format!(
                        "Measured {why} (was {was}); not comparable with this frame"
                    ));
                }
                (Some(p), None) if comparing => {
                    ui.label(row.text(p).unwrap_or_default());
                    ui.label(difference(row, current, p).unwrap_or_default());
                }
                (Some(p), None) => {
                    ui.weak(row.text(p).unwrap_or_default());
                }
                (None, _) => {
                    ui.label("");
                }
            }
            if comparing && previous.as_ref().is_some_and(|p| row.per_ray && second(p).is_some()) {
                ui.label("");
            }
            ui.end_row();
        }
    });
    if let Some(why) = &stale_now {
        ui.weak(egui::RichText::new(format!("(stale): the per-ray figures are {why}.")).italics());
    }
}

/// How many leaves hold each number of triangles, as bars.
fn leaf_histogram(ui: &mut egui::Ui, current: &StrategyFigures) {
    ui.add_space(6.0);
    ui.label("Leaf sizes (triangles per leaf)").on_hover_text("How many leaves hold each number of triangles");
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

/// The warp figures of the image's camera rays, as `bvhscope stats --warp N` prints them (its
/// headline SIMT efficiency the app did not show, issue 59): of the warp view's lanes, else 32.
/// Made once per frame (a pass over its counts), kept in egui's memory.
fn warp_line(app: &BvhscopeApp, ui: &mut egui::Ui) {
    use crate::render::warp::{WarpSize, WarpSummary, WarpView, WarpWork};
    let Some(shown) = app
        .shown
        .as_ref()
        .filter(|s| s.frame.is_complete() && s.frame.counted() && s.partial.is_none() && s.frame.secondary().is_none())
    else {
        return;
    };
    let size = shown.style.view.warp().unwrap_or(WarpSize::W32);
    let key = (std::sync::Arc::as_ptr(&shown.frame) as usize, size.lanes());
    let id = egui::Id::unique("warp-summary");
    let cached = ui.ctx().data(|d| d.get_temp::<((usize, u32), WarpSummary)>(id)).filter(|(k, _)| *k == key);
    let summary = cached.map(|(_, s)| s).unwrap_or_else(|| {
        let f = &shown.frame;
        let counts: Vec<_> = f.traced().map(|(_, c)| c).collect();
        let s = WarpView::frame(f.width(), f.height(), &counts, size, WarpWork::Steps).summary();
        ui.ctx().data_mut(|d| d.insert_temp(id, (key, s)));
        s
    });
    let (bw, bh) = size.block();
    ui.add_space(4.0);
    ui.label(format!("Warps of {} lanes ({bw}×{bh} pixels): {}", size.lanes(), summary.text())).on_hover_text(format!(
        "The image's camera rays in groups of {} side by side, as a GPU runs them: a group takes as long as its ray with the most steps (nodes visited + triangle tests) while finished lanes idle. SIMT efficiency: the share of lane-steps that do work. As bvhscope stats --warp {} prints it",
        size.lanes(),
        size.lanes()
    ));
}

/// How the speed-up is measured, the same words wherever it is said: one method, in
/// `explain::timing`, for the app and `bvhscope compare` (issue 59: the app said 73×, compare 105×).
const SPEEDUP_TIP: &str = "The image's rays (its camera and size) traced one at a time on one thread, closest hit, no shading: through this BVH, the median of up to 5 runs (fewer once they pass a second in all), and through a linear scan of every triangle, once (on an evenly spread sample, scaled to the frame, when the whole frame would take over 10 s). bvhscope compare times its trace column and speed-up this way (explain::timing); with the command below, on these rays. Runs on a busy machine vary by some per cent";

/// The speed-up over linear search the lab asks for: on demand (the scan of a big mesh takes
/// seconds), single rays on one thread, as `bvhscope compare`'s trace column times them.
fn speedup(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    ui.add_space(6.0);
    ui.label("Speed-up over linear search").on_hover_text(SPEEDUP_TIP);
    let Some(shown) = app.shown.as_ref().filter(|s| s.frame.is_complete() && s.partial.is_none()) else {
        ui.weak("After the frame is done.");
        return;
    };
    if !matches!(*shown.bvh, crate::bvh::SceneBvh::Single { .. }) {
        ui.weak("Of one BVH: uncheck Two levels.");
        return;
    }
    if let Some(job) = &app.jobs.speedup {
        ui.horizontal(|ui| {
            let bar = egui::ProgressBar::new(job.control.fraction())
                .desired_width((ui.available_width() - 70.0).max(60.0))
                .show_percentage();
            ui.add(bar);
            if ui.button("Cancel").clicked() {
                out.push(Action::TimeLinear(false));
            }
        });
        ui.ctx().request_repaint_after(std::time::Duration::from_millis(100));
        return;
    }
    match app.fresh_speedup() {
        Some(t) => {
            ui.label(speedup_text(&t.speedup, &t.camera)).on_hover_text(SPEEDUP_TIP);
            if ui.small_button("Time again").on_hover_text("Timings vary from run to run on a busy machine").clicked() {
                out.push(Action::TimeLinear(true));
            }
            // The command line that measures the same rays the same way (a file's scene only).
            if let crate::scene::SceneSource::File(path) = &app.scene.source {
                let cmd = crate::explain::words::compare_command(path, &t.bvh.build_params(), t.trace, &t.camera);
                egui::CollapsingHeader::new("The same rays on the command line").id_salt("speedup-command").show(
                    ui,
                    |ui| {
                        ui.add(egui::Label::new(egui::RichText::new(cmd).monospace()).wrap());
                    },
                );
            }
        }
        None => {
            if ui.button("Time against the linear scan").clicked() {
                out.push(Action::TimeLinear(true));
            }
        }
    }
}

/// The speed-up's sentence: the figure as `compare` rounds it, with what it was measured on.
pub fn speedup_text(s: &crate::explain::timing::Speedup, camera: &crate::render::Camera) -> String {
    let sampled = s.linear_sampled.map_or(String::new(), |n| format!(" (projected from {n} rays)"));
    format!(
        "{:.0}× faster: this BVH {} ms (median of {} runs), the linear scan {} ms{sampled}, for the {} rays of the {}×{} frame on one thread.",
        s.speedup,
        fmt_ms(s.tree_ms),
        s.tree_runs,
        fmt_ms(s.linear_ms),
        s.rays,
        camera.width,
        camera.height
    )
}

/// The statistics panel's GPU lines: where the frame on screen was traced, and the GPU build's
/// phases of the current BVH when it was built there (what `bvhscope stats --device gpu` prints).
fn gpu_lines(app: &BvhscopeApp, ui: &mut egui::Ui) {
    let built = app.current_bvh().and_then(|b| app.jobs.gpu.build_of(&b.bvh));
    let traced = app.shown.as_ref().filter(|s| s.gpu.is_some());
    if built.is_none() && traced.is_none() {
        return;
    }
    egui::Grid::new("gpu-stats").num_columns(2).striped(true).show(ui, |ui| {
        if let Some(s) = traced {
            let nodes = s.gpu.as_ref().map_or("", |g| g.nodes.label());
            ui.label("Traced on").on_hover_text("The frame on screen was traced on this GPU, in one pass at full resolution; its counts are those of bvhscope render --device gpu");
            ui.label(format!("GPU, {nodes} nodes"))
                .on_hover_text(s.gpu.as_ref().map_or(String::new(), |g| g.gpu.name()));
            ui.end_row();
            if s.cpu_finished > 0 {
                ui.label("Finished on the CPU").on_hover_text(format!(
                    "Rays whose GPU walk reached the step budget ({} steps a walk: nodes, stack pops and triangle tests) and were finished by the same walk on the CPU: every hit and count is the CPU walk's",
                    bvhscope_gpu::STEP_BUDGET
                ));
                ui.label(format!("{} of {} rays", s.cpu_finished, s.frame.width() as u64 * s.frame.height() as u64));
                ui.end_row();
            }
        }
        if let Some(b) = built {
            let on_gpu = crate::gpu_path::gpu_built();
            ui.label("GPU build").on_hover_text(format!("{on_gpu} built on the GPU: the phases, as bvhscope stats --device gpu prints them (PLOC: emission is its clustering, boxes the host's layout)"));
            ui.add(egui::Label::new(b.text()).wrap());
            ui.end_row();
        }
    });
    ui.add_space(6.0);
}
