//! The command line: `render`, `stats` and `compare`, over the same core as the app.
//! Errors print one line naming the file and the problem and exit with code 2.

mod args;
pub mod check;
mod compare;
pub mod device;
mod export_bvh;
mod grade;
pub mod inspect;
pub mod lesson;
mod progress;
pub(crate) mod rays;
pub(crate) mod render;
pub mod replay;
pub mod stats;
pub mod trace;

pub use crate::gpu_path::{Device, GpuNodes};
pub use args::{parse_camera, parse_size, BuildArgs};
pub use compare::{compare_rows, CompareRow};

use crate::mesh::MeshError;
use crate::scene::{Scene, SceneBuildError, SceneError};
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};

#[derive(Parser, Debug)]
#[command(
    name = "bvhscope",
    version,
    about = "Makes bounding volume hierarchies visible: build a BVH with a chosen split strategy, ray-cast it, and see what each ray costs."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// A mesh (.obj, .ply, .off, .stl, .gltf, .glb), scene (.json) or lesson (.json with "steps") to open in the desktop app.
    pub file: Option<PathBuf>,
    /// A BVH dump (bvhscope-bvh) to import for it in the app, as File ▸ Open BVH does.
    #[arg(long, value_name = "DUMP")]
    pub bvh: Option<PathBuf>,
}

/// Write a command's output to stdout. A reader that stops early (`| head`) closes the pipe: the
/// rest is not wanted, so the program ends quietly, with the status a Unix tool killed by SIGPIPE
/// has (141), where `print!` would panic. Any other failure (a full disk, `> /dev/full`) loses the
/// output: one line says so and the program exits with 2, never 0 ("correct") over an answer
/// nobody got.
pub fn out(text: &str) {
    use std::io::Write;
    let mut stdout = std::io::stdout().lock();
    match stdout.write_all(text.as_bytes()).and_then(|_| stdout.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => std::process::exit(141),
        Err(e) => {
            eprintln!("error: cannot write to standard output: {e}");
            std::process::exit(2)
        }
        Ok(()) => {}
    }
}

/// `text` safe to print on a terminal: control characters (an escape sequence in a student's file
/// name would retitle the terminal or recolour the table, a newline break a row) and the
/// characters that reorder a line's display written as escapes (`\u{1b}`, `\n`). File names and
/// whatever else came from outside pass through this on their way to stdout or stderr.
pub fn printable(text: &str) -> String {
    let mut o = String::with_capacity(text.len());
    for c in text.chars() {
        let reorders = matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
        if c.is_control() || reorders {
            o.extend(c.escape_default());
        } else {
            o.push(c);
        }
    }
    o
}

impl Cli {
    /// Parse a command line given as words, the program's name first, as `main` does (the app's
    /// tests run the commands it shows).
    pub fn from_words<I: IntoIterator<Item = T>, T: Into<std::ffi::OsString> + Clone>(
        words: I,
    ) -> Result<Cli, clap::Error> {
        Cli::try_parse_from(words)
    }
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Ray-cast a mesh to a PNG: normals, depth, or a heatmap of traversal work.
    Render(render::RenderArgs),
    /// Print the statistics of the BVH built over a mesh.
    Stats(stats::StatsArgs),
    /// Build every strategy and compare them (and a linear scan) on the same rays.
    Compare(compare::CompareArgs),
    /// One ray's walk through the BVH, step by step (a pixel of the camera, or a typed ray).
    Trace(trace::TraceArgs),
    /// One node of the BVH explained: its figures, and where each strategy would split it.
    Inspect(inspect::InspectArgs),
    /// The build played back split by split, as an animated PNG and a table of the SAH cost.
    Replay(replay::ReplayArgs),
    /// Check a BVH written by another program against the mesh and the linear scan (exit 0: correct,
    /// 1: defects, 2: unreadable).
    Check(check::CheckArgs),
    /// Write a built-in strategy's tree in the bvhscope-bvh format (the binary tree unless --layout
    /// wide4 or wide8 is given).
    ExportBvh(export_bvh::ExportBvhArgs),
    /// Grade a class: check every student's BVH dump, measure it next to bvhscope's trees, rank
    /// them, and write a report folder (HTML, CSV, JSON).
    Grade(grade::GradeArgs),
    /// Render a lesson (a teacher's steps through a BVH) to a handout folder: each step's picture
    /// as `render` draws it, and one HTML page with the captions and commands; or check it.
    Lesson(lesson::LessonArgs),
}

