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
    /// What the statistics rows describe: the single BVH; for two levels the top level, or the
    /// mesh's BVH when the scene places one mesh once (its top level is one node, nothing to
    /// describe).
    pub stats: TreeStats,
    /// Two levels: the top level's statistics.
    pub top_stats: Option<TreeStats>,
    /// Two levels: each mesh's name and its BVH's statistics.
    pub bottom: Vec<(String, TreeStats)>,
    pub scene_id: u64,
}

impl BuiltBvh {
    /// Statistics of a finished build; `names` are the scene's mesh names (two levels).
    pub fn new(bvh: Arc<SceneBvh>, names: &[String], scene_id: u64) -> Self {
        let (stats, top_stats, bottom) = match bvh.two_level() {
            Some(t) => {
                let top = TreeStats::of(&t.top);
                let bottom: Vec<(String, TreeStats)> = t
                    .bottom
                    .iter()
                    .enumerate()
                    .map(|(k, b)| (names.get(k).cloned().unwrap_or_else(|| format!("mesh {k}")), TreeStats::of(b)))
                    .collect();
                let rows = match (&t.instances[..], &bottom[..]) {
                    ([_], [(_, mesh)]) => mesh.clone(),
                    _ => top.clone(),
                };
                (rows, Some(top), bottom)
            }
            None => (TreeStats::of(bvh.tree()), None, Vec::new()),
        };
        Self { bvh, stats, top_stats, bottom, scene_id }
    }

    /// Whether the statistics rows describe the mesh's BVH of a two-level build of one placement.
    pub fn rows_are_the_mesh(&self) -> bool {
        self.bvh.two_level().is_some_and(|t| t.instances.len() == 1 && t.bottom.len() == 1)
    }

    /// Deepest level of the bottom BVHs (or of the single BVH): the box depth slider's end.
    pub fn bottom_max_depth(&self) -> u32 {
        match self.bvh.two_level() {
            Some(_) => self.bottom.iter().map(|(_, s)| s.max_depth).max().unwrap_or(0),
            None => self.stats.max_depth,
        }
    }
}
