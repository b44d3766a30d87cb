//! Turning a scene into one mesh for the single-level BVH: every mesh loaded once, every placement
//! applied (positions by the transform, normals by its inverse transpose).

use super::{describe, SceneDesc, SceneError};
use crate::bvh::BuildParams;
use crate::mesh::{load_obj, LoadReport, Mesh, MeshGroup};
use crate::render::Camera;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// What opening a file gives: the mesh to build over, and what a scene file adds.
#[derive(Clone, Debug)]
pub struct Loaded {
    pub mesh: Mesh,
    pub report: LoadReport,
    pub camera: Option<Camera>,
    pub build: Option<BuildParams>,
    pub warnings: Vec<String>,
    /// The scene's description, when the file was a scene.
    pub scene: Option<SceneDesc>,
}

/// Open an OBJ, or a scene file (`.json`: bvhscope's format or Moer-lite's).
pub fn load_any(path: impl AsRef<Path>) -> Result<Loaded, SceneError> {
    let path = path.as_ref();
    let is_scene = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if !is_scene {
        let (mesh, report) = load_obj(path)?;
        return Ok(Loaded { mesh, report, camera: None, build: None, warnings: Vec::new(), scene: None });
    }
    let start = std::time::Instant::now();
    let desc = describe(path)?;
    let (mesh, mut report) = flatten(path, &desc)?;
    report.load_time = start.elapsed();
    Ok(Loaded {
        mesh,
        report,
        camera: desc.camera,
        build: desc.build,
        warnings: desc.warnings.clone(),
        scene: Some(desc),
    })
}

/// One mesh holding every placed mesh of the scene; each placement is a group named after its file.
pub fn flatten(scene_path: &Path, desc: &SceneDesc) -> Result<(Mesh, LoadReport), SceneError> {
    if desc.meshes.is_empty() {
        return Err(SceneError::Field {
            path: scene_path.into(),
            field: "meshes".into(),
            message: "the scene has no meshes".into(),
        });
    }
    let mut cache: HashMap<PathBuf, (Mesh, LoadReport)> = HashMap::new();
    let mut out = Mesh {
        name: scene_path.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned()),
        ..Default::default()
    };
    let mut report = LoadReport { path: scene_path.into(), ..Default::default() };
    for (i, m) in desc.meshes.iter().enumerate() {
        if !cache.contains_key(&m.file) {
            let loaded = load_obj(&m.file).map_err(|e| {
                let hint = match (&e, &m.if_missing) {
                    (crate::mesh::MeshError::NotFound { .. }, Some(hint)) => format!(" ({hint})"),
                    _ => String::new(),
                };
                SceneError::Field { path: scene_path.into(), field: format!("meshes[{i}].file"), message: format!("{e}{hint}") }
            })?;
            cache.insert(m.file.clone(), loaded);
        }
        let (mesh, r) = &cache[&m.file];
        report.degenerate_skipped += r.degenerate_skipped;
        report.has_normals |= r.has_normals;
        report.has_uvs |= r.has_uvs;
        let base = out.positions.len() as u32;
        let first = out.triangles.len() as u32;
        out.positions.extend(mesh.positions.iter().map(|&p| m.transform.transform_point3(p)));
        let normal_matrix = glam::Mat3::from(m.transform.matrix3).inverse().transpose();
        out.normals.extend(
            (0..mesh.positions.len())
                .map(|v| mesh.normals.get(v).map_or(glam::Vec3::ZERO, |&n| (normal_matrix * n).normalize_or_zero())),
        );
        if !mesh.uvs.is_empty() {
            out.uvs.resize(base as usize, glam::Vec2::ZERO);
            out.uvs.extend(&mesh.uvs);
        }
        out.triangles.extend(mesh.triangles.iter().map(|t| t.map(|v| v + base)));
        let name = m.file.file_stem().map_or_else(|| format!("mesh {i}"), |s| s.to_string_lossy().into_owned());
        out.groups.push(MeshGroup { name, triangles: first..out.triangles.len() as u32 });
    }
    if !report.has_normals {
        out.normals.clear(); // no file had normals: the geometric normal serves
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
    report.vertices = out.positions.len();
    report.triangles = out.triangles.len();
    report.groups = out.groups.len();
    Ok((out, report))
}
