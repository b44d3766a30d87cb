//! The view panel: what the image shows, heatmap colours and range, the up axis, and the node-box
//! overlay.

use crate::app::jobs::Probe;
use crate::app::state::{Action, Actions, BoxLevel, BvhscopeApp, Film, Settings};
use crate::gpu_path::{Device, GpuNodes};
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
    // As wide as the tile shows, not as the widest row above (a build slider wider than the tile
    // widens the panel's layout, and rows laid out to that width were cut at the tile's edge
    // instead of wrapping: "Pri" for Primary, issue 59).
    let visible = (ui.clip_rect().right() - ui.cursor().left()).max(1.0);
    ui.vertical(|ui| {
        ui.set_max_width(visible.min(ui.available_width()));
        contents(app, ui, out);
    });
}

fn contents(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let mut edited = app.settings.clone();
    // "Trace on" shares the heading's row where it fits: the panel is tall already, and what
    // follows must stay on screen.
    ui.horizontal_wrapped(|ui| {
        ui.heading("View");
        ui.add_space(12.0);
        trace_on(app, ui, &mut edited);
    });
    // The range on screen: side by side, the pair's one scale (A's alone would clip B's hottest
    // pixels); the difference's is its own ±range (below).
    let compared = app.compare_images(ui.ctx());
    let difference = app.compare.mode == crate::render::PairView::Difference;
    let pair_range = compared.as_ref().filter(|_| !difference).and_then(|c| c.legend.as_ref());
    let legend_range =
        pair_range.or(app.shown.as_ref().and_then(|s| s.legend.as_ref())).map(|l| (l.range_min, l.range_max));
    let diff_legend = compared.as_ref().filter(|_| difference).and_then(|c| c.diff.as_ref()).map(|d| d.2.range_max);
    let ranges = Ranges { legend: legend_range, difference, diff_legend };
    let cost = super::stats::combined_cost_text(app.settings.build.cost);
    // The top level's depth, when two levels are built.
    let top_depth = app.current_bvh().and_then(|b| b.top_stats.as_ref()).map(|s| s.max_depth);
    let s = &mut edited;
    gpu_choices(app, ui, s);
    view_choices(ui, s, top_depth.is_some(), &cost);
    ui.add_enabled_ui(s.view.is_heatmap(), |ui| heatmap_controls(ui, s, &ranges));
    film_and_axis(app, ui, s);
    ui.separator();
    node_boxes(app, ui, s, top_depth);
    if edited != app.settings {
        out.push(Action::Edit(Box::new(edited)));
    }
}

/// The heatmap's range on screen: this frame's (or the pair's) legend, and for Compare's
/// difference B − A its own ± range.
struct Ranges {
    legend: Option<(f32, f32)>,
    difference: bool,
    diff_legend: Option<f32>,
}

/// The views, in two columns where both fit; the 64-lane switch of the warp views; the two-level
/// views when two levels are built.
fn view_choices(ui: &mut egui::Ui, s: &mut Settings, two_levels: bool, cost: &str) {
    // The warp views are listed once, at 32 lanes; "64 lanes" below switches the one shown.
    let listed = |v: &View| !v.is_per_level() && v.warp() != Some(WarpSize::W64);
    let shown = match s.view {
        View::WarpCost(_) => View::WarpCost(WarpSize::W32),
        View::SimtEfficiency(_) => View::SimtEfficiency(WarpSize::W32),
        v => v,
    };
    // In two columns where both fit, to keep the panel short; else one (presenting, a narrow
    // tile: the second column was cut at the tile's edge).
    let labels: Vec<(View, String)> =
        View::ALL.into_iter().filter(listed).map(|v| (v, v.label().replace(" (32 lanes)", ""))).collect();
    let font = egui::TextStyle::Body.resolve(ui.style());
    let widest = labels
        .iter()
        .map(|(_, l)| ui.painter().layout_no_wrap(l.clone(), font.clone(), egui::Color32::WHITE).size().x)
        .fold(0.0, f32::max);
    let sp = ui.spacing();
    let column = widest + sp.icon_width + sp.icon_spacing + sp.item_spacing.x;
    let columns = if 2.0 * column <= ui.available_width() { 2 } else { 1 };
    // "64-lane warps" takes the cell after the last view: always there, greyed where no warp view
    // is shown (a row that came with the warp views moved everything below it between clicks).
    let lanes = s.view.warp();
    let mut wide = lanes == Some(WarpSize::W64);
    let count = labels.len();
    egui::Grid::new("views").num_columns(columns).show(ui, |ui| {
        for (i, (v, label)) in labels.into_iter().enumerate() {
            if ui.radio(shown == v, label).on_hover_text(view_tip(v, cost)).clicked() {
                s.view = v;
            }
            if i % columns == columns - 1 {
                ui.end_row();
            }
        }
        ui.add_enabled(lanes.is_some(), egui::Checkbox::new(&mut wide, "64-lane warps"))
            .on_hover_text(
                "Groups of 64 rays (8×8 pixels, AMD's wave64) instead of 32 (8×4, NVIDIA's warp and most GPUs')",
            )
            .on_disabled_hover_text("For the Warp cost and SIMT efficiency views: choose one of them first");
        if count.is_multiple_of(columns) {
            ui.end_row();
        }
    });
    if lanes.is_some() {
        let size = if wide { WarpSize::W64 } else { WarpSize::W32 };
        s.view = match s.view {
            View::WarpCost(_) => View::WarpCost(size),
            _ => View::SimtEfficiency(size),
        };
    }
    if two_levels {
        ui.label("Two-level work (Nodes visited counts both levels)");
        for v in View::ALL.into_iter().filter(|v| v.is_per_level()) {
            ui.radio_value(&mut s.view, v, v.label()).on_hover_text(view_tip(v, cost));
        }
    }
}

