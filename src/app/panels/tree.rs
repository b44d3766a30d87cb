//! The Tree window: the binary tree as built, as an icicle (one row per depth, each node as wide
//! as its share of the triangles, coloured by a chosen metric) and as a collapsible list of
//! rows (only the visible ones laid out, so a million nodes stay fast). Selecting in either, in
//! the viewport (shift-click: the pixel's leaf) or in the Node window's breadcrumb selects the
//! same node everywhere.

mod scale;

use crate::app::state::{Action, Actions, BvhscopeApp};
use crate::app::views::node::{Explained, Metric, NodeView};
use crate::app::views::ray::nodes::RayOnTree;
use egui::{Color32, Pos2, Rect, RichText, Sense, Stroke};
use scale::Scale;

/// Depths the icicle shows.
const ICICLE_ROWS: u32 = 14;
const ICICLE_ROW_HEIGHT: f32 = 12.0;

/// Whether the view is open (its tile shown).
pub fn is_open(app: &BvhscopeApp) -> bool {
    app.nodes.window
}

/// The view's contents, in its tile (`panels::tiles`).
pub fn ui(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    if !app.nodes.window {
        return;
    }
    let bvh = app.current_bvh().map(|b| b.bvh.clone());
    let Some(e) = app.nodes.current(bvh.as_ref()) else {
        let why = if app.built.as_ref().is_some_and(|b| b.top_stats.is_some()) {
            "The tree view shows one BVH; this scene is built as two levels (uncheck Two levels)."
        } else {
            "Preparing the tree…"
        };
        ui.weak(why);
        return;
    };
    let (cut, twice) = references(e);
    let refs = if cut > 0 {
        format!(" (references: spatial splits cut {cut} triangles among several leaves, and the counts below count each part)")
    } else {
        String::new()
    };
    ui.label(format!(
        "The binary tree as built: {} nodes, {} triangles{refs}. Shift-click the image to select a pixel's leaf, or a drawn box's edge.",
        e.tree.nodes.len(),
        e.tree.prim_ids.len()
    ));
    if !twice.is_empty() {
        let shown: Vec<String> = twice.iter().take(4).cloned().collect();
        let more = if twice.len() > 4 { format!(", … ({} in all)", twice.len()) } else { String::new() };
        ui.colored_label(
            egui::Color32::from_rgb(220, 190, 90),
            format!("Warning: {}{more}: each is tested twice by every ray that reaches its leaf.", shown.join(", ")),
        );
    }
    let visits = app.nodes.visits.as_ref().filter(|v| std::sync::Arc::ptr_eq(&v.explained, e));
    ui.horizontal(|ui| {
        ui.label("Colour by");
        egui::ComboBox::from_id_salt("icicle-metric").selected_text(app.nodes.metric.label()).show_ui(ui, |ui| {
            for m in Metric::ALL {
                if ui.selectable_label(app.nodes.metric == m, m.label()).on_hover_text(m.help()).clicked() {
                    out.push(Action::SetMetric(m));
                }
            }
        });
        if app.nodes.metric == Metric::Visits && visits.is_none() {
            ui.weak("counting…");
        }
    });
    // The pinned ray the Ray view steps through, on this tree (the same trace, not walked again).
    let walk = app.pins.current().and_then(|r| RayOnTree::of(r, e));
    let ray = walk.as_ref().map(|w| Ray { walk: w, at: w.at.get(app.pins.step).copied().flatten() });
    if let Some(r) = &ray {
        ui.horizontal_wrapped(|ui| {
            ui.label(RichText::new("Pinned ray:").color(ENTERED));
            ui.label(format!("{} nodes entered (outlined, \"ray @ step\" in the rows);", r.walk.entered.len()));
            let at = r.at.map_or("the root's box test".to_string(), |n| format!("node {n}"));
            ui.label(RichText::new(format!("at step {}: {at}", app.pins.step + 1)).color(AT));
            ui.weak("(click a marked node to go to its step)");
        });
    }
    icicle(ui, e, &app.nodes, visits.map(|v| v.counts.as_slice()), ray.as_ref(), out);
    ui.separator();
    rows(ui, e, &app.nodes, visits.map(|v| v.counts.as_slice()), ray.as_ref(), out);
}

/// The pinned ray's walk on the tree, and the node it is at in the Ray view's step.
struct Ray<'a> {
    walk: &'a RayOnTree,
    at: Option<u32>,
}

impl Ray<'_> {
    /// What a click on `node` asks for: the node selected, and the Ray view at the step that
    /// entered it when the ray entered it.
    fn click(ray: Option<&Ray<'_>>, node: u32, out: &mut Actions) {
        out.push(Action::SelectNode(node));
        if let Some(k) = ray.and_then(|r| r.walk.step_of(node)) {
            out.push(Action::RayStep(k));
        }
    }
}

/// The nodes the pinned ray entered (the viewport's tested-box cyan) and the one it is at (the
/// viewport's current-node yellow).
const ENTERED: Color32 = super::explain_overlay::RAY_COLORS.tested_hit;
const AT: Color32 = super::explain_overlay::RAY_COLORS.current;

