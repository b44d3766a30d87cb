//! `BvhscopeApp::act`: the one place the state changes in answer to the user (the actions are
//! `state::Action`).

use super::export;
use crate::app::jobs::Pick;
use crate::app::state::{dock, Action, BvhscopeApp, MessageKind, PathWindow, Settings, PRESENT_SCALE, UI_SCALES};
use crate::app::views::{PinnedRay, RayView, SecondaryOf};
use crate::bvh::Strategy;
use crate::render::{ColorMap, View};
use crate::scene::Scene;
use std::sync::Arc;
use std::time::Instant;

impl BvhscopeApp {
    /// Apply one action: the only place the state changes in answer to the user.
    pub fn act(&mut self, action: Action) {
        use Action as A;
        match action {
            a @ (A::Open
            | A::OpenPath
            | A::OpenFile(..)
            | A::ShowBuiltin
            | A::SavePng
            | A::SavePngTyped
            | A::NoFileDialog(..)
            | A::ExportStats
            | A::ExportStatsJson
            | A::ExportCounts
            | A::SaveScene
            | A::OpenBvh
            | A::OpenBvhPath
            | A::ImportFile(..)
            | A::ExportBvh
            | A::UseImported(..)
            | A::ShowImported(..)
            | A::WrongMask(..)
            | A::OpenGradeReport
            | A::OpenGradeReportPath
            | A::OpenGradeReportFile(..)
            | A::ShowGrade(..)
            | A::ChooseStudent(..)
            | A::SelectDumpNode(..)
            | A::SelectTriangle(..)
            | A::Picked(..)
            | A::PathText(..)
            | A::PathFocused
            | A::ClosePathWindow) => self.act_file(a),
            a @ (A::Orbit(..)
            | A::Pan { .. }
            | A::Zoom(..)
            | A::FrameMesh
            | A::ResetView
            | A::Viewport { .. }
            | A::View(..)
            | A::SetThreshold(..)
            | A::ToggleBoxes
            | A::DepthUp
            | A::DepthDown
            | A::NextStrategy
            | A::NextColormap
            | A::ApplyPreset(..)
            | A::SetUpAxis(..)
            | A::Edit(..)
            | A::SetCamera(..)) => self.act_view(a),
            a @ (A::Compare(..)
            | A::CompareStrategy(..)
            | A::CompareB { .. }
            | A::CompareMode(..)
            | A::Wipe(..)
            | A::ShowReplay(..)
            | A::ReplayStep(..)
            | A::ReplayPlay(..)
            | A::ExportReplay
            | A::CancelFilm) => self.act_compare(a),
            a @ (A::PinPixel(..)
            | A::PinSecondary(..)
            | A::PinTyped
            | A::RayText { .. }
            | A::Unpin(..)
            | A::UnpinAll
            | A::SelectPinned(..)
            | A::RayStep(..)
            | A::RayStepBy(..)
            | A::RayPlay(..)
            | A::ShowRayWindow
            | A::Hottest { .. }
            | A::TimeLinear(..)
            | A::CopyTraceCommand) => self.act_ray(a),
            a @ (A::ShowTree(..)
            | A::SelectNode(..)
            | A::SelectPixelNode(..)
            | A::NodeStep(..)
            | A::ToggleOpen(..)
            | A::SetMetric(..)
            | A::SharedCostScale(..)) => self.act_nodes(a),
            a @ (A::Help
            | A::SetHelp(..)
            | A::Dismiss(..)
            | A::DismissEarlier(..)
            | A::Present(..)
            | A::TogglePresent
            | A::UiScale(..)
            | A::UiScaleBy(..)
            | A::ResetLayout
            | A::FoldLegend(..)) => self.act_window(a),
            a @ (A::OpenLesson
            | A::OpenLessonPath
            | A::OpenLessonFile(_)
            | A::LessonGo(_)
            | A::LessonNext
            | A::LessonPrevious
            | A::NewLesson
            | A::AddStep
            | A::ReplaceStep
            | A::LessonText { .. }
            | A::LessonEditing(_)
            | A::SaveLesson
            | A::CloseLesson) => self.act_lesson(a),
        }
    }
    /// Opening, saving and exporting files, the path window, the import and the grade report.
    fn act_file(&mut self, action: Action) {
        use Action as A;
        match action {
            A::Open => self.jobs.pick_file(Pick::Open, ""),
            A::OpenPath => self.path_window = Some(PathWindow::new(Pick::Open, String::new(), None)),
            // Loads in the background; the current scene stays until it has loaded.
            A::OpenFile(path) if crate::lesson::is_lesson(&path) => self.open_lesson(path),
            A::OpenFile(path) => self.jobs.load(path),
            A::ShowBuiltin => {
                self.messages.clear();
                self.set_scene(Arc::new(Scene::builtin()))
            }
            A::SavePng => self.jobs.pick_file(Pick::SavePng, &export::default_name(self, "png")),
            A::SavePngTyped => {
                self.path_window = Some(PathWindow::new(Pick::SavePng, export::typed_path(self, Pick::SavePng), None))
            }
            A::NoFileDialog(pick) => {
                let note =
                    "No file dialog is available on this system (no desktop portal or zenity). Type the path instead.";
                self.path_window = Some(PathWindow::new(pick, export::typed_path(self, pick), Some(note.into())));
            }
            A::ExportStats => self.jobs.pick_file(Pick::SaveStatsCsv, &export::default_name(self, "csv")),
            A::ExportStatsJson => self.jobs.pick_file(Pick::SaveStatsJson, &export::default_name(self, "json")),
            A::ExportCounts => self.jobs.pick_file(Pick::SaveCounts, &export::default_name(self, "counts")),
            A::SaveScene => self.jobs.pick_file(Pick::SaveScene, &export::suggested_name(self, Pick::SaveScene)),
            A::OpenBvh => self.jobs.pick_file(Pick::OpenBvh, ""),
            A::OpenBvhPath => self.path_window = Some(PathWindow::new(Pick::OpenBvh, String::new(), None)),
            A::ImportFile(path) => self.import_file(path),
            A::ExportBvh => self.jobs.pick_file(Pick::SaveBvh, &export::default_name(self, "bvh")),
            A::UseImported(on) => self.import.on = on && self.import.traced(self.scene_id).is_some(),
            A::ShowImported(open) => self.import.window = open,
            A::WrongMask(on) => self.import.mask = on,
            A::OpenGradeReport => self.jobs.pick_file(Pick::OpenGradeReport, ""),
            A::OpenGradeReportPath => {
                self.path_window = Some(PathWindow::new(Pick::OpenGradeReport, String::new(), None))
            }
            A::OpenGradeReportFile(path) => self.jobs.grade_report(path),
            A::ShowGrade(open) => self.grade.window = open,
            A::ChooseStudent(i) => self.choose_student(i),
            A::SelectDumpNode(d) => self.select_dump_node(d),
            A::SelectTriangle(t) => self.select_triangle(t),
            A::Picked(pick, path) => {
                self.path_window = None;
                self.picked(pick, path);
            }
            A::PathText(text) => {
                if let Some(w) = &mut self.path_window {
                    w.text = text;
                }
            }
            A::PathFocused => {
                if let Some(w) = &mut self.path_window {
                    w.focus = false;
                }
            }
            A::ClosePathWindow => self.path_window = None,
            _ => unreachable!("act sends only its file actions here"),
        }
    }

