//! Grading a class: every student's BVH dump checked (`explain::check`) and measured next to
//! bvhscope's own trees on the same mesh and camera, ranked within the class, and written as a
//! CSV, a JSON and one self-contained HTML page a teacher can send each student.
//!
//! - `discover`: what was handed in: a dump file, or a folder holding one dump, per student;
//! - `reference`: bvhscope's trees (SAH binned always, the rubric's other strategies), built and
//!   measured once per layout that the class uses, then dropped: only their figures and the SAH
//!   tree's frame (for the difference images) are kept;
//! - `measure`: the figures of one traced tree (SAH cost, EPO, work per ray, single-ray time…);
//! - `evaluate`: one submission read, checked, measured and drawn, then dropped: memory holds one
//!   submission at a time besides the references, whatever the size of the class;
//! - `rank`: the order within the class, by a key the rubric names (`rubric`);
//! - `report`: the report folder (`ReportDir`: the files service's `files::ReportDir` of the kind
//!   `GRADE`, whose list of the report's files says what a later run into the folder may
//!   replace) and what is written there: `table` (the CSV's records), `json`, `html` (with
//!   `page`'s style and script);
//! - `report_file`: `grade.json` read back (`GradeReport`), its paths found again, for the app.
//!
//! One broken file never stops the run: every failure of a submission becomes its row's verdict
//! and reason, a panic included (`evaluate`).

mod discover;
mod evaluate;
#[cfg(test)]
mod fair_tests;
#[cfg(test)]
mod grade_tests;
pub(crate) mod html;
mod json;
mod measure;
#[cfg(test)]
mod out_tests;
mod page;
mod rank;
mod reference;
mod report;
mod report_file;
mod rubric;
mod table;

pub use discover::{discover, Submission};
pub use evaluate::evaluate;
pub use html::write_html;
pub use json::document;
pub use measure::{Quality, Timing};
pub use rank::{rank, RankBy};
pub use reference::{ReferenceTree, References};
pub use report::{ReportDir, CSV_FILE, GRADE, HTML_FILE, IMAGES_DIR, JSON_FILE, MANIFEST_FILE};
pub use report_file::{is_report, GradeReport, GradedStudent};
pub use rubric::{Good, Rubric};
pub use table::csv_records;

use crate::bvh::{BuildParams, TraceOptions};
use crate::explain::check::Group;
use crate::files::FileError;
use crate::mesh::Mesh;
use crate::render::Camera;
use crate::work::WorkControl;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The version of `grade.json`'s layout (`json::document`), for readers such as the app
/// (`report_file`).
pub const FORMAT: &str = "bvhscope-grade";
pub const VERSION: u32 = 1;

/// Why a class cannot be graded at all (a submission's own trouble is its row, never this).
#[derive(Debug, thiserror::Error)]
pub enum GradeError {
    #[error(transparent)]
    File(#[from] FileError),
    #[error("{}: {field}: {message}", .path.display())]
    Rubric { path: PathBuf, field: String, message: String },
    #[error("{}: {message}", .path.display())]
    Output { path: PathBuf, message: String },
    /// A `grade.json` that cannot be read back (`GradeReport::read`).
    #[error("{}: {message}", .path.display())]
    Report { path: PathBuf, message: String },
}

/// What every submission is graded against.
pub struct Setup<'a> {
    pub mesh: &'a Mesh,
    /// The file the dumps are checked against: the OBJ, or a scene's one mesh file (a dump's
    /// `mesh` line names that file, and `check::wrong_mesh` compares the names).
    pub mesh_path: &'a Path,
    /// The mesh or scene as given on the command line (captions, the JSON).
    pub given_path: &'a Path,
    pub camera: Camera,
    /// Random rays the checker traces besides the camera's primary rays.
    pub rays: u64,
    /// Primary rays timed per tree, one at a time on one thread.
    pub time_rays: usize,
    pub trace: TraceOptions,
    /// The references' build settings (their strategy and layout are set per reference).
    pub params: BuildParams,
    /// Largest dump read, in bytes after decompression (`dump::max_bytes`).
    pub dump_limit: u64,
    /// The most time one submission may take; past it, its row says so and the class goes on.
    pub max_seconds: f64,
    pub rubric: Rubric,
    /// The heatmaps' rays after the camera's (`--ray-kind`): the figures and the ranks stay of
    /// the camera's rays, the one yardstick; only the images show these. `None`: camera rays.
    pub secondary: Option<crate::render::SecondaryRays>,
}

/// What the checker and the rubric say of a submission.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// No defect in a check the rubric requires (warnings allowed).
    Correct,
    /// Defects in a required check.
    Defects,
    /// The dump names another mesh, or numbers triangles past this one, and has defects.
    WrongMesh,
    /// The file cannot be read as a dump (named with the reason).
    Unreadable,
    /// No dump to read: an empty folder, a folder of several dumps, a path that is not there.
    NoDump,
    /// Checking or measuring it took longer than the limit (`Setup::max_seconds`): a tree whose
    /// boxes all overlap makes every ray visit every node.
    TimedOut,
}

impl Verdict {
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Correct => "correct",
            Verdict::Defects => "defects",
            Verdict::WrongMesh => "wrong mesh",
            Verdict::Unreadable => "unreadable",
            Verdict::NoDump => "no dump",
            Verdict::TimedOut => "timed out",
        }
    }
}

