//! Meshes as people have them: OBJ, PLY, OFF and STL, each read into the one `Mesh`, recognised
//! by their content (a PLY starts with `ply`, an OFF with its `OFF` keyword, a binary STL's size
//! is its triangle count's) and, for STL's ASCII form, by its name. Every reader keeps the file's
//! triangles in file order, numbered as the file has them (polygons fan-triangulated, strips
//! unrolled), so a BVH dump written for the same file names the same triangles; every reader
//! bounds what it allocates by the file's size, whatever its header claims.

use super::assemble::bad;
use crate::mesh::error::MeshError;
use crate::mesh::mesh::Mesh;
use crate::mesh::obj::{load_obj, read_user_file, LoadReport};
use std::path::Path;
use std::time::Instant;

/// The formats a mesh file may be in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    Obj,
    Ply,
    Off,
    Stl,
}

impl MeshFormat {
    /// The file name endings each format is known by (the open dialog's filter).
    pub const EXTENSIONS: [&'static str; 6] = ["obj", "ply", "off", "stl", "gltf", "glb"];

    /// The format of `bytes` read from `path`: by content where the format has a mark, else by
    /// the name's ending, else OBJ.
    pub fn of(path: &Path, bytes: &[u8]) -> MeshFormat {
        let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
        if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") {
            return MeshFormat::Ply;
        }
        if super::stl::is_binary(bytes) {
            return MeshFormat::Stl;
        }
        match ext.as_deref() {
            Some("stl") => MeshFormat::Stl,
            Some("off") => MeshFormat::Off,
            Some("ply") => MeshFormat::Ply,
            _ if super::off::has_header(bytes) => MeshFormat::Off,
            _ => MeshFormat::Obj,
        }
    }
}

/// Load a mesh file of any of the formats (`MeshFormat`).
pub fn load_mesh(path: impl AsRef<Path>) -> Result<(Mesh, LoadReport), MeshError> {
    let path = path.as_ref();
    let start = Instant::now();
    if super::is_gltf(path) {
        return Err(bad(
            path,
            "the file",
            "a glTF file is a scene of its own (its nodes place its meshes): open it as the scene, not as one mesh",
        ));
    }
    let bytes = read_user_file(path)?;
    let (mesh, mut report) = match MeshFormat::of(path, &bytes) {
        MeshFormat::Obj => return load_obj(path),
        MeshFormat::Ply => super::ply::parse(path, &bytes)?,
        MeshFormat::Off => super::off::parse(path, &bytes)?,
        MeshFormat::Stl => super::stl::parse(path, &bytes)?,
    };
    report.load_time = start.elapsed();
    Ok((mesh, report))
}

#[cfg(test)]
#[path = "formats_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "hostile_tests.rs"]
mod hostile_tests;
