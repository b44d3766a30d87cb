//! Pinned rays: a pixel's ray (or a typed one) traced step by step through the BVH that drew the
//! image (`bvh::trace`, the traversal that renders), and where the Ray panel and the viewport
//! stand in its steps. Each pinned ray keeps the BVH it was traced through, so the same pixel can
//! be pinned under two strategies and compared.

pub mod nodes;

use crate::bvh::{trace_query_into, Hit, NodeId, RayCounters, SceneBvh, StepKind, Trace, TraceLevel, TraceOptions};
use crate::geometry::Ray;
use crate::scene::SceneSource;
use glam::Vec3;
use std::sync::Arc;
use std::time::Instant;

/// Most rays pinned at once (the oldest goes when another is pinned).
pub const MAX_PINNED: usize = 4;

pub struct PinnedRay {
    /// "pixel 412, 230 · SAH binned, wide4".
    pub label: String,
    pub pixel: Option<(u32, u32)>,
    pub ray: Ray,
    pub bvh: Arc<SceneBvh>,
    pub opts: TraceOptions,
    pub hit: Option<Hit>,
    pub trace: Trace,
    /// The steps as the Ray window lists them: an imported tree's nodes by the dump's ids.
    pub named: Vec<crate::bvh::TraceStep>,
    /// The trace's totals: the counting sink's counts for this ray.
    pub counts: RayCounters,
    /// The `bvhscope trace` command that traces this ray through the same build (the scene's
    /// file named; none for the built-in scene, which has no file).
    pub command: Option<String>,
    /// An any-hit walk (a shadow or ambient-occlusion ray): it stops at the first hit found.
    pub any: bool,
}

/// Which of a pixel's secondary rays a pinned ray is.
#[derive(Clone, Copy, Debug)]
pub struct SecondaryOf {
    pub spec: crate::render::SecondarySpec,
    pub camera: crate::render::Camera,
    pub index: usize,
    pub of: usize,
}

impl PinnedRay {
    pub fn new(
        bvh: Arc<SceneBvh>,
        ray: Ray,
        opts: TraceOptions,
        pixel: Option<(u32, u32)>,
        source: &SceneSource,
    ) -> Self {
        Self::of(bvh, ray, opts, pixel, source, None)
    }

    /// Secondary ray `of.index` of `pixel` (from its camera ray's hit): walked as its kind asks,
    /// any hit for shadow and ao rays.
    pub fn of(
        bvh: Arc<SceneBvh>,
        ray: Ray,
        opts: TraceOptions,
        pixel: Option<(u32, u32)>,
        source: &SceneSource,
        secondary: Option<SecondaryOf>,
    ) -> Self {
        let any = secondary.is_some_and(|s| s.spec.kind.any_hit());
        let (hit, trace) = trace_query_into(&*bvh, &ray, opts, any, Trace::new());
        let mut at = match pixel {
            Some((x, y)) => format!("pixel {x}, {y}"),
            None => "typed ray".to_string(),
        };
        if let Some(s) = &secondary {
            at += &format!(" · {} ray {} of {}", s.spec.kind.name(), s.index, s.of);
        }
        let label = format!("{at} · {}", bvh.label());
        let counts = trace.counts();
        let command = match (source, secondary, pixel) {
            (SceneSource::File(path), Some(s), Some(p)) => Some(crate::explain::words::secondary_trace_command(
                path,
                &s.camera,
                p,
                &s.spec,
                s.index,
                &bvh.build_params(),
                opts,
            )),
            (SceneSource::File(path), _, _) => {
                let dump = bvh.import().map(|i| i.path.as_path());
                Some(crate::explain::words::trace_command(path, &ray, &bvh.build_params(), opts, dump))
            }
            (SceneSource::Builtin, ..) => None,
        };
        // An imported tree's nodes by the dump's ids and its triangles by the file's numbers, as
        // `bvhscope trace --bvh` prints them.
        let named = match (&*bvh, bvh.import()) {
            (SceneBvh::Single { mesh, .. }, Some(i)) => trace.steps.iter().map(|s| i.rename(s, mesh)).collect(),
            _ => trace.steps.clone(),
        };
        Self { label, pixel, ray, bvh, opts, hit, trace, named, counts, command, any }
    }

    pub fn len(&self) -> usize {
        self.trace.steps.len()
    }

    pub fn is_empty(&self) -> bool {
        self.trace.steps.is_empty()
    }

