//! A class's grade report in the app (`bvhscope grade`'s grade.json, read by the core's
//! `explain::grade::GradeReport` in a job): the students in the report's order, and choosing one
//! shows their tree as the grader saw it. Their dump is imported over the report's mesh as
//! File ▸ Open BVH does (the mesh opened first when another scene is on screen; the import checks
//! the dump again with the app's own rays), on the report's camera and traversal, side by side
//! against SAH binned in the dump's layout (the Compare view: A the student's tree, B SAH). A
//! student without a traceable tree (broken structure, another mesh, an unreadable file, no dump)
//! shows the report's reason only, and nothing is imported.

use crate::explain::grade::GradeReport;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(Default)]
pub struct GradeView {
    pub report: Option<Arc<GradeReport>>,
    /// The Grade report window is open.
    pub window: bool,
    /// The student chosen: their index in the report.
    pub chosen: Option<usize>,
    /// Why the chosen student's tree is not shown: the report's reason, a file not found, an
    /// import that failed.
    pub why_not: Option<String>,
    /// Showing the chosen student, while it is on its way.
    pub pending: Option<Pending>,
}

/// The steps of showing a student, each started when the one before has ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Pending {
    /// The report's mesh is loading; then `dump` is imported over it.
    Mesh { mesh: PathBuf, dump: PathBuf },
    /// The dump is being read and checked.
    Import { dump: PathBuf },
}
