//! The mesh on screen, where it came from, and the BVH built over it.

use crate::bvh::{BuildParams, SceneBvh, TreeStats};
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

/// The BVH of the current scene.
pub struct BuiltBvh {
    pub bvh: Arc<SceneBvh>,
    /// Of the single BVH, or of the top level of two.
    pub stats: TreeStats,
    /// Two levels: each mesh's name and its BVH's statistics.
    pub bottom: Vec<(String, TreeStats)>,
    pub scene_id: u64,
}

impl BuiltBvh {
    /// Deepest level of the bottom BVHs (or of the single BVH): the box depth slider's end.
    pub fn bottom_max_depth(&self) -> u32 {
        match self.bvh.two_level() {
            Some(_) => self.bottom.iter().map(|(_, s)| s.max_depth).max().unwrap_or(0),
            None => self.stats.max_depth,
        }
    }
}
