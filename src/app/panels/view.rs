//! The view panel: what the image shows, heatmap colours and range, the up axis, and the node-box
//! overlay.

use crate::app::jobs::Probe;
use crate::app::state::{Action, Actions, BoxLevel, BvhscopeApp, Film, Settings};
use crate::gpu_path::{Device, GPU_NODES};
use crate::render::secondary::MAX_SAMPLES;
use crate::render::warp::WarpSize;
use crate::render::{RayKind, UpAxis, View};

/// What a view shows, for its tooltip: its help, and for combined cost the constants in use.
fn view_tip(v: View, cost: &str) -> String {
    match v {
        View::Cost => format!("Heatmap of each ray's combined cost. {cost}"),
        _ => v.help().to_string(),
    }
}

pub fn show(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let mut edited = app.settings.clone();
    // "Trace on" shares the heading's row: the panel is tall already, and what follows must stay
    // on screen.
    ui.horizontal(|ui| {
        ui.heading("View");
        ui.add_space(12.0);
        trace_on(app, ui, &mut edited);
    });
    let max_depth = app.current_bvh().map_or(0, |b| b.bottom_max_depth());
    // The top level's depth, when two levels are built.
    let top_depth = app.current_bvh().and_then(|b| b.top_stats.as_ref()).map(|s| s.max_depth);
    // The range on screen: side by side, the pair's one scale (A's alone would clip B's hottest
    // pixels); the difference's is its own ±range (below).
    let compared = app.compare_images(ui.ctx());
    let difference = app.compare.mode == crate::render::PairView::Difference;
    let pair_range = compared.as_ref().filter(|_| !difference).and_then(|c| c.legend.as_ref());
    let legend_range =
        pair_range.or(app.shown.as_ref().and_then(|s| s.legend.as_ref())).map(|l| (l.range_min, l.range_max));
    let diff_legend = compared.as_ref().filter(|_| difference).and_then(|c| c.diff.as_ref()).map(|d| d.2.range_max);
    let cost = super::stats::combined_cost_text(app.settings.build.cost);
    let s = &mut edited;
    gpu_choices(app, ui, s);
    // The warp views are listed once, at 32 lanes; "64 lanes" below switches the one shown.
    let listed = |v: &View| !v.is_per_level() && v.warp() != Some(WarpSize::W64);
    let shown = match s.view {
        View::WarpCost(_) => View::WarpCost(WarpSize::W32),
        View::SimtEfficiency(_) => View::SimtEfficiency(WarpSize::W32),
        v => v,
    };
    // In two columns, to keep the panel short.
    egui::Grid::new("views").num_columns(2).show(ui, |ui| {
        for (i, v) in View::ALL.into_iter().filter(listed).enumerate() {
            if ui.radio(shown == v, v.label().replace(" (32 lanes)", "")).on_hover_text(view_tip(v, &cost)).clicked() {
                s.view = v;
            }
            if i % 2 == 1 {
                ui.end_row();
            }
        }
    });
    if let Some(lanes) = s.view.warp() {
        let mut wide = lanes == WarpSize::W64;
        ui.checkbox(&mut wide, "64 lanes per warp (AMD wave64)")
            .on_hover_text("Groups of 64 rays (8×8 pixels) instead of 32 (8×4, NVIDIA's warp and most GPUs')");
        let size = if wide { WarpSize::W64 } else { WarpSize::W32 };
        s.view = match s.view {
            View::WarpCost(_) => View::WarpCost(size),
            _ => View::SimtEfficiency(size),
        };
    }
    if top_depth.is_some() {
        ui.label("Two-level work (Nodes visited counts both levels)");
        for v in View::ALL.into_iter().filter(|v| v.is_per_level()) {
            ui.radio_value(&mut s.view, v, v.label()).on_hover_text(view_tip(v, &cost));
        }
    }
    ui.add_enabled_ui(s.view.is_heatmap(), |ui| {
        // The rays share the colour map's row: the panel must not grow taller for them.
        ui.horizontal(|ui| {
            combo(ui, "Colour map", &mut s.colormap)
                .on_hover_text("Perceptual colour maps: equal steps in value look like equal steps in colour");
            ui.add_space(8.0);
            combo(ui, "Rays", &mut s.rays.kind).on_hover_text("Which rays the heatmaps count: the camera's, or rays from each of its hits (bvhscope render --ray-kind). A pixel's value is the mean over its rays; grey pixels: the camera ray missed.");
        });
        ray_numbers(ui, &mut s.rays);
        let view = s.view;
        let mut auto = !s.fixed_ranges.contains_key(&view);
        if ui
            .checkbox(&mut auto, "Auto range (this frame's min..max)")
            .on_hover_text("Off: a fixed range for this view, kept when the strategy changes so two strategies show in the same colours. Each view has its own; opening a scene clears them.")
            .changed()
        {
            if auto {
                s.fixed_ranges.remove(&view);
            } else {
                let (lo, hi) = legend_range.unwrap_or((0.0, 100.0));
                s.fixed_ranges.insert(view, (lo, hi.max(lo + 1.0)));
            }
        }
        if let Some(range) = s.fixed_ranges.get_mut(&view) {
            ui.horizontal(|ui| {
                ui.label("Range");
                ui.add(egui::DragValue::new(&mut range.0).speed(0.5).prefix("min "));
                ui.add(egui::DragValue::new(&mut range.1).speed(0.5).prefix("max "));
            });
            if range.1 <= range.0 {
                range.1 = range.0 + 1.0;
            }
        }
        if let Some((lo, hi)) = legend_range.filter(|_| !difference) {
            if ui
                .button("Fix the current range")
                .on_hover_text("Keep this scale for this view, to compare strategies on the same colours (side by side: the pair's one scale)")
                .clicked()
            {
                s.fixed_ranges.insert(view, (lo, hi.max(lo + 1.0)));
            }
        }
        // The difference B − A (Compare): its own ±range, fixable as `render --difference --range`.
        if difference {
            let mut fixed = s.diff_ranges.contains_key(&view);
            if ui
                .checkbox(&mut fixed, "Fixed difference range (±)")
                .on_hover_text("Off: ± the 99th percentile of this difference's values. On: this ±range for this view, as bvhscope render --difference … --range -R:R")
                .changed()
            {
                if fixed {
                    s.diff_ranges.insert(view, diff_legend.unwrap_or(10.0).abs().max(1.0));
                } else {
                    s.diff_ranges.remove(&view);
                }
            }
            if let Some(r) = s.diff_ranges.get_mut(&view) {
                ui.add(egui::DragValue::new(r).speed(0.5).range(0.001..=f32::MAX).prefix("± "));
            }
        }
    });
    ui.checkbox(&mut s.progressive, "Progressive refinement")
        .on_hover_text("Coarse passes first (1/8, 1/4, 1/2, full)");
    ui.horizontal(|ui| {
        let scene = app.scene.camera.map(|c| (c.width, c.height));
        ui.label("Film").on_hover_text(
            "The image's size: the viewport's, or the scene file's camera size (letterboxed), so the statistics are those of the scene's frame, as bvhscope stats SCENE counts them",
        );
        ui.radio_value(&mut s.film, Film::Viewport, "viewport");
        let label = scene.map_or("the scene's (none)".to_string(), |(w, h)| format!("the scene's {w}×{h}"));
        ui.add_enabled_ui(scene.is_some(), |ui| ui.radio_value(&mut s.film, Film::Scene, label));
    });
    ui.horizontal(|ui| {
        ui.label("Up axis").on_hover_text(
            "Which axis of the mesh points up. Meshes exported Z-up (CAD, scans) look as if seen from underneath with Y up. Changing it resets the camera to the front view.",
        );
        for a in UpAxis::ALL {
            ui.radio_value(&mut s.up_axis, a, a.label()).on_hover_text(a.help());
        }
    });

    ui.separator();
    ui.heading("Node boxes");
    ui.checkbox(&mut s.show_boxes, "Show node boxes")
        .on_hover_text("The boxes of every node at the chosen depth, as wireframes over the image (B)");
    if let Some(top_max) = top_depth {
        ui.add_enabled_ui(s.show_boxes, |ui| {
            ui.horizontal(|ui| {
                for l in BoxLevel::ALL {
                    ui.radio_value(&mut s.box_level, l, l.label());
                }
            });
            ui.add_enabled(
                s.box_level.shows_top(),
                egui::Slider::new(&mut s.top_box_depth, 0..=top_max).text("Top-level depth"),
            )
            .on_hover_text("Boxes of the top level (over the placements), drawn white");
            ui.add_enabled(
                s.box_level.shows_bottom(),
                egui::Slider::new(&mut s.box_depth, 0..=max_depth)
                    .clamping(egui::SliderClamping::Edits)
                    .text("Bottom-level depth"),
            )
            .on_hover_text("Boxes of each mesh's own BVH, placed by each of its instances");
        });
    } else {
        ui.add_enabled(
            s.show_boxes,
            egui::Slider::new(&mut s.box_depth, 0..=max_depth).clamping(egui::SliderClamping::Edits).text("Box depth"),
        )
        .on_hover_text("Depth of the nodes whose boxes are drawn (0: the root); [ and ] step it");
    }
    ui.add_enabled(s.show_boxes, egui::Checkbox::new(&mut s.boxes_leaves_above, "Also leaves above this depth"))
        .on_hover_text("Leaves shallower than the depth, which have no nodes at it");
    ui.add_enabled(s.show_boxes, egui::Checkbox::new(&mut s.boxes_in_front, "Only in front of the surface"))
        .on_hover_text("Hide the parts of the boxes behind the surface the rays hit (depth-tested against the ray-cast image), so deep levels do not hide the mesh");
    if s.show_boxes {
        ui.label(format!("{} boxes drawn", app.boxes_drawn()));
    }
    if edited != app.settings {
        out.push(Action::Edit(Box::new(edited)));
    }
}

