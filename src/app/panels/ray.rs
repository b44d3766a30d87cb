//! The Ray window: the pinned rays (a Ctrl-click on the image, or a click while this window is
//! open, pins its pixel's ray; one can also be
//! typed), and the selected one's traversal step by step: the numbered steps indented by depth,
//! hit green and miss red, a step slider with play, pause and step buttons, the stack at the
//! current step, and the counts, the same as the hover read-out's and `bvhscope trace`'s.

use crate::app::state::{Action, Actions, BvhscopeApp};
use crate::bvh::{StepKind, TraceLevel};
use egui::{Color32, RichText};
use std::time::Duration;

/// How long a step shows while playing.
const PLAY_STEP: Duration = Duration::from_millis(180);

fn step_color(kind: &StepKind) -> Option<Color32> {
    match kind {
        StepKind::BoxTest { hit: true, .. } | StepKind::Triangle { hit: true, .. } | StepKind::ClosestHit { .. } => {
            Some(Color32::from_rgb(110, 200, 110))
        }
        StepKind::BoxTest { hit: false, .. } | StepKind::Triangle { hit: false, .. } => {
            Some(Color32::from_rgb(225, 110, 100))
        }
        StepKind::Skip { .. } => Some(Color32::from_rgb(240, 160, 60)),
        _ => None,
    }
}

/// Whether the view is open (its tile shown).
pub fn is_open(app: &BvhscopeApp) -> bool {
    !app.pins.pinned.is_empty() || app.ray_window
}

/// Rows of steps the list keeps in view however short the tile: what the rest gives way to.
pub const MIN_STEP_ROWS: f32 = 8.0;

/// The view's contents, in its tile (`panels::tiles`): the step controls and the step shown on
/// top, always in view; the stack, the legend, the pinned rays and the typed ray below them in a
/// scroll area of their own, as tall as leaves the step list `MIN_STEP_ROWS` rows; the step list
/// in the rest (a short tile showed two rows of steps and cut the controls off: issue 59).
pub fn ui(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let rays = &app.pins;
    if rays.pinned.is_empty() && !app.ray_window {
        return;
    }
    let Some(r) = rays.current() else {
        pinned_list(app, ui, out);
        ui.separator();
        typed_ray(app, ui, out);
        ui.add(
            egui::Label::new(
                "Click a pixel of the image to pin its ray (Ctrl-click while this window is closed), or type one above.",
            )
            .wrap(),
        );
        return;
    };
    let n = r.len();
    let k = rays.step.min(n.saturating_sub(1));
    controls(app, ui, out, n, k);
    // The step shown, whole and wrapped (the list below keeps one line a step).
    if let Some(s) = r.named.get(k) {
        ui.add(egui::Label::new(egui::RichText::new(format!("Step {}: {}", k + 1, s.brief())).strong()).wrap());
    }
    let stack = r.trace.steps[..=k.min(n.saturating_sub(1))].iter().rev().find_map(|s| s.stack());
    let stack_text = match stack {
        Some(([], _)) | None => "empty".to_string(),
        Some((st, below)) => {
            let under = if below > 0 { format!("… {below} more, ") } else { String::new() };
            under + &st.iter().map(|(n, t)| format!("{n} @ {t:.3}")).collect::<Vec<_>>().join(", ")
        }
    };
    let row = step_row_height(ui);
    let separator = ui.spacing().item_spacing.y * 2.0 + 1.0;
    // At least a row's height, so that the details can still be scrolled to in a short tile.
    let room = (ui.available_height() - (MIN_STEP_ROWS + 0.5) * row - separator).max(row);
    egui::ScrollArea::both().id_salt("ray-details").max_height(room).min_scrolled_height(room).auto_shrink([false, true]).show(ui, |ui| {
        ui.add(egui::Label::new(format!("Stack (bottom first): {stack_text}")).wrap()).on_hover_text(
            "What the traversal stack holds after this step: each node with the distance at which the ray enters its box",
        );
        legend(ui);
        command_line(r, ui, out);
        ui.separator();
        pinned_list(app, ui, out);
        ui.separator();
        typed_ray(app, ui, out);
    });
    ui.separator();
    steps_list(app, ui, out, k);
}

