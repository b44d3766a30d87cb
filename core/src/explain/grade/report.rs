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
//! The report is written into a fresh folder beside `--out` and renamed into place when complete
//! (`ReportDir::publish`): two runs into one `--out` never mix (each leaves a whole report, the
//! last one wins), no image of an earlier run survives, and the app never reads a half-written
//! report. So an existing `--out` is replaced as a whole, and is accepted only when it is empty
//! or holds a report (nothing else of the user's is in it); no input may be inside it, and no
//! report file may be an input.

use super::GradeError;
use crate::files::{refuse_inputs, FileError};
use std::path::{Path, PathBuf};

pub const CSV_FILE: &str = "grade.csv";
pub const JSON_FILE: &str = "grade.json";
pub const HTML_FILE: &str = "grade.html";
pub const IMAGES_DIR: &str = "images";

/// What a report folder holds: an `--out` holding anything else is not replaced.
const REPORT_ENTRIES: [&str; 4] = [CSV_FILE, JSON_FILE, HTML_FILE, IMAGES_DIR];

/// A report folder made ready for a class: written in `work` until `publish` renames it to `root`.
pub struct ReportDir {
    /// Where the report ends up (`--out`).
    pub root: PathBuf,
    /// Where it is written meanwhile: a fresh folder beside `root` (removed if never published).
    work: Option<tempfile::TempDir>,
    /// Every input, with what it is ("the mesh", "alice's dump").
    inputs: Vec<(PathBuf, String)>,
}

impl ReportDir {
    /// Make a fresh folder ready beside `root`, after refusing a `root` that is a file, a
    /// submission's folder, a folder holding anything but a report, or one holding an input, and
    /// report files that are inputs (`inputs`: path and what it is).
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
        let mut dir = ReportDir { root: root.to_path_buf(), work: None, inputs };
        for name in [CSV_FILE, JSON_FILE, HTML_FILE] {
            let path = dir.root.join(name);
            let inputs: Vec<(&Path, &str)> = dir.inputs.iter().map(|(p, w)| (p.as_path(), w.as_str())).collect();
            refuse_inputs(&path, &inputs)?;
        }
        if root.is_dir() {
            let inside = std::fs::canonicalize(root).map_err(|source| FileError::Read { path: root.into(), source })?;
            let within =
                dir.inputs.iter().find(|(p, _)| std::fs::canonicalize(p).is_ok_and(|p| p.starts_with(&inside)));
            if let Some((_, what)) = within {
                return Err(fail(format!(
                    "holds {what}: a report replaces its folder as a whole; write it to another folder (--out)"
                )));
            }
            let list = std::fs::read_dir(root).map_err(|source| FileError::Read { path: root.into(), source })?;
            let other =
                list.filter_map(|e| e.ok()).find(|e| !REPORT_ENTRIES.contains(&&*e.file_name().to_string_lossy()));
            if let Some(e) = other {
                return Err(fail(format!(
                    "holds {}, which is not part of a grade report: a report replaces its folder as a whole; write it to a new or empty folder, or an earlier report's (--out)",
                    e.file_name().to_string_lossy()
                )));
            }
        }
        let parent = match root.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent).map_err(|source| FileError::Write { path: parent.clone(), source })?;
        let name = root.file_name().map_or_else(|| "grade-report".into(), |n| n.to_string_lossy().into_owned());
        let work = tempfile::Builder::new()
            .prefix(&format!(".{name}.writing-"))
            .tempdir_in(&parent)
            .map_err(|source| FileError::Write { path: root.into(), source })?;
        // A temporary folder is private (0700); the report is as readable as any folder made here.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(work.path(), std::fs::Permissions::from_mode(0o755));
        }
        let images = work.path().join(IMAGES_DIR);
        std::fs::create_dir_all(&images).map_err(|source| FileError::Write { path: images, source })?;
        dir.work = Some(work);
        Ok(dir)
    }

    /// The folder being written.
    fn work(&self) -> &Path {
        self.work.as_ref().map_or(self.root.as_path(), |w| w.path())
    }

    /// The path a report file will have once published (for messages).
    pub fn file(&self, name: &str) -> PathBuf {
        self.root.join(name)
    }

    /// An image of a student, as a path relative to the folder (`images/NNN-name-KIND.png`).
    pub fn image_name(slug: &str, kind: &str) -> String {
        format!("{IMAGES_DIR}/{slug}-{kind}.png")
    }

    /// Write an image at `rel` (relative to the folder).
    pub fn write_png(&self, rel: &str, img: &image::RgbImage) -> Result<(), FileError> {
        crate::files::write_png(&self.work().join(rel), img)
    }

    /// Write a report file (`CSV_FILE`…).
    pub fn write(&self, name: &str, bytes: &[u8]) -> Result<(), FileError> {
        crate::files::write_bytes(&self.work().join(name), bytes)
    }

    /// Read back an image written here (for the HTML page), at most `limit` bytes: this run's,
    /// never an earlier run's.
    pub fn read_image(&self, rel: &str, limit: u64) -> Option<Vec<u8>> {
        let (file, _) = crate::files::open_regular(&self.work().join(rel)).ok()?;
        crate::files::read_limited(file, limit).ok().flatten()
    }

    /// The HTML page's path while it is written (the page is streamed by `html::write_html`).
    pub fn html_path(&self) -> Result<PathBuf, FileError> {
        Ok(self.work().join(HTML_FILE))
    }

    /// Put the finished report in place: the folder written renamed to `root`, an earlier report
    /// there moved aside first and removed after. Another run may publish meanwhile: each rename
    /// is of a whole report, so `root` always holds one.
    pub fn publish(&mut self) -> Result<(), GradeError> {
        let Some(work) = self.work.take() else { return Ok(()) };
        let fail = |e: std::io::Error| GradeError::Output {
            path: self.root.clone(),
            message: format!("cannot be put in place: {e}"),
        };
        let parent = work.path().parent().map(Path::to_path_buf).unwrap_or_else(|| PathBuf::from("."));
        let work = work.keep();
        let mut last = None;
        for _ in 0..16 {
            match std::fs::rename(&work, &self.root) {
                Ok(()) => return Ok(()),
                Err(e) if self.root.is_dir() => {
                    // An earlier report (checked in `prepare`, or another run's since): aside,
                    // then removed once this one is in place.
                    let aside =
                        tempfile::Builder::new().prefix(".grade-report.old-").tempdir_in(&parent).map_err(fail)?;
                    match std::fs::rename(&self.root, aside.path().join("report")) {
                        Ok(()) | Err(_) => last = Some(e),
                    }
                }
                Err(e) => {
                    let _ = std::fs::remove_dir_all(&work);
                    return Err(fail(e));
                }
            }
        }
        let _ = std::fs::remove_dir_all(&work);
        Err(fail(last.unwrap_or_else(|| std::io::Error::other("another run kept replacing it"))))
    }
}
