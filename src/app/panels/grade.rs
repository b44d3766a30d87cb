//! The Grade report window: a class's grade.json (`bvhscope grade`) as its students in the
//! report's order, each with their rank, verdict, and either their SAH cost against bvhscope's
//! SAH tree or, when their tree could not be traced, why. Choosing one shows their tree against
//! SAH binned (`update::grade`), or only the reason; what the choice led to is said above the list.

use crate::app::state::{Action, Actions, BvhscopeApp};
use crate::app::views::Pending;
use crate::explain::grade::{GradeReport, Verdict};

/// Characters of a reason shown in the list (the whole of it on hover, and for the student chosen).
const REASON_SHOWN: usize = 44;

const RED: egui::Color32 = egui::Color32::from_rgb(235, 110, 90);

fn verdict_color(v: Verdict) -> egui::Color32 {
    match v {
        Verdict::Correct => egui::Color32::from_rgb(120, 200, 120),
        Verdict::Defects | Verdict::WrongMesh => RED,
        Verdict::Unreadable | Verdict::NoDump | Verdict::TimedOut => egui::Color32::from_rgb(220, 190, 90),
    }
}

/// Whether the view is open (its tile shown).
pub fn is_open(app: &BvhscopeApp) -> bool {
    app.grade.window && app.grade.report.is_some()
}

/// The view's contents, in its tile (`panels::tiles`).
pub fn ui(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let Some(r) = app.grade.report.as_ref().filter(|_| app.grade.window) else { return };
    ui.label(egui::RichText::new(r.file.display().to_string()).strong());
    ui.label(format!("{} students over {}, ranked by {}.", r.students.len(), r.mesh_given, r.rank_by));
    if let Err(missing) = &r.mesh {
        ui.colored_label(RED, missing);
    }
    chosen(app, r, ui);
    ui.separator();
    egui::ScrollArea::vertical().auto_shrink([false, true]).show(ui, |ui| students(app, r, ui, out));
}

/// What closing the view's tile asks for.
pub fn close() -> Action {
    Action::ShowGrade(false)
}

/// What choosing the student led to: their tree shown, on its way, or why not.
fn chosen(app: &BvhscopeApp, r: &GradeReport, ui: &mut egui::Ui) {
    let Some(s) = app.grade.chosen.and_then(|i| r.students.get(i)) else {
        ui.weak("Choose a student: their BVH is imported and checked again with this app's rays, on the report's camera and traversal, side by side against SAH binned.");
        return;
    };
    let name = egui::RichText::new(&s.name).strong();
    match (&app.grade.pending, &app.grade.why_not) {
        (Some(p), _) => {
            ui.horizontal(|ui| {
                ui.spinner();
                ui.label(name);
                match p {
                    Pending::Mesh { mesh, .. } => ui.label(format!("opening {}…", mesh.display())),
                    Pending::Import { dump } => ui.label(format!("reading and checking {}…", dump.display())),
                };
            });
        }
        (None, Some(why)) => {
            ui.label(name);
            ui.colored_label(RED, format!("Not shown: {why}"));
        }
        (None, None) => {
            ui.label(name);
            let imported = app.import.tree.as_ref().filter(|t| s.openable().is_ok_and(|d| d == t.path));
            match (imported, app.compare.on) {
                (Some(t), true) => {
                    let b = app.compare.strategy.label();
                    let d = t.defects();
                    ui.label(format!("A = imported: {} ({d} defects as checked here), B = {b}.", t.name()));
                }
                (Some(t), false) => {
                    ui.weak(format!("imported: {}; View › Compare side by side… sets it against SAH.", t.name()));
                }
                (None, _) => {
                    ui.weak("no longer shown: choose them again to show their tree.");
                }
            }
        }
    }
}

/// The class, one row per student in the report's order.
fn students(app: &BvhscopeApp, r: &GradeReport, ui: &mut egui::Ui, out: &mut Actions) {
    egui::Grid::new("grade-students").num_columns(4).striped(true).show(ui, |ui| {
        for head in ["rank", "student", "verdict", "SAH cost vs SAH tree, or why not traced"] {
            ui.strong(head);
        }
        ui.end_row();
        for (i, s) in r.students.iter().enumerate() {
            ui.label(s.rank.map_or("–".to_string(), |k| k.to_string()));
            let hover = match s.openable() {
                Ok(dump) => format!("Show {}'s tree ({}) against SAH binned", s.name, dump.display()),
                Err(why) => format!("Nothing to show: {why}"),
            };
            if ui.selectable_label(app.grade.chosen == Some(i), &s.name).on_hover_text(hover).clicked() {
                out.push(Action::ChooseStudent(i));
            }
            ui.colored_label(verdict_color(s.verdict), s.verdict.label());
            match (s.layout, s.versus_sah) {
                (Some(layout), Some(v)) => {
                    let good = match s.good {
                        Some(true) => ", good",
                        _ => "",
                    };
                    ui.label(format!("{:+.1} % ({}){good}", (v - 1.0) * 100.0, layout.name()));
                }
                _ => {
                    let reason = short_reason(&s.reason);
                    let short: String = reason.chars().take(REASON_SHOWN).collect();
                    let more = if reason.chars().count() > REASON_SHOWN { "…" } else { "" };
                    ui.weak(format!("{short}{more}")).on_hover_text(&s.reason);
                }
            }
            ui.end_row();
        }
    });
}

/// A reason that starts with its file's whole path, with the file's name only: in a narrow column
/// the folders of a class's files would hide what went wrong.
fn short_reason(reason: &str) -> String {
    match reason.split_once(": ") {
        Some((head, tail)) if head.contains(['/', '\\']) => {
            let name = std::path::Path::new(head).file_name().map(|n| n.to_string_lossy().into_owned());
            format!("{}: {tail}", name.unwrap_or_else(|| head.to_string()))
        }
        _ => reason.to_string(),
    }
}
