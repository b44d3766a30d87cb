//! The command line: `render`, `stats` and `compare`, over the same core as the app.
//! Errors print one line naming the file and the problem and exit with code 2.

mod args;
mod compare;
mod progress;
mod render;
mod stats;

pub use args::{parse_camera, parse_size, BuildArgs};
pub use compare::{compare_rows, CompareRow};

use crate::mesh::MeshError;
use crate::scene::{load_any, Loaded, SceneError};
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
    /// A mesh (.obj) or scene (.json) to open in the desktop app.
    pub file: Option<PathBuf>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Ray-cast a mesh to a PNG: normals, depth, or a heatmap of traversal work.
    Render(render::RenderArgs),
    /// Print the statistics of the BVH built over a mesh.
    Stats(stats::StatsArgs),
    /// Build every strategy and compare them (and a linear scan) on the same rays.
    Compare(compare::CompareArgs),
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
}

/// Load a mesh or a scene with a spinner when it takes over a second, and print what was skipped.
pub(crate) fn load_mesh(path: &Path) -> Result<Loaded, CliError> {
    let label = format!("loading {}", path.display());
    let loaded = progress::with_spinner(&label, || load_any(path))?;
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
    if let Some(note) = loaded.scene.as_ref().and_then(|s| s.note.as_ref()) {
        eprintln!("about this scene: {note}");
    }
    Ok(loaded)
}

/// Build what `build` asks for over a loaded file; for two levels an OBJ is one placement of itself.
pub(crate) fn build_scene(loaded: &Loaded, build: &crate::bvh::SceneBuild) -> crate::bvh::SceneBvh {
    let single;
    let instances = match &loaded.instances {
        Some(i) => i,
        None => {
            single = crate::scene::SceneInstances {
                meshes: vec![std::sync::Arc::new(loaded.mesh.clone())],
                placements: vec![(0, glam::Affine3A::IDENTITY)],
            };
            &single
        }
    };
    let meshes = instances.mesh_refs();
    let label = if build.top.is_some() { "building the two-level BVH" } else { "building the BVH" };
    progress::with_spinner(label, || {
        let control = crate::work::WorkControl::new();
        match crate::bvh::SceneBvh::build(&loaded.mesh, Some((&meshes, &instances.placements)), build, &control) {
            Ok(b) => b,
            Err(crate::work::Cancelled) => unreachable!("nobody else holds this control"),
        }
    })
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
        Command::Stats(a) => stats::run(&a),
        Command::Compare(a) => compare::run(&a),
    }
}