/// The colour map, the rays counted, and the range: auto, fixed, or the difference's ±.
fn heatmap_controls(ui: &mut egui::Ui, s: &mut Settings, ranges: &Ranges) {
    let (legend_range, difference, diff_legend) = (ranges.legend, ranges.difference, ranges.diff_legend);
    // A row each: side by side, a narrow tile cut the rays' name to "Pri" (issue 59).
    combo(ui, "Colour map", &mut s.colormap)
        .on_hover_text("Perceptual colour maps: equal steps in value look like equal steps in colour");
    combo(ui, "Rays", &mut s.rays.kind).on_hover_text("Which rays the heatmaps count: the camera's, or rays from each of its hits (bvhscope render --ray-kind). A pixel's value is the mean over its rays; grey pixels: the camera ray missed.");
    ray_numbers(ui, &mut s.rays);
    let view = s.view;
    // The range's values are always there, beside the checkbox (greyed, this frame's, while
    // auto): rows that came and went moved the controls below them between two clicks
    // (issue 59), as do the fix button and the difference's row below.
    let mut auto = !s.fixed_ranges.contains_key(&view);
    let auto_range = legend_range.filter(|_| !difference).unwrap_or((0.0, 100.0));
    let mut shown_range = s.fixed_ranges.get(&view).copied().unwrap_or(auto_range);
    ui.horizontal_wrapped(|ui| {
        if ui
            .checkbox(&mut auto, "Auto range")
            .on_hover_text("On: this frame's min..max. Off: a fixed range for this view, kept when the strategy changes so two strategies show in the same colours. Each view has its own; opening a scene clears them.")
            .changed()
        {
            if auto {
                s.fixed_ranges.remove(&view);
            } else {
                let (lo, hi) = legend_range.unwrap_or((0.0, 100.0));
                s.fixed_ranges.insert(view, (lo, hi.max(lo + 1.0)));
                shown_range = (lo, hi.max(lo + 1.0));
            }
        }
        let why = "Auto range is on (this frame's min..max): uncheck it to set the range";
        let min = egui::DragValue::new(&mut shown_range.0).speed(0.5).prefix("min ");
        ui.add_enabled(!auto, min).on_disabled_hover_text(why);
        let max = egui::DragValue::new(&mut shown_range.1).speed(0.5).prefix("max ");
        ui.add_enabled(!auto, max).on_disabled_hover_text(why);
    });
    if let Some(range) = s.fixed_ranges.get_mut(&view) {
        *range = shown_range;
        if range.1 <= range.0 {
            range.1 = range.0 + 1.0;
        }
    }
    let fixable = legend_range.filter(|_| !difference);
    let why = if difference {
        "The difference B − A has its own ± range: the rows below"
    } else {
        "No heatmap on screen yet"
    };
    if ui
        .add_enabled(fixable.is_some(), egui::Button::new("Fix the current range"))
        .on_hover_text("Keep this scale for this view, to compare strategies on the same colours (side by side: the pair's one scale)")
        .on_disabled_hover_text(why)
        .clicked()
    {
        if let Some((lo, hi)) = fixable {
            s.fixed_ranges.insert(view, (lo, hi.max(lo + 1.0)));
        }
    }
    // The difference B − A (Compare): its own ±range, fixable as `render --difference --range`.
    ui.add_enabled_ui(difference, |ui| {
        ui.horizontal_wrapped(|ui| {
        let why = "For Compare's Difference B − A only";
        let mut fixed = s.diff_ranges.contains_key(&view);
        if ui
            .checkbox(&mut fixed, "Fixed difference range (±)")
            .on_hover_text("Off: ± the 99th percentile of this difference's values. On: this ±range for this view, as bvhscope render --difference … --range -R:R")
            .on_disabled_hover_text(why)
            .changed()
        {
            if fixed {
                s.diff_ranges.insert(view, diff_legend.unwrap_or(10.0).abs().max(1.0));
            } else {
                s.diff_ranges.remove(&view);
            }
        }
        let mut r = s.diff_ranges.get(&view).copied().or(diff_legend.map(f32::abs)).unwrap_or(10.0);
        ui.add_enabled(fixed, egui::DragValue::new(&mut r).speed(0.5).range(0.001..=f32::MAX).prefix("± "))
            .on_disabled_hover_text(if difference { "Check Fixed difference range to set it" } else { why });
        if let Some(fixed) = s.diff_ranges.get_mut(&view) {
            *fixed = r;
        }
        });
    });
}