/// An error the CLI reports in one line before exiting with code 2.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    #[error(transparent)]
    Mesh(#[from] MeshError),
    #[error(transparent)]
    Scene(SceneError),
    #[error("{0}")]
    Usage(String),
    #[error("{}: cannot write: {source}", .path.display())]
    Write { path: PathBuf, source: std::io::Error },
    #[error(transparent)]
    File(#[from] crate::files::FileError),
    /// Standard output could not be written (a full disk, a closed pipe).
    #[error("cannot write to standard output: {0}")]
    Stdout(std::io::Error),
    /// `check` found defects (reported on stdout): exit code 1.
    #[error("{0} defects")]
    Defects(usize),
}

/// Load a mesh or a scene with a spinner when it takes over a second, and print what was skipped
/// and the first sentence of the scene's note.
pub(crate) fn load_mesh(path: &Path) -> Result<Scene, CliError> {
    load_noted(path, false)
}

/// `load_mesh`, with the scene's whole note (`stats`, the command that describes a scene; a
/// paragraph before every render's one line of output buried that line).
pub(crate) fn load_noted(path: &Path, whole_note: bool) -> Result<Scene, CliError> {
    let label = format!("loading {}", path.display());
    let loaded = progress::with_spinner(&label, || Scene::open(path))?;
    if loaded.report.degenerate_skipped > 0 {
        eprintln!(
            "note: {}: {} degenerate (zero-area) triangles skipped",
            path.display(),
            loaded.report.degenerate_skipped
        );
    }
    for w in &loaded.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    if let Some(note) = loaded.desc.as_ref().and_then(|s| s.note.as_ref()) {
        match crate::explain::words::first_sentence(note) {
            Some(first) if !whole_note => {
                eprintln!("about this scene: {first} (the whole note: bvhscope stats {})", path.display())
            }
            _ => eprintln!("about this scene: {note}"),
        }
    }
    Ok(loaded)
}

/// Build what `build` asks for over a loaded file: on `gpu` when there is one and it builds this
/// (`gpu_path::builds_on_gpu`; the phases come back too), else on the CPU, where for two levels
/// an OBJ is one placement of itself. One level over a scene too large to flatten is refused
/// (`Scene::check_one_level`), before anything is allocated.
pub(crate) fn build_scene(
    gpu: Option<&bvhscope_gpu::Gpu>,
    scene: &Scene,
    build: &crate::bvh::SceneBuild,
) -> Result<(crate::bvh::SceneBvh, Option<device::GpuBuild>), CliError> {
    if build.top.is_none() {
        scene.check_one_level().map_err(|e| CliError::Usage(format!("{e} (--two-level)")))?;
    }
    if let Some(gpu) = gpu {
        if let Some(built) = device::gpu_build_scene(gpu, scene, build)? {
            return Ok((built.0, Some(built.1)));
        }
    }
    let label = if build.top.is_some() { "building the two-level BVH" } else { "building the BVH" };
    progress::with_spinner(label, || match scene.build(build, &crate::work::WorkControl::new()) {
        Ok(b) => Ok(b),
        Err(SceneBuildError::Scene(e)) => Err(e.into()),
        Err(SceneBuildError::Cancelled) => unreachable!("nobody else holds this control"),
    })
    .map(|bvh| (bvh, None))
}

impl From<SceneError> for CliError {
    fn from(e: SceneError) -> Self {
        match e {
            SceneError::Mesh(m) => CliError::Mesh(m),
            other => CliError::Scene(other),
        }
    }
}

/// Run a parsed subcommand.
pub fn run(command: Command) -> Result<(), CliError> {
    match command {
        Command::Render(a) => render::run(&a),
        Command::Trace(a) => trace::run(&a),
        Command::Inspect(a) => inspect::run(&a),
        Command::Replay(a) => replay::run(&a),
        Command::Check(a) => check::run(&a),
        Command::ExportBvh(a) => export_bvh::run(&a),
        Command::Grade(a) => grade::run(&a),
        Command::Lesson(a) => lesson::run(&a),
        Command::Stats(a) => stats::run(&a),
        Command::Compare(a) => compare::run(&a),
    }
}
