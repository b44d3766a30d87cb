//! The report folder, what the app reads back (NOTES.md describes it):
//!
//! ```text
//! OUT/grade.html            the page a teacher sends (images inline: no other file needed)
//! OUT/grade.csv             one row per student (RFC 4180)
//! OUT/grade.json            everything: setup, rubric, references, rows (`json::document`)
//! OUT/images/NNN-name-visits.png       a student's heatmap (nodes visited per pixel)
//! OUT/images/NNN-name-difference.png   the student's tree minus the SAH tree, per pixel
//! ```
//!
//! Every file is written atomically (`files`), and none may be an input: a report file that is
//! the mesh, the rubric or a submission is refused before anything is graded, an image before it
//! is written; the folder may not be a submission's folder.

use super::GradeError;
use crate::files::{refuse_inputs, FileError};
use std::path::{Path, PathBuf};

pub const CSV_FILE: &str = "grade.csv";
pub const JSON_FILE: &str = "grade.json";
pub const HTML_FILE: &str = "grade.html";
pub const IMAGES_DIR: &str = "images";

/// A report folder made ready for a class.
pub struct ReportDir {
    pub root: PathBuf,
    /// Every input, with what it is ("the mesh", "alice's dump").
    inputs: Vec<(PathBuf, String)>,
}

impl ReportDir {
    /// Make `root` (and its `images` folder) ready, after refusing a root that is a submission's
    /// folder or a file, and report files that are inputs (`inputs`: path and what it is).
    pub fn prepare(root: &Path, inputs: Vec<(PathBuf, String)>) -> Result<ReportDir, GradeError> {
        let fail = |message: String| GradeError::Output { path: root.to_path_buf(), message };
        if root.exists() && !root.is_dir() {
            return Err(fail("is a file: the report is written to a folder (--out)".into()));
        }
        if root.is_dir() {
            let same = inputs.iter().find(|(p, _)| p.is_dir() && same_file::is_same_file(p, root).unwrap_or(false));
            if let Some((_, what)) = same {
                return Err(fail(format!("is also {what}: write the report to another folder (--out)")));
            }
        }
        let dir = ReportDir { root: root.to_path_buf(), inputs };
        for name in [CSV_FILE, JSON_FILE, HTML_FILE] {
            dir.refuse(&dir.root.join(name))?;
        }
        let images = root.join(IMAGES_DIR);
        std::fs::create_dir_all(&images).map_err(|source| FileError::Write { path: images, source })?;
        Ok(dir)
    }

    fn refuse(&self, path: &Path) -> Result<(), FileError> {
        let inputs: Vec<(&Path, &str)> = self.inputs.iter().map(|(p, w)| (p.as_path(), w.as_str())).collect();
        refuse_inputs(path, &inputs)
    }

    /// The path of a report file.
    pub fn file(&self, name: &str) -> PathBuf {
        self.root.join(name)
    }

    /// An image of a student, as a path relative to the folder (`images/NNN-name-KIND.png`).
    pub fn image_name(slug: &str, kind: &str) -> String {
        format!("{IMAGES_DIR}/{slug}-{kind}.png")
    }

    /// Write an image at `rel` (relative to the folder), unless that file is an input.
    pub fn write_png(&self, rel: &str, img: &image::RgbImage) -> Result<(), FileError> {
        let path = self.root.join(rel);
        self.refuse(&path)?;
        crate::files::write_png(&path, img)
    }

    /// Write a report file (`CSV_FILE`…), unless it is an input.
    pub fn write(&self, name: &str, bytes: &[u8]) -> Result<(), FileError> {
        let path = self.file(name);
        self.refuse(&path)?;
        crate::files::write_bytes(&path, bytes)
    }

    /// Read back an image written here (for the HTML page), at most `limit` bytes.
    pub fn read_image(&self, rel: &str, limit: u64) -> Option<Vec<u8>> {
        let (file, _) = crate::files::open_regular(&self.root.join(rel)).ok()?;
        crate::files::read_limited(file, limit).ok().flatten()
    }

    /// The HTML page's path, unless it is an input (the page is streamed by `html::write_html`).
    pub fn html_path(&self) -> Result<PathBuf, FileError> {
        let path = self.file(HTML_FILE);
        self.refuse(&path)?;
        Ok(path)
    }
}