/// Progressive refinement, the film's size and the up axis.
fn film_and_axis(app: &BvhscopeApp, ui: &mut egui::Ui, s: &mut Settings) {
    ui.checkbox(&mut s.progressive, "Progressive refinement")
        .on_hover_text("Coarse passes first (1/8, 1/4, 1/2, full)");
    ui.horizontal_wrapped(|ui| {
        let scene = app.scene.camera.map(|c| (c.width, c.height));
        ui.label("Film").on_hover_text(
            "The image's size: the viewport's, or the scene file's camera size (letterboxed), so the statistics are those of the scene's frame, as bvhscope stats SCENE counts them",
        );
        ui.radio_value(&mut s.film, Film::Viewport, "viewport");
        let label = scene.map_or("the scene's (none)".to_string(), |(w, h)| format!("the scene's {w}×{h}"));
        // Added as one widget, not in a child ui: a row wraps whole widgets, and a child ui at
        // its end ran past the tile's edge.
        let scene_film = egui::RadioButton::new(s.film == Film::Scene, label);
        if ui.add_enabled(scene.is_some(), scene_film).on_disabled_hover_text("The scene file has no camera").clicked() {
            s.film = Film::Scene;
        }
    });
    ui.horizontal_wrapped(|ui| {
        ui.label("Up axis").on_hover_text(
            "Which axis of the mesh points up. Meshes exported Z-up (CAD, scans) look as if seen from underneath with Y up. Changing it resets the camera to the front view.",
        );
        for a in UpAxis::ALL {
            ui.radio_value(&mut s.up_axis, a, a.label()).on_hover_text(a.help());
        }
    });
}

