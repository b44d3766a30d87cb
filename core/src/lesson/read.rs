//! The lesson file's reader: strict JSON (`crate::json`: every key once, every field checked), the
//! options by the names of `crate::options` (as the CLI and scene files take them), every error
//! one line naming the file, the step and the field (`steps[3].bvh.strategy: expected one of …`).
//!
//! ```json
//! { "title": "Why SAH wins",
//!   "steps": [
//!     { "caption": "Midpoint's boxes at depth 3", "scene": "../scenes/knot-on-floor.json",
//!       "bvh": { "strategy": "midpoint" }, "view": "normals", "boxes": 3 },
//!     { "caption": "The cost of each ray", "view": "visits", "range": [0, 30], "boxes": "off",
//!       "show": { "ray": { "pixel": [640, 300], "step": 12 } },
//!       "question": "Why is the floor hot?", "answer": "Its two triangles sit deep in the tree." } ] }
//! ```

use super::{BuildEdit, Lesson, RaysEdit, Show, Step};
use crate::json::{join, kind, Fields};
use crate::options::{Choice, BUILD_PARAMS};
use crate::render::secondary::MAX_SAMPLES;
use crate::render::{Camera, HeatRange};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// A lesson file is a few kilobytes of text; this bounds what a hostile one makes us read.
pub const MAX_LESSON_BYTES: u64 = 4 << 20;
/// More steps than any lecture has.
pub const MAX_STEPS: usize = 2000;
/// A caption, question or answer is a few lines.
const MAX_TEXT: usize = 4000;

#[derive(Debug, thiserror::Error)]
pub enum LessonError {
    #[error(transparent)]
    File(#[from] crate::files::FileError),
    #[error("{}: {message}", .path.display())]
    Too { path: PathBuf, message: String },
    #[error("{}: line {line}: not valid JSON: {message}", .path.display())]
    Json { path: PathBuf, line: usize, message: String },
    #[error("{}: {field}: {message}", .path.display())]
    Field { path: PathBuf, field: String, message: String },
}

type F<'a> = Fields<'a, LessonError>;

/// Whether `path` is a lesson file (not a scene, a mesh or a dump): JSON of at most
/// `MAX_LESSON_BYTES` whose top level is an object with a "steps" key. A scene file has no
/// "steps"; a lesson with mistakes still counts, so that opening it says what is wrong.
pub fn is_lesson(path: &Path) -> bool {
    let Ok((file, len)) = crate::files::open_regular(path) else { return false };
    if len > MAX_LESSON_BYTES {
        return false;
    }
    let Ok(Some(bytes)) = crate::files::read_limited(file, MAX_LESSON_BYTES) else { return false };
    matches!(serde_json::from_slice::<Value>(&bytes), Ok(Value::Object(o)) if o.contains_key("steps"))
}

/// Read the lesson file `path` (paths in it are relative to its folder).
pub fn read_lesson(path: &Path) -> Result<Lesson, LessonError> {
    let (file, _) = crate::files::open_regular(path)?;
    let too = |message: String| LessonError::Too { path: path.into(), message };
    let bytes = crate::files::read_limited(file, MAX_LESSON_BYTES)
        .map_err(|source| crate::files::FileError::Read { path: path.into(), source })?
        .ok_or_else(|| too(format!("more than the {} MB a lesson file may take", MAX_LESSON_BYTES >> 20)))?;
    let text =
        String::from_utf8(bytes).map_err(|e| too(format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to())))?;
    parse_lesson(path, &text)
}

/// A lesson from its text (`path` names it in errors and anchors its relative paths).
pub fn parse_lesson(path: &Path, text: &str) -> Result<Lesson, LessonError> {
    let json = crate::json::parse(text).map_err(|e| LessonError::Json {
        path: path.into(),
        line: e.line(),
        message: e.to_string(),
    })?;
    let f: F = Fields::new(path, |path, field, message| LessonError::Field {
        path: path.into(),
        field: field.into(),
        message,
    });
    let base = path.parent().unwrap_or(Path::new("."));
    let root = f.object(&json, "(top level)")?;
    f.known(root, "", &["title", "steps", "comment"])?;
    let title = root.get("title").map(|v| text_field(&f, v, "title")).transpose()?.unwrap_or_default();
    let list = f.array(f.get(&json, "", "steps")?, "steps")?;
    if list.is_empty() {
        return Err(f.err("steps", "a lesson needs at least one step"));
    }
    if list.len() > MAX_STEPS {
        return Err(f.err("steps", format!("{} steps, more than the {MAX_STEPS} a lesson may have", list.len())));
    }
    let steps = list
        .iter()
        .enumerate()
        .map(|(i, s)| step(&f, s, &format!("steps[{i}]"), base))
        .collect::<Result<Vec<_>, _>>()?;
    if steps[0].scene.is_none() {
        return Err(f.err("steps[0].scene", "missing: the first step names the scene or mesh the lesson opens"));
    }
    Ok(Lesson { title, steps })
}

