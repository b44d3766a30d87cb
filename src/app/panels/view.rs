//! The view panel: what the image shows, heatmap colours and range, and the node-box overlay.

use crate::app::{BoxLevel, BvhscopeApp};
use crate::render::{ColorMap, View};

pub fn show(app: &mut BvhscopeApp, ui: &mut egui::Ui) {
    ui.heading("View");
    let max_depth = app.current_bvh().map_or(0, |b| b.bottom_max_depth());
    // The top level's depth, when two levels are built.
    let top_depth = app.current_bvh().filter(|b| b.bvh.two_level().is_some()).map(|b| b.stats.max_depth);
    let legend_range = app.shown.as_ref().and_then(|s| s.legend.as_ref()).map(|l| (l.range_min, l.range_max));
    let s = &mut app.settings;
    for v in View::ALL.into_iter().filter(|v| !v.is_per_level()) {
        ui.radio_value(&mut s.view, v, v.label());
    }
    if top_depth.is_some() {
        ui.label("Two-level work (Nodes visited counts both levels)");
        for v in View::ALL.into_iter().filter(|v| v.is_per_level()) {
            ui.radio_value(&mut s.view, v, v.label()).on_hover_text(match v {
                View::TopVisits => "Nodes of the top level (over the placements) visited per ray",
                View::BottomVisits => "Nodes of the meshes' own BVHs visited per ray",
                _ => "Placements whose mesh BVH the ray entered (moved into object space)",
            });
        }
    } else if s.view.is_per_level() {
        s.view = View::Visits; // a single BVH has no levels to tell apart
    }
    ui.add_enabled_ui(s.view.is_heatmap(), |ui| {
        ui.horizontal(|ui| {
            let label = ui.label("Colour map");
            egui::ComboBox::from_id_salt("colormap")
                .selected_text(s.colormap.label())
                .show_ui(ui, |ui| {
                    for c in ColorMap::ALL {
                        ui.selectable_value(&mut s.colormap, c, c.label());
                    }
                })
                .response
                .labelled_by(label.id);
        });
        ui.checkbox(&mut s.auto_range, "Auto range (this frame's min..max)");
        if !s.auto_range {
            ui.horizontal(|ui| {
                ui.label("Range");
                ui.add(egui::DragValue::new(&mut s.fixed_range.0).speed(0.5).prefix("min "));
                ui.add(egui::DragValue::new(&mut s.fixed_range.1).speed(0.5).prefix("max "));
            });
            if s.fixed_range.1 <= s.fixed_range.0 {
                s.fixed_range.1 = s.fixed_range.0 + 1.0;
            }
        }
        if let Some((lo, hi)) = legend_range {
            if ui
                .button("Fix the current range")
                .on_hover_text("Keep this scale, to compare strategies on the same colours")
                .clicked()
            {
                s.auto_range = false;
                s.fixed_range = (lo, hi.max(lo + 1.0));
            }
        }
    });
    ui.checkbox(&mut s.progressive, "Progressive refinement")
        .on_hover_text("Coarse passes first (1/8, 1/4, 1/2, full)");

    ui.separator();
    ui.heading("Node boxes");
    ui.checkbox(&mut s.show_boxes, "Show node boxes");
    s.box_depth = s.box_depth.min(max_depth);
    if let Some(top_max) = top_depth {
        ui.add_enabled_ui(s.show_boxes, |ui| {
            ui.horizontal(|ui| {
                for l in BoxLevel::ALL {
                    ui.radio_value(&mut s.box_level, l, l.label());
                }
            });
            s.top_box_depth = s.top_box_depth.min(top_max);
            ui.add_enabled(
                s.box_level.shows_top(),
                egui::Slider::new(&mut s.top_box_depth, 0..=top_max).text("Top-level depth"),
            )
            .on_hover_text("Boxes of the top level (over the placements), drawn white");
            ui.add_enabled(
                s.box_level.shows_bottom(),
                egui::Slider::new(&mut s.box_depth, 0..=max_depth).text("Bottom-level depth"),
            )
            .on_hover_text("Boxes of each mesh's own BVH, placed by each of its instances");
        });
    } else {
        ui.add_enabled(s.show_boxes, egui::Slider::new(&mut s.box_depth, 0..=max_depth).text("Box depth"));
    }
    ui.add_enabled(s.show_boxes, egui::Checkbox::new(&mut s.boxes_leaves_above, "Also leaves above this depth"));
    if s.show_boxes {
        ui.label(format!("{} boxes drawn", app.boxes_drawn));
    }
}
