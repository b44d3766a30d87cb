//! Import of the Moer-lite renderer's `scene.json` (the NJU course framework the lab uses): the
//! pinhole camera (`transform.position/lookAt/up`, `verticalFov` in degrees, `film.size`) and the
//! `triangle` shapes of `scene.shapes` with their OBJ `file` and `transform` (`translate`, `scale`,
//! `rotate: {axis, radian}`, applied as world = T·R·S·p, as Moer-lite's `Shape` does). Moer-lite's
//! pinhole maps pixel centres exactly as our `Camera` does (row 0 at the top, x along right·aspect),
//! so its camera carries over unchanged. Analytic shapes are not tessellated yet: they are named
//! in a warning and the rest of the scene loads.

use crate::json::{join, kind};
use crate::render::Camera;
use crate::scene::desc::{resolve, trs, Fields, SceneDesc, SceneError, SceneMesh};
use glam::Vec3;
use std::path::Path;

/// A Moer-lite scene has a `scene` object and a camera with a `transform`.
pub(super) fn looks_like(json: &serde_json::Value) -> bool {
    json.get("scene").is_some_and(|s| s.is_object()) && json.get("camera").is_some_and(|c| c.get("transform").is_some())
}

pub(super) fn describe(json: &serde_json::Value, base: &Path, f: &Fields) -> Result<SceneDesc, SceneError> {
    let c = f.get(json, "", "camera")?;
    if let Some(t) = c.get("type").and_then(|t| t.as_str()) {
        if t != "pinhole" {
            return Err(f.err("camera.type", format!("'{t}' cameras are not supported (pinhole is)")));
        }
    }
    let t = f.get(c, "camera", "transform")?;
    let film = f.get(c, "camera", "film")?;
    let (w, h) = f.size(f.get(film, "camera.film", "size")?, "camera.film.size")?;
    let camera = Camera {
        position: f.vec3(f.get(t, "camera.transform", "position")?, "camera.transform.position")?,
        look_at: f.vec3(f.get(t, "camera.transform", "lookAt")?, "camera.transform.lookAt")?,
        up: f.vec3(f.get(t, "camera.transform", "up")?, "camera.transform.up")?,
        vfov_deg: f.number(f.get(c, "camera", "verticalFov")?, "camera.verticalFov")?,
        width: w,
        height: h,
    };
    camera.validate().map_err(|e| f.err("camera", e.to_string()))?;

    let shapes = f.get(f.get(json, "", "scene")?, "scene", "shapes")?;
    let list = f.array(shapes, "scene.shapes")?;
    let mut desc = SceneDesc { camera: Some(camera), ..Default::default() };
    let mut skipped = Vec::new();
    for (i, s) in list.iter().enumerate() {
        let field = format!("scene.shapes[{i}]");
        let ty = f.text(f.get(s, &field, "type")?, &join(&field, "type"))?;
        match ty.as_str() {
            "triangle" => {}
            "sphere" | "parallelogram" | "disk" | "cylinder" | "cone" | "cube" => {
                skipped.push(format!("{field} ({ty})"));
                continue;
            }
            other => return Err(f.err(&join(&field, "type"), format!("unknown shape type '{other}'"))),
        }
        let file = f.get(s, &field, "file")?;
        let file = file
            .as_str()
            .ok_or_else(|| f.err(&join(&field, "file"), format!("expected a path, found {}", kind(file))))?;
        let transform = match s.get("transform") {
            None => glam::Affine3A::IDENTITY,
            Some(t) => {
                let tf = join(&field, "transform");
                let vec = |key: &str, default: Vec3| -> Result<Vec3, SceneError> {
                    t.get(key).map_or(Ok(default), |v| f.vec3(v, &join(&tf, key)))
                };
                let (axis, radian) = match t.get("rotate") {
                    Some(r) => {
                        let rf = join(&tf, "rotate");
                        (
                            f.vec3(f.get(r, &rf, "axis")?, &join(&rf, "axis"))?,
                            f.number(f.get(r, &rf, "radian")?, &join(&rf, "radian"))?,
                        )
                    }
                    None => (Vec3::Y, 0.0),
                };
                let scale = vec("scale", Vec3::ONE)?;
                if scale.cmpeq(Vec3::ZERO).any() {
                    return Err(f.err(&join(&tf, "scale"), "a scale of 0 flattens the mesh"));
                }
                trs(vec("translate", Vec3::ZERO)?, axis, radian, scale)
            }
        };
        desc.meshes.push(SceneMesh::new(resolve(base, file), transform));
    }
    if !skipped.is_empty() {
        desc.warnings.push(format!("analytic shapes are not supported yet and were skipped: {}", skipped.join(", ")));
    }
    Ok(desc)
}
