//! The Imported BVH window: what the checker found in the imported dump (as `bvhscope check`
//! prints it: grouped, each finding its root cause and its first cases, defects and warnings
//! counted), each finding that names a node or a triangle a link that selects it; the wrong pixels
//! of the view on screen; and the switch between the imported tree and the built strategy.

use crate::app::state::{Action, Actions, BvhscopeApp};
use crate::explain::check::Group;

/// Findings listed per group before "… and N more" (a broken dump of a million nodes can have a
/// million findings; the CLI lists them all).
const SHOWN_PER_GROUP: usize = 200;

/// Whether the view is open (its tile shown).
pub fn is_open(app: &BvhscopeApp) -> bool {
    app.import.window && app.import.tree.as_ref().is_some_and(|t| t.scene_id == app.scene_id)
}

/// The view's contents, in its tile (`panels::tiles`).
pub fn ui(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let Some(t) = app.import.tree.as_ref().filter(|t| t.scene_id == app.scene_id && app.import.window) else {
        return;
    };
    let d = t.defects();
    ui.label(egui::RichText::new(t.path.display().to_string()).strong());
    let verdict = if d == 0 { "is correct" } else { "has defects" };
    ui.label(format!("{d} defects, {} warnings: the BVH {verdict}.", t.findings.len() - d));
    match &t.bvh {
        Ok(_) => {
            let mut on = app.import.on;
            if ui
                .checkbox(&mut on, "Show the imported tree")
                .on_hover_text("Every view traces it; off: the strategy chosen in the Build panel")
                .changed()
            {
                out.push(Action::UseImported(on));
            }
        }
        Err(why) => {
            ui.colored_label(egui::Color32::from_rgb(230, 120, 90), format!("Not traced: {why}."));
        }
    }
    wrong_pixels(app, ui, out);
    ui.weak(format!(
        "Rays: the frame's primary rays and {} random ones, against the linear scan. bvhscope check MESH --bvh FILE prints the same findings.",
        t.rays
    ));
    ui.separator();
    egui::ScrollArea::vertical().auto_shrink([false, true]).show(ui, |ui| {
        for g in Group::ALL {
            let here: Vec<_> = t.findings.iter().filter(|f| f.group == g).collect();
            if here.is_empty() {
                continue;
            }
            let d = here.iter().filter(|f| f.defect).count();
            let title = format!("{} ({d} defects, {} warnings)", g.label(), here.len() - d);
            egui::CollapsingHeader::new(title).default_open(true).show(ui, |ui| {
                for f in here.iter().take(SHOWN_PER_GROUP) {
                    let color = if f.defect {
                        egui::Color32::from_rgb(235, 110, 90)
                    } else {
                        egui::Color32::from_rgb(220, 190, 90)
                    };
                    let line = f.line(crate::explain::check::LISTED);
                    let text = egui::RichText::new(format!("{} {line}", if f.defect { "defect:" } else { "warning:" }))
                        .color(color);
                    let action = f.node.map(Action::SelectDumpNode).or(f.triangle.map(Action::SelectTriangle));
                    match action {
                        Some(a) => {
                            let what = match (f.node, f.triangle) {
                                (Some(n), _) => format!("Select node {n} in the tree view"),
                                (None, Some(tri)) => format!("Select the leaf of triangle {tri}"),
                                _ => String::new(),
                            };
                            if ui.link(text).on_hover_text(what).clicked() {
                                out.push(a);
                            }
                        }
                        None => {
                            ui.label(text);
                        }
                    }
                }
                if here.len() > SHOWN_PER_GROUP {
                    ui.weak(format!("… and {} more (bvhscope check lists them all)", here.len() - SHOWN_PER_GROUP));
                }
            });
        }
    });
}

/// What closing the view's tile asks for.
pub fn close() -> Action {
    Action::ShowImported(false)
}

/// The wrong pixels of the image on screen, and the red mask's switch.
fn wrong_pixels(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let Some(s) = app.shown.as_ref().filter(|s| s.bvh.import().is_some()) else {
        return;
    };
    let text = match app.import.wrong_for(&s.bvh, &s.camera, &s.trace) {
        Some(w) if w.pixels.is_empty() => "Every pixel of this view hits what the linear scan hits.".to_string(),
        Some(w) => format!(
            "{} of {} pixels of this view hit differently from the linear scan.",
            w.pixels.len(),
            s.camera.width as u64 * s.camera.height as u64
        ),
        None => "Tracing this view's pixels against the linear scan…".to_string(),
    };
    ui.label(text);
    let mut mask = app.import.mask;
    if ui.checkbox(&mut mask, "Show wrong pixels in red").changed() {
        out.push(Action::WrongMask(mask));
    }
}
