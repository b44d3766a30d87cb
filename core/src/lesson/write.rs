//! A lesson written as the reader takes it back: what the app records (each step only what it
//! changes) reopens as the same steps. Paths are written relative to the lesson's folder when they
//! lie under it or beside it, so a lesson folder moves as a whole.

use super::{BuildEdit, Lesson, Show, Step};
use crate::options::{ParamOption, BUILD_PARAMS};
use crate::render::HeatRange;
use serde_json::{json, Map, Value};
use std::path::{Component, Path, PathBuf};

/// The lesson's text, to be saved as `path` (relative paths are written against its folder).
pub fn write_lesson(lesson: &Lesson, path: &Path) -> String {
    let base = path.parent().unwrap_or(Path::new("."));
    let steps: Vec<Value> = lesson.steps.iter().map(|s| step(s, base)).collect();
    let mut top = Map::new();
    if !lesson.title.is_empty() {
        top.insert("title".into(), lesson.title.clone().into());
    }
    top.insert("steps".into(), steps.into());
    let mut text = serde_json::to_string_pretty(&Value::Object(top)).unwrap_or_default();
    text.push('\n');
    text
}

fn step(s: &Step, base: &Path) -> Value {
    let mut o = Map::new();
    let mut put = |k: &str, v: Value| {
        o.insert(k.into(), v);
    };
    put("caption", s.caption.clone().into());
    if let Some(q) = &s.question {
        put("question", q.clone().into());
    }
    if let Some(a) = &s.answer {
        put("answer", a.clone().into());
    }
    if let Some(p) = &s.scene {
        put("scene", relative(p, base).to_string_lossy().replace('\\', "/").into());
    }
    if !s.bvh.is_empty() {
        put("bvh", build_edit(&s.bvh));
    }
    if let Some(v) = s.order {
        put("order", v.name().into());
    }
    if let Some(v) = s.test {
        put("test", v.name().into());
    }
    if !s.rays.is_empty() {
        let r = &s.rays;
        let mut m = Map::new();
        if let Some(k) = r.kind {
            m.insert("kind".into(), k.name().into());
        }
        if let Some(n) = r.samples {
            m.insert("samples".into(), n.into());
        }
        if let Some(n) = r.seed {
            m.insert("seed".into(), n.into());
        }
        if let Some(l) = r.ao_length {
            m.insert("ao_length".into(), l.into());
        }
        if let Some(l) = r.light {
            m.insert("light".into(), json!([l.x, l.y, l.z]));
        }
        put("rays", m.into());
    }
    if let Some(v) = s.view {
        put("view", v.name().into());
    }
    if let Some(v) = s.colormap {
        put("colormap", v.name().into());
    }
    match s.range {
        Some(HeatRange::Auto) => put("range", "auto".into()),
        Some(HeatRange::Fixed { min, max }) => put("range", json!([min, max])),
        None => {}
    }
    if let Some(c) = &s.camera {
        let v3 = |v: glam::Vec3| json!([v.x, v.y, v.z]);
        put(
            "camera",
            json!({
                "position": v3(c.position), "look_at": v3(c.look_at), "up": v3(c.up),
                "vertical_fov": c.vfov_deg, "size": [c.width, c.height],
            }),
        );
    }
    match s.boxes {
        Some(Some(d)) => put("boxes", d.into()),
        Some(None) => put("boxes", "off".into()),
        None => {}
    }
    if let Some(show) = &s.show {
        put("show", self::show(show));
    }
    Value::Object(o)
}

fn build_edit(e: &BuildEdit) -> Value {
    let mut m = Map::new();
    if let Some(s) = e.strategy {
        m.insert("strategy".into(), s.name().into());
    }
    if let Some(l) = e.layout {
        m.insert("layout".into(), l.name().into());
    }
    for &(param, v) in &e.params {
        if let Some(o) = BUILD_PARAMS.iter().find(|o| o.param == param) {
            m.insert(o.key.into(), ParamOption::to_json(v));
        }
    }
    Value::Object(m)
}

fn show(s: &Show) -> Value {
    match s {
        Show::Image => "image".into(),
        Show::Ray { pixel, step } => {
            let mut r = Map::new();
            r.insert("pixel".into(), json!([pixel.0, pixel.1]));
            if let Some(k) = step {
                r.insert("step".into(), (*k).into());
            }
            json!({ "ray": r })
        }
        Show::Node(n) => json!({ "node": n }),
        Show::Tree(n) => json!({ "tree": n }),
        Show::Compare { b, mode } => json!({ "compare": { "bvh": build_edit(b), "mode": mode.name() } }),
        Show::Replay { splits } => json!({ "replay": { "splits": splits } }),
    }
}

/// `p` as the lesson at `base` writes it: relative to `base` when it lies in `base` or beside it
/// (under `base`'s parent: `../scenes/lab.json`), so a lesson moves with its folder's neighbours;
/// else absolute. Both are made absolute (against the working folder) and `..` folded first.
fn relative(p: &Path, base: &Path) -> PathBuf {
    let (p, base) = (normal(p), normal(base));
    let up = base.parent().filter(|_| !p.starts_with(&base)).unwrap_or(&base);
    match p.strip_prefix(up) {
        Ok(rest) if up == base => rest.to_path_buf(),
        Ok(rest) if up.parent().is_some() => Path::new("..").join(rest),
        _ => p,
    }
}

/// `p` absolute with `.` and `..` folded (lexically: what a link points to is not looked up).
pub(super) fn normal(p: &Path) -> PathBuf {
    let abs = if p.is_absolute() { p.to_path_buf() } else { std::env::current_dir().unwrap_or_default().join(p) };
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            c => out.push(c.as_os_str()),
        }
    }
    out
}