    /// The camera, the view and the boxes shown, and the build settings changed from the keyboard.
    fn act_view(&mut self, action: Action) {
        use Action as A;
        match action {
            A::Orbit(dx, dy) => self.orbit.orbit(dx, dy),
            A::Pan { dx, dy, height } => self.orbit.pan(dx, dy, height),
            A::Zoom(amount) => self.orbit.zoom(amount),
            A::FrameMesh => self.orbit.frame(&self.scene.bounds(), self.viewport_aspect),
            A::ResetView => self.reset_view(),
            A::Viewport { rect, image, pixels } => {
                self.viewport_rect = rect;
                self.image_rect = image;
                self.viewport_aspect = image.width() / image.height().max(1.0);
                self.viewport_pixels = pixels;
            }
            A::View(i) => {
                self.settings.view = View::ALL[i.min(View::ALL.len() - 1)];
                self.threshold = None;
            }
            A::SetThreshold(t) => self.threshold = t,
            A::ToggleBoxes => self.settings.show_boxes = !self.settings.show_boxes,
            A::DepthUp => {
                let max = self.current_bvh().map_or(0, |b| b.bottom_max_depth());
                self.settings.box_depth = (self.settings.box_depth + 1).min(max);
                self.settings.show_boxes = true;
            }
            A::DepthDown => {
                self.settings.box_depth = self.settings.box_depth.saturating_sub(1);
                self.settings.show_boxes = true;
            }
            A::NextStrategy => {
                self.import.on = false;
                let i = Strategy::ALL.iter().position(|s| *s == self.settings.build.strategy).unwrap_or(0);
                self.settings.build.strategy = Strategy::ALL[(i + 1) % Strategy::ALL.len()];
            }
            A::NextColormap => {
                let i = ColorMap::ALL.iter().position(|c| *c == self.settings.colormap).unwrap_or(0);
                self.settings.colormap = ColorMap::ALL[(i + 1) % ColorMap::ALL.len()];
            }
            A::ApplyPreset(preset) => {
                self.settings.apply_preset(preset);
                self.message(MessageKind::Info, format!("{}: {}", preset.label(), preset.help()));
            }
            A::SetUpAxis(up) => {
                if self.settings.up_axis != up {
                    self.settings.up_axis = up;
                    self.reset_view();
                }
            }
            A::Edit(settings) => {
                let up = settings.up_axis;
                self.settings = Settings { up_axis: self.settings.up_axis, ..*settings };
                self.act(A::SetUpAxis(up));
            }
            A::SetCamera(camera) => self.set_camera(camera),
            _ => unreachable!("act sends only its view actions here"),
        }
    }

