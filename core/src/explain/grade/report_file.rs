//! `grade.json` read back, for the app's Grade report window: the class in the report's order,
//! each student's verdict, rank and reason, and where their dump and the mesh are now.
//!
//! The report names its files as `grade` was given them, relative to where it ran, not to the
//! report folder; a report opened later, from elsewhere, must still find them. Each path is tried
//! as given, then from the report folder's parent (`grade … --out DIR` is usually run beside
//! DIR), then from the folder itself; when none exists, the message names the file and every place
//! looked in.
//!
//! Only format `bvhscope-grade` version 1 is read (`FORMAT`, `VERSION`): a report of another
//! version is refused in one line naming the file, never half read.

use super::{GradeError, Verdict, FORMAT, JSON_FILE, VERSION};
use crate::bvh::{Layout, TraceOptions};
use crate::render::Camera;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The largest report read: a class of a hundred takes about a megabyte.
const MAX_BYTES: u64 = 256 << 20;

/// A grade report, as the app shows it.
#[derive(Clone, Debug)]
pub struct GradeReport {
    /// The `grade.json` read.
    pub file: PathBuf,
    /// The mesh or scene as `grade` was given it (captions).
    pub mesh_given: String,
    /// That file where it is now; `Err` names it and where it was looked for.
    pub mesh: Result<PathBuf, String>,
    /// The camera and traversal every student was measured with.
    pub camera: Camera,
    pub trace: TraceOptions,
    /// What the ranks are by, in words.
    pub rank_by: String,
    /// The students, in the report's order (the order given to `grade`).
    pub students: Vec<GradedStudent>,
}

/// One student's row, as much of it as choosing them needs.
#[derive(Clone, Debug, PartialEq)]
pub struct GradedStudent {
    pub name: String,
    pub verdict: Verdict,
    /// Place among the correct submissions (1 = best).
    pub rank: Option<usize>,
    /// Every "good" threshold of the rubric met (correct submissions only).
    pub good: Option<bool>,
    /// The first root cause, or why nothing was read; empty when correct.
    pub reason: String,
    /// The dump, where it is now: `None` when the report has none for them (an empty folder),
    /// `Err` when the file named is not found (the message names it).
    pub dump: Option<Result<PathBuf, String>>,
    /// The layout the grader traced their tree in; `None` when it could not be traced (broken
    /// structure, another mesh, an unreadable file), and then there is nothing to show but the
    /// reason.
    pub layout: Option<Layout>,
    /// Their tree's SAH cost over bvhscope's SAH tree's in the same layout.
    pub versus_sah: Option<f64>,
}

impl GradedStudent {
    /// The dump to import, or why there is none to show (the reason the report gives, or the
    /// file that is not there).
    pub fn openable(&self) -> Result<&Path, String> {
        let why = || if self.reason.is_empty() { self.verdict.label().to_string() } else { self.reason.clone() };
        match (&self.dump, self.layout) {
            (Some(Ok(path)), Some(_)) => Ok(path),
            (Some(Err(missing)), Some(_)) => Err(missing.clone()),
            _ => Err(why()),
        }
    }
}

/// The fields of `grade.json` read here (the rest is for the page and for scripts).
#[derive(Deserialize)]
struct ReportJson {
    mesh: String,
    camera: Camera,
    trace: TraceOptions,
    rank_by: String,
    students: Vec<StudentJson>,
}

#[derive(Deserialize)]
struct StudentJson {
    name: String,
    dump: Option<String>,
    verdict: Verdict,
    reason: String,
    rank: Option<usize>,
    good: Option<bool>,
    quality: Option<QualityJson>,
    versus_sah: Option<VersusJson>,
}

#[derive(Deserialize)]
struct QualityJson {
    layout: String,
}

#[derive(Deserialize)]
struct VersusJson {
    sah_cost: Option<f64>,
}

