//! A class's grade report in the app: a report read, a student chosen and shown (their dump
//! imported over the report's mesh, on its camera, side by side against SAH binned; the view's
//! state is `views::GradeView`).

use crate::app::state::{orbit, Action, BvhscopeApp, MessageKind, OrbitCamera};
use crate::app::views::{GradeView, ImportView, Pending};
use crate::explain::grade::GradeReport;
use crate::scene::SceneSource;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Whether two paths name the same file (the report's mesh may be named otherwise than the scene
/// open, e.g. relative against absolute).
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

impl BvhscopeApp {
    /// A report read (or why not): shown in the Grade report window, nothing chosen yet.
    pub(in crate::app) fn report_read(&mut self, read: Result<Box<GradeReport>, String>) {
        match read {
            Ok(r) => {
                let text = format!("Opened the grade report {}: {} students", r.file.display(), r.students.len());
                self.message(MessageKind::Info, text);
                if let Err(missing) = &r.mesh {
                    self.message(MessageKind::Warning, format!("{}: {missing}", r.file.display()));
                }
                self.grade = GradeView { report: Some(Arc::from(r)), window: true, ..Default::default() };
            }
            Err(e) => self.message(MessageKind::Error, e),
        }
    }

    /// Choose student `i` of the report: show their tree, or say why there is none to show.
    pub(in crate::app) fn choose_student(&mut self, i: usize) {
        let Some(report) = self.grade.report.clone() else { return };
        let Some(student) = report.students.get(i) else { return };
        (self.grade.chosen, self.grade.why_not, self.grade.pending) = (Some(i), None, None);
        let ready = student.openable().map(Path::to_path_buf).and_then(|dump| Ok((report.mesh.clone()?, dump)));
        let (mesh, dump) = match ready {
            Ok(both) => both,
            Err(why) => {
                // The tree on screen is another student's: it must not pass for this one's.
                self.drop_import();
                self.grade.why_not = Some(why);
                return;
            }
        };
        if self.scene_is(&mesh) {
            self.show_student(dump);
        } else {
            self.grade.pending = Some(Pending::Mesh { mesh: mesh.clone(), dump });
            self.jobs.load(mesh);
        }
    }

    /// Forget the imported tree (and a running import), back to the strategy built.
    fn drop_import(&mut self) {
        if let Some(job) = self.jobs.import.take() {
            job.control.cancel();
        }
        self.import = ImportView { mask: self.import.mask, ..Default::default() };
        self.compare.on = false;
    }

    /// The report's camera and traversal, then `dump` imported (its check traces that camera's
    /// rays, as the grader did).
    fn show_student(&mut self, dump: PathBuf) {
        let Some(r) = self.grade.report.clone() else { return };
        self.settings.up_axis = orbit::up_axis_of(&r.camera);
        self.orbit = OrbitCamera::exactly(&r.camera, self.settings.up_axis);
        self.settings.trace = r.trace;
        self.grade.pending = Some(Pending::Import { dump: dump.clone() });
        self.import_file(dump);
    }

    /// A scene loaded (`JobEvent::Loaded`): the chosen student's dump is imported when it is the
    /// report's mesh; another file opened meanwhile ends the wait (a dump being read is of the
    /// scene it replaced, and is dropped with it).
    pub(in crate::app) fn grade_scene_loaded(&mut self) {
        let Some(pending) = self.grade.pending.clone() else { return };
        match pending {
            Pending::Mesh { mesh, dump } if self.scene_is(&mesh) => self.show_student(dump),
            _ => self.grade.pending = None,
        }
    }

    /// Whether the scene on screen is the file `mesh`.
    fn scene_is(&self, mesh: &Path) -> bool {
        matches!(&self.scene.source, SceneSource::File(p) if same_file(p, mesh))
    }

    /// The report's mesh could not be loaded.
    pub(in crate::app) fn grade_load_failed(&mut self, why: &str) {
        if let Some(Pending::Mesh { .. }) = self.grade.pending.take() {
            self.grade.why_not = Some(why.to_string());
        }
    }

    /// A dump imported (`JobEvent::Imported`; `Err` why it could not be read or traced): the
    /// chosen student's is set side by side against SAH binned in its layout.
    pub(in crate::app) fn grade_imported(&mut self, path: Option<&Path>, traced: Result<(), String>) {
        let Some(Pending::Import { dump }) = &self.grade.pending else { return };
        // The import job of another dump ended (an error carries no path: only the newest import
        // reports, and that is this one).
        if path.is_some_and(|p| p != dump) {
            return;
        }
        self.grade.pending = None;
        match traced {
            Ok(()) => {
                // Off first, so B starts again from the imported tree: SAH binned, its layout.
                self.compare.on = false;
                self.act(Action::Compare(true));
            }
            Err(why) => self.grade.why_not = Some(why),
        }
    }
}
