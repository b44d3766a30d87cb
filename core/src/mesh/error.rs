//! Why a mesh could not be loaded: one error type, every message starting with the file name and,
//! where known, the line.

use crate::files::FileError;
use std::fmt;
use std::path::PathBuf;

/// Why a mesh could not be loaded. Every message starts with the file name.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file could not be opened or read (not found, a directory, not a regular file, an I/O
    /// error): the file services' own error.
    #[error(transparent)]
    File(#[from] FileError),
    #[error("{}: line {line}: not a text file (binary data: a NUL byte)", .path.display())]
    NotText { path: PathBuf, line: usize },
    #[error("{}{}: {message}", .path.display(), LineSuffix(*.line))]
    Parse { path: PathBuf, line: Option<usize>, message: String },
    #[error("{}{}: {message}", .path.display(), LineSuffix(*.line))]
    IndexOutOfRange { path: PathBuf, line: Option<usize>, message: String },
    #[error("{}{}: {what} has a NaN or infinite coordinate", .path.display(), LineSuffix(*.line))]
    NonFinite { path: PathBuf, line: Option<usize>, what: &'static str },
    #[error("{}{}: a vertex coordinate exceeds ±{MAX_COORDINATE:e}, too large to trace in single precision (scale the mesh down)", .path.display(), LineSuffix(*.line))]
    TooLarge { path: PathBuf, line: Option<usize> },
    #[error("{}: no triangles{}", .path.display(), if *.degenerate > 0 { format!(" (all {} faces are degenerate)", .degenerate) } else { String::new() })]
    NoTriangles { path: PathBuf, degenerate: usize },
}

impl MeshError {
    /// The line the error points at, when known.
    pub fn line(&self) -> Option<usize> {
        match self {
            MeshError::NotText { line, .. } => Some(*line),
            MeshError::Parse { line, .. }
            | MeshError::IndexOutOfRange { line, .. }
            | MeshError::NonFinite { line, .. }
            | MeshError::TooLarge { line, .. } => *line,
            _ => None,
        }
    }
}

struct LineSuffix(Option<usize>);

impl fmt::Display for LineSuffix {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(n) => write!(f, ": line {n}"),
            None => Ok(()),
        }
    }
}

/// Largest coordinate magnitude accepted. The triangle tests multiply three coordinates
/// together (edge functions times depth), so beyond about 1e12 single precision overflows and
/// rays silently miss; 1e10 leaves a wide margin.
pub const MAX_COORDINATE: f32 = 1e10;
