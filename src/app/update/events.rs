//! What arrives from outside the panels: background jobs' results (a loaded scene, a build, a
//! render pass, …), files picked in a dialog, dropped files and keys.

use super::export;
use crate::app::jobs::{JobEvent, PassOutput, Pick, Probe};
use crate::app::state::{shortcuts, Action, Actions, BvhscopeApp, MeasuredRays, MessageKind, Shown};
use crate::dump::BvhDump;
use crate::gpu_path::Device;
use crate::scene::{SceneBuildError, SceneSource};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

impl BvhscopeApp {
    pub(super) fn apply(&mut self, ctx: &egui::Context, event: JobEvent) {
        match event {
            JobEvent::Loaded(Ok(scene)) => {
                if let SceneSource::File(p) = &scene.source {
                    self.settings.remember(p.clone());
                }
                let r = &scene.report;
                let mut text = format!("Opened {}: {} triangles", scene.title(), r.triangles);
                if r.degenerate_skipped > 0 {
                    text += &format!(" ({} degenerate triangles skipped)", r.degenerate_skipped);
                }
                // The messages were about the scene before (a student's warning, a check's
                // note): a new scene starts with its own.
                self.messages.clear();
                self.message(MessageKind::Info, text);
                self.set_scene(scene);
                if let Some(dump) = self.pending_import.take() {
                    self.import_file(dump);
                }
                self.grade_scene_loaded();
            }
            JobEvent::Loaded(Err(e)) => {
                self.grade_load_failed(&e);
                self.message(MessageKind::Error, e);
            }
            JobEvent::GradeReport(read) => self.report_read(read),
            JobEvent::Failed(e) => self.message(MessageKind::Error, e),
            JobEvent::Speedup(t) => self.speedup = Some(*t),
            JobEvent::Filmed(Ok(saved)) => self.message(MessageKind::Info, saved),
            JobEvent::Filmed(Err(why)) => self.message(MessageKind::Error, why),
            e @ (JobEvent::GpuProbed(_) | JobEvent::GpuFailed(_)) => self.gpu_event(e),
            JobEvent::Explained(e) => {
                // A new tree: keep the selection where the id still exists, and its open rows.
                let n = e.tree.nodes.len() as u32;
                self.nodes.selected = self.nodes.selected.filter(|&s| s < n);
                self.nodes.open.retain(|&o| o < n);
                self.nodes.inspection = None;
                self.nodes.explained = Some(e);
                if let Some(s) = self.nodes.selected {
                    self.nodes.select(s);
                }
            }
            JobEvent::Visits(v) => self.nodes.visits = Some(v),
            JobEvent::Compared(b) => {
                if b.scene_id == self.scene_id {
                    self.compare.b = Some(*b);
                }
            }
            JobEvent::Inspected { node, explained, inspection } => {
                let current = self.nodes.explained.as_ref().is_some_and(|e| Arc::ptr_eq(e, &explained));
                if current && self.nodes.selected == Some(node) {
                    self.nodes.inspection = Some(inspection);
                }
            }
            JobEvent::Built { scene_id, result: Ok(bvh), .. }
                if scene_id == self.scene_id && self.import.shown(scene_id).is_none() =>
            {
                self.set_built(bvh)
            }
            JobEvent::Imported(Err(e)) => {
                self.grade_imported(None, Err(e.clone()));
                self.message(MessageKind::Error, e);
            }
            JobEvent::Imported(Ok(tree)) if tree.scene_id == self.scene_id => {
                let (d, w) = (tree.defects(), tree.findings.len() - tree.defects());
                let kind = if d > 0 { MessageKind::Warning } else { MessageKind::Info };
                let shown = match &tree.bvh {
                    Ok(_) => "shown as \"imported\" in the strategy list".to_string(),
                    Err(why) => format!("not traced: {why}"),
                };
                self.message(kind, format!("Checked {}: {d} defects, {w} warnings; {shown}", tree.name()));
                self.import.on = tree.bvh.is_ok();
                self.import.window = true;
                self.import.wrong = None;
                let traced = tree.bvh.as_ref().map(|_| ()).map_err(|why| format!("not traced: {why}"));
                let path = tree.path.clone();
                self.import.tree = Some(*tree);
                self.grade_imported(Some(&path), traced);
            }
            JobEvent::Imported(_) => {}
            JobEvent::Wrong(w) => self.import.wrong = Some(w),
            JobEvent::Built { scene_id, result: Err(SceneBuildError::Scene(e)), .. } if scene_id == self.scene_id => {
                self.message(MessageKind::Error, e.to_string());
            }
            // A cancelled build, another scene's, or one the GPU failed (its message is `GpuFailed`'s).
            JobEvent::Built { .. } | JobEvent::NotBuilt => {}
            JobEvent::Pass(pass) => self.show_pass(ctx, pass),
            JobEvent::Picked { pick, path: Some(path), .. } => self.act(Action::Picked(pick, path)),
            JobEvent::Picked { pick, path: None, took } => {
                // rfd answers None at once when it has no portal or zenity to ask; a person who
                // cancels a real dialog takes longer than that.
                if took < Duration::from_millis(300) {
                    self.act(Action::NoFileDialog(pick));
                }
            }
        }
    }

