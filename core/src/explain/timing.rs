//! How fast a tree traces, as a student's renderer would see it: the camera's primary rays traced
//! one at a time, closest hit only, no shading, and the same rays through the linear scan, for
//! the speed-up the lab asks for. One implementation for `compare`'s trace column, the app's
//! statistics panel and `grade`: the same rays, the same clock, the same runs (`time_tree`).
//!
//! The linear scan tests every triangle for every ray, so on a big mesh a whole frame would take
//! minutes: it is timed on the whole frame only when that is projected to fit the budget, else on
//! an evenly spread sample of the frame's rays, scaled to the frame (and said so).

use crate::bvh::{Accelerator, NoStats, TraceOptions};
use crate::render::Camera;
use crate::work::{Cancelled, WorkControl};
use rayon::prelude::*;
use serde::Serialize;
use std::time::{Duration, Instant};

/// Pixel `i` of `n` evenly spread over the camera's frame (all of them, in order, when `n` is the
/// pixel count).
pub fn sample_pixel(camera: &Camera, i: usize, n: usize) -> (u32, u32) {
    let total = camera.width as usize * camera.height as usize;
    let p = (i * total / n.max(1)) as u32;
    (p % camera.width, p / camera.width)
}

/// Trace `n` of the camera's pixels (evenly spread) one ray at a time, closest hit only, on the
/// current thread pool: the work of a renderer's intersection loop and nothing else.
pub fn trace_rays<A: Accelerator>(accel: &A, camera: &Camera, trace: TraceOptions, n: usize) -> Duration {
    let gen = camera.ray_gen();
    let start = Instant::now();
    (0..n).into_par_iter().with_min_len(256).for_each(|i| {
        let (x, y) = sample_pixel(camera, i, n);
        let mut ray = gen.pixel_ray(x, y);
        std::hint::black_box(accel.closest_hit(&mut ray, trace, &mut NoStats));
    });
    start.elapsed()
}

/// `trace_rays` in chunks, checking `control` between them (a linear scan of a big mesh runs for
/// seconds) and counting the rays done.
fn trace_rays_controlled<A: Accelerator>(
    accel: &A,
    camera: &Camera,
    trace: TraceOptions,
    n: usize,
    control: &WorkControl,
) -> Result<Duration, Cancelled> {
    let gen = camera.ray_gen();
    let mut spent = Duration::ZERO;
    let chunk = 4096;
    for start in (0..n).step_by(chunk) {
        control.check()?;
        let end = (start + chunk).min(n);
        let t = Instant::now();
        (start..end).into_par_iter().with_min_len(256).for_each(|i| {
            let (x, y) = sample_pixel(camera, i, n);
            let mut ray = gen.pixel_ray(x, y);
            std::hint::black_box(accel.closest_hit(&mut ray, trace, &mut NoStats));
        });
        spent += t.elapsed();
        control.add_done((end - start) as u64);
    }
    Ok(spent)
}

/// A linear scan's time on the frame: on all of it when projected to fit `budget`, else on a
/// spread sample (about a fifth of the budget's worth), scaled to the frame. Returns (ms for the
/// frame, rays timed when sampled).
pub fn time_linear<A: Accelerator>(
    linear: &A,
    camera: &Camera,
    trace: TraceOptions,
    budget: Duration,
    control: &WorkControl,
) -> Result<(f64, Option<usize>), Cancelled> {
    let total = camera.width as usize * camera.height as usize;
    let probe = 256.min(total);
    let t = trace_rays_controlled(linear, camera, trace, probe, control)?;
    let projected = t.as_secs_f64() * total as f64 / probe as f64;
    if projected <= budget.as_secs_f64() {
        return Ok((ms(trace_rays_controlled(linear, camera, trace, total, control)?), None));
    }
    let n = ((budget.as_secs_f64() / 5.0 / t.as_secs_f64().max(1e-9)) * probe as f64) as usize;
    let n = n.clamp(probe, total);
    let t = trace_rays_controlled(linear, camera, trace, n, control)?;
    Ok((ms(t) * total as f64 / n as f64, Some(n)))
}

pub fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Runs of a tree's trace timed for a speed-up unless told otherwise (`compare --runs`' default):
/// the median is taken, as one run, often the first and cold, can be twice the next on a busy
/// machine (the app's single run said 73× where `compare`'s median said 105×, issue 59).
pub const RUNS: u32 = 5;

/// Runs of one measure stop once they have taken this long in all (at least one is made).
pub const BUDGET_MS: f64 = 1000.0;

