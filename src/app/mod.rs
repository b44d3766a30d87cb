//! The desktop app (eframe/egui): a thin layer of state and panels over the core. Its parts,
//! from the bottom up, each using only those below it:
//!
//! - `views`: the state of each explain view (node, ray, replay, compare, import, grade);
//! - `jobs`: the background work (loads, builds, renders, the GPU's) and its messages;
//! - `state`: `BvhscopeApp` (the state), the `Action`s that change it, the settings, the caches
//!   and the images derived from the state;
//! - `update`: what changes the state: `act` applies an action, `reconcile` decides what to
//!   rebuild and re-render, the jobs' events, files saved;
//! - `panels`: the panels, the windows, the viewport and the docked tiles; they read the state
//!   and emit actions;
//! - here: the window and the frame loop (input, actions, reconcile, panels).
//!
//! Data flows one way: mesh → BVH → renderer → image → screen.

mod jobs;
mod panels;
mod state;
mod update;
mod views;

pub use crate::render::PairView;
pub use crate::scene::{Scene, SceneSource};
pub use jobs::{Pick, Probe, Timed};
pub use panels::lesson::plain as caption_text;
pub use state::{
    Action, Actions, AppOptions, BoxLevel, BuildCache, BuiltBvh, BvhscopeApp, Film, LessonState, MeasuredRays, Message,
    MessageKind, OrbitCamera, OverlayBox, Pane, PathWindow, Settings, Shown, StrategyFigures,
};
pub use update::{default_name, StatsFormat};
pub use views::{
    CompareView, GradeView, ImportView, ImportedTree, Metric, NodeStep, NodeView, PinnedRay, RayView, ReplayView,
};

use state::DOCK_KEY;
use std::time::Duration;

/// Open the window and run until it is closed.
pub fn run(options: AppOptions) -> Result<(), String> {
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("bvhscope")
            .with_app_id("bvhscope")
            .with_inner_size([1400.0, 860.0])
            .with_min_inner_size([800.0, 500.0])
            .with_drag_and_drop(true),
        ..Default::default()
    };
    eframe::run_native("bvhscope", native, Box::new(move |cc| Ok(Box::new(BvhscopeApp::new(cc, options)))))
        .map_err(|e| format!("cannot open the window: {e}"))
}

impl eframe::App for BvhscopeApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        // The screen's scale is a setting (saved; Ctrl +/− and View › Present change it), not
        // egui's own keyboard zoom, which the shortcuts replace.
        ctx.options_mut(|o| o.zoom_with_keyboard = false);
        let zoom = self.settings.zoom();
        if (ctx.zoom_factor() - zoom).abs() > 1e-3 {
            ctx.set_zoom_factor(zoom);
        }
        let mut actions = Actions::new();
        self.handle_input(&ctx, &mut actions);
        // The panels see the state as it is after the input's actions.
        for action in actions.drain(..) {
            self.act(action);
        }
        self.reconcile();
        panels::show_all(self, ui, &mut actions);
        // What the panels asked for takes effect now, and shows in the next frame.
        if !actions.is_empty() {
            for action in actions {
                self.act(action);
            }
            self.reconcile();
            ctx.request_repaint();
        }
        if let Some(text) = self.clipboard.take() {
            ctx.copy_text(text);
        }
        if self.jobs.is_busy() {
            // Keep progress indicators moving; results also wake the UI themselves.
            ctx.request_repaint_after(Duration::from_millis(100));
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, eframe::APP_KEY, &self.settings);
        // Presenting, the layout to come back to is saved, not the one fitted for the room.
        if let Some(layout) = self.dock_presenting.as_ref().map(|p| p.before()).or(self.dock.as_ref()) {
            eframe::set_value(storage, DOCK_KEY, layout);
        }
    }
}