    /// Act on a chosen file.
    pub(super) fn picked(&mut self, pick: Pick, path: PathBuf) {
        if let Err(e) = export::check_output(self, pick, &path) {
            return self.message(MessageKind::Error, e);
        }
        let result = match pick {
            Pick::Open => {
                // A lesson chosen in File ▸ Open opens as a lesson.
                self.act(Action::OpenFile(path));
                return;
            }
            Pick::OpenLesson => {
                self.open_lesson(path);
                return;
            }
            Pick::SaveLesson => self.save_lesson(&path),
            Pick::SavePng => export::save_png(self, &path),
            Pick::SaveStatsCsv => export::save_stats(self, &path, export::StatsFormat::Csv),
            Pick::SaveStatsJson => export::save_stats(self, &path, export::StatsFormat::Json),
            Pick::SaveCounts => export::save_counts(self, &path),
            Pick::OpenBvh => {
                self.import_file(path);
                return;
            }
            Pick::OpenGradeReport => {
                self.jobs.grade_report(path);
                return;
            }
            Pick::SaveBvh => export::save_bvh(self, &path),
            Pick::SaveAnimation => match export::film_request(self) {
                Ok(r) => {
                    self.jobs.film(r, path);
                    return;
                }
                Err(e) => Err(e),
            },
            Pick::SaveScene => self
                .scene_file_text()
                .and_then(|t| crate::files::write_bytes(&path, t.as_bytes()).map_err(|e| e.to_string())),
        };
        match result {
            Ok(()) => self.message(MessageKind::Info, format!("Saved {}", path.display())),
            Err(e) => self.message(MessageKind::Error, e),
        }
    }

