//! glTF 2.0 (`.gltf` with its buffers in files beside it or in data URIs, or one `.glb`): what
//! Blender, game engines and the glTF sample models write. Its node hierarchy is the two-level
//! scene the lab teaches: each mesh is read once (its triangle primitives, indexed or not, any
//! index type), and each node that uses it is a placement, its transform composed down the
//! hierarchy from the scene's roots. Primitives of other modes (points, lines, strips, fans) are
//! skipped with a warning. A mesh's triangles are numbered primitive by primitive, in the file's
//! order; a mesh's index is its place among the file's meshes that hold triangles.
//!
//! The file is hostile until checked: buffers are read only from the file's folder or below and
//! no further than their `byteLength` (`files::beside`, `files::read_declared`), accessors by our
//! own checked reader (`gltf_access.rs`), the node graph must be a forest (§3.5.1: a node has at
//! most one parent), and vertices, triangles, nodes and placements count against
//! `files::limits`.

use super::assemble::{bad, finish};
use super::gltf_access::Access;
use crate::files::limits;
use crate::mesh::error::MeshError;
use crate::mesh::mesh::Mesh;
use crate::mesh::obj::{read_user_file, LoadReport};
use glam::{Affine3A, Mat4};
use std::collections::HashMap;
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
    let (json, blob) = container(path, &bytes)?;
    let gltf = document(path, json)?;
    let root = gltf.as_json();
    limits::NODES.check(root.nodes.len() as u64).map_err(|e| bad(path, "the nodes", e))?;
    let buffers = buffers(path, &gltf, blob)?;
    let mut access = Access::new(root, buffers, bytes.len() as u64);
    let mut warnings = Vec::new();
    // Each mesh with triangles, read once; `index[m]` its place among them.
    let mut meshes = Vec::new();
    let mut index = vec![None; gltf.meshes().len()];
    let mut triangles_in_file = 0u64;
    for m in gltf.meshes() {
        let name = m.name().map_or_else(|| format!("mesh {}", m.index()), str::to_string);
        let (mut positions, mut normals, mut triangles) = (Vec::new(), Vec::new(), Vec::new());
        let mut all_normals = true;
        // Primitives that share their vertices (one POSITION and NORMAL accessor, several index
        // lists, as exporters write a mesh of several materials) share them here too.
        let mut read: HashMap<(usize, Option<usize>), u32> = HashMap::new();
        for p in m.primitives() {
            let at = format!("{name}, primitive {}", p.index());
            if p.mode() != gltf::mesh::Mode::Triangles {
                warnings.push(format!("{at}: {:?} primitives are skipped (triangles only)", p.mode()));
                continue;
            }
            let Some(pos) = p.get(&gltf::Semantic::Positions) else {
                return Err(bad(path, at, "no POSITION attribute"));
            };
            let accessor = |i: usize, role: &str, why: String| bad(path, &at, format!("{role} (accessor {i}) {why}"));
            let nor = p.get(&gltf::Semantic::Normals).map(|a| a.index());
            let key = (pos.index(), nor.filter(|_| all_normals));
            let base = match read.get(&key) {
                Some(&base) => base,
                None => {
                    let base = positions.len() as u32;
                    let read_positions = access.vec3s(pos.index()).map_err(|e| accessor(pos.index(), "POSITION", e))?;
                    for (k, p) in read_positions.iter().enumerate() {
                        super::assemble::point(p.to_array().map(f64::from))
                            .map_err(|e| bad(path, &at, format!("POSITION element {k}: {e}")))?;
                    }
                    positions.extend(read_positions);
                    match key.1 {
                        Some(n) => {
                            let read_normals = access.vec3s(n).map_err(|e| accessor(n, "NORMAL", e))?;
                            if let Some(k) = read_normals.iter().position(|v| !v.is_finite()) {
                                let v = read_normals[k];
                                return Err(bad(path, &at, format!("NORMAL element {k} is ({v}): not finite")));
                            }
                            normals.extend(read_normals);
                        }
                        None => all_normals = false,
                    }
                    read.insert(key, base);
                    base
                }
            };
            // Checked within the vertex limit when it was read.
            let n = access.root.accessors[pos.index()].count.0 as u32;
            let indices: Vec<u32> = match p.indices() {
                Some(a) => access.indices(a.index()).map_err(|e| accessor(a.index(), "the indices", e))?,
                None => {
                    access.make(4 * n as u64).map_err(|e| bad(path, &at, e))?;
                    (0..n).collect()
                }
            };
            if !indices.len().is_multiple_of(3) {
                return Err(bad(path, at, format!("{} indices, not a whole number of triangles", indices.len())));
            }
            if let Some(k) = indices.iter().position(|&i| i >= n) {
                return Err(bad(path, at, format!("index {k} refers to vertex {}, but it has {n}", indices[k])));
            }
            triangles_in_file += indices.len() as u64 / 3;
            limits::TRIANGLES.check(triangles_in_file).map_err(|e| bad(path, &at, e))?;
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
    let mut placements = placements(path, &gltf, &index)?;
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

/// The JSON and the binary chunk: a GLB's two chunks (§4.4), their lengths checked here (the
/// crate's GLB reader subtracts before it checks), or the whole file as JSON.
fn container<'a>(path: &Path, bytes: &'a [u8]) -> Result<(&'a [u8], Option<&'a [u8]>), MeshError> {
    if !bytes.starts_with(b"glTF") {
        return Ok((bytes, None));
    }
    let word = |at: usize| bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(bad(path, "the GLB header", "the file ends inside it"));
    };
    if version != 2 {
        return Err(bad(path, "the GLB header", format!("version {version}; only glTF 2 is read")));
    }
    if length > bytes.len() {
        return Err(bad(path, "the GLB header", format!("declares {length} bytes, the file holds {}", bytes.len())));
    }
    let mut chunks = Vec::new();
    let mut at = 12;
    while at + 8 <= length {
        let (n, kind) = (word(at).unwrap_or(0), &bytes[at + 4..at + 8]);
        let start = at + 8;
        if n > length - start {
            return Err(bad(
                path,
                format!("GLB chunk {}", chunks.len()),
                format!("declares {n} bytes, past the file's end"),
            ));
        }
        chunks.push((kind, &bytes[start..start + n]));
        at = start + n.next_multiple_of(4).min(length - start);
    }
    match chunks.as_slice() {
        [(b"JSON", json), rest @ ..] => Ok((json, rest.iter().find(|(k, _)| *k == b"BIN\0").map(|(_, b)| *b))),
        _ => Err(bad(path, "GLB chunk 0", "is not the JSON chunk")),
    }
}