/// The median of up to `runs` timings by `time` (ms), or of fewer once they pass `BUDGET_MS` in
/// all, so that a slow mesh's table still comes in minutes; with the runs made. Past the budget,
/// one more run when the count is even: the median of two would be the slower, often the first,
/// cold one.
pub fn budgeted_median<E>(runs: u32, mut time: impl FnMut() -> Result<f64, E>) -> Result<(f64, usize), E> {
    let mut times = vec![time()?];
    while times.len() < runs as usize && (times.iter().sum::<f64>() < BUDGET_MS || times.len().is_multiple_of(2)) {
        times.push(time()?);
    }
    times.sort_by(f64::total_cmp);
    Ok((times[times.len() / 2], times.len()))
}

/// A tree's trace of the camera's whole frame, single rays on the current thread pool: the median
/// of up to `runs` runs within `BUDGET_MS` (ms, runs made). The trace column of `compare` and the
/// app's speed-up both take it.
pub fn time_tree<A: Accelerator>(
    tree: &A,
    camera: &Camera,
    trace: TraceOptions,
    runs: u32,
    control: &WorkControl,
) -> Result<(f64, usize), Cancelled> {
    let rays = camera.width as usize * camera.height as usize;
    budgeted_median(runs, || trace_rays_controlled(tree, camera, trace, rays, control).map(ms))
}

/// A tree's single-ray trace time against the linear scan's, on one thread.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Speedup {
    /// Rays of the frame.
    pub rays: usize,
    /// The tree's trace of the whole frame (ms; the median of `tree_runs` runs).
    pub tree_ms: f64,
    pub tree_runs: usize,
    /// The linear scan's, for the whole frame (ms; projected from `linear_sampled` rays when set).
    pub linear_ms: f64,
    pub linear_sampled: Option<usize>,
    /// `linear_ms / tree_ms`.
    pub speedup: f64,
}

impl Speedup {
    /// The speed-up of a tree timed by `time_tree` over a scan timed by `time_linear`, on `rays`.
    pub fn of(
        rays: usize,
        (tree_ms, tree_runs): (f64, usize),
        (linear_ms, linear_sampled): (f64, Option<usize>),
    ) -> Self {
        Self { rays, tree_ms, tree_runs, linear_ms, linear_sampled, speedup: linear_ms / tree_ms.max(1e-9) }
    }
}

/// `tree` and `linear` traced on `camera`'s frame one ray at a time on one thread (the lab's
/// speed-up: what one core of a student's renderer gains): the tree by `time_tree` (`runs`), the
/// linear scan by `time_linear` within `budget`, as `compare` times its rows; `control` counts
/// the rays and can stop it.
pub fn speedup_one_thread<A: Accelerator + Sync, L: Accelerator + Sync>(
    tree: &A,
    linear: &L,
    camera: &Camera,
    trace: TraceOptions,
    runs: u32,
    budget: Duration,
    control: &WorkControl,
) -> Result<Speedup, Cancelled> {
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a thread pool can be started");
    let rays = camera.width as usize * camera.height as usize;
    control.set_total(rays as u64 * (runs as u64 + 1));
    one.install(|| {
        let tree = time_tree(tree, camera, trace, runs, control)?;
        Ok(Speedup::of(rays, tree, time_linear(linear, camera, trace, budget, control)?))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{AnyBvh, BuildParams, LinearScan};
    use crate::mesh::generate;

    /// A tree beats the scan on a mesh of thousands of triangles; a budget too small for the whole
    /// frame samples it; a cancelled control stops it.
    #[test]
    fn a_tree_is_faster_than_the_scan_and_a_small_budget_samples() {
        let mesh = generate::torus_knot(2, 3, 0.3, 128, 12);
        let camera = Camera::framing_up(&mesh.bounds(), 64, 48, crate::render::UpAxis::Y, 45.0);
        let bvh = AnyBvh::build(&mesh, &BuildParams::default());
        let linear = LinearScan::new(&mesh);
        let s = speedup_one_thread(
            &bvh,
            &linear,
            &camera,
            TraceOptions::default(),
            RUNS,
            Duration::from_secs(30),
            &WorkControl::new(),
        )
        .unwrap();
        assert_eq!(s.rays, 64 * 48);
        assert!((1..=RUNS as usize).contains(&s.tree_runs), "{s:?}");
        assert!(s.speedup > 2.0, "{s:?}");
        assert_eq!(s.linear_sampled, None);
        let (_, sampled) =
            time_linear(&linear, &camera, TraceOptions::default(), Duration::from_micros(1), &WorkControl::new())
                .unwrap();
        assert!(sampled.is_some_and(|n| n < 64 * 48));
        let stop = WorkControl::new();
        stop.cancel();
        assert!(speedup_one_thread(&bvh, &linear, &camera, TraceOptions::default(), 1, Duration::from_secs(1), &stop)
            .is_err());
    }
}
