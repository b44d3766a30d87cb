//! glTF 2.0 (`.gltf` with its buffers in files beside it or in data URIs, or one `.glb`): what
//! Blender, game engines and the glTF sample models write. Its node hierarchy is the two-level
//! scene the lab teaches: each mesh is read once (its triangle primitives, indexed or not, any
//! index type), and each node that uses it is a placement, its transform composed down the
//! hierarchy from the scene's roots. Primitives of other modes (points, lines, strips, fans) are
//! skipped with a warning. A mesh's triangles are numbered primitive by primitive, in the file's
//! order; a mesh's index is its place among the file's meshes that hold triangles.

use super::assemble::{bad, finish};
use super::{read_user_file, LoadReport, Mesh, MeshError};
use glam::{Affine3A, Mat4, Vec3};
use std::path::Path;

/// A glTF file's meshes and where its nodes place them.
pub struct GltfScene {
    pub meshes: Vec<Mesh>,
    /// (index into `meshes`, object-to-world transform), in the order the nodes are visited.
    pub placements: Vec<(u32, Affine3A)>,
    pub warnings: Vec<String>,
    pub report: LoadReport,
}

/// Whether `path` names a glTF file (`.gltf` or `.glb`).
pub fn is_gltf(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

pub fn load_gltf(path: &Path) -> Result<GltfScene, MeshError> {
    let bytes = read_user_file(path)?;
    let gltf = gltf::Gltf::from_slice(&bytes).map_err(|e| bad(path, "the document", e))?;
    let buffers = buffers(path, &gltf)?;
    let mut warnings = Vec::new();
    // Each mesh with triangles, read once; `index[m]` its place among them.
    let mut meshes = Vec::new();
    let mut index = vec![None; gltf.meshes().len()];
    for m in gltf.meshes() {
        let name = m.name().map_or_else(|| format!("mesh {}", m.index()), str::to_string);
        let (mut positions, mut normals, mut triangles) = (Vec::new(), Vec::new(), Vec::new());
        let mut all_normals = true;
        for p in m.primitives() {
            let at = format!("{name}, primitive {}", p.index());
            if p.mode() != gltf::mesh::Mode::Triangles {
                warnings.push(format!("{at}: {:?} primitives are skipped (triangles only)", p.mode()));
                continue;
            }
            // An empty accessor is refused before the crate's reader computes `count - 1` of it.
            let empty = p.attributes().map(|(_, a)| a).chain(p.indices()).any(|a| a.count() == 0);
            if empty {
                return Err(bad(path, at, "an accessor of no elements"));
            }
            let reader = p.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let Some(read) = reader.read_positions() else {
                return Err(bad(path, at, "no POSITION attribute (or its data lies outside its buffer)"));
            };
            let base = positions.len() as u32;
            positions.extend(read.map(Vec3::from_array));
            let n = positions.len() as u32 - base;
            match reader.read_normals() {
                Some(read) if all_normals => normals.extend(read.map(Vec3::from_array)),
                _ => all_normals = false,
            }
            let indices: Vec<u32> = match reader.read_indices() {
                Some(read) => read.into_u32().collect(),
                None if p.indices().is_some() => return Err(bad(path, at, "its indices lie outside their buffer")),
                None => (0..n).collect(),
            };
            if !indices.len().is_multiple_of(3) {
                return Err(bad(path, at, format!("{} indices, not a whole number of triangles", indices.len())));
            }
            if let Some(i) = indices.iter().find(|&&i| i >= n) {
                return Err(bad(path, at, format!("refers to vertex {i}, but it has {n}")));
            }
            triangles.extend(indices.chunks_exact(3).map(|t| [t[0] + base, t[1] + base, t[2] + base]));
        }
        if !all_normals || normals.len() != positions.len() {
            normals.clear();
        }
        if triangles.is_empty() {
            continue;
        }
        let (mut mesh, _) = finish(path, positions, normals, triangles).map_err(|e| match e {
            MeshError::NoTriangles { degenerate, .. } => {
                bad(path, &name, format!("all {degenerate} triangles have zero area"))
            }
            e => e,
        })?;
        mesh.name = name.clone();
        mesh.groups[0].name = name;
        index[m.index()] = Some(meshes.len() as u32);
        meshes.push(mesh);
    }
    if meshes.is_empty() {
        return Err(MeshError::NoTriangles { path: path.into(), degenerate: 0 });
    }
    // The nodes of the default scene (else the first), each mesh node a placement.
    let mut placements = Vec::new();
    let roots: Vec<gltf::Node> = match gltf.default_scene().or_else(|| gltf.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => Vec::new(),
    };
    let mut stack: Vec<(gltf::Node, Mat4, usize)> = roots.into_iter().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > 256 {
            return Err(bad(
                path,
                format!("node {}", node.index()),
                "the hierarchy is deeper than 256 levels (a cycle?)",
            ));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(k) = node.mesh().and_then(|m| index[m.index()]) {
            placements.push((k, Affine3A::from_mat4(world)));
        }
        stack.extend(node.children().map(|c| (c, world, depth + 1)));
    }
    if placements.is_empty() {
        // No scene places anything: each mesh once, where it is.
        placements = (0..meshes.len() as u32).map(|k| (k, Affine3A::IDENTITY)).collect();
    }
    let report = LoadReport {
        path: path.into(),
        has_normals: meshes.iter().any(|m| !m.normals.is_empty()),
        degenerate_skipped: meshes.iter().map(|m| m.file_triangles - m.triangles.len()).sum(),
        ..Default::default()
    };
    Ok(GltfScene { meshes, placements, warnings, report })
}

/// Each buffer's bytes: the GLB's binary chunk, a data URI's, or a file beside the glTF's.
fn buffers(path: &Path, gltf: &gltf::Gltf) -> Result<Vec<Vec<u8>>, MeshError> {
    use base64::Engine;
    let mut out = Vec::new();
    for b in gltf.buffers() {
        let at = format!("buffer {}", b.index());
        let data = match b.source() {
            gltf::buffer::Source::Bin => {
                gltf.blob.clone().ok_or_else(|| bad(path, &at, "refers to the GLB's binary chunk, which is missing"))?
            }
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                let (_, data) = uri.split_once(',').ok_or_else(|| bad(path, &at, "a data URI without data"))?;
                base64::engine::general_purpose::STANDARD
                    .decode(data)
                    .map_err(|e| bad(path, &at, format!("its data URI is not base64: {e}")))?
            }
            gltf::buffer::Source::Uri(uri) => {
                let file = path.parent().unwrap_or(Path::new(".")).join(uri.replace("%20", " "));
                read_user_file(&file).map_err(|e| bad(path, &at, e))?
            }
        };
        if data.len() < b.length() {
            return Err(bad(path, &at, format!("holds {} bytes, its declared length is {}", data.len(), b.length())));
        }
        out.push(data);
    }
    Ok(out)
}

#[cfg(test)]
#[path = "gltf_tests.rs"]
mod tests;