    pub(super) fn show_pass(&mut self, ctx: &egui::Context, p: PassOutput) {
        let options = egui::TextureOptions::NEAREST;
        // A pass that only adds counts to the image on screen keeps the image's figures: its
        // time and speed are those of the counted walk, not of what drew the image.
        let counted_image_on_screen = self.shown.as_ref().filter(|_| p.info.counts_only);
        let rays_per_s = match counted_image_on_screen {
            Some(s) => s.rays_per_s,
            None => p.info.rays as f64 / p.info.pass_time.as_secs_f64().max(1e-9),
        };
        if p.info.stride == 1 {
            if !p.info.counts_only {
                self.last_full_frame = Some(p.info.elapsed);
            }
            // An import's check waits for the scene's first full frame (`Jobs::import`).
            if p.partial.is_none() && self.current_bvh().is_some_and(|b| Arc::ptr_eq(&b.bvh, &p.bvh)) {
                self.jobs.shown_scene.store(self.scene_id, std::sync::atomic::Ordering::SeqCst);
            }
            // Per-ray figures belong to the BVH that traced them; a pass of an older BVH that
            // arrives after a rebuild must not be shown (or remembered) under the new strategy.
            // A replay's partial tree is not the strategy's tree: its figures are not recorded.
            // An uncounted frame (the normal and depth views' image, its counts to follow) has none.
            if p.partial.is_none()
                && p.frame.counted()
                && self.current_bvh().is_some_and(|b| Arc::ptr_eq(&b.bvh, &p.bvh))
            {
                // An imported tree's rays counted on the mesh's box, as the tree beside it.
                let summary = match p.bvh.yardstick() {
                    Some(y) => p.frame.ray_summary_in(&p.camera, &y),
                    None => p.frame.ray_summary(),
                };
                let secondary = p.frame.secondary().copied();
                self.rays = Some(MeasuredRays { summary, camera: p.camera, trace: p.trace, secondary });
            }
        }
        let texture = match self.shown.take() {
            Some(mut s) => {
                s.texture.set(p.image, options);
                s.texture
            }
            None => ctx.load_texture("bvhscope-view", p.image, options),
        };
        let build_label = p.bvh.label();
        // A threshold belongs to the scale it was set on: another view, or a range that no longer
        // holds it, clears it (it used to say "pixels above 125.1" over a 0..1 scale).
        let same_view = self.shown.as_ref().is_some_and(|s| s.style.view == p.style.view);
        let holds = |t: f32| p.legend.as_ref().is_some_and(|l| (l.range_min..=l.range_max).contains(&t));
        if self.threshold.is_some_and(|t| !same_view || !holds(t)) {
            self.threshold = None;
        }
        self.shown = Some(Shown {
            texture,
            frame: p.frame,
            camera: p.camera,
            legend: p.legend,
            style: p.style,
            rays_per_s,
            build_label,
            bvh: p.bvh,
            trace: p.trace,
            partial: p.partial,
            gpu: p.gpu,
            cpu_finished: p.cpu_finished,
        });
    }

    /// Job results, and the actions of input outside the panels: dropped files and keys.
    pub(in crate::app) fn handle_input(&mut self, ctx: &egui::Context, actions: &mut Actions) {
        for event in self.jobs.poll() {
            self.apply(ctx, event);
        }
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw.dropped_files.iter().map(|f| f.path().to_path_buf()).filter(|p| !p.as_os_str().is_empty()).collect()
        });
        // A grade report (its grade.json or its folder) is listed, a dump is imported for the
        // current mesh, anything else is opened.
        let open = |p: PathBuf| {
            if crate::explain::grade::is_report(&p) {
                Action::OpenGradeReportFile(p)
            } else if BvhDump::sniff(&p) {
                Action::ImportFile(p)
            } else {
                Action::OpenFile(p)
            }
        };
        actions.extend(dropped.into_iter().take(1).map(open));
        // A lesson's keys first: with a lesson open, the clicker's keys are its own.
        if self.lesson.is_some() {
            actions.extend(shortcuts::lesson_keys(ctx));
        }
        actions.extend(shortcuts::pressed(ctx));
        // The step being applied moves on (its scene loaded, its tree built, its frame there).
        actions.extend(self.lesson_actions());
        // Info messages fade out; errors stay until dismissed.
        self.messages.retain(|m| m.kind != MessageKind::Info || m.at.elapsed() < Duration::from_secs(6));
    }
}

impl BvhscopeApp {
    /// The GPU's answers: the adapter found or not, a GPU job that failed (back to the CPU).
    fn gpu_event(&mut self, event: JobEvent) {
        match event {
            JobEvent::GpuProbed(Ok(gpu)) => self.jobs.gpu.probe = Probe::Found(gpu),
            JobEvent::GpuProbed(Err(why)) => {
                if self.settings.device == Device::Gpu {
                    self.message(MessageKind::Warning, format!("No GPU: {why}. Tracing on the CPU."));
                    self.settings.device = Device::Cpu;
                }
                self.jobs.gpu.probe = Probe::Missing(why);
            }
            JobEvent::GpuFailed(why) => {
                self.message(MessageKind::Error, format!("{why}. Switched back to the CPU."));
                self.settings.device = Device::Cpu;
                // The last render and build asked for the GPU: ask again, on the CPU.
                self.jobs.last_render = None;
                self.jobs.last_build = None;
            }
            _ => {}
        }
    }
}
