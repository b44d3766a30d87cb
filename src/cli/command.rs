//! The command line as parsed (`Cli`, `Command`) and run: each subcommand's arguments and its `run`.

use crate::cli::error::CliError;
use crate::cli::{check, compare, export_bvh, grade, inspect, lesson, render, replay, stats, trace};
use clap::{Parser, Subcommand};
use std::path::PathBuf;

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
