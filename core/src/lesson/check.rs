//! `bvhscope lesson --check`: a lesson checked as the app would show it, before a class sees it.
//! Every scene it names is opened (through the same readers and limits as any scene or mesh),
//! every step's tree is built (a tree is built once per scene and options), and every target is
//! looked up: a Node or Tree view's node among the tree's nodes, a Ray view's pixel in the image
//! and its step within the ray's walk, a replay's splits within the build's.
//! Each problem names the step and the field, as the reader's errors do.

use super::{Lesson, Show, StepState};
use crate::bvh::{trace_ray, Bvh, SceneBuild, SceneBvh};
use crate::render::{Camera, SecondaryRays, UpAxis};
use crate::scene::Scene;
use crate::work::WorkControl;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

/// One thing wrong with a lesson: the step (0-based, as in the file's `steps[i]`), the field
/// within it, and what is wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Problem {
    pub step: usize,
    pub field: String,
    pub message: String,
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "steps[{}].{}: {}", self.step, self.field, self.message)
    }
}

/// The camera a step shows: its own, else its scene's, else one framing the scene at 1280×720,
/// as `render` picks it when its flags leave it out.
pub fn step_camera(state: &StepState, scene: &Scene) -> Camera {
    state
        .camera
        .or(scene.camera)
        .unwrap_or_else(|| Camera::framing_up(&scene.bounds(), 1280, 720, UpAxis::Y, Camera::DEFAULT_VFOV_DEG))
}

/// Every problem of `lesson`, in step order; `progress(step, steps)` before each step. Stops
/// early (with what it found) when `control` is cancelled.
pub fn check(lesson: &Lesson, control: &WorkControl, mut progress: impl FnMut(usize, usize)) -> Vec<Problem> {
    let states = lesson.states();
    let mut scenes: HashMap<PathBuf, Option<Scene>> = HashMap::new();
    // Keyed by the options' debug text: `BuildParams` holds floats, so it is not `Hash`.
    let mut trees: HashMap<(PathBuf, String), Result<SceneBvh, String>> = HashMap::new();
    let mut out = Vec::new();
    for (i, state) in states.iter().enumerate() {
        if control.is_cancelled() {
            break;
        }
        progress(i, states.len());
        let problem = |field: &str, message: String| Problem { step: i, field: field.into(), message };
        // A scene's problem is said once, at the first step that shows it.
        let scene = scenes.entry(state.scene.clone()).or_insert_with(|| match Scene::open(&state.scene) {
            Ok(s) => Some(s),
            Err(e) => {
                let named = (0..=i).rev().find(|&k| lesson.steps[k].scene.is_some()).unwrap_or(i);
                out.push(Problem { step: named, field: "scene".into(), message: e.to_string() });
                None
            }
        });
        let Some(scene) = scene.as_ref() else { continue };
        let params = state.build_params(scene.build.as_ref());
        let tree = trees
            .entry((state.scene.clone(), format!("{params:?}")))
            .or_insert_with(|| scene.build(&SceneBuild { bvh: params, top: None }, control).map_err(|e| e.to_string()));
        let bvh = match tree {
            Ok(b) => b,
            Err(e) => {
                out.push(problem("bvh", format!("the tree cannot be built: {e}")));
                continue;
            }
        };
        let Some(binary) = bvh.binary_tree() else { continue };
        let camera = step_camera(state, scene);
        if let Some((field, message)) = target(state, bvh, &binary, &camera, scene) {
            out.push(problem(field, message));
        }
    }
    out
}

/// What is wrong with the step's explain view's target, if anything.
fn target(
    state: &StepState,
    bvh: &SceneBvh,
    binary: &Bvh,
    camera: &Camera,
    scene: &Scene,
) -> Option<(&'static str, String)> {
    let nodes = binary.nodes.len();
    let past = |n: u32| format!("node {n} is past the tree's last ({} nodes: 0 to {})", nodes, nodes.saturating_sub(1));
    match state.show {
        Show::Node(n) if n as usize >= nodes => Some(("show.node", past(n))),
        Show::Tree(n) if n as usize >= nodes => Some(("show.tree", past(n))),
        Show::Replay { splits } => {
            let all = crate::explain::replay::Replay::of(Arc::new(binary.clone())).splits();
            (splits as usize > all)
                .then(|| ("show.replay.splits", format!("{splits} splits, more than the build's {all}")))
        }
        Show::Ray { pixel: (x, y), step } => {
            if x >= camera.width || y >= camera.height {
                return Some((
                    "show.ray.pixel",
                    format!("({x}, {y}) is outside the step's {}×{} image", camera.width, camera.height),
                ));
            }
            let k = step?;
            let ray = match state.rays.kind.is_secondary() {
                false => camera.ray_gen().pixel_ray(x, y),
                true => {
                    let sec = SecondaryRays::new(state.rays, &scene.bounds(), camera);
                    match sec.pixel_rays(bvh, bvh, camera, state.trace, (x, y)).and_then(|r| r.first().copied()) {
                        Some(r) => r,
                        None => {
                            return Some((
                                "show.ray.pixel",
                                format!("({x}, {y})'s camera ray misses, so it has no {} rays", state.rays.kind.name()),
                            ))
                        }
                    }
                }
            };
            let walk = trace_ray(bvh, &ray, state.trace).1.taken();
            (k as u64 > walk)
                .then(|| ("show.ray.step", format!("step {k}, past the end of the ray's walk of {walk} steps")))
        }
        _ => None,
    }
}
