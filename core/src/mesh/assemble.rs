//! What the mesh readers of other formats than OBJ share (`ply.rs`, `off.rs`, `stl.rs`,
//! `gltf.rs`): their one kind of error, the mesh put together from a file's vertices and
//! triangles with the checks the OBJ reader makes, fan triangulation, and the bound on what a
//! header's count may reserve.

use crate::files::limits;
use crate::geometry::triangle::double_area;
use crate::mesh::error::{MeshError, MAX_COORDINATE};
use crate::mesh::mesh::{Mesh, MeshGroup};
use crate::mesh::obj::LoadReport;
use glam::Vec3;
use std::path::Path;

/// A reader's error: the file, where in it (`element`: "vertex 12", "face 3", "line 40"), what.
pub(crate) fn bad(path: &Path, element: impl std::fmt::Display, message: impl std::fmt::Display) -> MeshError {
    MeshError::Parse { path: path.into(), line: None, message: format!("{element}: {message}") }
}

/// A mesh from a file's vertices (normals: none, or one per vertex) and its triangles in file
/// order: every index checked, zero-area triangles left out (each kept one keeps its number in
/// the file), coordinates checked as the OBJ reader checks them.
pub(crate) fn finish(
    path: &Path,
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    file_triangles: Vec<[u32; 3]>,
) -> Result<(Mesh, LoadReport), MeshError> {
    let n = positions.len();
    if let Some((t, i)) =
        file_triangles.iter().enumerate().find_map(|(t, tri)| tri.iter().find(|&&i| i as usize >= n).map(|&i| (t, i)))
    {
        return Err(bad(path, format!("triangle {t}"), format!("refers to vertex {i}, but only {n} are declared")));
    }
    // The readers check each coordinate where they read it (naming its line or element); this
    // is the last guard, naming the vertex.
    for (k, p) in positions.iter().enumerate() {
        point(p.to_array().map(f64::from)).map_err(|e| bad(path, format!("vertex {k}"), e))?;
    }
    if let Some(k) = normals.iter().position(|v| !v.is_finite()) {
        return Err(bad(path, format!("vertex {k}"), format!("its normal ({}) is not finite", normals[k])));
    }
    limits::VERTICES.check(n as u64).map_err(|e| bad(path, "the vertices", e))?;
    limits::TRIANGLES.check(file_triangles.len() as u64).map_err(|e| bad(path, "the triangles", e))?;
    let (mut triangles, mut numbers) =
        (Vec::with_capacity(file_triangles.len()), Vec::with_capacity(file_triangles.len()));
    for (i, t) in file_triangles.iter().enumerate() {
        if double_area(&t.map(|k| positions[k as usize])) != 0.0 {
            triangles.push(*t);
            numbers.push(i as u32);
        }
    }
    let degenerate = file_triangles.len() - triangles.len();
    if triangles.is_empty() {
        return Err(MeshError::NoTriangles { path: path.into(), degenerate });
    }
    let name = path.file_stem().map_or_else(|| path.display().to_string(), |s| s.to_string_lossy().into_owned());
    let report = LoadReport {
        path: path.into(),
        vertices: n,
        triangles: triangles.len(),
        degenerate_skipped: degenerate,
        groups: 1,
        has_normals: !normals.is_empty(),
        has_uvs: false,
        load_time: Default::default(),
    };
    let count = triangles.len() as u32;
    let mesh = Mesh {
        groups: vec![MeshGroup { name: name.clone(), triangles: 0..count }],
        name,
        positions,
        normals,
        uvs: Vec::new(),
        triangles,
        file_numbers: numbers,
        file_triangles: file_triangles.len(),
    };
    Ok((mesh, report))
}

/// A coordinate read as a number (in double precision, so 1e39 is seen as the finite number it
/// is) as a vertex takes it, or why it cannot be one, with its value.
pub(crate) fn coordinate(x: f64) -> Result<f32, String> {
    if !x.is_finite() {
        return Err(format!("coordinate {x} is not a finite number"));
    }
    if x.abs() > MAX_COORDINATE as f64 {
        return Err(format!(
            "coordinate {x:e} exceeds ±{MAX_COORDINATE:e}, too large to trace in single precision (scale the mesh down)"
        ));
    }
    Ok(x as f32)
}

/// A vertex position from three numbers (`coordinate`).
pub(crate) fn point(p: [f64; 3]) -> Result<Vec3, String> {
    Ok(Vec3::new(coordinate(p[0])?, coordinate(p[1])?, coordinate(p[2])?))
}

/// Fan-triangulate a polygon (as the OBJ reader does: (0, i, i + 1)).
pub(crate) fn fan(polygon: &[u32], out: &mut Vec<[u32; 3]>) {
    for i in 1..polygon.len().saturating_sub(1) {
        out.push([polygon[0], polygon[i], polygon[i + 1]]);
    }
}

/// At most `claimed` items, and no more than `bytes` of the file could hold at `least` bytes an
/// item: what a reader reserves, so a header's count never allocates beyond the file.
pub(crate) fn capacity(claimed: u64, bytes: usize, least: usize) -> usize {
    (claimed as usize).min(bytes / least.max(1) + 1)
}