/// The document, validated by the crate once what its validation indexes unchecked is checked
/// here (a POSITION accessor that does not exist panicked inside it).
fn document(path: &Path, json: &[u8]) -> Result<gltf::Document, MeshError> {
    let root: gltf::json::Root = gltf::json::deserialize::from_slice(json)
        .map_err(|e| bad(path, "the document", format!("not glTF JSON: {e}")))?;
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive.attributes.get(&gltf::json::validation::Checked::Valid(gltf::Semantic::Positions));
            if let Some(i) = position.map(|i| i.value()).filter(|&i| i >= root.accessors.len()) {
                return Err(bad(
                    path,
                    format!("mesh {m}, primitive {p}"),
                    format!("POSITION names accessor {i}, which does not exist"),
                ));
            }
        }
    }
    gltf::Document::from_json(root).map_err(|e| bad(path, "the document", document_error(e)))
}

/// The crate's refusal of the document, its first few faults (a hostile file may have millions).
fn document_error(e: gltf::Error) -> String {
    match e {
        gltf::Error::Validation(faults) => {
            let first: Vec<String> = faults.iter().take(3).map(|(at, why)| format!("{at}: {why}")).collect();
            let more = faults.len().saturating_sub(3);
            let more = if more > 0 { format!(" (and {more} more)") } else { String::new() };
            format!("invalid glTF: {}{more}", first.join("; "))
        }
        e => e.to_string(),
    }
}