/// A finding of the checker as the report lists it: the line `check` prints (its first few
/// cases), what it names, and how many cases it has in all. Kept instead of the finding itself:
/// a finding lists every case, thousands for a wrong box, and a class holds a hundred rows.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FindingLine {
    pub group: Group,
    pub defect: bool,
    /// Whether its group is one the rubric requires (a defect elsewhere does not fail).
    pub required: bool,
    pub node: Option<u32>,
    pub triangle: Option<u32>,
    pub line: String,
    pub cases: usize,
}

/// Each measured figure over the same figure of bvhscope's SAH tree in the same layout (1 = as
/// good, below 1 = better): what ranks and the rubric's "good" thresholds compare, so trees of
/// different layouts are held to their own reference.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct VersusSah {
    pub sah_cost: f64,
    pub nodes_per_ray: f64,
    pub tri_tests_per_ray: f64,
    pub trace_time: f64,
}

/// The images of a submission, as paths relative to the report folder.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Images {
    /// Nodes visited per pixel, on the class's scale.
    pub visits: String,
    /// The submission minus bvhscope's SAH tree, per pixel (blue: fewer nodes, red: more).
    pub difference: String,
}

/// One student's row.
#[derive(Clone, Debug, Serialize)]
pub struct GradeRow {
    /// Order of the submissions as given (after discovery).
    pub index: usize,
    /// The student, by the file or folder handed in.
    pub name: String,
    /// A file name for the student's images (unique in the class).
    pub slug: String,
    /// The file or folder as given.
    #[serde(serialize_with = "lossy")]
    pub submission: PathBuf,
    /// The dump read (the file itself, or the one in the folder).
    #[serde(serialize_with = "lossy_opt")]
    pub dump: Option<PathBuf>,
    pub verdict: Verdict,
    /// The first root cause (the first defect of a required check, or why nothing was read);
    /// empty when correct.
    pub reason: String,
    pub defects: usize,
    pub warnings: usize,
    /// The checker's findings, the first twelve of each group.
    pub findings: Vec<FindingLine>,
    /// Findings in all (`findings` leaves the rest of a long group out).
    pub findings_total: usize,
    /// Rays the checker traced.
    pub rays_checked: u64,
    /// Of them, the rays the student's tree hit differently from the linear scan.
    pub wrong_rays: u64,
    pub quality: Option<Quality>,
    pub versus_sah: Option<VersusSah>,
    /// Place in the class among the correct submissions (1 = best), by the rubric's key.
    pub rank: Option<usize>,
    /// Whether every "good" threshold of the rubric is met (correct submissions only).
    pub good: Option<bool>,
    /// The rubric's "good" thresholds missed, in words (not rays: `wrong_rays` counts those).
    pub misses: Vec<String>,
    pub images: Option<Images>,
    /// What else went wrong that is not the student's (an image that could not be written).
    pub notes: Vec<String>,
    /// Seconds spent on this submission.
    pub seconds: f64,
}

impl GradeRow {
    /// A row for a submission that was not checked: `verdict` and why.
    pub fn not_checked(sub: &Submission, verdict: Verdict, reason: String) -> GradeRow {
        GradeRow {
            index: sub.index,
            name: sub.name.clone(),
            slug: sub.slug.clone(),
            submission: sub.path.clone(),
            dump: sub.dump.clone(),
            verdict,
            reason,
            defects: 0,
            warnings: 0,
            findings: Vec::new(),
            findings_total: 0,
            rays_checked: 0,
            wrong_rays: 0,
            quality: None,
            versus_sah: None,
            rank: None,
            good: None,
            misses: Vec::new(),
            images: None,
            notes: Vec::new(),
            seconds: 0.0,
        }
    }
}

/// A path as text, any bytes that are not UTF-8 replaced (serde refuses such a path, and a
/// student's file name must not break the report).
fn lossy<S: serde::Serializer>(p: &Path, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&p.to_string_lossy())
}

fn lossy_opt<S: serde::Serializer>(p: &Option<PathBuf>, s: S) -> Result<S::Ok, S::Error> {
    match p {
        Some(p) => lossy(p, s),
        None => s.serialize_none(),
    }
}

/// A graded class: the rows in the order given, and what they were measured against.
pub struct Graded {
    pub rows: Vec<GradeRow>,
    pub references: References,
    /// Seconds the grading took: the references built and timed (`References::seconds`), then
    /// the submissions. The one time the terminal, the page and grade.json give.
    pub seconds: f64,
}

/// Grade every submission, one at a time, then rank them. `references` is built before
/// (`References::new`: the caller shows its own progress) and grows a layout when a submission
/// needs one. `control` counts submissions done (its total is their number), for a progress bar;
/// `on_row` sees each row as it is finished.
pub fn grade_class(
    setup: &Setup,
    mut references: References,
    submissions: &[Submission],
    out: &ReportDir,
    control: &WorkControl,
    mut on_row: impl FnMut(&GradeRow),
) -> Graded {
    let start = std::time::Instant::now();
    let before = references.seconds;
    control.set_total(submissions.len() as u64);
    let mut rows = Vec::with_capacity(submissions.len());
    for sub in submissions {
        let row = evaluate(sub, setup, &mut references, out);
        on_row(&row);
        rows.push(row);
        control.add_done(1);
    }
    rank(&mut rows, setup.rubric.rank_by);
    Graded { rows, references, seconds: before + start.elapsed().as_secs_f64() }
}