impl GradeReport {
    /// Read the report at `path`: a `grade.json`, or the report folder holding one.
    pub fn read(path: &Path) -> Result<GradeReport, GradeError> {
        let file = if path.is_dir() { path.join(JSON_FILE) } else { path.to_path_buf() };
        let (f, _) = crate::files::open_regular(&file)?;
        let fail = |message: String| GradeError::Report { path: file.clone(), message };
        let bytes = crate::files::read_limited(f, MAX_BYTES)
            .map_err(|source| crate::files::FileError::Read { path: file.clone(), source })?
            .ok_or_else(|| fail(format!("more than {} MB: not a grade report", MAX_BYTES >> 20)))?;
        let value: serde_json::Value =
            serde_json::from_slice(&bytes).map_err(|e| fail(format!("not a grade report: broken JSON: {e}")))?;
        // The format and version first: a future report is named as such, not as broken.
        match value.get("format").and_then(|f| f.as_str()) {
            Some(FORMAT) => {}
            Some(other) => return Err(fail(format!("not a bvhscope grade report: its format is \"{other}\""))),
            None => return Err(fail(format!("not a bvhscope grade report: no \"format\": \"{FORMAT}\""))),
        }
        match value.get("version").and_then(|v| v.as_u64()) {
            Some(v) if v == VERSION as u64 => {}
            Some(v) => {
                return Err(fail(format!("version {v} of the {FORMAT} format; this bvhscope reads version {VERSION}")))
            }
            None => return Err(fail(format!("no whole-number \"version\" (this bvhscope reads version {VERSION})"))),
        }
        let r = ReportJson::deserialize(value).map_err(|e| fail(format!("not a readable grade report: {e}")))?;
        let folder = file.parent().unwrap_or(Path::new(".")).to_path_buf();
        let students = r
            .students
            .into_iter()
            .map(|s| GradedStudent {
                dump: s.dump.as_deref().map(|d| resolve(d, &folder, &format!("{}'s dump", s.name))),
                layout: s.quality.and_then(|q| Layout::ALL.into_iter().find(|l| l.name() == q.layout)),
                versus_sah: s.versus_sah.and_then(|v| v.sah_cost),
                name: s.name,
                verdict: s.verdict,
                reason: s.reason,
                rank: s.rank,
                good: s.good,
            })
            .collect();
        Ok(GradeReport {
            mesh: resolve(&r.mesh, &folder, "the mesh"),
            mesh_given: r.mesh,
            camera: r.camera,
            trace: r.trace,
            rank_by: r.rank_by,
            students,
            file,
        })
    }
}

/// `given`, a path as `grade` was given it, where it is now: as given, else from the report
/// folder's parent, else from the folder; `Err` names `what` and every place looked in.
fn resolve(given: &str, folder: &Path, what: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(given);
    let mut tried = vec![path.clone()];
    if path.is_relative() {
        if let Some(parent) = folder.parent() {
            tried.push(parent.join(&path));
        }
        tried.push(folder.join(&path));
    }
    tried.dedup();
    if let Some(found) = tried.iter().find(|p| p.is_file()) {
        return Ok(found.clone());
    }
    let places: Vec<String> = tried.iter().map(|p| p.display().to_string()).collect();
    Err(format!("{what} {given} is not found (looked for {})", places.join(", ")))
}

/// Whether `path` looks like a grade report rather than a mesh, a scene or a dump (what a file
/// dropped on the app is taken for): a report folder, or the format's name in its first kilobytes.
pub fn is_report(path: &Path) -> bool {
    use std::io::Read;
    if path.is_dir() {
        return path.join(JSON_FILE).is_file();
    }
    let Ok((file, _)) = crate::files::open_regular(path) else { return false };
    let mut head = Vec::new();
    if file.take(4096).read_to_end(&mut head).is_err() {
        return false;
    }
    let name = format!("\"{FORMAT}\"");
    head.windows(name.len()).any(|w| w == name.as_bytes())
}