/// Each buffer's bytes, no more than its `byteLength`: the GLB's binary chunk, a data URI's, or
/// a file at or below the glTF's folder.
fn buffers(path: &Path, gltf: &gltf::Document, blob: Option<&[u8]>) -> Result<Vec<Vec<u8>>, MeshError> {
    use base64::Engine;
    let mut out = Vec::new();
    let mut total = 0u64;
    for b in gltf.buffers() {
        let at = format!("buffer {}", b.index());
        let declared = b.length() as u64;
        total = total.saturating_add(declared);
        limits::BUFFER_BYTES.check(total).map_err(|e| bad(path, &at, e))?;
        let short = |len: usize| bad(path, &at, format!("holds {len} bytes, its declared length is {declared}"));
        let mut data = match b.source() {
            gltf::buffer::Source::Bin => {
                blob.ok_or_else(|| bad(path, &at, "refers to the GLB's binary chunk, which is missing"))?.to_vec()
            }
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                let (_, data) = uri.split_once(',').ok_or_else(|| bad(path, &at, "a data URI without data"))?;
                base64::engine::general_purpose::STANDARD
                    .decode(data)
                    .map_err(|e| bad(path, &at, format!("its data URI is not base64: {e}")))?
            }
            gltf::buffer::Source::Uri(uri) => {
                let file = crate::files::beside(path, uri).map_err(|e| bad(path, &at, format!("uri {e}")))?;
                crate::files::read_declared(&file, declared).map_err(|e| match e {
                    crate::files::FileError::Short { len, .. } => short(len as usize),
                    e => bad(path, &at, e),
                })?
            }
        };
        if (data.len() as u64) < declared {
            return Err(short(data.len()));
        }
        data.truncate(declared as usize);
        out.push(data);
    }
    Ok(out)
}

/// Where the nodes of the default scene (else the first) place the meshes (`index`: a glTF mesh's
/// place among those with triangles). The graph must be a forest, each node visited once: a node
/// named twice as a child, or a root that is also a child, would place its subtree again at each
/// level (a 1 KB file made a million placements).
fn placements(path: &Path, gltf: &gltf::Document, index: &[Option<u32>]) -> Result<Vec<(u32, Affine3A)>, MeshError> {
    let root = gltf.as_json();
    let node = |i: usize| format!("node {i}");
    let mut parent: Vec<Option<usize>> = vec![None; root.nodes.len()];
    for (i, n) in root.nodes.iter().enumerate() {
        for c in n.children.iter().flatten().map(|c| c.value()) {
            match parent[c] {
                Some(p) if p == i => {
                    return Err(bad(path, node(i), format!("names node {c} twice among its children")))
                }
                Some(p) => {
                    return Err(bad(
                        path,
                        node(c),
                        format!("has two parents, node {p} and node {i}: a glTF node has at most one"),
                    ))
                }
                None => parent[c] = Some(i),
            }
        }
        if let Some(m) = n.matrix {
            if [m[3], m[7], m[11], m[15]] != [0.0, 0.0, 0.0, 1.0] {
                return Err(bad(
                    path,
                    node(i),
                    "a projective matrix (its last row is not 0 0 0 1): only affine transforms place a mesh",
                ));
            }
        }
    }
    let Some(scene) = gltf.default_scene().or_else(|| gltf.scenes().next()) else { return Ok(Vec::new()) };
    let mut is_root = vec![false; root.nodes.len()];
    let mut stack = Vec::new();
    for r in scene.nodes().map(|n| n.index()) {
        if let Some(p) = parent[r] {
            return Err(bad(path, node(r), format!("is a root of scene {} and a child of node {p}", scene.index())));
        }
        if std::mem::replace(&mut is_root[r], true) {
            return Err(bad(path, node(r), format!("is named twice among scene {}'s nodes", scene.index())));
        }
        stack.push((r, Mat4::IDENTITY));
    }
    let nodes: Vec<gltf::Node> = gltf.nodes().collect();
    let mut out = Vec::new();
    while let Some((i, parent)) = stack.pop() {
        let n = &nodes[i];
        let world = parent * Mat4::from_cols_array_2d(&n.transform().matrix());
        if !world.is_finite() {
            return Err(bad(path, node(i), "its transform, composed down the hierarchy, is not finite"));
        }
        if let Some(k) = n.mesh().and_then(|m| index[m.index()]) {
            limits::PLACEMENTS.check(out.len() as u64 + 1).map_err(|e| bad(path, node(i), e))?;
            out.push((k, Affine3A::from_mat4(world)));
        }
        stack.extend(n.children().map(|c| (c.index(), world)));
    }
    Ok(out)
}

#[cfg(test)]
#[path = "gltf_tests.rs"]
mod tests;
