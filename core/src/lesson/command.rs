//! The command lines of a lesson's step: the `bvhscope render` words that draw its picture (the
//! handout runs exactly these, so its PNG is `render`'s, byte for byte) and the command-line twin
//! of the explain view it opens (`trace`, `inspect`, `replay`), printed beside the picture. A
//! step's words name only what the lesson named: what it leaves out is the scene's own (its
//! `bvh` settings, its camera) or `render`'s default, as in the app.

use super::{BuildEdit, Show, StepState};
use crate::bvh::{TraceOptions, TraversalOrder};
use crate::geometry::TriangleTest;
use crate::options::BUILD_PARAMS;
use crate::render::{Camera, ColorMap, HeatRange, PairView, RayKind};
use glam::Vec3;
use std::path::{Component, Path, PathBuf};

/// The words after `bvhscope` that render `state`'s picture of the scene at `scene` to `png`.
pub fn render_words(state: &StepState, scene: &Path, png: &Path) -> Vec<String> {
    let mut w = vec!["render".to_string(), scene.display().to_string()];
    build_words(&state.build, &mut w);
    trace_words(state.trace, &mut w);
    w.extend(["--view".into(), state.view.name().into()]);
    if state.colormap != ColorMap::default() {
        w.extend(["--colormap".into(), state.colormap.name().into()]);
    }
    // A difference has its own scale (± a percentile of |B − A|, as the app's Compare starts
    // it): the heatmap's range is not the difference's.
    let difference = matches!(against(state), Some((_, mode)) if mode == PairView::Difference.name());
    if let (HeatRange::Fixed { min, max }, true, false) = (state.range, state.view.is_heatmap(), difference) {
        w.extend(["--range".into(), format!("{min}:{max}")]);
    }
    camera_words(state.camera.as_ref(), &mut w);
    ray_words(state, &mut w);
    if let Some(d) = state.boxes {
        w.extend(["--boxes".into(), d.to_string()]);
    }
    if let Some((strategy, mode)) = against(state) {
        w.extend(["--against".into(), strategy.into(), "--pair-view".into(), mode.into()]);
    }
    w.extend(["-o".into(), png.display().to_string()]);
    w
}

/// `Show::Compare` as `render --against`: only when B differs from A in its strategy alone (what
/// `--against` builds), and a difference only of a heatmap.
fn against(state: &StepState) -> Option<(&'static str, &'static str)> {
    let Show::Compare { b, mode } = &state.show else { return None };
    let strategy_only = b.layout.is_none() && b.params.is_empty();
    let drawable = state.view.is_heatmap() || *mode != PairView::Difference;
    Some((b.strategy?.name(), mode.name())).filter(|_| strategy_only && drawable)
}

/// The command-line twin of the explain view the step opens (none for the image alone or
/// Compare, whose picture `render --against` draws): words after `bvhscope`.
pub fn explain_words(state: &StepState, scene: &Path) -> Option<Vec<String>> {
    let mut w = vec![String::new(), scene.display().to_string()];
    match state.show {
        Show::Ray { pixel: (x, y), .. } => {
            w[0] = "trace".into();
            w.extend(["--pixel".into(), format!("{x},{y}")]);
            camera_words(state.camera.as_ref(), &mut w);
            ray_words(state, &mut w);
        }
        Show::Node(n) | Show::Tree(n) => {
            w[0] = "inspect".into();
            w.extend(["--node".into(), n.to_string()]);
        }
        Show::Replay { .. } => {
            w[0] = "replay".into();
            camera_words(state.camera.as_ref(), &mut w);
        }
        Show::Image | Show::Compare { .. } => return None,
    }
    let mut build = Vec::new();
    build_words(&state.build, &mut build);
    if !matches!(state.show, Show::Node(_) | Show::Tree(_) | Show::Replay { .. }) {
        trace_words(state.trace, &mut build);
    }
    w.splice(2..2, build);
    if matches!(state.show, Show::Replay { .. }) {
        w.extend(["-o".into(), "replay.png".into()]);
    }
    Some(w)
}

fn build_words(b: &BuildEdit, w: &mut Vec<String>) {
    if let Some(s) = b.strategy {
        w.extend(["--strategy".into(), s.name().into()]);
    }
    for &(param, v) in &b.params {
        if let Some(o) = BUILD_PARAMS.iter().find(|o| o.param == param) {
            w.extend([format!("--{}", o.name), v.to_string()]);
        }
    }
    if let Some(l) = b.layout {
        w.extend(["--layout".into(), l.name().into()]);
    }
}

fn trace_words(t: TraceOptions, w: &mut Vec<String>) {
    if t.order != TraversalOrder::default() {
        w.extend(["--order".into(), t.order.name().into()]);
    }
    if t.test != TriangleTest::default() {
        w.extend(["--triangle-test".into(), t.test.name().into()]);
    }
}

fn camera_words(c: Option<&Camera>, w: &mut Vec<String>) {
    let Some(c) = c else { return };
    let v = |v: Vec3| format!("{},{},{}", v.x, v.y, v.z);
    w.extend(["--camera".into(), format!("{}:{}:{}", v(c.position), v(c.look_at), v(c.up))]);
    w.extend(["--fov".into(), c.vfov_deg.to_string(), "--size".into(), format!("{}x{}", c.width, c.height)]);
}

fn ray_words(state: &StepState, w: &mut Vec<String>) {
    let r = &state.rays;
    if r.kind == RayKind::Primary {
        return;
    }
    w.extend(["--ray-kind".into(), r.kind.name().into(), "--samples".into(), r.samples.to_string()]);
    w.extend(["--ao-length".into(), r.ao_length.to_string(), "--seed".into(), r.seed.to_string()]);
    if let Some(l) = r.light {
        w.extend(["--light".into(), format!("{},{},{}", l.x, l.y, l.z)]);
    }
}

/// `words` as one line to paste into a shell, `bvhscope` first.
pub fn shown(words: &[String]) -> String {
    let quoted: Vec<String> = words.iter().map(|w| crate::explain::words::shell_word(w)).collect();
    format!("bvhscope {}", quoted.join(" "))
}

/// `p` with `.` and `x/..` folded away lexically, relative paths kept relative
/// (`lessons/../scenes/a.json` is `scenes/a.json`): the scene as a reader of the handout names it.
pub fn folded(p: &Path) -> PathBuf {
    let mut out: Vec<Component> = Vec::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    if out.is_empty() {
        return PathBuf::from(".");
    }
    out.iter().collect()
}
