//! The rubric: how a class is graded, from an optional JSON file, checked as the scene file is
//! (every field; an unknown or repeated key is an error naming it, with the file):
//!
//! ```json
//! {
//!   "note": "Lab 1, BVH",
//!   "mesh": "models/Monkey.obj",
//!   "camera": { "position": [0, 1, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "vertical_fov": 45, "size": [480, 270] },
//!   "rays": 100000,
//!   "time_rays": 16384,
//!   "required": ["structure", "coverage", "bounds", "rays"],
//!   "references": ["sah", "midpoint"],
//!   "rank_by": "sah_cost",
//!   "good": { "sah_cost_within": 0.10, "nodes_per_ray_within": 0.25, "tri_tests_per_ray_within": 0.5,
//!             "speedup_at_least": 50, "max_depth_at_most": 64 }
//! }
//! ```
//!
//! Every key is optional. `mesh` (relative to the rubric) must be the mesh the command is given:
//! the rubric names the mesh its thresholds were set for. A "within" threshold is a fraction over
//! bvhscope's SAH tree in the same layout (0.10: at most 10 % above it).

use super::{GradeError, Quality, RankBy, VersusSah};
use crate::bvh::Strategy;
use crate::explain::check::Group;
use crate::json::Fields;
use glam::Vec3;
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

/// What is "good", beyond correct; each threshold optional.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Good {
    pub sah_cost_within: Option<f64>,
    pub nodes_per_ray_within: Option<f64>,
    pub tri_tests_per_ray_within: Option<f64>,
    pub speedup_at_least: Option<f64>,
    pub max_depth_at_most: Option<u32>,
}

impl Good {
    /// The thresholds `q` misses, in words (none: good). `v` is `q` over bvhscope's SAH tree.
    pub fn misses(&self, q: &Quality, v: &VersusSah) -> Vec<String> {
        let mut out = Vec::new();
        let pct = |x: f64| format!("{:+.1} %", (x - 1.0) * 100.0);
        let mut within = |limit: Option<f64>, ratio: f64, what: &str| {
            if let Some(w) = limit.filter(|&w| !(ratio <= 1.0 + w)) {
                out.push(format!("{what} {} of the SAH tree's (good: within {:.0} %)", pct(ratio), w * 100.0));
            }
        };
        within(self.sah_cost_within, v.sah_cost, "SAH cost");
        within(self.nodes_per_ray_within, v.nodes_per_ray, "nodes per ray");
        within(self.tri_tests_per_ray_within, v.tri_tests_per_ray, "triangle tests per ray");
        if let Some(s) = self.speedup_at_least.filter(|&s| !(q.speedup_over_linear >= s)) {
            out.push(format!("speed-up over the linear scan {:.0}× (good: at least {s}×)", q.speedup_over_linear));
        }
        if let Some(d) = self.max_depth_at_most.filter(|&d| q.max_depth > d) {
            out.push(format!("depth {} (good: at most {d})", q.max_depth));
        }
        out
    }

    /// Whether any threshold is set.
    pub fn any(&self) -> bool {
        *self != Good::default()
    }
}

/// A camera as a rubric gives it (its size apart: `Rubric::size`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RubricCamera {
    pub position: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    pub vertical_fov: f32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Rubric {
    /// The file it was read from; `None` for the default rubric.
    pub file: Option<PathBuf>,
    pub note: Option<String>,
    pub mesh: Option<PathBuf>,
    pub camera: Option<RubricCamera>,
    pub size: Option<(u32, u32)>,
    pub rays: Option<u64>,
    pub time_rays: Option<u32>,
    /// The checks whose defects fail a submission (structure always: a tree with structure
    /// defects cannot be traced).
    pub required: Vec<Group>,
    pub references: Vec<Strategy>,
    pub rank_by: RankBy,
    pub good: Good,
}

impl Default for Rubric {
    /// Every check required; SAH binned and midpoint as references; ranked by SAH cost; good
    /// within 10 % of the SAH tree's SAH cost (the lab's bonus exercise).
    fn default() -> Self {
        Rubric {
            file: None,
            note: None,
            mesh: None,
            camera: None,
            size: None,
            rays: None,
            time_rays: None,
            required: Group::ALL.to_vec(),
            references: vec![Strategy::SahBinned, Strategy::Midpoint],
            rank_by: RankBy::SahCost,
            good: Good { sah_cost_within: Some(0.10), ..Good::default() },
        }
    }
}

