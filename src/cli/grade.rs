//! `bvhscope grade MESH SUBMISSIONS... [--out DIR] [--rubric FILE]`: a class's BVH dumps, each
//! checked, measured next to bvhscope's own trees, ranked, and written as a report folder
//! (`explain::grade` does the work; this file reads the options and shows the progress).
//! Exit 0 once the report is written, whatever the students' verdicts; 2 when it cannot be.

use super::args::{BuildArgs, DumpLimit, ViewArgs};
use super::progress;
use crate::cli::error::CliError;
use crate::cli::load::load_mesh;
use crate::cli::print::printable;
use crate::explain::check::MAX_RAYS;
use crate::explain::grade::{
    csv_records, discover, document, grade_class, write_html, GradeError, GradeRow, Graded, References, ReportDir,
    Rubric, Setup, CSV_FILE, HTML_FILE, JSON_FILE,
};
use crate::work::WorkControl;
use clap::Args;
use std::fmt::Write as _;
use std::path::PathBuf;

/// The frame's size unless told: small enough that a class of a hundred takes minutes, the
/// scene camera's shape kept (`check`'s).
const DEFAULT_SIZE: (u32, u32) = super::check::CHECK_SIZE;
use super::check::fit;
const DEFAULT_RAYS: u64 = 100_000;
const DEFAULT_TIME_RAYS: u32 = 16_384;

#[derive(Args, Debug)]
pub struct GradeArgs {
    #[arg(help = crate::cli::args::MESH_HELP)]
    pub mesh: PathBuf,
    /// The submissions: each a dump (.json, .json.gz, .txt) or a folder holding one dump, the
    /// student named by the file or folder (`class/*` grades a whole class).
    #[arg(required = true, value_name = "SUBMISSIONS")]
    pub submissions: Vec<PathBuf>,
    /// The report's folder (made if needed): grade.html, grade.csv, grade.json, images/ and
    /// grade-files.txt, their list. A folder that is not empty is replaced only when it holds
    /// nothing but what an earlier report listed there.
    #[arg(long, short, default_value = "grade-report")]
    pub out: PathBuf,
    /// A rubric (JSON): the checks required, thresholds for "good", the ranking key, the mesh,
    /// camera and rays. Without one: every check required, good within 10 % of the SAH tree's
    /// SAH cost, ranked by SAH cost.
    #[arg(long)]
    pub rubric: Option<PathBuf>,
    /// Random rays checked per submission, besides the frame's primary rays [default: the
    /// rubric's, else 100000].
    #[arg(long, value_parser = clap::value_parser!(u64).range(0..=MAX_RAYS))]
    pub rays: Option<u64>,
    /// Primary rays timed per tree, one at a time on one thread [default: the rubric's, else 16384].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub time_rays: Option<u32>,
    /// The most seconds one submission may take: a slower one is named as such and the class goes on.
    #[arg(long, default_value_t = 120.0, value_parser = parse_seconds)]
    pub max_seconds: f64,
    #[command(flatten)]
    pub dump_limit: DumpLimit,
    /// The frame (its size defaults to the rubric's, else the scene camera's within 480x360,
    /// else 480x270).
    #[command(flatten)]
    pub view_args: ViewArgs,
    /// The heatmaps' rays: with a secondary kind the images show those rays' work from each hit;
    /// the figures and the ranks stay the camera rays'.
    #[command(flatten)]
    pub ray_kind: super::rays::RayArgs,
    /// How the references are built and every tree traversed (their strategies are the rubric's).
    #[command(flatten)]
    pub build: BuildArgs,
}

fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if (0.1..=86400.0).contains(&v) => Ok(v),
        _ => Err(format!("'{s}' is not a number of seconds from 0.1 to 86400")),
    }
}

fn grade_err(e: GradeError) -> CliError {
    match e {
        GradeError::File(f) => CliError::File(f),
        other => CliError::Usage(other.to_string()),
    }
}