/// A labelled combo box of a choice from the option tables (`options::Choice`): its labels, each
/// with its help on hover.
fn combo<T: crate::options::Choice>(ui: &mut egui::Ui, label: &str, value: &mut T) -> egui::Response {
    // Salted by its text, not by the label's id: an auto id moves when widgets before it come
    // and go, and the open list would close.
    let salt = label;
    let label = ui.label(label);
    egui::ComboBox::from_id_salt(salt)
        .selected_text(value.named().label)
        .show_ui(ui, |ui| {
            for n in T::TABLE {
                ui.selectable_value(value, n.value, n.label).on_hover_text(n.help);
            }
        })
        .response
        .labelled_by(label.id)
}

/// For ao rays and bounces, beside the ray kind: rays per pixel (and the ao rays' length). The
/// same rays as `bvhscope render --ray-kind` for the seed.
fn ray_numbers(ui: &mut egui::Ui, r: &mut crate::render::SecondarySpec) {
    if !matches!(r.kind, RayKind::Ao | RayKind::Bounce) {
        return;
    }
    ui.horizontal(|ui| {
        ui.add(egui::DragValue::new(&mut r.samples).range(1..=MAX_SAMPLES).suffix(" rays per pixel"))
            .on_hover_text("Rays per pixel (--samples)");
        if r.kind == RayKind::Ao {
            let mut percent = r.ao_length * 100.0;
            // Written back only when dragged: percent / 100 need not give back the same float.
            if ui
                .add(egui::DragValue::new(&mut percent).range(0.1..=100.0).speed(0.5).suffix(" % of the diagonal long"))
                .on_hover_text("Length of the ao rays, as a share of the scene's diagonal (--ao-length)")
                .changed()
            {
                r.ao_length = percent / 100.0;
            }
        }
    });
}

