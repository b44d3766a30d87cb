//! The view panel: what the image shows, heatmap colours and range, and the node-box overlay.

use crate::app::BvhscopeApp;
use crate::render::{ColorMap, View};

pub fn show(app: &mut BvhscopeApp, ui: &mut egui::Ui) {
    ui.heading("View");
    let max_depth = app.current_bvh().map_or(0, |b| b.stats.max_depth);
    let legend_range = app.shown.as_ref().and_then(|s| s.legend.as_ref()).map(|l| (l.range_min, l.range_max));
    let s = &mut app.settings;
    for v in View::ALL {
        ui.radio_value(&mut s.view, v, v.label());
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
    ui.add_enabled(s.show_boxes, egui::Slider::new(&mut s.box_depth, 0..=max_depth).text("Box depth"));
    ui.add_enabled(s.show_boxes, egui::Checkbox::new(&mut s.boxes_leaves_above, "Also leaves above this depth"));
    if s.show_boxes {
        ui.label(format!("{} boxes drawn", app.boxes_drawn));
    }
}