pub fn run(a: &GradeArgs) -> Result<(), CliError> {
    let b = &a.build;
    let refused =
        [(b.strategy.is_some(), "--strategy"), (b.layout.is_some(), "--layout"), (b.two_level, "--two-level")];
    if let Some((_, flag)) = refused.iter().find(|(given, _)| *given) {
        return Err(CliError::Usage(format!(
            "grade: {flag} does not apply: each dump is traced in its own layout, next to the rubric's reference strategies (\"references\")"
        )));
    }
    let rubric = match &a.rubric {
        Some(p) => Rubric::read(p).map_err(grade_err)?,
        None => Rubric::default(),
    };
    rubric.check_mesh(&a.mesh).map_err(grade_err)?;
    let subs = discover(&a.submissions);
    // Before anything is loaded: no report file may be an input.
    let mut inputs = vec![(a.mesh.clone(), "the mesh".to_string())];
    if let Some(r) = &a.rubric {
        inputs.push((r.clone(), "the rubric".into()));
    }
    for s in &subs {
        inputs.push((s.path.clone(), format!("the submission '{}'", s.name)));
        if let Some(d) = s.dump.as_ref().filter(|d| **d != s.path) {
            inputs.push((d.clone(), format!("the dump of '{}'", s.name)));
        }
    }
    let mut dir = ReportDir::prepare(&a.out, inputs).map_err(grade_err)?;
    let scene = load_mesh(&a.mesh)?;
    let mesh = scene.flat_mesh()?;
    // A scene of one mesh file: the dumps name that file, and are checked against it.
    let one_file = scene.desc.as_ref().filter(|d| d.meshes.len() == 1).map(|d| d.meshes[0].file.clone());
    let mesh_path = one_file.unwrap_or_else(|| a.mesh.clone());
    let size =
        a.view_args.size.or(rubric.size).or(scene.camera.map(|c| fit((c.width, c.height)))).unwrap_or(DEFAULT_SIZE);
    let base = rubric
        .camera
        .map(|c| crate::render::Camera {
            position: c.position,
            look_at: c.look_at,
            up: c.up,
            vfov_deg: c.vertical_fov,
            width: size.0,
            height: size.1,
        })
        .or(scene.camera);
    let view = ViewArgs { size: Some(size), ..a.view_args.clone() };
    let camera = view.camera(&scene.bounds(), base.as_ref())?;
    let setup = Setup {
        mesh: &mesh,
        mesh_path: &mesh_path,
        given_path: &a.mesh,
        camera,
        rays: a.rays.or(rubric.rays).unwrap_or(DEFAULT_RAYS),
        time_rays: a.time_rays.or(rubric.time_rays).unwrap_or(DEFAULT_TIME_RAYS) as usize,
        trace: b.trace_options(),
        params: b.params(scene.build.as_ref()),
        dump_limit: a.dump_limit.bytes(&mesh),
        max_seconds: a.max_seconds,
        rubric,
        secondary: a.ray_kind.secondary(a.ray_kind.one("grade")?, &scene.bounds(), &camera),
    };
    let refs = progress::with_spinner("building and timing the reference trees", || References::new(&setup));
    let control = WorkControl::new();
    let n = subs.len();
    // The bar shows on a terminal; elsewhere (a log, CI) a line per student says how it goes.
    let lines = !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let label = format!("grading {n} submissions");
    let graded = progress::with_bar(&label, &control, || {
        let mut done = 0;
        grade_class(&setup, refs, &subs, &dir, &control, |row| {
            done += 1;
            if lines {
                eprintln!("[{done}/{n}] {}: {} ({:.1} s)", printable(&row.name), row.verdict.label(), row.seconds);
            }
        })
    });
    write_report(&setup, &graded, &dir)?;
    dir.publish().map_err(grade_err)?;
    super::out(&summary(&graded.rows));
    // The grading's one time, as the page and grade.json give it (it was this command's own,
    // the report's writing included, and differed from the page's).
    eprintln!(
        "wrote {} ({}, {} and images/): {n} submissions graded in {:.1} s",
        printable(&dir.file(HTML_FILE).display().to_string()),
        CSV_FILE,
        JSON_FILE,
        graded.seconds
    );
    Ok(())
}

/// The CSV (by the `csv` crate: RFC 4180 quoting), the JSON and the HTML page.
fn write_report(setup: &Setup, graded: &Graded, dir: &ReportDir) -> Result<(), CliError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for rec in csv_records(&graded.rows) {
        w.write_record(&rec).map_err(|e| CliError::Usage(format!("{CSV_FILE}: {e}")))?;
    }
    let bytes = w.into_inner().map_err(|e| CliError::Usage(format!("{CSV_FILE}: {e}")))?;
    dir.write(CSV_FILE, &bytes)?;
    let json = serde_json::to_vec_pretty(&document(setup, graded))
        .map_err(|e| CliError::Usage(format!("{JSON_FILE}: {e}")))?;
    dir.write(JSON_FILE, &json)?;
    write_html(setup, graded, dir)?;
    Ok(())
}

/// The class on stdout: rank, student, verdict and the main figures, in the order given.
fn summary(rows: &[GradeRow]) -> String {
    let w = rows.iter().map(|r| printable(&r.name).chars().count()).max().unwrap_or(7).clamp(7, 40);
    let mut o = format!(
        "{:>4}  {:<w$}  {:<10}  {:>9}  {:>8}  {:>11}  {:>8}  first cause\n",
        "rank", "student", "verdict", "SAH cost", "vs SAH", "nodes / ray", "speed-up"
    );
    for r in rows {
        let q = r.quality.as_ref();
        // Escaped before they are cut to width: an escape sequence cut in half is still one.
        let name: String = printable(&r.name).chars().take(w).collect();
        let cause: String = printable(&r.reason).chars().take(100).collect();
        let _ = writeln!(
            o,
            "{:>4}  {:<w$}  {:<10}  {:>9}  {:>8}  {:>11}  {:>8}  {cause}",
            r.rank.map_or("–".into(), |k| k.to_string()),
            name,
            r.verdict.label(),
            q.map_or("–".into(), |q| format!("{:.2}", q.sah_cost)),
            r.versus_sah.map_or("–".into(), |v| format!("{:+.1}%", (v.sah_cost - 1.0) * 100.0)),
            q.map_or("–".into(), |q| format!("{:.2}", q.nodes_per_ray)),
            q.map_or("–".into(), |q| format!("{:.0}x", q.speedup_over_linear)),
        );
    }
    o
}