const KEYS: [&str; 11] =
    ["note", "comment", "mesh", "camera", "rays", "time_rays", "required", "references", "rank_by", "good", "size"];
const CAMERA_KEYS: [&str; 5] = ["position", "look_at", "up", "vertical_fov", "size"];
const GOOD_KEYS: [&str; 5] =
    ["sah_cost_within", "nodes_per_ray_within", "tri_tests_per_ray_within", "speedup_at_least", "max_depth_at_most"];

/// A rubric file's largest size: a rubric is a few hundred bytes.
const MAX_BYTES: u64 = 1 << 20;

impl Rubric {
    /// Read a rubric file (a regular file, at most a megabyte).
    pub fn read(path: &Path) -> Result<Rubric, GradeError> {
        let (file, _) = crate::files::open_regular(path)?;
        let read_err = |source| crate::files::FileError::Read { path: path.into(), source };
        let bytes = crate::files::read_limited(file, MAX_BYTES).map_err(read_err)?;
        let err =
            |message: &str| GradeError::Rubric { path: path.into(), field: "(file)".into(), message: message.into() };
        let bytes = bytes.ok_or_else(|| err("more than a megabyte: not a rubric"))?;
        let text = String::from_utf8(bytes).map_err(|_| err("not UTF-8 text"))?;
        Rubric::parse(path, &text)
    }

    /// A rubric from its text (`path` names it in errors and anchors `mesh`).
    pub fn parse(path: &Path, text: &str) -> Result<Rubric, GradeError> {
        let f = Fields::new(path, |path, field, message| GradeError::Rubric {
            path: path.into(),
            field: field.into(),
            message,
        });
        // A key given twice is refused: a rubric whose first "good" were silently lost would
        // grade as if nothing were wrong.
        let json: Value = crate::json::parse(text).map_err(|e| f.err(&format!("line {}", e.line()), e.to_string()))?;
        let root = f.object(&json, "(top level)")?;
        f.known(root, "", &KEYS)?;
        let mut r = Rubric { file: Some(path.to_path_buf()), ..Rubric::default() };
        r.note = root.get("note").map(|v| f.text(v, "note")).transpose()?;
        if let Some(m) = root.get("mesh") {
            let m = f.text(m, "mesh")?;
            r.mesh = Some(path.parent().unwrap_or(Path::new(".")).join(m));
        }
        if let Some(c) = root.get("camera") {
            let o = f.object(c, "camera")?;
            f.known(o, "camera", &CAMERA_KEYS)?;
            let need = |k: &str| o.get(k).ok_or_else(|| f.err(&format!("camera.{k}"), "missing"));
            r.camera = Some(RubricCamera {
                position: f.vec3(need("position")?, "camera.position")?,
                look_at: f.vec3(need("look_at")?, "camera.look_at")?,
                up: o.get("up").map(|u| f.vec3(u, "camera.up")).transpose()?.unwrap_or(Vec3::Y),
                vertical_fov: match o.get("vertical_fov") {
                    Some(v) => f.number_in(v, "camera.vertical_fov", 0.01, 179.9)? as f32,
                    None => crate::render::Camera::DEFAULT_VFOV_DEG,
                },
            });
            r.size = o.get("size").map(|s| f.size(s, "camera.size")).transpose()?;
        }
        if let Some(s) = root.get("size") {
            if r.size.is_some() {
                return Err(f.err("size", "given twice: here and as camera.size"));
            }
            r.size = Some(f.size(s, "size")?);
        }
        r.rays = root.get("rays").map(|v| f.whole(v, "rays", 0, super::super::check::MAX_RAYS)).transpose()?;
        r.time_rays =
            root.get("time_rays").map(|v| f.whole(v, "time_rays", 1, 1_000_000).map(|n| n as u32)).transpose()?;
        if let Some(v) = root.get("required") {
            let names: Vec<&str> = Group::ALL.iter().map(|g| g.label()).collect();
            r.required =
                f.list(v, "required", |s| Group::ALL.into_iter().find(|g| g.label() == s), &names.join(", "))?;
            if !r.required.contains(&Group::Structure) {
                return Err(
                    f.err("required", "must hold \"structure\": a tree with structure defects cannot be traced")
                );
            }
        }
        if let Some(v) = root.get("references") {
            r.references = f.list(v, "references", Strategy::from_name, &Strategy::ALL.map(|s| s.name()).join(", "))?;
        }
        if let Some(v) = root.get("rank_by") {
            let names = RankBy::ALL.map(|r| r.name()).join(", ");
            r.rank_by = v
                .as_str()
                .and_then(RankBy::from_name)
                .ok_or_else(|| f.err("rank_by", format!("expected one of {names}")))?;
        }
        if let Some(g) = root.get("good") {
            let o = f.object(g, "good")?;
            f.known(o, "good", &GOOD_KEYS)?;
            let fraction = |k: &str| o.get(k).map(|v| f.number_in(v, &format!("good.{k}"), 0.0, 1e6)).transpose();
            r.good = Good {
                sah_cost_within: fraction("sah_cost_within")?,
                nodes_per_ray_within: fraction("nodes_per_ray_within")?,
                tri_tests_per_ray_within: fraction("tri_tests_per_ray_within")?,
                speedup_at_least: fraction("speedup_at_least")?,
                max_depth_at_most: o
                    .get("max_depth_at_most")
                    .map(|v| f.whole(v, "good.max_depth_at_most", 0, u32::MAX as u64).map(|n| n as u32))
                    .transpose()?,
            };
        }
        Ok(r)
    }