const STEP_KEYS: [&str; 15] = [
    "caption", "question", "answer", "scene", "bvh", "order", "test", "rays", "view", "colormap", "range", "camera",
    "boxes", "show", "comment",
];

fn step(f: &F, v: &Value, at: &str, base: &Path) -> Result<Step, LessonError> {
    let o = f.object(v, at)?;
    f.known(o, at, &STEP_KEYS)?;
    let field = |k: &str| join(at, k);
    let text = |k: &str| o.get(k).map(|v| text_field(f, v, &field(k))).transpose();
    let caption =
        text("caption")?.ok_or_else(|| f.err(&field("caption"), "missing: every step says what to look at"))?;
    let (question, answer) = (text("question")?, text("answer")?);
    if answer.is_some() && question.is_none() {
        return Err(f.err(&field("answer"), "an answer needs its question"));
    }
    let scene = match o.get("scene") {
        Some(v) => {
            let name = text_field(f, v, &field("scene"))?;
            if name.is_empty() {
                return Err(f.err(&field("scene"), "an empty path"));
            }
            Some(crate::scene::resolve(base, &name))
        }
        None => None,
    };
    let bvh = o.get("bvh").map(|v| build_edit(f, v, &field("bvh"))).transpose()?.unwrap_or_default();
    let rays = o.get("rays").map(|v| rays(f, v, &field("rays"))).transpose()?.unwrap_or_default();
    let range = match o.get("range") {
        None => None,
        Some(Value::String(s)) if s == "auto" => Some(HeatRange::Auto),
        Some(v) => {
            let r = v.as_array().filter(|a| a.len() == 2);
            let bad = || f.err(&field("range"), format!("expected \"auto\" or [min, max], found {}", kind(v)));
            let r = r.ok_or_else(bad)?;
            let (min, max) = (
                f.number(&r[0], &format!("{}[0]", field("range")))?,
                f.number(&r[1], &format!("{}[1]", field("range")))?,
            );
            if !(min < max) {
                return Err(f.err(&field("range"), format!("min {min} is not below max {max}")));
            }
            Some(HeatRange::Fixed { min, max })
        }
    };
    let boxes = match o.get("boxes") {
        None => None,
        Some(Value::String(s)) if s == "off" => Some(None),
        Some(v) => Some(Some(f.whole(v, &field("boxes"), 0, 64).map_err(|_| {
            f.err(&field("boxes"), format!("expected a depth from 0 to 64 or \"off\", found {}", crate::json::shown(v)))
        })? as u32)),
    };
    let camera = o.get("camera").map(|v| camera(f, v, &field("camera"))).transpose()?;
    let show = o.get("show").map(|v| show(f, v, &field("show"), camera.as_ref())).transpose()?;
    Ok(Step {
        caption,
        question,
        answer,
        scene,
        bvh,
        order: o.get("order").map(|v| choice(f, v, &field("order"))).transpose()?,
        test: o.get("test").map(|v| choice(f, v, &field("test"))).transpose()?,
        rays,
        view: o.get("view").map(|v| choice(f, v, &field("view"))).transpose()?,
        colormap: o.get("colormap").map(|v| choice(f, v, &field("colormap"))).transpose()?,
        range,
        camera,
        boxes,
        show,
    })
}

fn text_field(f: &F, v: &Value, field: &str) -> Result<String, LessonError> {
    let t = f.text(v, field)?;
    if t.len() > MAX_TEXT {
        return Err(f.err(field, format!("{} bytes, more than the {MAX_TEXT} a text may have", t.len())));
    }
    Ok(t)
}

/// A name from a choice's table (`crate::options`).
fn choice<T: Choice>(f: &F, v: &Value, field: &str) -> Result<T, LessonError> {
    let bad = || f.err(field, format!("expected one of {}, found {}", T::names(), crate::json::shown(v)));
    v.as_str().and_then(T::from_name).ok_or_else(bad)
}

/// `{"strategy": …, "layout": …, "max_leaf_size": …}`: the names of a scene file's `bvh`.
pub(super) fn build_edit(f: &F, v: &Value, at: &str) -> Result<BuildEdit, LessonError> {
    let o = f.object(v, at)?;
    let mut e = BuildEdit::default();
    for (key, v) in o {
        let field = join(at, key);
        match key.as_str() {
            "strategy" => e.strategy = Some(choice(f, v, &field)?),
            "layout" => e.layout = Some(choice(f, v, &field)?),
            k => match BUILD_PARAMS.iter().find(|o| o.key == k) {
                Some(o) => e.params.push((o.param, o.from_json(v).map_err(|m| f.err(&field, m))?)),
                None => {
                    let keys: Vec<&str> =
                        ["strategy", "layout"].into_iter().chain(BUILD_PARAMS.map(|o| o.key)).collect();
                    return Err(f.err(&field, format!("unknown field (expected {})", keys.join(", "))));
                }
            },
        }
    }
    Ok(e)
}

