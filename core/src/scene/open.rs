//! A scene as the app and the CLI hold it: where it came from, what loading reported, what a scene
//! file adds (camera, BVH settings, note), and its geometry: one mesh (an OBJ, the built-in scene),
//! or a scene file's meshes, each loaded once, with their placements.
//!
//! A scene of placements is not flattened when it is opened. Two levels need only the meshes and a
//! transform per placement, so a scene placing a mesh 100,000 times costs memory per placement,
//! not per placed triangle; one level flattens it, on demand, once, and only within a budget
//! (`MAX_FLAT_TRIANGLES`) that is checked before a byte is allocated.

use super::flatten;
use crate::bvh::{BuildParams, SceneBuild, SceneBvh};
use crate::geometry::Aabb;
use crate::mesh::{generate, load_mesh, LoadReport, Mesh};
use crate::render::Camera;
use crate::scene::desc::{describe, SceneDesc, SceneError};
use crate::scene::flatten::{load_instances, SceneInstances};
use crate::work::{Cancelled, WorkControl};
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// Most triangles one level may flatten a scene into. A flattened triangle costs about 26 bytes
/// (its share of positions, normals and indices), and the build about 100 more while it runs: 20M
/// triangles stay within a few gigabytes, where 100k placements of a 968-triangle mesh (97M) took
/// 42 s and 18.7 GB and a few more were killed for lack of memory.
pub const MAX_FLAT_TRIANGLES: u64 = crate::files::limits::TRIANGLES.max;

#[derive(Clone, Debug, PartialEq)]
pub enum SceneSource {
    Builtin,
    File(PathBuf),
}

#[derive(Clone, Debug)]
pub enum Geometry {
    /// One mesh: an OBJ file, or the built-in scene.
    Mesh(Arc<Mesh>),
    /// A scene file's meshes and placements; `bounds` is the box of every placed vertex.
    Placed { instances: SceneInstances, bounds: Aabb, flat: Arc<OnceLock<Arc<Mesh>>> },
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub source: SceneSource,
    pub report: LoadReport,
    pub geometry: Geometry,
    /// What a scene file adds: its camera, BVH settings, description and warnings.
    pub camera: Option<Camera>,
    pub build: Option<BuildParams>,
    pub desc: Option<SceneDesc>,
    pub warnings: Vec<String>,
}

/// Why a scene's BVH was not built.
#[derive(Debug, thiserror::Error)]
pub enum SceneBuildError {
    #[error("cancelled")]
    Cancelled,
    #[error(transparent)]
    Scene(#[from] SceneError),
}

impl From<Cancelled> for SceneBuildError {
    fn from(_: Cancelled) -> Self {
        SceneBuildError::Cancelled
    }
}

impl Scene {
    /// Open a mesh (OBJ, PLY, OFF or STL: `mesh::load_mesh`), or a scene file (`.json`:
    /// bvhscope's format or Moer-lite's).
    pub fn open(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
        let path = path.as_ref();
        if crate::mesh::is_gltf(path) {
            // A glTF's nodes place its meshes: a scene of placements, as a scene file's are.
            let start = std::time::Instant::now();
            let g = crate::mesh::load_gltf(path)?;
            let instances =
                SceneInstances { meshes: g.meshes.into_iter().map(Arc::new).collect(), placements: g.placements };
            let mut scene = Scene::of_placements(path, instances, g.report, start)?;
            scene.warnings = g.warnings;
            return Ok(scene);
        }
        let is_scene = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"));
        if !is_scene {
            let (mesh, report) = load_mesh(path)?;
            return Ok(Scene::of_mesh(mesh, report, SceneSource::File(path.into())));
        }
        let start = std::time::Instant::now();
        let desc = describe(path)?;
        let (instances, report) = load_instances(path, &desc)?;
        let mut scene = Scene::of_placements(path, instances, report, start)?;
        (scene.camera, scene.build, scene.warnings) = (desc.camera, desc.build, desc.warnings.clone());
        scene.desc = Some(desc);
        Ok(scene)
    }

    /// A scene of `instances` read from `path` (a scene file, a glTF), its report completed.
    fn of_placements(
        path: &Path,
        instances: SceneInstances,
        mut report: LoadReport,
        start: std::time::Instant,
    ) -> Result<Scene, SceneError> {
        let bounds = instances.placed_bounds().ok_or_else(|| SceneError::Field {
            path: path.into(),
            field: "meshes".into(),
            message: "a transform moves the mesh beyond the coordinates that can be traced".into(),
        })?;
        if instances.placed_triangles() > u32::MAX as u64 {
            return Err(SceneError::Field {
                path: path.into(),
                field: "meshes".into(),
                message: format!(
                    "the placements hold {} triangles, more than the {} triangle ids there are",
                    instances.placed_triangles(),
                    u32::MAX
                ),
            });
        }
        report.vertices = instances.placed_vertices() as usize;
        report.triangles = instances.placed_triangles() as usize;
        report.groups = instances.placements.len();
        report.load_time = start.elapsed();
        Ok(Scene {
            source: SceneSource::File(path.into()),
            report,
            geometry: Geometry::Placed { instances, bounds, flat: Default::default() },
            camera: None,
            build: None,
            warnings: Vec::new(),
            desc: None,
        })
    }

