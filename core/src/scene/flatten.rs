//! A scene's meshes: every distinct mesh file loaded once (what the two-level BVH instances), and
//! the scene flattened into one mesh for the single-level BVH: every placement applied (positions
//! by the transform, normals by its inverse transpose).

use crate::geometry::Aabb;
use crate::mesh::{load_mesh, LoadReport, Mesh, MeshGroup};
use crate::scene::desc::{SceneDesc, SceneError};
use glam::Affine3A;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The meshes of a scene, each loaded once, and their placements: what the two-level BVH is
/// built from.
#[derive(Clone, Debug)]
pub struct SceneInstances {
    pub meshes: Vec<Arc<Mesh>>,
    /// (index into `meshes`, object-to-world transform), in the scene file's order.
    pub placements: Vec<(u32, Affine3A)>,
}

impl SceneInstances {
    pub fn mesh_refs(&self) -> Vec<&Mesh> {
        self.meshes.iter().map(|m| &**m).collect()
    }

    /// Triangles of the scene with every placement applied: what flattening would make.
    pub fn placed_triangles(&self) -> u64 {
        self.placements.iter().map(|&(k, _)| self.meshes[k as usize].triangle_count() as u64).sum()
    }

    /// Vertices of the scene with every placement applied.
    pub fn placed_vertices(&self) -> u64 {
        self.placements.iter().map(|&(k, _)| self.meshes[k as usize].positions.len() as u64).sum()
    }

    /// The box of every placed vertex (as flattening would place them), computed without
    /// flattening; `None` when a placement moves a vertex beyond the coordinates that can be
    /// traced.
    pub fn placed_bounds(&self) -> Option<Aabb> {
        let mut out = Aabb::EMPTY;
        for &(k, transform) in &self.placements {
            for &p in &self.meshes[k as usize].positions {
                let q = transform.transform_point3(p);
                if !q.is_finite() || q.abs().max_element() > crate::mesh::MAX_COORDINATE {
                    return None;
                }
                out = out.grow(q);
            }
        }
        Some(out)
    }
}

/// Load every distinct mesh file of the scene once.
pub fn load_instances(scene_path: &Path, desc: &SceneDesc) -> Result<(SceneInstances, LoadReport), SceneError> {
    if desc.meshes.is_empty() {
        return Err(SceneError::Field {
            path: scene_path.into(),
            field: "meshes".into(),
            message: "the scene has no meshes".into(),
        });
    }
    let mut index: HashMap<PathBuf, u32> = HashMap::new();
    let mut out = SceneInstances { meshes: Vec::new(), placements: Vec::new() };
    let mut report = LoadReport { path: scene_path.into(), ..Default::default() };
    for (i, m) in desc.meshes.iter().enumerate() {
        let k = match index.get(&m.file) {
            Some(&k) => k,
            None => {
                let (mesh, r) = load_mesh(&m.file).map_err(|e| {
                    let hint = match (&e, &m.if_missing) {
                        (crate::mesh::MeshError::File(crate::files::FileError::NotFound { .. }), Some(hint)) => {
                            format!(" ({hint})")
                        }
                        _ => String::new(),
                    };
                    SceneError::Field {
                        path: scene_path.into(),
                        field: format!("meshes[{i}].file"),
                        message: format!("{e}{hint}"),
                    }
                })?;
                report.degenerate_skipped += r.degenerate_skipped;
                report.has_normals |= r.has_normals;
                report.has_uvs |= r.has_uvs;
                out.meshes.push(Arc::new(mesh));
                index.insert(m.file.clone(), out.meshes.len() as u32 - 1);
                out.meshes.len() as u32 - 1
            }
        };
        out.placements.push((k, m.transform));
    }
    Ok((out, report))
}

/// One mesh holding every placed mesh of the scene, in placement order; each placement is a group
/// named after its mesh.
pub fn flatten(scene_path: &Path, scene: &SceneInstances) -> Result<Mesh, SceneError> {
    let mut out = Mesh {
        name: scene_path.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned()),
        ..Default::default()
    };
    let has_normals = scene.meshes.iter().any(|m| !m.normals.is_empty());
    for (i, &(k, transform)) in scene.placements.iter().enumerate() {
        let mesh = &scene.meshes[k as usize];
        let base = out.positions.len() as u32;
        let first = out.triangles.len() as u32;
        out.positions.extend(mesh.positions.iter().map(|&p| transform.transform_point3(p)));
        if has_normals {
            let normal_matrix = glam::Mat3::from(transform.matrix3).inverse().transpose();
            out.normals.extend(
                (0..mesh.positions.len()).map(|v| {
                    mesh.normals.get(v).map_or(glam::Vec3::ZERO, |&n| (normal_matrix * n).normalize_or_zero())
                }),
            );
        }
        if !mesh.uvs.is_empty() {
            out.uvs.resize(base as usize, glam::Vec2::ZERO);
            out.uvs.extend(&mesh.uvs);
        }
        out.triangles.extend(mesh.triangles.iter().map(|t| t.map(|v| v + base)));
        // Triangles numbered as in the files, one after the other (zero-area ones counted), as a
        // dump of the flattened scene numbers them.
        let numbered = out.file_triangles as u32;
        out.file_numbers.extend((0..mesh.triangle_count() as u32).map(|t| numbered + mesh.file_number(t)));
        out.file_triangles += mesh.file_triangle_count();
        let name = if mesh.name.is_empty() { format!("mesh {i}") } else { mesh.name.clone() };
        out.groups.push(MeshGroup { name, triangles: first..out.triangles.len() as u32 });
    }
    if !out.uvs.is_empty() {
        out.uvs.resize(out.positions.len(), glam::Vec2::ZERO);
    }
    if out.positions.iter().any(|p| !p.is_finite() || p.abs().max_element() > crate::mesh::MAX_COORDINATE) {
        return Err(SceneError::Field {
            path: scene_path.into(),
            field: "meshes".into(),
            message: "a transform moves the mesh beyond the coordinates that can be traced".into(),
        });
    }
    Ok(out)
}
