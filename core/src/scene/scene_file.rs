//! bvhscope's scene file (JSON): a camera, any number of meshes with transforms, and the BVH
//! settings to start with. The README documents the format; every field is checked and an error
//! names it (`meshes[1].transform.rotate.degrees: expected a number, found a string`).

use crate::bvh::BuildParams;
use crate::json::{join, kind};
use crate::render::Camera;
use crate::scene::desc::{fields, resolve, trs, Fields, SceneDesc, SceneError, SceneMesh};
use glam::{Affine3A, Mat4, Vec3};
use std::path::Path;

pub(super) fn describe(json: &serde_json::Value, base: &Path, f: &Fields) -> Result<SceneDesc, SceneError> {
    let root = f.object(json, "(top level)")?;
    f.known(root, "", &["camera", "meshes", "bvh", "note", "comment"])?;
    let camera = root.get("camera").map(|c| camera(c, f)).transpose()?;
    let meshes_json = f.get(json, "", "meshes")?;
    let list = f.array(meshes_json, "meshes")?;
    let mut meshes = Vec::new();
    for (i, m) in list.iter().enumerate() {
        let field = format!("meshes[{i}]");
        if let Some(o) = m.as_object() {
            f.known(o, &field, &["file", "transform", "if_missing"])?;
        }
        let file = f.get(m, &field, "file")?;
        let file = file
            .as_str()
            .ok_or_else(|| f.err(&join(&field, "file"), format!("expected a path, found {}", kind(file))))?;
        let transform = match m.get("transform") {
            Some(t) => transform(t, &join(&field, "transform"), f)?,
            None => Affine3A::IDENTITY,
        };
        let if_missing = m.get("if_missing").map(|v| f.text(v, &join(&field, "if_missing"))).transpose()?;
        meshes.push(SceneMesh { file: resolve(base, file), transform, if_missing });
    }
    let build = root.get("bvh").map(|b| bvh(b, f)).transpose()?;
    let note = root.get("note").map(|v| f.text(v, "note")).transpose()?;
    Ok(SceneDesc { camera, meshes, build, note, warnings: Vec::new() })
}

fn camera(c: &serde_json::Value, f: &Fields) -> Result<Camera, SceneError> {
    let (w, h) = f.size(f.get(c, "camera", "size")?, "camera.size")?;
    let cam = Camera {
        position: f.vec3(f.get(c, "camera", "position")?, "camera.position")?,
        look_at: f.vec3(f.get(c, "camera", "look_at")?, "camera.look_at")?,
        up: match c.get("up") {
            Some(u) => f.vec3(u, "camera.up")?,
            None => Vec3::Y,
        },
        vfov_deg: match c.get("vertical_fov") {
            Some(v) => f.number(v, "camera.vertical_fov")?,
            None => Camera::DEFAULT_VFOV_DEG,
        },
        width: w,
        height: h,
    };
    cam.validate().map_err(|e| f.err("camera", e.to_string()))?;
    Ok(cam)
}

/// `{"translate": [..], "rotate": {"axis": [..], "degrees": a}, "scale": s | [..]}` or
/// `{"matrix": [[4 numbers] × 4]}` (row-major, last row 0 0 0 1).
fn transform(t: &serde_json::Value, field: &str, f: &Fields) -> Result<Affine3A, SceneError> {
    let o = f.object(t, field)?;
    if let Some(m) = o.get("matrix") {
        if o.len() > 1 {
            return Err(f.err(field, "give either matrix or translate/rotate/scale, not both"));
        }
        let mf = join(field, "matrix");
        let rows = m.as_array().filter(|r| r.len() == 4).ok_or_else(|| f.err(&mf, "expected 4 rows of 4 numbers"))?;
        let mut v = [[0f32; 4]; 4];
        for (i, row) in rows.iter().enumerate() {
            let r = row
                .as_array()
                .filter(|r| r.len() == 4)
                .ok_or_else(|| f.err(&format!("{mf}[{i}]"), "expected 4 numbers"))?;
            for (j, x) in r.iter().enumerate() {
                v[i][j] = f.number(x, &format!("{mf}[{i}][{j}]"))?;
            }
        }
        if v[3] != [0.0, 0.0, 0.0, 1.0] {
            return Err(f.err(&format!("{mf}[3]"), "the last row must be [0, 0, 0, 1] (no projection)"));
        }
        let m = Mat4::from_cols_array_2d(&v).transpose();
        // Singular relative to its own scale: |det| against the product of its columns' lengths
        // (Hadamard's bound, 1 for any rotation and scale, 0 for a matrix that flattens), so a
        // matrix scaling by 1e-4 (det 1e-12) loads as `"scale": 0.0001` does.
        let m3 = glam::Mat3::from_mat4(m).as_dmat3();
        let lengths = m3.x_axis.length() * m3.y_axis.length() * m3.z_axis.length();
        if !(lengths > 0.0 && m3.determinant().abs() / lengths > 1e-6) {
            return Err(f.err(&mf, "the matrix is singular (it flattens the mesh)"));
        }
        return Ok(Affine3A::from_mat4(m));
    }
    for key in o.keys() {
        if !["translate", "rotate", "scale"].contains(&key.as_str()) {
            return Err(f.err(&join(field, key), "unknown field (expected translate, rotate, scale or matrix)"));
        }
    }
    let translate = o.get("translate").map(|v| f.vec3(v, &join(field, "translate"))).transpose()?.unwrap_or(Vec3::ZERO);
    let (axis, degrees) = match o.get("rotate") {
        Some(r) => {
            let rf = join(field, "rotate");
            let axis = f.vec3(f.get(r, &rf, "axis")?, &join(&rf, "axis"))?;
            if axis.length_squared() == 0.0 {
                return Err(f.err(&join(&rf, "axis"), "the rotation axis is zero"));
            }
            (axis, f.number(f.get(r, &rf, "degrees")?, &join(&rf, "degrees"))?)
        }
        None => (Vec3::Y, 0.0),
    };
    let scale = match o.get("scale") {
        Some(s) if s.is_number() => Vec3::splat(f.number(s, &join(field, "scale"))?),
        Some(s) => f.vec3(s, &join(field, "scale"))?,
        None => Vec3::ONE,
    };
    if scale.cmpeq(Vec3::ZERO).any() {
        return Err(f.err(&join(field, "scale"), "a scale of 0 flattens the mesh"));
    }
    Ok(trs(translate, axis, degrees.to_radians(), scale))
}