fn rays(f: &F, v: &Value, at: &str) -> Result<RaysEdit, LessonError> {
    let o = f.object(v, at)?;
    f.known(o, at, &["kind", "samples", "seed", "ao_length", "light"])?;
    let field = |k: &str| join(at, k);
    Ok(RaysEdit {
        kind: o.get("kind").map(|v| choice(f, v, &field("kind"))).transpose()?,
        samples: o
            .get("samples")
            .map(|v| f.whole(v, &field("samples"), 1, MAX_SAMPLES as u64).map(|x| x as u32))
            .transpose()?,
        seed: o.get("seed").map(|v| f.whole(v, &field("seed"), 0, u64::MAX)).transpose()?,
        ao_length: o.get("ao_length").map(|v| share(f, v, &field("ao_length"))).transpose()?,
        light: o.get("light").map(|v| f.vec3(v, &field("light"))).transpose()?,
    })
}

/// A share of the scene's diagonal, as `--ao-length` takes it: above 0, at most 100.
fn share(f: &F, v: &Value, field: &str) -> Result<f32, LessonError> {
    match v.as_f64() {
        Some(x) if x > 0.0 && x <= 100.0 => Ok(x as f32),
        _ => Err(f.err(
            field,
            format!("expected a share of the diagonal above 0 (at most 100), found {}", crate::json::shown(v)),
        )),
    }
}

/// A camera as a scene file writes it, and its image size.
fn camera(f: &F, c: &Value, at: &str) -> Result<Camera, LessonError> {
    let o = f.object(c, at)?;
    f.known(o, at, &["position", "look_at", "up", "vertical_fov", "size"])?;
    let field = |k: &str| join(at, k);
    let (width, height) = f.size(f.get(c, at, "size")?, &field("size"))?;
    let cam = Camera {
        position: f.vec3(f.get(c, at, "position")?, &field("position"))?,
        look_at: f.vec3(f.get(c, at, "look_at")?, &field("look_at"))?,
        up: o.get("up").map(|u| f.vec3(u, &field("up"))).transpose()?.unwrap_or(glam::Vec3::Y),
        vfov_deg: match o.get("vertical_fov") {
            Some(v) => f.number_in(v, &field("vertical_fov"), 1.0, 179.0)? as f32,
            None => Camera::DEFAULT_VFOV_DEG,
        },
        width,
        height,
    };
    cam.validate().map_err(|e| f.err(at, e.to_string()))?;
    Ok(cam)
}

/// `"image"`, or an object naming one view and its target.
fn show(f: &F, v: &Value, at: &str, camera: Option<&Camera>) -> Result<Show, LessonError> {
    if v.as_str() == Some("image") {
        return Ok(Show::Image);
    }
    const VIEWS: [&str; 5] = ["ray", "node", "tree", "compare", "replay"];
    let o = f
        .object(v, at)
        .map_err(|_| f.err(at, format!("expected \"image\" or an object naming one of {}", VIEWS.join(", "))))?;
    f.known(o, at, &VIEWS)?;
    let (key, target) = match o.iter().next() {
        Some(kv) if o.len() == 1 => kv,
        _ => return Err(f.err(at, format!("expected one of {}, found {} of them", VIEWS.join(", "), o.len()))),
    };
    let field = join(at, key);
    let node = |v: &Value| f.whole(v, &field, 0, u32::MAX as u64).map(|n| n as u32);
    Ok(match key.as_str() {
        "ray" => {
            let r = f.object(target, &field)?;
            f.known(r, &field, &["pixel", "step"])?;
            let pixel = f.get(target, &field, "pixel")?;
            let p: Option<Vec<u64>> = pixel.as_array().and_then(|a| a.iter().map(Value::as_u64).collect());
            let (x, y) = match p.as_deref() {
                Some(&[x, y]) if x <= u32::MAX as u64 && y <= u32::MAX as u64 => (x as u32, y as u32),
                _ => return Err(f.err(&join(&field, "pixel"), "expected [x, y], whole numbers")),
            };
            if let Some(c) = camera.filter(|c| x >= c.width || y >= c.height) {
                return Err(f.err(
                    &join(&field, "pixel"),
                    format!("({x}, {y}) is outside the step's {}×{} image", c.width, c.height),
                ));
            }
            let step = r
                .get("step")
                .map(|s| f.whole(s, &join(&field, "step"), 0, u32::MAX as u64).map(|s| s as u32))
                .transpose()?;
            Show::Ray { pixel: (x, y), step }
        }
        "node" => Show::Node(node(target)?),
        "tree" => Show::Tree(node(target)?),
        "compare" => {
            let c = f.object(target, &field)?;
            f.known(c, &field, &["bvh", "mode"])?;
            let b = build_edit(f, f.get(target, &field, "bvh")?, &join(&field, "bvh"))?;
            let mode = c.get("mode").map(|m| choice(f, m, &join(&field, "mode"))).transpose()?.unwrap_or_default();
            Show::Compare { b, mode }
        }
        _ => {
            let r = f.object(target, &field)?;
            f.known(r, &field, &["splits"])?;
            let splits = f.whole(f.get(target, &field, "splits")?, &join(&field, "splits"), 0, u32::MAX as u64)? as u32;
            Show::Replay { splits }
        }
    })
}
