//! The build panel: strategy and its parameters, traversal order and triangle test. Any change
//! rebuilds (or re-renders) in the background.

use crate::app::state::{Action, Actions, BvhscopeApp, Settings};
use crate::bvh::{BuildParams, Param, ParamLimits, ParamValue, Preset, Strategy};
use crate::options::{Choice, ParamOption, BUILD_PARAMS, TOP_MAX_LEAF_SIZE};

/// The reinsertion the current single BVH's build made, if any.
fn reinsertion_of(bvh: &crate::bvh::SceneBvh) -> Option<crate::bvh::reinsert::Reinsertion> {
    match bvh {
        crate::bvh::SceneBvh::Single { bvh, .. } => crate::bvh::TreeView::report(bvh).reinsertion,
        crate::bvh::SceneBvh::TwoLevel { .. } => None,
    }
}

/// A slider over a build parameter's whole range (logarithmic where the table says: leaf sizes of
/// 1..255 and costs of 0.01..100 are chosen near their small ends), labelled and explained by it.
/// The rail shrinks so that the value and the label fit the panel's width beside it; where even a
/// short rail leaves no room (a narrow panel, or presenting at a larger scale), the label takes a
/// line of its own above the slider instead of being cut off at the panel's edge.
fn param(ui: &mut egui::Ui, build: &mut BuildParams, o: &ParamOption) {
    const MIN_RAIL: f32 = 60.0;
    let width_of = |ui: &egui::Ui, text: &str| {
        egui::WidgetText::from(text)
            .into_galley(ui, Some(egui::TextWrapMode::Extend), f32::INFINITY, egui::TextStyle::Body)
            .size()
            .x
    };
    let v = o.param.get(build);
    // The value's box: its widest text (the largest whole value, or a six-decimal real) in a
    // button's padding.
    let widest = match o.limits() {
        ParamLimits::Whole(l) => l.max.to_string(),
        ParamLimits::Real(_) => "0.000000".to_string(),
    };
    let gap = ui.spacing().item_spacing.x;
    let value = (width_of(ui, &widest) + 2.0 * ui.spacing().button_padding.x).max(ui.spacing().interact_size.x);
    let room = ui.available_width() - value - width_of(ui, o.label) - 2.0 * gap;
    let above = room < MIN_RAIL;
    let named = above.then(|| ui.label(o.label).on_hover_text(o.help_line()).id);
    let rail = if above { ui.available_width() - value - gap } else { room };
    ui.spacing_mut().slider_width = rail.clamp(MIN_RAIL, 100.0);
    let label = if above { "" } else { o.label };
    let r = match o.limits() {
        ParamLimits::Whole(l) => {
            let mut x = v.whole();
            let r = ui.add(egui::Slider::new(&mut x, l.min..=l.max).logarithmic(o.log).text(label));
            o.param.set(build, ParamValue::Whole(x));
            r
        }
        ParamLimits::Real(l) => {
            let mut x = v.real();
            let r = ui.add(egui::Slider::new(&mut x, l.min..=l.max).logarithmic(o.log).text(label));
            o.param.set(build, ParamValue::Real(x));
            r
        }
    };
    // A screen reader (and a test) still finds the slider by its name when it stands above.
    let r = match named {
        Some(id) => r.labelled_by(id),
        None => r,
    };
    r.on_hover_text(o.help_line());
}

/// One radio button per value of a choice, with its help.
fn radios<T: Choice>(ui: &mut egui::Ui, value: &mut T) {
    for n in T::TABLE {
        ui.radio_value(value, n.value, n.label).on_hover_text(n.help);
    }
}

pub fn show(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    ui.heading("Build");
    presets(app, ui, out);
    let mut edited = app.settings.clone();
    let s = &mut edited;
    if app.has_instances() {
        two_levels(app, ui, s);
    }
    let on = strategy_choice(app, ui, s, out);
    // An imported tree is traced as written: the build's parameters do not apply to it.
    ui.add_enabled_ui(!on, |ui| {
        // Each parameter of the table, greyed out where the strategy does not read it.
        for o in &BUILD_PARAMS {
            ui.add_enabled_ui(s.build.strategy.reads(o.param), |ui| param(ui, &mut s.build, o));
            // What the last build's reinsertion did (the binary tree's SAH cost before and after).
            if o.param == Param::ReinsertPasses {
                if let Some(r) = app.current_bvh().and_then(|b| reinsertion_of(&b.bvh)) {
                    ui.weak(format!("Reinsertion: {}", r.summary()));
                }
            }
        }
    });

    ui.add_space(4.0);
    ui.label("Layout");
    // On the GPU the tree is built binary and traced in the GPU's own node format (View ▸ GPU
    // nodes): the CPU's layout choice would show one thing and trace another.
    let gpu = s.device == crate::gpu_path::Device::Gpu;
    ui.add_enabled_ui(!on && !gpu, |ui| radios(ui, &mut s.build.layout));
    if on {
        ui.weak("The imported tree keeps its own layout and leaves.");
    } else if gpu {
        ui.weak("Traced on the GPU in its own node format: GPU nodes, under View.");
    }
    ui.label("Traversal order (binary layout)");
    radios(ui, &mut s.trace.order);
    // A list, not radios: three tests in one row keep the View section in sight (issue 59's room).
    super::view::combo(ui, "Triangle test", &mut s.trace.test);
    if edited != app.settings {
        out.push(Action::Edit(Box::new(edited)));
    }
    if let Some(job) = &app.jobs.build {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label(format!("{} {:.0}%", job.label, job.control.fraction() * 100.0));
        });
    }
}