    /// Side by side and the build replay.
    fn act_compare(&mut self, action: Action) {
        use Action as A;
        match action {
            A::Compare(on) => {
                if on && !self.compare.on {
                    let imported = self.import.shown(self.scene_id).map(|b| b.build_params().bvh.layout);
                    self.compare.start_from(&self.settings.build, self.settings.trace, imported);
                }
                self.compare.on = on;
                if on {
                    self.replay.window = false;
                }
            }
            A::CompareStrategy(st) => self.compare.strategy = st,
            A::CompareB { max_leaf_size, layout, trace } => {
                self.compare.max_leaf_size = crate::bvh::params::MAX_LEAF_SIZE.clamp(max_leaf_size);
                self.compare.layout = layout;
                self.compare.trace = trace;
            }
            A::CompareMode(m) => self.compare.mode = m,
            A::Wipe(x) => self.compare.wipe = x.clamp(0.0, 1.0),
            A::ShowReplay(open) => {
                self.replay.window = open;
                if open {
                    self.compare.on = false;
                }
                self.replay.playing = false;
            }
            A::ReplayStep(k) => {
                self.replay.set(k);
                self.replay.last_tick = Some(Instant::now());
            }
            A::ReplayPlay(on) => {
                let n = self.replay.replay.as_ref().map_or(0, |r| r.splits());
                if on && self.replay.k >= n {
                    self.replay.k = 0;
                }
                self.replay.playing = on;
                self.replay.last_tick = Some(Instant::now());
            }
            A::ExportReplay => self.jobs.pick_file(Pick::SaveAnimation, &export::default_name(self, "gif")),
            A::CancelFilm => {
                if let Some(job) = self.jobs.film.take() {
                    job.control.cancel();
                }
            }
            _ => unreachable!("act sends only its compare actions here"),
        }
    }