    /// `Err` when the rubric names another mesh than `given` (the same file by any name passes).
    pub fn check_mesh(&self, given: &Path) -> Result<(), GradeError> {
        let (Some(m), Some(file)) = (&self.mesh, &self.file) else { return Ok(()) };
        if same_file::is_same_file(m, given).unwrap_or(false) {
            return Ok(());
        }
        let message = format!(
            "names {}, but the class is graded against {}: give that mesh, or leave \"mesh\" out of the rubric",
            m.display(),
            given.display()
        );
        Err(GradeError::Rubric { path: file.clone(), field: "mesh".into(), message })
    }

    /// The rubric as a rubric file writes it, every setting given (what the report states).
    pub fn to_json(&self) -> Value {
        let mut o = Map::new();
        if let Some(n) = &self.note {
            o.insert("note".into(), json!(n));
        }
        if let Some(m) = &self.mesh {
            o.insert("mesh".into(), json!(m.display().to_string()));
        }
        if let Some(c) = &self.camera {
            let v = |v: Vec3| json!([v.x, v.y, v.z]);
            let cam = json!({"position": v(c.position), "look_at": v(c.look_at), "up": v(c.up), "vertical_fov": c.vertical_fov});
            o.insert("camera".into(), cam);
        }
        if let Some((w, h)) = self.size {
            o.insert("size".into(), json!([w, h]));
        }
        if let Some(n) = self.rays {
            o.insert("rays".into(), json!(n));
        }
        if let Some(n) = self.time_rays {
            o.insert("time_rays".into(), json!(n));
        }
        o.insert("required".into(), json!(self.required.iter().map(|g| g.label()).collect::<Vec<_>>()));
        o.insert("references".into(), json!(self.references.iter().map(|s| s.name()).collect::<Vec<_>>()));
        o.insert("rank_by".into(), json!(self.rank_by.name()));
        let g = &self.good;
        let mut good = Map::new();
        let mut put = |k: &str, v: Option<f64>| {
            if let Some(v) = v {
                good.insert(k.into(), json!(v));
            }
        };
        put("sah_cost_within", g.sah_cost_within);
        put("nodes_per_ray_within", g.nodes_per_ray_within);
        put("tri_tests_per_ray_within", g.tri_tests_per_ray_within);
        put("speedup_at_least", g.speedup_at_least);
        if let Some(d) = g.max_depth_at_most {
            good.insert("max_depth_at_most".into(), json!(d));
        }
        o.insert("good".into(), Value::Object(good));
        Value::Object(o)
    }
}
