//! The report folder, what the app reads back (NOTES.md describes it):
//!
//! ```text
//! OUT/grade.html            the page a teacher sends (images inline: no other file needed)
//! OUT/grade.csv             one row per student (RFC 4180)
//! OUT/grade.json            everything: setup, rubric, references, rows (`json::document`)
//! OUT/images/NNN-name-visits.png       a student's heatmap (nodes visited per pixel)
//! OUT/images/NNN-name-difference.png   the student's tree minus the SAH tree, per pixel
//! OUT/grade-files.txt       every file above with its size, written last (`manifest`)
//! ```
//!
//! The report is written into a fresh folder beside `--out` and renamed into place when complete
//! (`ReportDir::publish`): two runs into one `--out` never mix (each leaves a whole report, the
//! last one wins), no image of an earlier run survives, and the app never reads a half-written
//! report. An existing `--out` is accepted only when it is empty or holds nothing but what an
//! earlier report listed in its `grade-files.txt`, unchanged (`manifest::ours`): anything else
//! (a file of the user's, a report file edited since, a link, an older report that wrote no
//! list) is refused by name, before any work and again before the report is put in place, and
//! only the listed files are ever removed. No input may be inside `--out`, and no report file
//! may be an input.

use super::manifest;
use super::GradeError;
use crate::files::{refuse_inputs, FileError};
use std::path::{Path, PathBuf};

pub const CSV_FILE: &str = "grade.csv";
pub const JSON_FILE: &str = "grade.json";
pub const HTML_FILE: &str = "grade.html";
pub const IMAGES_DIR: &str = "images";

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
    /// submission's folder, a folder holding anything but what an earlier report listed
    /// (`manifest::ours`), or one holding an input, and report files that are inputs (`inputs`:
    /// path and what it is).
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
                    "holds {what}: a report replaces what it wrote there; write it to another folder (--out)"
                )));
            }
            manifest::ours(root).map_err(fail)?;
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

    /// Put the finished report in place: its files listed (`manifest::write`), the folder written
    /// renamed to `root`, an earlier report there moved aside first and, once this one is in
    /// place, emptied of the files its list names and removed. `root` is checked again first:
    /// grading a class takes minutes, and a file put there meanwhile is refused as in `prepare`
    /// (the new report is then left beside it, named). Another run may publish meanwhile: each
    /// rename is of a whole report, so `root` always holds one.
    pub fn publish(&mut self) -> Result<(), GradeError> {
        let Some(work) = self.work.take() else { return Ok(()) };
        manifest::write(work.path())?;
        let fail = |message: String| GradeError::Output { path: self.root.clone(), message };
        let parent = work.path().parent().map(Path::to_path_buf).unwrap_or_else(|| PathBuf::from("."));
        let work = work.keep();
        let mut asides = Vec::new();
        let mut last = None;
        for _ in 0..16 {
            if self.root.is_dir() {
                if let Err(why) = manifest::ours(&self.root) {
                    let _ = Self::clear(&asides);
                    return Err(fail(format!("{why} (the new report is left in {})", work.display())));
                }
            }
            match std::fs::rename(&work, &self.root) {
                Ok(()) => return Self::clear(&asides).map_err(fail),
                Err(e) if self.root.is_dir() => {
                    // An earlier report (checked just above): aside, then removed by its list
                    // once this one is in place.
                    let aside = tempfile::Builder::new()
                        .prefix(".grade-report.old-")
                        .tempdir_in(&parent)
                        .map_err(|e| fail(format!("cannot be put in place: {e}")))?
                        .keep();
                    if std::fs::rename(&self.root, aside.join("report")).is_err() {
                        let _ = std::fs::remove_dir(&aside);
                    } else {
                        asides.push(aside);
                    }
                    last = Some(e);
                }
                Err(e) => {
                    last = Some(e);
                    break;
                }
            }
        }
        let _ = std::fs::remove_dir_all(&work);
        self.restore(&mut asides);
        let _ = Self::clear(&asides);
        let e = last.unwrap_or_else(|| std::io::Error::other("another run kept replacing it"));
        Err(fail(format!("cannot be put in place: {e}")))
    }

    /// The report last moved aside put back where it was, when nothing took its place: a
    /// report that cannot be published leaves the earlier one as it found it.
    fn restore(&self, asides: &mut Vec<PathBuf>) {
        if let Some(aside) = asides.pop() {
            if std::fs::rename(aside.join("report"), &self.root).is_ok() {
                let _ = std::fs::remove_dir(&aside);
            } else {
                asides.push(aside);
            }
        }
    }

    /// Remove the earlier reports moved aside, each by its own list (`manifest::remove`): what
    /// it did not list (put there in the instant between the check and the move) is kept, and
    /// named.
    fn clear(asides: &[PathBuf]) -> Result<(), String> {
        for aside in asides {
            manifest::remove(&aside.join("report")).map_err(|why| {
                format!(
                    "the report is in place, but the earlier one moved aside to {} is kept ({why})",
                    aside.display()
                )
            })?;
            let _ = std::fs::remove_dir(aside);
        }
        Ok(())
    }
}