    /// Pinned rays: pinning, stepping, the hottest pixels, the linear-scan timing and the trace command.
    fn act_ray(&mut self, action: Action) {
        use Action as A;
        match action {
            A::PinPixel(x, y) => {
                let Some(s) = &self.shown else { return };
                if s.partial.is_some() {
                    let note =
                        "The image shows a partial tree of the build replay: close the Replay window to pin a ray.";
                    self.message(MessageKind::Info, note);
                    return;
                }
                if x < s.camera.width && y < s.camera.height {
                    let ray = s.camera.ray_gen().pixel_ray(x, y);
                    self.pins.pin(PinnedRay::new(s.bvh.clone(), ray, s.trace, Some((x, y)), &self.scene.source));
                }
            }
            A::PinSecondary(x, y, k) => {
                let Some(s) = self.shown.as_ref().filter(|s| s.partial.is_none()) else { return };
                let Some(sec) = self.secondary_rays(&s.camera) else { return };
                let rays = sec.pixel_rays(&*s.bvh, &*s.bvh, &s.camera, s.trace, (x, y)).unwrap_or_default();
                if let Some(&ray) = rays.get(k) {
                    let of = SecondaryOf { spec: sec.spec, camera: s.camera, index: k, of: rays.len() };
                    let source = &self.scene.source;
                    self.pins.pin(PinnedRay::of(s.bvh.clone(), ray, s.trace, Some((x, y)), source, Some(of)));
                }
            }
            A::PinTyped => match (self.pins.typed_ray(), self.current_bvh()) {
                (Ok(ray), Some(b)) => {
                    let pinned = PinnedRay::new(b.bvh.clone(), ray, self.settings.trace, None, &self.scene.source);
                    self.pins.pin(pinned);
                }
                (Err(e), _) => self.message(MessageKind::Error, e),
                (_, None) => self.message(MessageKind::Error, "no BVH is built yet to trace the ray through"),
            },
            A::RayText { origin, dir } => (self.pins.origin_text, self.pins.dir_text) = (origin, dir),
            A::Unpin(i) => self.pins.unpin(i),
            A::UnpinAll => {
                self.pins = RayView {
                    origin_text: self.pins.origin_text.clone(),
                    dir_text: self.pins.dir_text.clone(),
                    ..Default::default()
                };
                self.ray_window = false;
            }
            A::SelectPinned(i) => self.pins.select(i),
            A::RayStep(k) => self.pins.set_step(k),
            A::RayStepBy(d) => {
                self.pins.set_step(self.pins.step.saturating_add_signed(d as isize));
                self.pins.last_tick = Some(Instant::now());
            }
            A::RayPlay(on) => {
                self.pins.playing = on;
                self.pins.last_tick = Some(Instant::now());
                if on && self.pins.current().is_some_and(|r| self.pins.step + 1 >= r.len()) {
                    self.pins.step = 0; // play again from the start
                }
            }
            A::ShowRayWindow => self.ray_window = true,
            A::Hottest { next } => {
                let Some(s) = self.shown.as_ref() else { return };
                let k = if next { self.hottest.map_or(0, |k| k + 1) } else { 0 };
                match crate::render::hottest(&s.frame, s.style.view, s.style.cost, k) {
                    Some((x, y, v)) => {
                        self.hottest = Some(k);
                        let what = s.style.view.label().to_lowercase();
                        let text = format!(
                            "Pixel {x},{y}: the {} most {what} ({}), pinned in the Ray window",
                            crate::explain::words::ordinal(k as u32 + 1),
                            crate::render::legend::fmt_value(v as f64)
                        );
                        self.message(MessageKind::Info, text);
                        self.act(A::PinPixel(x, y));
                    }
                    None => self.message(
                        MessageKind::Info,
                        "The hottest pixels are of a finished heatmap: choose a heatmap view",
                    ),
                }
            }
            A::TimeLinear(false) => self.jobs.cancel_speedup(),
            A::TimeLinear(true) => {
                if let Some(s) = &self.shown {
                    self.jobs.speedup(s.bvh.clone(), s.camera, s.trace);
                }
            }
            A::CopyTraceCommand => match self.pins.current().and_then(|r| r.command.clone()) {
                Some(cmd) => {
                    self.message(MessageKind::Info, "Copied the pinned ray's trace command to the clipboard");
                    self.clipboard = Some(cmd);
                }
                None if self.pins.current().is_some() => self.message(
                    MessageKind::Info,
                    "The built-in scene has no file to name on the command line: open a mesh to copy its trace command",
                ),
                None => self.message(MessageKind::Info, "Pin a ray first (Ctrl+click on the image)"),
            },
            _ => unreachable!("act sends only its ray actions here"),
        }
    }

