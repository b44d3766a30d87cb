//! The report folder, what the app reads back (NOTES.md describes it):
//!
//! ```text
//! OUT/grade.html            the page a teacher sends (images inline: no other file needed)
//! OUT/grade.csv             one row per student (RFC 4180)
//! OUT/grade.json            everything: setup, rubric, references, rows (`json::document`)
//! OUT/images/NNN-name-visits.png       a student's heatmap (nodes visited per pixel)
//! OUT/images/NNN-name-difference.png   the student's tree minus the SAH tree, per pixel
//! OUT/grade-files.txt       every file above with its size, written last (`files::manifest`)
//! ```
//!
//! Written and put in place by the files service's report folder (`files::ReportDir`, of the kind
//! `GRADE`): into a fresh folder beside `--out`, renamed into place when complete, replacing only
//! what an earlier report listed in its `grade-files.txt`. No input may be inside `--out`, and no
//! report file may be an input.

use super::GradeError;
use crate::files::{FolderError, FolderKind};
use std::path::{Path, PathBuf};

pub const CSV_FILE: &str = "grade.csv";
pub const JSON_FILE: &str = "grade.json";
pub const HTML_FILE: &str = "grade.html";
pub const IMAGES_DIR: &str = "images";
/// The list of the report's files: what a later run into the folder may replace.
pub const MANIFEST_FILE: &str = GRADE.list;

/// A grade report, as the files service's report folder knows it.
pub const GRADE: FolderKind = FolderKind {
    what: "grade report",
    list: "grade-files.txt",
    first_line: "bvhscope-grade-files 1",
    names: &[CSV_FILE, JSON_FILE, HTML_FILE, IMAGES_DIR],
    folders: &[IMAGES_DIR],
    flag: "--out",
};

/// A report folder made ready for a class (`files::ReportDir` of the kind `GRADE`, whose writing
/// methods it lends), its errors grade's own.
pub struct ReportDir(crate::files::ReportDir);

impl ReportDir {
    /// `files::ReportDir::prepare` into `root` (`--out`) for a grade report.
    pub fn prepare(root: &Path, inputs: Vec<(PathBuf, String)>) -> Result<ReportDir, GradeError> {
        Ok(ReportDir(crate::files::ReportDir::prepare(root, &GRADE, inputs)?))
    }

    /// An image of a student, as a path relative to the folder (`images/NNN-name-KIND.png`).
    pub fn image_name(slug: &str, kind: &str) -> String {
        format!("{IMAGES_DIR}/{slug}-{kind}.png")
    }

    /// Put the finished report in place (`files::ReportDir::publish`).
    pub fn publish(&mut self) -> Result<(), GradeError> {
        Ok(self.0.publish()?)
    }
}

impl std::ops::Deref for ReportDir {
    type Target = crate::files::ReportDir;
    fn deref(&self) -> &crate::files::ReportDir {
        &self.0
    }
}

/// A report folder's refusals are grade's `Output` errors, word for word.
impl From<FolderError> for GradeError {
    fn from(e: FolderError) -> GradeError {
        match e {
            FolderError::File(f) => GradeError::File(f),
            FolderError::Output { path, message } => GradeError::Output { path, message },
        }
    }
}
