//! The triangle mesh we render, and loading it from OBJ, PLY, OFF and STL files (`formats`).

mod assemble;
mod error;
mod formats;
pub mod generate;
mod gltf;
mod gltf_access;
#[allow(clippy::module_inception)]
mod mesh;
mod obj;
mod obj_lines;
mod obj_numbering;
mod obj_parallel;
mod off;
mod ply;
mod stl;
mod surface;

pub use error::{MeshError, MAX_COORDINATE};
pub use formats::{load_mesh, MeshFormat};
pub use gltf::{is_gltf, load_gltf, GltfScene};
pub use mesh::{Mesh, MeshGroup, SurfaceInteraction};
pub(crate) use obj::decode_text;
pub use obj::{load_obj, parse_obj, read_user_file, write_obj, LoadReport};
pub use surface::Surface;