    /// The tree view and the node inspector.
    fn act_nodes(&mut self, action: Action) {
        use Action as A;
        match action {
            A::ShowTree(open) => {
                self.nodes.window = open;
                if open && self.nodes.selected.is_none() {
                    self.nodes.selected = Some(0);
                    self.nodes.inspection = None;
                }
            }
            A::SelectNode(n) => {
                self.nodes.window = true;
                self.nodes.select(n);
            }
            A::SelectPixelNode(x, y) => {
                let Some(shown) = &self.shown else { return };
                let explained = self.nodes.current(Some(&shown.bvh)).cloned();
                match (explained, shown.frame.sample(x, y)) {
                    (_, s) if !s.is_hit() => self.message(MessageKind::Info, "That pixel hits nothing: no leaf to select."),
                    (Some(e), s) => match e.hierarchy.leaf_of_hit(&e.tree, s.prim, shown.camera.ray_gen().pixel_ray(x, y).at(s.t)) {
                        Some(leaf) => self.act(A::SelectNode(leaf)),
                        None => self.message(MessageKind::Warning, "The pixel's triangle is in no leaf of this tree."),
                    },
                    (None, _) => self.message(
                        MessageKind::Info,
                        "The tree view is still being prepared (or the scene is built as two levels, which it does not show).",
                    ),
                }
            }
            A::NodeStep(step) => {
                if let Some(n) = self.nodes.step(step) {
                    self.nodes.select(n);
                }
            }
            A::ToggleOpen(n) => {
                if !self.nodes.open.remove(&n) {
                    self.nodes.open.insert(n);
                }
            }
            A::SetMetric(m) => self.nodes.metric = m,
            A::SharedCostScale(on) => self.nodes.shared_scale = on,
            _ => unreachable!("act sends only its nodes actions here"),
        }
    }

    /// Help, messages, presenting, the UI scale and the dock.
    fn act_window(&mut self, action: Action) {
        use Action as A;
        match action {
            A::Help => self.show_help = !self.show_help,
            A::SetHelp(on) => self.show_help = on,
            A::Dismiss(i) => {
                if i < self.messages.len() {
                    self.messages.remove(i);
                }
            }
            A::Present(on) => self.settings.present = on,
            A::TogglePresent => self.settings.present = !self.settings.present,
            A::UiScale(s) => self.settings.ui_scale = s.clamp(*UI_SCALES.start(), *UI_SCALES.end()),
            A::UiScaleBy(steps) => {
                // From the scale on screen, so a step while presenting starts at 150 %.
                let s = ((self.settings.zoom() * 10.0).round() + steps as f32) / 10.0;
                self.settings.ui_scale = s.clamp(*UI_SCALES.start(), *UI_SCALES.end());
                self.settings.present &= self.settings.ui_scale >= PRESENT_SCALE;
            }
            A::ResetLayout => {
                self.dock = Some(dock::default_layout());
                self.dock_presenting = None;
            }
            A::FoldLegend(folded) => self.settings.legend_folded = folded,
            A::DismissEarlier(n) => {
                self.messages.drain(..n.min(self.messages.len()));
            }
            _ => unreachable!("act sends only its window actions here"),
        }
    }
}