    /// A scene of one mesh, nothing else.
    pub fn of_mesh(mesh: Mesh, report: LoadReport, source: SceneSource) -> Scene {
        Scene {
            source,
            report,
            geometry: Geometry::Mesh(Arc::new(mesh)),
            camera: None,
            build: None,
            desc: None,
            warnings: Vec::new(),
        }
    }

    /// The scene shown when no file is given.
    pub fn builtin() -> Scene {
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
        Scene::of_mesh(mesh, report, SceneSource::Builtin)
    }

    /// The file name, or the built-in mesh's name.
    pub fn title(&self) -> String {
        match (&self.source, &self.geometry) {
            (SceneSource::File(p), _) => crate::files::file_name(p),
            (SceneSource::Builtin, Geometry::Mesh(m)) => m.name.clone(),
            (SceneSource::Builtin, Geometry::Placed { .. }) => "built-in scene".into(),
        }
    }

    pub fn path(&self) -> Option<&Path> {
        match &self.source {
            SceneSource::File(p) => Some(p),
            SceneSource::Builtin => None,
        }
    }

    /// The box of every (placed) vertex.
    pub fn bounds(&self) -> Aabb {
        match &self.geometry {
            Geometry::Mesh(m) => m.bounds(),
            Geometry::Placed { bounds, .. } => *bounds,
        }
    }

    /// A scene file's meshes and placements.
    pub fn instances(&self) -> Option<&SceneInstances> {
        match &self.geometry {
            Geometry::Placed { instances, .. } => Some(instances),
            Geometry::Mesh(_) => None,
        }
    }

    /// Triangles a one-level BVH is built over (every placement applied).
    pub fn placed_triangles(&self) -> u64 {
        match &self.geometry {
            Geometry::Mesh(m) => m.triangle_count() as u64,
            Geometry::Placed { instances, .. } => instances.placed_triangles(),
        }
    }

    /// Whether one level may be built: `Err` says why not in one line (naming the file).
    pub fn check_one_level(&self) -> Result<(), SceneError> {
        let triangles = self.placed_triangles();
        if triangles <= MAX_FLAT_TRIANGLES {
            return Ok(());
        }
        Err(SceneError::TooLargeToFlatten {
            path: self.path().map_or_else(|| PathBuf::from(self.title()), Path::to_path_buf),
            triangles,
            budget: MAX_FLAT_TRIANGLES,
        })
    }

    /// The one mesh a one-level BVH is built over: the mesh, or the scene flattened (once, and
    /// kept; refused past the budget).
    pub fn flat_mesh(&self) -> Result<Arc<Mesh>, SceneError> {
        match &self.geometry {
            Geometry::Mesh(m) => Ok(m.clone()),
            Geometry::Placed { instances, flat, .. } => {
                if let Some(m) = flat.get() {
                    return Ok(m.clone());
                }
                self.check_one_level()?;
                let path = self.path().unwrap_or(Path::new("scene"));
                let mesh = Arc::new(flatten(path, instances)?);
                Ok(flat.get_or_init(|| mesh).clone())
            }
        }
    }

    /// Build what `build` asks for: two levels when `build.top` is given (an OBJ is then one
    /// placement of itself), else one level over the flat mesh.
    pub fn build(&self, build: &SceneBuild, control: &WorkControl) -> Result<SceneBvh, SceneBuildError> {
        let Some(top) = build.top else {
            return Ok(SceneBvh::build_single(self.flat_mesh()?, &build.bvh, control)?);
        };
        let bvh = match &self.geometry {
            Geometry::Mesh(m) => {
                SceneBvh::build_two_level(vec![m.clone()], &[(0, glam::Affine3A::IDENTITY)], &top, &build.bvh, control)
            }
            Geometry::Placed { instances, .. } => {
                SceneBvh::build_two_level(instances.meshes.clone(), &instances.placements, &top, &build.bvh, control)
            }
        };
        Ok(bvh?)
    }
}

/// Open an OBJ or a scene file (`Scene::open`).
pub fn load_any(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
    Scene::open(path)
}
