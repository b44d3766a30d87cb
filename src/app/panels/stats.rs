//! The statistics panel: the current strategy's tree and per-ray figures, next to the strategy
//! shown before it, and the leaf-size histogram. Every row says what it counts in its tooltip.

use crate::app::state::{Action, Actions, BuiltBvh, BvhscopeApp, StrategyFigures};
use crate::bvh::{fmt_ms, SahCost, TreeView};
use crate::render::RaySummary;
use egui_plot::{Bar, BarChart, Plot};

/// A row: its name, what it means (tooltip), and its value for a strategy (`None`: not measured
/// yet). Per-ray rows are marked, because they depend on the camera as well as on the tree.
struct StatRow {
    name: &'static str,
    tip: &'static str,
    per_ray: bool,
    value: fn(&StrategyFigures) -> Option<String>,
}

fn rays(f: &StrategyFigures) -> Option<&RaySummary> {
    f.rays.as_ref().map(|r| &r.summary)
}

const ROWS: &[StatRow] = &[
    StatRow {
        name: "Build ms",
        tip: "Time to build the BVH: every level (for two levels, the meshes' BVHs and the top level), with the tree laid out for traversal",
        per_ray: false,
        value: |f| Some(fmt_ms(f.build_ms)),
    },
    StatRow {
        name: "Nodes",
        tip: "Interior nodes and leaves (for the 4-wide layout: wide nodes and leaf slots)",
        per_ray: false,
        value: |f| Some(f.stats.nodes.to_string()),
    },
    StatRow { name: "Leaves", tip: "Nodes that hold triangles", per_ray: false, value: |f| Some(f.stats.leaves.to_string()) },
    StatRow {
        name: "Depth max / mean",
        tip: "Levels from the root (depth 0) to the deepest leaf, and the mean over leaves, in levels of this layout",
        per_ray: false,
        value: |f| Some(format!("{} / {:.1}", f.stats.max_depth, f.stats.mean_leaf_depth)),
    },
    StatRow {
        name: "SAH cost",
        tip: "Surface area heuristic of the whole tree: Σ interior C_trav·A(node)/A(root) + Σ leaves C_isect·N·A(leaf)/A(root). The expected traversal steps plus triangle tests of a random ray through the root box (constants below)",
        per_ray: false,
        value: |f| Some(format!("{:.2}", f.stats.sah_cost)),
    },
    StatRow {
        name: "EPO",
        tip: "End-point overlap (Aila, Karras & Laine 2013, \"On Quality Metrics of Bounding Volume Hierarchies\"): Σ over nodes of C(n) × the area of other subtrees' triangles inside the node's box, over the total triangle area, with C(n) = C_trav for interior nodes and C_isect × triangles for leaves. A ray that starts or ends on a surface must visit every box around that point; EPO counts the ones that are not its leaf's ancestors, which the SAH does not see. Of the binary tree as built (the 4-wide layout is collapsed from it). Where summing every node would cost more than about the build, the terms it could not afford are estimated from points on the surface: value ± two standard errors",
        per_ray: false,
        value: |f| f.stats.epo.map(|e| crate::bvh::epo::figure(e, f.stats.epo_error)),
    },
    StatRow {
        name: "References / triangle",
        tip: "Leaf entries per triangle: 1, unless SBVH's spatial splits cut triangles so several leaves reference the parts of one (its growth bound limits this). In parentheses: the spatial splits",
        per_ray: false,
        value: |f| Some(format!("{:.3} ({})", f.stats.references_per_triangle(), f.stats.spatial_splits)),
    },
    StatRow {
        name: "Bytes / triangle",
        tip: "Memory of the nodes, the triangle index array and the triangles the tree keeps in leaf order (36 bytes each), per triangle",
        per_ray: false,
        value: |f| Some(format!("{:.1}", f.stats.memory_bytes as f64 / f.stats.triangles.max(1) as f64)),
    },
    StatRow {
        name: "SIMD kernels",
        tip: "What the wide layout's walk runs on this CPU, chosen when the program starts: avx2 (eight boxes in one pass, leaves four triangles per pass), simd4 (four lanes: SSE2 or NEON), scalar. BVHSCOPE_SIMD=simd4 or scalar asks for a more portable one. Every choice finds the same hits with the same counts",
        per_ray: false,
        value: |f| Some(f.stats.simd.unwrap_or("— (binary)").to_string()),
    },
    StatRow {
        name: "Fallback splits",
        tip: "Nodes where the strategy found no useful split (midpoint with an empty side, SAH with coincident centroids) and an equal-count split was used",
        per_ray: false,
        value: |f| Some(f.stats.fallback_splits.to_string()),
    },
    StatRow {
        name: "Rays in root box",
        tip: "Share of the frame's primary rays that enter the root box; the others cost one box test and visit nothing. The per-ray rows below are means over these rays, unless they say all rays. An imported tree is measured on the mesh's box instead (its SAH cost too), as the tree beside it: a root box larger than the mesh's lets more rays in, and their work counts against it",
        per_ray: true,
        value: |f| rays(f).map(|r| format!("{:.1} %", 100.0 * r.root_fraction())),
    },
    StatRow {
        name: "Nodes visited / ray",
        tip: "Nodes taken from the stack and processed (interior and leaf), per ray that enters the root box",
        per_ray: true,
        value: |f| rays(f).map(|r| format!("{:.2}", r.root_mean_nodes_visited)),
    },
    StatRow {
        name: "Box tests / ray",
        tip: "Ray–box slab tests per ray that enters the root box (the root's own test included; a wide node tests each valid child)",
        per_ray: true,
        value: |f| rays(f).map(|r| format!("{:.2}", r.root_mean_box_tests)),
    },
    StatRow {
        name: "Triangle tests / ray",
        tip: "Ray–triangle tests per ray that enters the root box",
        per_ray: true,
        value: |f| rays(f).map(|r| format!("{:.2}", r.root_mean_triangle_tests)),
    },
    StatRow {
        name: "Nodes / ray, all rays",
        tip: "Nodes visited per ray over all primary rays of the frame, those that miss the root box (0 nodes) included",
        per_ray: true,
        value: |f| rays(f).map(|r| format!("{:.2}", r.mean_nodes_visited)),
    },
    StatRow {
        name: "Tri tests / ray, all rays",
        tip: "Triangle tests per ray over all primary rays of the frame",
        per_ray: true,
        value: |f| rays(f).map(|r| format!("{:.2}", r.mean_triangle_tests)),
    },
    StatRow {
        name: "Most in one ray",
        tip: "The most nodes visited, and the most triangle tests, of any one ray of the frame",
        per_ray: true,
        value: |f| rays(f).map(|r| format!("{} / {}", r.max_nodes_visited, r.max_triangle_tests)),
    },
];

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
    // The scene's note: its first sentence, the rest on asking (a paragraph pushed the figures
    // out of a projector's view).
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
    ui.add_space(6.0);
    let Some(current) = app.current_figures() else {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label("Building…");
        });
        return;
    };
    gpu_lines(app, ui);
    // Side by side, the second column is B and a third gives B − A; otherwise it is the strategy
    // shown before this one.
    let b = app.compare_figures();
    let comparing = b.is_some();
    let previous = b.or_else(|| app.previous.clone());
    let key = app.rays_key();
    // The second column's per-ray figures count only when they come from the same rays as the
    // current ones (B: the same camera; its traversal is its own).
    let comparable = |f: &StrategyFigures| match (&f.rays, &key) {
        (Some(r), Some((camera, _))) if comparing => r.camera == *camera,
        (Some(r), Some((camera, trace))) => r.comparable(camera, trace),
        _ => false,
    };
    let columns = if comparing { 4 } else { 3 };
    // Four columns share the width (a long label such as an imported file's wraps within its own).
    let width = if comparing { super::layout::grid_column_width(ui, columns) } else { 0.4 * ui.available_width() };
    egui::Grid::new("bvh-stats").num_columns(columns).striped(true).max_col_width(width).show(ui, |ui| {
        ui.label("");
        ui.strong(&current.label);
        match &previous {
            Some(p) if comparing => ui.strong(&p.label).on_hover_text("B, the build compared side by side"),
            Some(p) => ui.weak(format!("before: {}", p.label)).on_hover_text("The strategy shown before this one, for comparison"),
            None => ui.weak("before: —").on_hover_text("The strategy shown before this one, for comparison"),
        };
        if comparing {
            ui.strong("B - A");
        }
        ui.end_row();
        for row in ROWS {
            ui.label(row.name).on_hover_text(row.tip);
            let a = (row.value)(&current);
            ui.label(a.clone().unwrap_or_else(|| "…".into()));
            match &previous {
                Some(p) if row.per_ray && !comparable(p) => {
                    let was = (row.value)(p).unwrap_or_else(|| "not measured".into());
                    ui.weak(egui::RichText::new("stale").italics()).on_hover_text(format!(
                        "Measured with another camera, image size or traversal order (was {was}); not comparable with this frame"
                    ));
                }
                Some(p) if comparing => {
                    let b = (row.value)(p);
                    ui.label(b.clone().unwrap_or_default());
                    // The difference of the rows that are one number (a percentage's too).
                    let num = |v: &Option<String>| v.as_deref().and_then(|t| t.trim_end_matches(" %").parse::<f64>().ok());
                    match (num(&a), num(&b)) {
                        // Counts (nodes, leaves) differ by whole numbers: no decimals for them.
                        (Some(x), Some(y)) if [&a, &b].iter().all(|v| v.as_deref().is_some_and(|t| t.parse::<i64>().is_ok())) => {
                            ui.label(format!("{:+}", (y - x) as i64))
                        }
                        (Some(x), Some(y)) => ui.label(format!("{:+.2}", y - x)),
                        _ => ui.label(""),
                    };
                }
                Some(p) => {
                    ui.weak((row.value)(p).unwrap_or_default());
                }
                None => {
                    ui.label("");
                }
            }
            if comparing && previous.as_ref().is_some_and(|p| row.per_ray && !comparable(p)) {
                ui.label("");
            }
            ui.end_row();
        }
    });
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
    speedup(app, ui, out);

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

