//! The one error every command reports, in one line, before exiting with code 2.

use crate::mesh::MeshError;
use crate::scene::SceneError;
use std::path::PathBuf;

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

impl From<SceneError> for CliError {
    fn from(e: SceneError) -> Self {
        match e {
            SceneError::Mesh(m) => CliError::Mesh(m),
            other => CliError::Scene(other),
        }
    }
}