/// First, Back, Play, Step, Last and the step slider, wrapped onto a second line in a narrow
/// tile (the slider and Last were off its right edge when presenting).
fn controls(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions, n: usize, k: usize) {
    let rays = &app.pins;
    ui.horizontal_wrapped(|ui| {
        if ui.button("First").on_hover_text("The first step").clicked() {
            out.push(Action::RayStep(0));
        }
        if ui.button("Back").on_hover_text("One step back").clicked() {
            out.push(Action::RayStepBy(-1));
        }
        let (label, tip) =
            if rays.playing { ("Pause", "Stop playing") } else { ("Play", "Play the steps one after another") };
        if ui.button(label).on_hover_text(tip).clicked() {
            out.push(Action::RayPlay(!rays.playing));
        }
        if ui.button("Step").on_hover_text("One step forward").clicked() {
            out.push(Action::RayStepBy(1));
        }
        if ui.button("Last").on_hover_text("The last step").clicked() {
            out.push(Action::RayStep(n.saturating_sub(1)));
        }
        let mut step = k + 1;
        // The slider takes the rest of the line, or a line of its own when under 80 points are
        // left for its rail (a slider does not wrap by itself: it ran off the tile).
        let text = format!("of {n}");
        let text_width = 8.0 * text.len() as f32 + 60.0;
        if ui.available_size_before_wrap().x < text_width + 80.0 {
            ui.end_row();
        }
        ui.spacing_mut().slider_width = (ui.available_size_before_wrap().x - text_width).clamp(60.0, 220.0);
        let slider = egui::Slider::new(&mut step, 1..=n.max(1)).text(text);
        if ui.add(slider).on_hover_text("The step the viewport shows").changed() {
            out.push(Action::RayStep(step - 1));
        }
    });
    if rays.playing {
        let due = rays.last_tick.is_none_or(|t| t.elapsed() >= PLAY_STEP);
        if due {
            out.push(Action::RayStepBy(1));
        }
        ui.ctx().request_repaint_after(PLAY_STEP);
    }
}

/// A step row's height: a selectable label's text and the button padding, at least the interact
/// size.
fn step_row_height(ui: &egui::Ui) -> f32 {
    let text_height = ui.text_style_height(&egui::TextStyle::Monospace);
    (text_height + 2.0 * ui.spacing().button_padding.y).max(ui.spacing().interact_size.y)
}

/// What closing the view's tile asks for.
pub fn close() -> Action {
    Action::UnpinAll
}

/// The pinned rays, each with its counts and hit, to select, compare and unpin.
fn pinned_list(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let rays = &app.pins;
    if rays.pinned.is_empty() {
        return;
    }
    egui::Grid::new("pinned-rays").num_columns(7).striped(true).show(ui, |ui| {
        for h in ["Pinned ray", "Nodes", "Boxes", "Leaves", "Triangles", "Hit", ""] {
            ui.strong(h);
        }
        ui.end_row();
        for (i, r) in rays.pinned.iter().enumerate() {
            if ui.selectable_label(i == rays.selected, &r.label).on_hover_text("Show this ray's steps").clicked() {
                out.push(Action::SelectPinned(i));
            }
            let c = r.counts;
            for v in [c.nodes_visited, c.box_tests, c.leaves_visited, c.triangle_tests] {
                ui.label(v.to_string());
            }
            ui.label(r.hit.map_or("nothing".to_string(), |h| format!("triangle {} at t = {:.4}", h.prim, h.t)));
            if ui.small_button("Unpin").on_hover_text("Remove this ray").clicked() {
                out.push(Action::Unpin(i));
            }
            ui.end_row();
        }
    });
    ui.weak("Click another pixel (or the same one after changing the strategy) to compare.");
    secondary_rays(app, ui, out);
}

/// With a secondary ray kind in the View panel: the selected pixel's rays of that kind, each
/// a button that pins it to walk (as `bvhscope trace --pixel … --ray-kind … --secondary K`).
fn secondary_rays(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let spec = app.settings.rays;
    let Some((x, y)) = app.pins.current().and_then(|r| r.pixel).filter(|_| spec.kind.is_secondary()) else {
        return;
    };
    let hit =
        app.shown.as_ref().is_some_and(|s| x < s.camera.width && y < s.camera.height && s.frame.sample(x, y).is_hit());
    if !hit {
        ui.weak(format!("Pixel {x}, {y}: its camera ray missed, so it has no {} rays.", spec.kind.name()));
        return;
    }
    ui.label(format!("Pixel {x}, {y}'s {} rays:", spec.kind.label().to_lowercase())).on_hover_text(spec.describe());
    // Rows of eight: the tile scrolls sideways, so a wrapped row would not wrap.
    let n = spec.rays_per_hit().min(32) as usize;
    for row in (0..n).step_by(8) {
        ui.horizontal(|ui| {
            for k in row..(row + 8).min(n) {
                if ui.small_button(format!("ray {k}")).on_hover_text("Pin this ray to walk it step by step").clicked() {
                    out.push(Action::PinSecondary(x, y, k));
                }
            }
        });
    }
}

/// What the viewport's colours mean, in those colours.
fn legend(ui: &mut egui::Ui) {
    let c = &super::explain_overlay::RAY_COLORS;
    ui.horizontal_wrapped(|ui| {
        ui.spacing_mut().item_spacing.x = 8.0;
        ui.weak("In the image:");
        for (text, color) in [
            ("current node", c.current),
            ("visited", Color32::from_gray(170)),
            ("skipped", c.skipped),
            ("box tested: hit", c.tested_hit),
            ("miss", c.tested_miss),
            ("leaf triangles: hit", c.triangle_hit),
            ("missed", c.triangle_miss),
            ("closest hit (dot)", c.hit_point),
        ] {
            ui.label(RichText::new(text).color(color));
        }
    });
}