/// What closing the view's tile asks for.
pub fn close() -> Action {
    Action::ShowTree(false)
}

/// A node's value of the metric (`None`: not known yet).
fn metric_value(e: &Explained, metric: Metric, visits: Option<&[u32]>, n: usize) -> Option<f64> {
    match metric {
        Metric::Visits => visits.map(|v| v[n] as f64),
        Metric::Sah => Some(e.sah_terms[n]),
        Metric::Overlap => Some(e.child_overlap(n)),
        Metric::Epo => Some(e.epo_terms[n]),
        Metric::Depth => Some(e.hierarchy.depth[n] as f64),
    }
}

/// The nodes the icicle draws (down to `ICICLE_ROWS`, at least a pixel wide), with their rects.
fn icicle_cells(e: &Explained, rect: Rect) -> Vec<(u32, Rect)> {
    let total = e.tree.prim_ids.len().max(1) as f32;
    let mut out = Vec::new();
    let mut stack = vec![0u32];
    while let Some(n) = stack.pop() {
        let i = n as usize;
        let (d, first, count) = (e.hierarchy.depth[i], e.hierarchy.first[i], e.hierarchy.count[i]);
        let x0 = rect.left() + rect.width() * first as f32 / total;
        let x1 = rect.left() + rect.width() * (first + count) as f32 / total;
        let y0 = rect.top() + d as f32 * ICICLE_ROW_HEIGHT;
        if d >= ICICLE_ROWS || x1 - x0 < 1.0 {
            continue;
        }
        out.push((n, Rect::from_min_max(Pos2::new(x0, y0), Pos2::new(x1, y0 + ICICLE_ROW_HEIGHT))));
        let node = &e.tree.nodes[i];
        if !node.is_leaf() {
            stack.extend([node.index, node.index + 1]);
        }
    }
    out
}

fn icicle(
    ui: &mut egui::Ui,
    e: &Explained,
    view: &NodeView,
    visits: Option<&[u32]>,
    ray: Option<&Ray<'_>>,
    out: &mut Actions,
) {
    let depth = e.hierarchy.depth.iter().copied().max().unwrap_or(0).min(ICICLE_ROWS - 1) + 1;
    let size = egui::vec2(ui.available_width(), depth as f32 * ICICLE_ROW_HEIGHT);
    let (rect, response) = ui.allocate_exact_size(size, Sense::click());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "Icicle of the tree"));
    let cells = icicle_cells(e, rect);
    let values: Vec<Option<f64>> =
        cells.iter().map(|&(n, _)| metric_value(e, view.metric, visits, n as usize)).collect();
    let scale = Scale::of(view.metric, &values);
    let painter = ui.painter_at(rect);
    let selected_path = view.selected.map(|s| e.hierarchy.path(s)).unwrap_or_default();
    for (&(n, r), v) in cells.iter().zip(&values) {
        let fill = match (v, &scale) {
            (Some(v), Some(s)) => s.color(*v),
            _ => Color32::from_gray(60),
        };
        painter.rect_filled(r.shrink(0.25), 0.0, fill);
        if ray.is_some_and(|ray| ray.walk.entered.contains_key(&n)) {
            painter.rect_stroke(r, 0.0, Stroke::new(1.0, ENTERED), egui::StrokeKind::Inside);
        }
        if selected_path.contains(&n) {
            let color = if Some(n) == view.selected { Color32::WHITE } else { Color32::from_gray(200) };
            painter.rect_stroke(r, 0.0, Stroke::new(1.5, color), egui::StrokeKind::Inside);
        }
    }
    // The ray's node last, over the selection's outline.
    if let Some((_, r)) = ray.and_then(|ray| ray.at).and_then(|a| cells.iter().find(|(n, _)| *n == a)) {
        painter.rect_stroke(*r, 0.0, Stroke::new(2.5, AT), egui::StrokeKind::Inside);
    }
    if response.clicked() {
        if let Some(pos) = response.interact_pointer_pos() {
            // The deepest cell under the pointer.
            if let Some(&(n, _)) =
                cells.iter().filter(|(_, r)| r.contains(pos)).max_by_key(|(n, _)| e.hierarchy.depth[*n as usize])
            {
                Ray::click(ray, n, out);
            }
        }
    }
    response.on_hover_text(format!(
        "One row per depth (the first {ICICLE_ROWS}), each node as wide as its triangles; colour: {}. Click to select (a node the pinned ray entered: the Ray view goes to that step).",
        view.metric.label()
    ));
    if let Some(s) = &scale {
        scale::bar(ui, s, view.metric);
    }
}

