//! The build panel: strategy and its parameters, traversal order and triangle test. Any change
//! rebuilds (or re-renders) in the background.

use crate::app::BvhscopeApp;
use crate::bvh::{Layout, Preset, SplitStrategy, TraversalOrder};
use crate::geometry::TriangleTest;

pub fn show(app: &mut BvhscopeApp, ui: &mut egui::Ui) {
    ui.heading("Build");
    for preset in Preset::ALL {
        let on = app.settings.is_preset(preset);
        let text = if on { format!("{} (on)", preset.label()) } else { preset.label().to_string() };
        if ui
            .add_enabled(!on, egui::Button::new(text))
            .on_hover_text(format!(
                "One click to {}: the BVH a student writes in the lab, so the figures compare with yours",
                preset.description()
            ))
            .on_disabled_hover_text(format!("These are the settings of {}", preset.description()))
            .clicked()
        {
            app.apply_preset(preset);
        }
    }
    let has_instances = app.has_instances();
    let placements = app.scene.instances.as_ref().map_or(0, |i| i.placements.len());
    let meshes = app.scene.instances.as_ref().map_or(0, |i| i.meshes.len());
    let s = &mut app.settings;
    if has_instances {
        ui.checkbox(&mut s.two_level, format!("Two levels: {placements} placements of {meshes} meshes"))
            .on_hover_text("A top-level BVH over the scene's mesh placements, and one BVH per mesh built once however often it is placed. Off: one BVH over the whole scene flattened.");
        if s.two_level {
            ui.horizontal(|ui| {
                let label = ui.label("Top-level strategy");
                egui::ComboBox::from_id_salt("top-strategy")
                    .selected_text(s.top_build.strategy.label())
                    .show_ui(ui, |ui| {
                        for k in SplitStrategy::ALL {
                            ui.selectable_value(&mut s.top_build.strategy, k, k.label()).on_hover_text(k.description());
                        }
                    })
                    .response
                    .labelled_by(label.id);
            });
            ui.add(egui::Slider::new(&mut s.top_build.max_leaf_size, 1..=16).text("Placements per leaf"))
                .on_hover_text("Most placements in a leaf of the top level");
            ui.label("Bottom level (each mesh's BVH)");
        }
    }
    let label = ui.label("Split strategy");
    egui::ComboBox::from_id_salt("strategy")
        .selected_text(s.build.strategy.label())
        .width(200.0)
        .show_ui(ui, |ui| {
            for k in SplitStrategy::ALL {
                ui.selectable_value(&mut s.build.strategy, k, k.label()).on_hover_text(k.description());
            }
        })
        .response
        .labelled_by(label.id)
        .on_hover_text(s.build.strategy.description());

    ui.add(egui::Slider::new(&mut s.build.max_leaf_size, 1..=32).text("Max leaf size"))
        .on_hover_text("Most triangles in a leaf. The SAH strategies may stop earlier when a leaf is cheaper.");
    let sah = s.build.strategy == SplitStrategy::SahBinned;
    ui.add_enabled(sah, egui::Slider::new(&mut s.build.sah_bins, 2..=64).text("SAH bins"))
        .on_hover_text("Bins per axis of the binned SAH: more bins, closer to the exact sweep, slower build. Small nodes use fewer: a third of their triangle count, at least 4 (never more than asked for).");
    ui.add(egui::Slider::new(&mut s.build.cost.traversal, 0.1..=4.0).text("SAH traversal cost"))
        .on_hover_text("Cost of one traversal step relative to one triangle test (1 = equal).");

    ui.add_space(4.0);
    ui.label("Layout");
    for l in Layout::ALL {
        let tip = match l {
            Layout::Binary => "The binary BVH as built (two children per node), as in the handout",
            Layout::Wide4 => "Collapsed into 4-wide nodes whose boxes are tested together with SIMD: faster",
        };
        ui.radio_value(&mut s.build.layout, l, l.label()).on_hover_text(tip);
    }
    ui.label("Traversal order (binary layout)");
    for o in TraversalOrder::ALL {
        let tip = match o {
            TraversalOrder::SplitAxisSign => {
                "The handout's rule: the ray's sign on the node's split axis picks the near child"
            }
            TraversalOrder::EntryDistance => "Visit the child whose box the ray enters first",
        };
        ui.radio_value(&mut s.trace.order, o, o.label()).on_hover_text(tip);
    }
    ui.label("Triangle test");
    for t in TriangleTest::ALL {
        let tip = match t {
            TriangleTest::Watertight => "Woop, Benthin & Wald 2013: no cracks along shared edges",
            TriangleTest::MollerTrumbore => "Möller & Trumbore 1997: the classic; may miss rays exactly through edges",
        };
        ui.radio_value(&mut s.trace.test, t, t.label()).on_hover_text(tip);
    }
    if let Some(job) = &app.jobs.build {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label(format!("{} {:.0}%", job.label, job.control.fraction() * 100.0));
        });
    }
}