/// The node-box overlay: on or off, its depth (per level when two are built), which boxes.
fn node_boxes(app: &BvhscopeApp, ui: &mut egui::Ui, s: &mut Settings, top_depth: Option<u32>) {
    let max_depth = app.current_bvh().map_or(0, |b| b.bottom_max_depth());
    ui.heading("Node boxes");
    ui.checkbox(&mut s.show_boxes, "Show node boxes")
        .on_hover_text("The boxes of every node at the chosen depth, as wireframes over the image (B)");
    if let Some(top_max) = top_depth {
        ui.add_enabled_ui(s.show_boxes, |ui| {
            ui.horizontal_wrapped(|ui| {
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
    // Always a row (greyed with none drawn), so nothing moves when the boxes are switched on.
    let drawn = if s.show_boxes { format!("{} boxes drawn", app.boxes_drawn()) } else { "no boxes drawn".to_string() };
    ui.add_enabled(s.show_boxes, egui::Label::new(drawn));
}

/// A labelled combo box of a choice from the option tables (`options::Choice`): its labels, each
/// with its help on hover. As wide as its widest label whichever is chosen (choosing does not move
/// what follows), on its label's row where both fit, else below it: its text is never cut (a
/// narrow tile cut "Primary" to "Pri", issue 59).
pub(super) fn combo<T: crate::options::Choice>(ui: &mut egui::Ui, label: &str, value: &mut T) -> egui::Response {
    // Salted by its text, not by the label's id: an auto id moves when widgets before it come
    // and go, and the open list would close.
    let salt = label;
    let font = egui::TextStyle::Button.resolve(ui.style());
    let text_width = |t: &str| ui.painter().layout_no_wrap(t.to_string(), font.clone(), egui::Color32::WHITE).size().x;
    let widest = T::TABLE.iter().map(|n| text_width(n.label)).fold(0.0, f32::max);
    let sp = ui.spacing();
    // The button's text, the gap, the arrow, the padding either side.
    let width = widest + sp.icon_spacing + sp.icon_width + 2.0 * sp.button_padding.x + sp.item_spacing.x;
    let one_row = text_width(label) + sp.item_spacing.x + width <= ui.available_width();
    let mut add = |ui: &mut egui::Ui| {
        let label = ui.label(label);
        // Narrower than its text (a tile narrower than any label), the text wraps, never cut.
        let width = width.min(ui.available_width());
        egui::ComboBox::from_id_salt(salt)
            .width(width)
            .wrap()
            .selected_text(value.named().label)
            .show_ui(ui, |ui| {
                for n in T::TABLE {
                    ui.selectable_value(value, n.value, n.label).on_hover_text(n.help);
                }
            })
            .response
            .labelled_by(label.id)
    };
    if one_row {
        ui.horizontal(|ui| add(ui)).inner
    } else {
        add(ui)
    }
}

/// For ao rays and bounces, below the ray kind: rays per pixel (and the ao rays' length). The
/// same rays as `bvhscope render --ray-kind` for the seed. Always a row, greyed for the kinds
/// with one ray per pixel: a row that came with ao rays moved the controls below it.
fn ray_numbers(ui: &mut egui::Ui, r: &mut crate::render::SecondarySpec) {
    let many = matches!(r.kind, RayKind::Ao | RayKind::Bounce);
    let one = "One ray per pixel for this kind: rays per pixel are for Ambient occlusion and Diffuse bounce";
    ui.horizontal_wrapped(|ui| {
        ui.add_enabled(many, egui::DragValue::new(&mut r.samples).range(1..=MAX_SAMPLES).suffix(" rays per pixel"))
            .on_hover_text("Rays per pixel (--samples)")
            .on_disabled_hover_text(one);
        let mut percent = r.ao_length * 100.0;
        // Written back only when dragged: percent / 100 need not give back the same float.
        if ui
            .add_enabled(
                r.kind == RayKind::Ao,
                egui::DragValue::new(&mut percent).range(0.1..=100.0).speed(0.5).suffix(" % of diagonal"),
            )
            .on_hover_text("Length of the ao rays, as a share of the scene's diagonal (--ao-length)")
            .on_disabled_hover_text("The length of Ambient occlusion rays only")
            .changed()
        {
            r.ao_length = percent / 100.0;
        }
    });
}

/// "Trace on: CPU / GPU": the GPU greyed, with the reason on hover, until an adapter is found.
fn trace_on(app: &BvhscopeApp, ui: &mut egui::Ui, s: &mut Settings) {
    let probe = &app.jobs.gpu.probe;
    ui.label("Trace on").on_hover_text(
        format!("Where the frames are traced: the CPU, or the GPU (wgpu compute shaders) at full resolution in one pass, with the same per-pixel counts as the CPU's binary layout (bvhscope render --device gpu). With the GPU, the tree is built in the binary layout and {} are built on the GPU too.", crate::gpu_path::gpu_built()),
    );
    ui.radio_value(&mut s.device, Device::Cpu, Device::Cpu.label());
    let why = match probe {
        Probe::Looking => "Looking for a GPU adapter…".to_string(),
        Probe::Missing(why) => format!("No GPU: {why}"),
        Probe::Found(g) if g.is_software() => {
            format!("{} (a software adapter: its counts are right, its times are no GPU's)", g.name())
        }
        Probe::Found(g) => g.name(),
    };
    // The GPU chosen but not tracing now (two levels, the replay, secondary rays): why, on hover
    // here and on the greyed GPU nodes row. Its label stays "GPU": a longer one wrapped this row
    // and moved every row below it.
    let blocked = app.gpu_blocked().filter(|_| s.device == Device::Gpu);
    let why = match blocked {
        Some(blocked) if matches!(probe, Probe::Found(_)) => format!("{why}. Traced on the CPU now: {blocked}"),
        _ => why,
    };
    // One widget, so that the heading's row wraps it whole where the tile is narrow.
    let gpu = egui::RadioButton::new(s.device == Device::Gpu, Device::Gpu.label());
    if ui.add_enabled(matches!(probe, Probe::Found(_)), gpu).on_hover_text(&why).on_disabled_hover_text(&why).clicked()
    {
        s.device = Device::Gpu;
    }
}

/// The GPU's node format: always a row, greyed while the CPU traces, with why on hover (it came
/// with the GPU's button and moved the view choices below it between two clicks).
fn gpu_choices(app: &BvhscopeApp, ui: &mut egui::Ui, s: &mut Settings) {
    let why = if s.device != Device::Gpu {
        Some("The node format the GPU walks: for Trace on GPU".to_string())
    } else {
        app.gpu_blocked().map(|why| format!("Traced on the CPU now: {why}"))
    };
    ui.add_enabled_ui(why.is_none(), |ui| {
        ui.horizontal_wrapped(|ui| {
            let label = ui.label("GPU nodes");
            if let Some(why) = &why {
                label.on_disabled_hover_text(why);
            }
            for nodes in GpuNodes::ALL {
                let r = ui.radio_value(&mut s.gpu_nodes, nodes, nodes.label()).on_hover_text(nodes.help());
                if let Some(why) = &why {
                    r.on_disabled_hover_text(format!("{}. {why}", nodes.help()));
                }
            }
        });
    });
}