    /// Where the ray is drawn to: its hit, or past the farthest box it crossed (at least `far`).
    /// A two-level ray's object-space `t` is the world one, so every box's exit counts.
    pub fn end(&self, far: f32) -> Vec3 {
        let t = self.hit.map(|h| h.t).unwrap_or_else(|| {
            let exits = self.trace.steps.iter().filter_map(|s| match s.kind {
                StepKind::BoxTest { t_exit: Some(t), .. } => Some(t),
                _ => None,
            });
            exits.fold(far, f32::max)
        });
        self.ray.at(t)
    }
}

/// What the viewport draws of a ray at one step.
#[derive(Default)]
pub struct StepPicture {
    /// The node the walk is at (entered, or the leaf reached).
    pub current: Option<(TraceLevel, NodeId)>,
    /// Nodes entered before it.
    pub visited: Vec<(TraceLevel, NodeId)>,
    /// Nodes popped and skipped.
    pub skipped: Vec<(TraceLevel, NodeId)>,
    /// The box tested at this very step, and whether it was hit.
    pub tested: Option<(TraceLevel, NodeId, bool)>,
    /// Triangles of the current leaf tested so far: (id, hit).
    pub triangles: Vec<(u32, bool)>,
    /// The closest hit so far: its parameter along the ray.
    pub closest_t: Option<f32>,
}

impl PinnedRay {
    /// What has happened up to and including step `k`.
    pub fn picture(&self, k: usize) -> StepPicture {
        let mut p = StepPicture::default();
        for s in self.trace.steps.iter().take(k + 1) {
            let at = s.level;
            p.tested = None;
            match s.kind {
                StepKind::Enter { node, .. } => {
                    p.visited.extend(p.current.take());
                    p.current = Some((at, node));
                    p.triangles.clear();
                }
                StepKind::Leaf { node, .. } => {
                    if p.current != Some((at, node)) {
                        p.visited.extend(p.current.take());
                        p.current = Some((at, node));
                    }
                    p.triangles.clear();
                }
                StepKind::Skip { node, .. } => p.skipped.push((at, node)),
                StepKind::BoxTest { node, hit, .. } => p.tested = Some((at, node, hit)),
                StepKind::Triangle { triangle, hit, .. } => p.triangles.push((triangle, hit)),
                StepKind::ClosestHit { t, .. } => p.closest_t = Some(t),
                _ => {}
            }
        }
        p
    }
}

/// The pinned rays and the player over the selected one's steps.
#[derive(Default)]
pub struct RayView {
    pub pinned: Vec<PinnedRay>,
    pub selected: usize,
    /// The step shown (0-based) of the selected ray.
    pub step: usize,
    pub playing: bool,
    pub last_tick: Option<Instant>,
    /// The typed ray's fields: "x, y, z".
    pub origin_text: String,
    pub dir_text: String,
}

impl RayView {
    pub fn current(&self) -> Option<&PinnedRay> {
        self.pinned.get(self.selected)
    }

    /// Pin a ray (the oldest goes past `MAX_PINNED`), select it and show its first step.
    pub fn pin(&mut self, ray: PinnedRay) {
        if self.pinned.len() == MAX_PINNED {
            self.pinned.remove(0);
        }
        self.pinned.push(ray);
        self.selected = self.pinned.len() - 1;
        self.step = 0;
        self.playing = false;
    }

    pub fn unpin(&mut self, i: usize) {
        if i < self.pinned.len() {
            self.pinned.remove(i);
            self.selected = self.selected.min(self.pinned.len().saturating_sub(1));
            self.set_step(self.step);
        }
    }

    pub fn select(&mut self, i: usize) {
        if i < self.pinned.len() {
            self.selected = i;
            self.set_step(self.step);
        }
    }

    /// Show step `k`, kept within the selected ray's steps.
    pub fn set_step(&mut self, k: usize) {
        let n = self.current().map_or(0, |r| r.len());
        self.step = k.min(n.saturating_sub(1));
        if self.step + 1 >= n {
            self.playing = false;
        }
    }

    /// The ray typed in the fields: origin and direction, or why not.
    pub fn typed_ray(&self) -> Result<Ray, String> {
        let parse = |what: &str, s: &str| -> Result<Vec3, String> {
            let v: Vec<f32> = s
                .split([',', ' '])
                .filter(|c| !c.trim().is_empty())
                .map(|c| c.trim().parse::<f32>())
                .collect::<Result<_, _>>()
                .map_err(|_| format!("{what}: '{s}' is not three numbers x, y, z"))?;
            match v[..] {
                [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(Vec3::new(x, y, z)),
                _ => Err(format!("{what}: '{s}' is not three finite numbers x, y, z")),
            }
        };
        let (o, d) = (parse("origin", &self.origin_text)?, parse("direction", &self.dir_text)?);
        if d == Vec3::ZERO {
            return Err("direction: it is zero".into());
        }
        Ok(Ray::new(o, d))
    }
}
