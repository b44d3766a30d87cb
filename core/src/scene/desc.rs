//! A scene as read from a file (`SceneDesc`: meshes, placements, camera, build), its errors, and the reading helpers the scene formats share.

use crate::bvh::BuildParams;
use crate::mesh::MeshError;
use crate::render::Camera;
use glam::{Affine3A, Vec3};
use std::path::{Path, PathBuf};

/// One mesh of a scene: its OBJ file (absolute, or relative to the scene file) and placement.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneMesh {
    pub file: PathBuf,
    pub transform: Affine3A,
    /// Said with the error when the file does not exist (e.g. where to get a mesh that is not
    /// shipped with bvhscope).
    pub if_missing: Option<String>,
}

impl SceneMesh {
    pub fn new(file: PathBuf, transform: Affine3A) -> Self {
        Self { file, transform, if_missing: None }
    }
}

/// A scene as described by a file, before its meshes are loaded.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneDesc {
    pub camera: Option<Camera>,
    pub meshes: Vec<SceneMesh>,
    pub build: Option<BuildParams>,
    /// What the scene is for, in a sentence or two (shown when it is opened).
    pub note: Option<String>,
    /// Things in the file that were skipped (e.g. analytic shapes), said to the user.
    pub warnings: Vec<String>,
}

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{}: line {line}: not valid JSON: {message}", .path.display())]
    Json { path: PathBuf, line: usize, message: String },
    #[error("{}: {field}: {message}", .path.display())]
    Field { path: PathBuf, field: String, message: String },
    #[error(
        "{}: one level would flatten the scene into {triangles} triangles, more than the {budget} a single BVH may hold here; use two levels (a BVH per mesh, built once, and one over the placements)",
        .path.display()
    )]
    TooLargeToFlatten { path: PathBuf, triangles: u64, budget: u64 },
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

/// Translation, rotation about an axis, and scale, applied as world = T·R·S·p (Moer-lite's order).
pub fn trs(translate: Vec3, axis: Vec3, radians: f32, scale: Vec3) -> Affine3A {
    let rotation = match axis.try_normalize() {
        Some(a) if radians != 0.0 => glam::Quat::from_axis_angle(a, radians),
        _ => glam::Quat::IDENTITY,
    };
    Affine3A::from_scale_rotation_translation(scale, rotation, translate)
}

/// The most placements a scene file may hold: the one limit every file counts against
/// (`files::limits::PLACEMENTS`, which says why).
pub const MAX_PLACEMENTS: usize = crate::files::limits::PLACEMENTS.max as usize;

/// The largest scene file read (what `MAX_PLACEMENTS` written out takes, and room to spare): a
/// bigger one is refused before it is read, so its JSON is never held in memory.
pub const MAX_SCENE_BYTES: u64 = 32 << 20;

/// Refuse a scene of more than `MAX_PLACEMENTS` placements, naming the file.
pub(crate) fn check_placements(path: &Path, n: usize) -> Result<(), SceneError> {
    crate::files::limits::PLACEMENTS.check(n as u64).map_err(|message| SceneError::Field {
        path: path.into(),
        field: "meshes".into(),
        message,
    })
}

/// Read a JSON file, with errors that name the file and the line.
pub(super) fn read_json(path: &Path) -> Result<serde_json::Value, SceneError> {
    if let Ok(m) = std::fs::metadata(path) {
        if m.is_file() && m.len() > MAX_SCENE_BYTES {
            return Err(SceneError::Field {
                path: path.into(),
                field: "(the file)".into(),
                message: format!(
                    "{} MB, more than the {} MB a scene file may take (at most {MAX_PLACEMENTS} placements)",
                    m.len() >> 20,
                    MAX_SCENE_BYTES >> 20
                ),
            });
        }
    }
    let bytes = crate::mesh::read_user_file(path)?;
    let text = crate::mesh::decode_text(path, &bytes)?;
    // Every placement names its file: counted in the text, before a JSON value is made of it.
    check_placements(path, text.matches("\"file\"").count())?;
    crate::json::parse(&text).map_err(|e| SceneError::Json {
        path: path.into(),
        line: e.line(),
        message: e.to_string(),
    })
}

/// Which format a scene file is in.
pub fn describe(path: &Path) -> Result<SceneDesc, SceneError> {
    let json = read_json(path)?;
    let base = path.parent().unwrap_or(Path::new("."));
    let field = fields(path);
    // Counted before any placement is made.
    let desc = if crate::scene::moer_lite::looks_like(&json) {
        crate::scene::moer_lite::describe(&json, base, &field)
    } else {
        crate::scene::scene_file::describe(&json, base, &field)
    }?;
    check_placements(path, desc.meshes.len())?;
    Ok(desc)
}

/// Typed reading of a scene file's JSON values, with errors naming the field
/// (`camera.transform.position`).
pub(crate) type Fields<'a> = crate::json::Fields<'a, SceneError>;

/// The fields of the scene file `path`.
pub(crate) fn fields(path: &Path) -> Fields<'_> {
    Fields::new(path, |path, field, message| SceneError::Field { path: path.into(), field: field.into(), message })
}

/// A mesh path from a scene file: relative paths are relative to the scene file's folder.
pub(crate) fn resolve(base: &Path, file: &str) -> PathBuf {
    let p = PathBuf::from(file);
    if p.is_absolute() {
        p
    } else {
        base.join(p)
    }
}
