//! The triangle mesh we render, and loading it from OBJ files.

pub mod generate;
#[allow(clippy::module_inception)]
mod mesh;
mod obj;
mod obj_lines;
mod obj_parallel;

pub use mesh::{Mesh, MeshGroup, SurfaceInteraction};
pub use obj::{load_obj, parse_obj, write_obj, LoadReport, MeshError, MAX_COORDINATE};