/// The speed-up over linear search the lab asks for: on demand (the scan of a big mesh takes
/// seconds), single rays on one thread, as `bvhscope compare`'s trace column times them.
fn speedup(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    ui.add_space(6.0);
    ui.label("Speed-up over linear search").on_hover_text(
        "The frame's primary rays traced one at a time on one thread, closest hit, no shading: through this BVH, and through a linear scan of every triangle (on a spread sample when the whole frame would take over 10 s). bvhscope compare prints the same column",
    );
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
            let s = &t.speedup;
            let sampled = s.linear_sampled.map_or(String::new(), |n| format!(" (projected from {n} rays)"));
            ui.label(format!(
                "{:.0}× faster: this BVH {} ms, the linear scan {} ms{sampled}, for the {} rays of the {}×{} frame on one thread.",
                s.speedup,
                fmt_ms(s.tree_ms),
                fmt_ms(s.linear_ms),
                s.rays,
                t.camera.width,
                t.camera.height
            ));
            if ui.small_button("Time again").on_hover_text("Timings vary from run to run on a busy machine").clicked() {
                out.push(Action::TimeLinear(true));
            }
        }
        None => {
            if ui.button("Time against the linear scan").clicked() {
                out.push(Action::TimeLinear(true));
            }
        }
    }
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
            let nodes = s.gpu.as_ref().map_or("", |g| g.nodes.name());
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