/// The scene's `bvh` object: the names and limits of `crate::options`, as the CLI takes them.
fn bvh(b: &serde_json::Value, f: &Fields) -> Result<BuildParams, SceneError> {
    use crate::options::{Choice, BUILD_PARAMS};
    fn choice<T: Choice>(v: &serde_json::Value, field: &str, f: &Fields) -> Result<T, SceneError> {
        v.as_str().and_then(T::from_name).ok_or_else(|| f.err(field, format!("expected one of {}", T::names())))
    }
    let o = f.object(b, "bvh")?;
    let mut p = BuildParams::default();
    for (key, v) in o {
        let field = join("bvh", key);
        match key.as_str() {
            "strategy" => p.strategy = choice(v, &field, f)?,
            "layout" => p.layout = choice(v, &field, f)?,
            k => match BUILD_PARAMS.iter().find(|o| o.key == k) {
                Some(o) => o.param.set(&mut p, o.from_json(v).map_err(|e| f.err(&field, e))?),
                None => {
                    let keys: Vec<&str> =
                        ["strategy", "layout"].into_iter().chain(BUILD_PARAMS.map(|o| o.key)).collect();
                    return Err(f.err(&field, format!("unknown field (expected {})", keys.join(", "))));
                }
            },
        }
    }
    Ok(p)
}

/// Parse a scene file's text (for tests and tools; `path` names it in errors and anchors paths).
pub fn parse_scene_file(path: &Path, text: &str) -> Result<SceneDesc, SceneError> {
    let json: serde_json::Value = crate::json::parse(text).map_err(|e| SceneError::Json {
        path: path.into(),
        line: e.line(),
        message: e.to_string(),
    })?;
    describe(&json, path.parent().unwrap_or(Path::new(".")), &fields(path))
}

/// A scene file for a camera, the meshes (paths written as given) and BVH settings.
pub fn write_scene_file(camera: &Camera, meshes: &[super::SceneMesh], build: &BuildParams) -> String {
    use crate::options::{ParamOption, BUILD_PARAMS};
    let mut bvh = serde_json::json!({ "strategy": build.strategy.name(), "layout": build.layout.name() });
    for o in &BUILD_PARAMS {
        bvh[o.key] = ParamOption::to_json(o.param.get(build));
    }
    let v3 = |v: Vec3| serde_json::json!([v.x, v.y, v.z]);
    let meshes: Vec<serde_json::Value> = meshes
        .iter()
        .map(|m| {
            let rows = Mat4::from(m.transform).transpose().to_cols_array_2d();
            serde_json::json!({ "file": m.file.to_string_lossy(), "transform": { "matrix": rows } })
        })
        .collect();
    let v = serde_json::json!({
        "camera": {
            "position": v3(camera.position), "look_at": v3(camera.look_at), "up": v3(camera.up),
            "vertical_fov": camera.vfov_deg, "size": [camera.width, camera.height],
        },
        "meshes": meshes,
        "bvh": bvh,
    });
    serde_json::to_string_pretty(&v).unwrap_or_default()
}