/// The `bvhscope trace` command that prints this ray's steps, to copy into a terminal or a report.
fn command_line(r: &crate::app::views::PinnedRay, ui: &mut egui::Ui, out: &mut Actions) {
    ui.horizontal(|ui| match &r.command {
        Some(cmd) => {
            let tip = format!("{cmd}\n(Ctrl+Shift+C)");
            if ui.button("Copy trace command").on_hover_text(tip).clicked() {
                out.push(Action::CopyTraceCommand);
            }
            ui.weak("the same steps on the command line (bvhscope trace)");
        }
        None => {
            ui.weak("The built-in scene has no file to name on the command line (bvhscope trace).");
        }
    });
}

/// Fields to type a ray from elsewhere (a student's own renderer).
fn typed_ray(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let (mut origin, mut dir) = (app.pins.origin_text.clone(), app.pins.dir_text.clone());
    let mut pin = false;
    ui.horizontal(|ui| {
        let l = ui.label("Origin");
        let o =
            ui.add(egui::TextEdit::singleline(&mut origin).desired_width(110.0).hint_text("x, y, z")).labelled_by(l.id);
        let l = ui.label("Direction");
        let d =
            ui.add(egui::TextEdit::singleline(&mut dir).desired_width(110.0).hint_text("x, y, z")).labelled_by(l.id);
        let enter = (o.lost_focus() || d.lost_focus()) && ui.input(|i| i.key_pressed(egui::Key::Enter));
        pin =
            ui.button("Pin typed ray").on_hover_text("Trace this ray (world space) through the current BVH").clicked()
                || enter;
    });
    if origin != app.pins.origin_text || dir != app.pins.dir_text {
        out.push(Action::RayText { origin, dir });
    }
    if pin {
        out.push(Action::PinTyped);
    }
}

/// The steps, numbered and indented by depth, coloured hit / miss; only the rows in view are laid
/// out, so a long walk stays fast. Clicking a row shows that step.
fn steps_list(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions, k: usize) {
    let Some(r) = app.pins.current() else { return };
    let steps = &r.named;
    let row_height = step_row_height(ui);
    let levels = steps.iter().any(|s| s.level != TraceLevel::Mesh);
    // One line per step (show_rows needs equal rows): long stacks scroll sideways.
    let area = egui::ScrollArea::both().auto_shrink([false, false]).id_salt("ray-steps");
    // When the step moves (a button, the slider, playing), bring it into view once.
    let shown_id = ui.scope_id().with("ray-step-shown");
    let moved = ui.data(|d| d.get_temp::<(usize, usize)>(shown_id)) != Some((app.pins.selected, k));
    ui.data_mut(|d| d.insert_temp(shown_id, (app.pins.selected, k)));
    let mut entered = 0;
    let depths: Vec<u32> = steps
        .iter()
        .map(|s| {
            if let StepKind::Enter { depth, .. } = s.kind {
                entered = depth;
            }
            s.depth().unwrap_or(entered + 1)
        })
        .collect();
    // Rows touch (their highlight marks them apart): more of them in a short tile.
    ui.spacing_mut().item_spacing.y = 0.0;
    area.show_rows(ui, row_height, steps.len(), |ui, range| {
        ui.style_mut().wrap_mode = Some(egui::TextWrapMode::Extend);
        if moved {
            // Row k's place, from the first row laid out (rows above it are not).
            let top = ui.cursor().top() + (k as f32 - range.start as f32) * (row_height + ui.spacing().item_spacing.y);
            let row = egui::Rect::from_min_size(egui::pos2(ui.cursor().left(), top), egui::vec2(1.0, row_height));
            ui.scroll_to_rect(row, None);
        }
        for i in range {
            let s = &steps[i];
            let level = match (levels, s.level) {
                (false, _) | (_, TraceLevel::Mesh) => String::new(),
                (true, TraceLevel::Top) => "top  ".into(),
                (true, TraceLevel::Bottom { instance }) => format!("#{instance:<4}"),
            };
            // The stack each push, pop and skip leaves is shown above for the step chosen: the
            // list keeps its lines short, and a whole line is the row's tooltip.
            let text = format!("{:>4}  {level}{}{}", i + 1, crate::bvh::trace::indent_by(depths[i], 1), s.brief());
            let mut rich = RichText::new(text).monospace();
            if let Some(c) = step_color(&s.kind) {
                rich = rich.color(c);
            }
            if ui.selectable_label(i == k, rich).on_hover_text(s.text()).clicked() {
                out.push(Action::RayStep(i));
            }
        }
    });
}
