//! The mesh on screen and where it came from.

use crate::bvh::BuildParams;
use crate::mesh::{generate, LoadReport, Mesh};
use crate::render::Camera;
use crate::scene::{Loaded, SceneDesc, SceneInstances};
use std::path::PathBuf;
use std::sync::Arc;

#[derive(Clone, Debug, PartialEq)]
pub enum SceneSource {
    Builtin,
    File(PathBuf),
}

#[derive(Clone)]
pub struct Scene {
    pub mesh: Arc<Mesh>,
    pub report: LoadReport,
    pub source: SceneSource,
    /// What a scene file adds: its camera, BVH settings, meshes and warnings.
    pub camera: Option<Camera>,
    pub build: Option<BuildParams>,
    pub desc: Option<SceneDesc>,
    pub warnings: Vec<String>,
    /// A scene file's meshes and placements (what a two-level BVH is built over).
    pub instances: Option<SceneInstances>,
}

impl Scene {
    pub fn new(mesh: Arc<Mesh>, report: LoadReport, source: SceneSource) -> Self {
        Self { mesh, report, source, camera: None, build: None, desc: None, warnings: Vec::new(), instances: None }
    }

    /// A loaded OBJ or scene file.
    pub fn from_loaded(l: Loaded, path: PathBuf) -> Self {
        Self {
            mesh: Arc::new(l.mesh),
            report: l.report,
            source: SceneSource::File(path),
            camera: l.camera,
            build: l.build,
            desc: l.scene,
            warnings: l.warnings,
            instances: l.instances,
        }
    }

    /// The scene shown when no file is given.
    pub fn builtin() -> Self {
        let mesh = generate::builtin_scene();
        let report = LoadReport {
            path: PathBuf::from(&mesh.name),
            vertices: mesh.positions.len(),
            triangles: mesh.triangle_count(),
            groups: mesh.groups.len(),
            has_normals: true,
            has_uvs: true,
            ..Default::default()
        };
        Self::new(Arc::new(mesh), report, SceneSource::Builtin)
    }

    pub fn title(&self) -> String {
        match &self.source {
            SceneSource::Builtin => self.mesh.name.clone(),
            SceneSource::File(p) => {
                p.file_name().map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into_owned())
            }
        }
    }
}