fn rows(
    ui: &mut egui::Ui,
    e: &Explained,
    view: &NodeView,
    visits: Option<&[u32]>,
    ray: Option<&Ray<'_>>,
    out: &mut Actions,
) {
    // The ray's node's row is shown (its ancestors open) as the Ray view steps.
    let ray_at = ray.and_then(|r| r.at);
    let rows = view.rows_showing(ray_at);
    let row_height = ui.spacing().interact_size.y;
    let mut area = egui::ScrollArea::vertical().auto_shrink([false, false]).id_salt("tree-rows");
    // Bring a newly selected node's row into view once (from the icicle, the viewport, a key).
    // So is the ray's node's when the Ray view steps.
    let scrolled_id = ui.scope_id().with("tree-scrolled-to");
    let before = ui.data(|d| d.get_temp::<(Option<u32>, Option<u32>)>(scrolled_id));
    ui.data_mut(|d| d.insert_temp(scrolled_id, (view.selected, ray_at)));
    let target = match before {
        Some((_, r)) if r != ray_at && ray_at.is_some() => ray_at,
        Some((s, _)) if s == view.selected => None,
        _ => view.selected,
    };
    if target.is_some() {
        if let Some(k) = target.and_then(|s| rows.iter().position(|&r| r == s)) {
            // The row in the middle of what the list shows.
            let step = row_height + ui.spacing().item_spacing.y;
            let visible = (ui.available_height() / step).max(1.0);
            area = area.vertical_scroll_offset((k as f32 - visible / 2.0).max(0.0) * step);
        }
    }
    ui.horizontal(|ui| {
        ui.strong("node · depth · triangles · area of parent's · SAH share · visits");
    });
    area.show_rows(ui, row_height, rows.len(), |ui, range| {
        ui.style_mut().wrap_mode = Some(egui::TextWrapMode::Extend);
        for &n in &rows[range] {
            let i = n as usize;
            let node = &e.tree.nodes[i];
            ui.horizontal(|ui| {
                ui.add_space(e.hierarchy.depth[i] as f32 * 10.0);
                if node.is_leaf() {
                    ui.add_sized([18.0, row_height], egui::Label::new(" "));
                } else {
                    let sign = if view.open.contains(&n) { "-" } else { "+" };
                    if ui.add_sized([18.0, row_height], egui::Button::new(sign).small()).clicked() {
                        out.push(Action::ToggleOpen(n));
                    }
                }
                let parent = e.hierarchy.parent[i];
                let ratio = if parent == u32::MAX {
                    "root".to_string()
                } else {
                    let pa = e.tree.nodes[parent as usize].bounds().area();
                    if pa > 0.0 {
                        format!("{:.0}%", 100.0 * node.bounds().area() / pa)
                    } else {
                        "-".into()
                    }
                };
                let kind = if node.is_leaf() { "leaf" } else { "node" };
                let v = visits.map_or("…".to_string(), |v| v[i].to_string());
                let mut text = format!(
                    "{kind} {n} · d{} · {} tris · {ratio} · {:.3} · {v}",
                    e.hierarchy.depth[i], e.hierarchy.count[i], e.sah_terms[i]
                );
                let entered = ray.and_then(|r| r.walk.step_of(n));
                if let Some(k) = entered {
                    text += &format!(" · ray @ step {}", k + 1);
                }
                let mut rich = RichText::new(text).monospace();
                if ray_at == Some(n) {
                    rich = rich.color(Color32::BLACK).background_color(AT);
                } else if entered.is_some() {
                    rich = rich.color(ENTERED);
                }
                if ui.selectable_label(view.selected == Some(n), rich).clicked() {
                    Ray::click(ray, n, out);
                }
            });
        }
    });
}

/// How many triangles spatial splits cut among several leaves, and the triangles referenced twice
/// in one leaf ("triangle 928 is referenced twice (leaf 17)", by the file's triangle numbers and,
/// for an imported tree, the dump's node ids), which is no split but a duplicate.
pub fn references(e: &Explained) -> (usize, Vec<String>) {
    let h = &e.hierarchy;
    let (mut cut, mut twice) = (0, Vec::new());
    let names = e.bvh.import();
    let file_number = |t: u32| match &*e.bvh {
        crate::bvh::SceneBvh::Single { mesh, .. } => mesh.file_number(t),
        _ => t,
    };
    let mut prims: Vec<u32> = h.other_slots.keys().copied().collect();
    prims.sort_unstable();
    for prim in prims {
        let mut leaves: Vec<u32> =
            h.slots_of_prim(prim).filter_map(|s| h.leaf_of_slot.get(s as usize).copied()).collect();
        leaves.sort_unstable();
        let n = leaves.len();
        leaves.dedup();
        if leaves.len() > 1 {
            cut += 1;
        }
        if leaves.len() < n {
            // The leaf that holds it more than once.
            let mut all: Vec<u32> =
                h.slots_of_prim(prim).filter_map(|s| h.leaf_of_slot.get(s as usize).copied()).collect();
            all.sort_unstable();
            let leaf = all.windows(2).find(|w| w[0] == w[1]).map_or(all[0], |w| w[0]);
            let leaf = names.and_then(|i| i.dump_of_binary_node(leaf)).unwrap_or(leaf);
            twice.push(format!("triangle {} is referenced twice (leaf {leaf})", file_number(prim)));
        }
    }
    (cut, twice)
}