/// The presets, one button each (greyed where its settings are the current ones).
fn presets(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    for preset in Preset::ALL {
        let on = app.settings.is_preset(preset);
        let text = if on { format!("{} (on)", preset.label()) } else { preset.label().to_string() };
        if ui
            .add_enabled(!on, egui::Button::new(text))
            .on_hover_text(format!("One click to {}", preset.help()))
            .on_disabled_hover_text(format!("These are the settings of {}", preset.help()))
            .clicked()
        {
            out.push(Action::ApplyPreset(preset));
        }
    }
}

/// Two levels over a scene of placed meshes: on or off, the top level's strategy and leaves.
fn two_levels(app: &BvhscopeApp, ui: &mut egui::Ui, s: &mut Settings) {
    let placements = app.scene.instances().map_or(0, |i| i.placements.len());
    let meshes = app.scene.instances().map_or(0, |i| i.meshes.len());
    ui.checkbox(&mut s.two_level, format!("Two levels: {placements} placements of {meshes} meshes"))
        .on_hover_text("A top-level BVH over the scene's mesh placements, and one BVH per mesh built once however often it is placed. Off: one BVH over the whole scene flattened.");
    if s.two_level {
        ui.horizontal(|ui| {
            let label = ui.label("Top-level strategy");
            egui::ComboBox::from_id_salt("top-strategy")
                .selected_text(s.top_build.strategy.label())
                .show_ui(ui, |ui| {
                    for k in Strategy::ALL {
                        ui.selectable_value(&mut s.top_build.strategy, k, k.label()).on_hover_text(k.help());
                    }
                })
                .response
                .labelled_by(label.id);
        });
        let n = &TOP_MAX_LEAF_SIZE;
        ui.add(
            egui::Slider::new(&mut s.top_build.max_leaf_size, n.limits.min..=n.limits.max)
                .logarithmic(true)
                .text(n.label),
        )
        .on_hover_text(n.help);
        ui.label("Bottom level (each mesh's BVH)");
    }
}

/// The split strategy, with an imported tree (File ▸ Open BVH) as one more entry; whether the
/// imported tree is the one traced.
fn strategy_choice(app: &BvhscopeApp, ui: &mut egui::Ui, s: &mut Settings, out: &mut Actions) -> bool {
    // The strategies, and an imported tree (File ▸ Open BVH) as one more entry.
    let imported = app.import.tree.as_ref().filter(|t| t.scene_id == app.scene_id);
    let on = app.import.on && imported.is_some();
    let label = ui.label("Split strategy");
    let selected = match imported.filter(|_| on) {
        Some(t) => format!("imported: {}", t.name()),
        None => s.build.strategy.label().to_string(),
    };
    egui::ComboBox::from_id_salt("strategy")
        .selected_text(selected)
        // No wider than the panel: a wider box widens the panel's content past its edge, where
        // the sliders below would be laid out and cut off.
        .width(ui.available_width().min(200.0))
        .show_ui(ui, |ui| {
            for k in Strategy::ALL {
                if ui.selectable_label(!on && s.build.strategy == k, k.label()).on_hover_text(k.help()).clicked() {
                    s.build.strategy = k;
                    out.push(Action::UseImported(false));
                }
            }
            if let Some(t) = imported {
                let text = format!("imported: {}", t.name());
                let tip = format!(
                    "The BVH read from {}, traced as written. {} defects, {} warnings (View › Imported BVH…)",
                    t.path.display(),
                    t.defects(),
                    t.findings.len() - t.defects()
                );
                let item = ui.add_enabled(t.bvh.is_ok(), egui::Button::selectable(on, text));
                let why = t.bvh.as_ref().err().cloned().unwrap_or_default();
                if item.on_hover_text(tip).on_disabled_hover_text(format!("Cannot be traced: {why}")).clicked() {
                    out.push(Action::UseImported(true));
                }
            }
        })
        .response
        .labelled_by(label.id)
        .on_hover_text(if on { "The imported BVH, as its program wrote it" } else { s.build.strategy.help() });
    on
}
