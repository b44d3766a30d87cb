//! The Node view's table of where each strategy splits the node: the strategies' names in a
//! column of their own that stays put while the figures scroll sideways (a narrow tile), and why
//! a strategy prices no plane as a footnote under the table, not as a cell as wide as the table.

use super::{strategy_color, AXES};
use crate::bvh::Strategy;
use crate::explain::inspect::Inspection;
use egui::RichText;

/// The footnote marks, one per distinct note (there are three reasons a strategy prices no plane).
const MARKS: [&str; 3] = ["¹", "²", "³"];

/// The notes of the rows that have no plane, in the order first met, each with the strategies it
/// is said of: (note, strategies).
pub(super) fn footnotes(ins: &Inspection) -> Vec<(&'static str, Vec<Strategy>)> {
    let mut notes: Vec<(&'static str, Vec<Strategy>)> = Vec::new();
    for (s, m) in &ins.markers {
        if m.is_some() {
            continue;
        }
        let note = crate::explain::inspect::text::no_split_text(*s);
        match notes.iter_mut().find(|(n, _)| *n == note) {
            Some((_, who)) => who.push(*s),
            None => notes.push((note, vec![*s])),
        }
    }
    notes
}

/// The mark of footnote `k` (past the third, its number in brackets).
fn mark(k: usize) -> String {
    MARKS.get(k).map_or_else(|| format!("[{}]", k + 1), |m| m.to_string())
}

/// Where each strategy puts its plane here, and every term of its cost, written out (as
/// `bvhscope inspect` prints them; nothing only on hover, for a room to read).
/// `width`: the tile's, which the table keeps to (its figures scroll sideways past it).
pub(super) fn planes(ui: &mut egui::Ui, ins: &Inspection, own: Option<Strategy>, width: f32) {
    ui.add(
        egui::Label::new("Where each strategy splits these triangles: C_trav + C_isect (A_L/A n_L + A_R/A n_R)").wrap(),
    );
    let notes = footnotes(ins);
    let note_of = |s: Strategy| notes.iter().position(|(_, who)| who.contains(&s));
    // Both grids' rows are one line of body text at least this tall, so they stay side by side.
    let row = ui.spacing().interact_size.y;
    ui.horizontal_top(|ui| {
        ui.spacing_mut().item_spacing.x = 0.0;
        let names =
            egui::Grid::new("node-plane-names").num_columns(1).striped(true).min_row_height(row).show(ui, |ui| {
                ui.strong("Strategy");
                ui.end_row();
                for (s, _) in &ins.markers {
                    let name =
                        if Some(*s) == own { format!("{} (this tree)", s.label()) } else { s.label().to_string() };
                    ui.add(egui::Label::new(RichText::new(name).color(strategy_color(*s))).extend());
                    ui.end_row();
                }
            });
        ui.add_space(8.0);
        let rest = (width - names.response.rect.width() - 8.0).max(60.0);
        egui::ScrollArea::horizontal().id_salt("node-planes-scroll").max_width(rest).show(ui, |ui| {
            ui.spacing_mut().item_spacing.x = 8.0;
            egui::Grid::new("node-planes").num_columns(6).striped(true).min_row_height(row).show(ui, |ui| {
                for head in ["Plane", "n_L", "n_R", "A_L/A", "A_R/A", "Cost"] {
                    ui.strong(head);
                }
                ui.end_row();
                for (s, m) in &ins.markers {
                    match m {
                        Some(m) => {
                            ui.label(format!("{} = {}", AXES[m.axis as usize], m.position));
                            ui.label(m.left.to_string());
                            ui.label(m.right.to_string());
                            ui.label(format!("{:.3}", m.area_left));
                            ui.label(format!("{:.3}", m.area_right));
                            ui.label(format!("{:.3}", m.cost));
                        }
                        None => {
                            let k = note_of(*s).unwrap_or(0);
                            ui.label(format!("— {}", mark(k))).on_hover_text(notes[k].0);
                        }
                    }
                    ui.end_row();
                }
            });
        });
    });
    for (k, (note, who)) in notes.iter().enumerate() {
        let names: Vec<&str> = who.iter().map(|s| s.label()).collect();
        ui.add(egui::Label::new(format!("{} {}: {note}", mark(k), names.join(", "))).wrap());
    }
}