/// "Trace on: CPU / GPU": the GPU greyed, with the reason on hover, until an adapter is found.
fn trace_on(app: &BvhscopeApp, ui: &mut egui::Ui, s: &mut Settings) {
    let probe = &app.jobs.gpu.probe;
    ui.label("Trace on").on_hover_text(
        format!("Where the frames are traced: the CPU, or the GPU (wgpu compute shaders) at full resolution in one pass, with the same per-pixel counts as the CPU's binary layout (bvhscope render --device gpu). With the GPU, the tree is built in the binary layout and {} are built on the GPU too.", crate::gpu_path::gpu_built()),
    );
    ui.radio_value(&mut s.device, Device::Cpu, "CPU");
    let why = match probe {
        Probe::Looking => "Looking for a GPU adapter…".to_string(),
        Probe::Missing(why) => format!("No GPU: {why}"),
        Probe::Found(g) if g.is_software() => {
            format!("{} (a software adapter: its counts are right, its times are no GPU's)", g.name())
        }
        Probe::Found(g) => g.name(),
    };
    // The GPU chosen but not tracing now (two levels, the replay): the button says so.
    let label = if s.device == Device::Gpu && app.gpu_blocked().is_some() { "GPU (CPU now)" } else { "GPU" };
    ui.add_enabled_ui(matches!(probe, Probe::Found(_)), |ui| ui.radio_value(&mut s.device, Device::Gpu, label))
        .inner
        .on_hover_text(&why)
        .on_disabled_hover_text(&why);
}

/// With the GPU chosen: its node format, and why it does not trace now if it does not.
fn gpu_choices(app: &BvhscopeApp, ui: &mut egui::Ui, s: &mut Settings) {
    if s.device != Device::Gpu {
        return;
    }
    ui.horizontal(|ui| {
        ui.label("GPU nodes");
        for row in &GPU_NODES {
            ui.radio_value(&mut s.gpu_nodes, row.nodes, row.label).on_hover_text(row.help);
        }
    });
    if let Some(why) = app.gpu_blocked() {
        ui.label(format!("Traced on the CPU: {why}"));
    }
}
