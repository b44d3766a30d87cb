//! The figures of one traced tree, the same for a student's and for bvhscope's: its statistics
//! (`TreeStats`), its EPO (bounded), its work per ray on the camera's frame, and its time per
//! ray traced one at a time on one thread, next to the linear scan's.

use crate::bvh::{epo, Accelerator, AnyBvh, Bvh, LinearScan, NoStats, TraceOptions, TreeStats, TreeView};
use crate::geometry::Aabb;
use crate::mesh::Mesh;
use crate::render::{render_progressive, Camera, Frame, RenderSettings};
use crate::work::{Cancelled, WorkControl};
use serde::Serialize;
use std::time::{Duration, Instant};

/// What a tree is worth, measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Quality {
    /// The layout it is traced in (`binary`, `wide4`, `wide8`).
    pub layout: &'static str,
    /// Interior nodes and leaves (of a wide layout: wide nodes and leaf slots).
    pub nodes: usize,
    pub leaves: usize,
    pub max_depth: u32,
    pub mean_leaf_depth: f64,
    /// `leaf_sizes[k]`: leaves holding k triangles.
    pub leaf_sizes: Vec<usize>,
    /// Triangle references in the leaves.
    pub references: usize,
    pub sah_cost: f64,
    /// End-point overlap of the binary tree (a wide dump's binarised one); `None` when its
    /// boxes overlap so much that measuring it would take too long (`epo_skipped` says why).
    pub epo: Option<f64>,
    pub epo_skipped: Option<String>,
    /// Means over all the camera's primary rays…
    pub nodes_per_ray: f64,
    pub tri_tests_per_ray: f64,
    /// … and over those that enter the root box.
    pub root_nodes_per_ray: f64,
    pub root_tri_tests_per_ray: f64,
    /// Single rays, closest hit, no shading, one thread (`Timing`).
    pub trace_ns_per_ray: f64,
    /// The linear scan's time per ray over this tree's.
    pub speedup_over_linear: f64,
    /// Bytes of the tree as traced (nodes, triangle order, triangles).
    pub memory_bytes: usize,
}

/// How trees are timed: the same evenly spread primary rays for every tree, traced one at a time
/// on the calling thread (as a student's renderer does), the fastest of `RUNS` runs (other work
/// on a shared machine only ever adds time, so the fastest run is the steadiest figure); the
/// linear scan likewise on as many of them as fit in a fifth of a second per run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Timing {
    /// Rays timed per tree.
    pub rays: usize,
    pub runs: u32,
    /// Rays the linear scan was timed on, and its time per ray.
    pub linear_rays: usize,
    pub linear_ns_per_ray: f64,
}

pub const RUNS: u32 = 5;

/// What one run of the linear scan's timing may take.
const LINEAR_BUDGET: Duration = Duration::from_millis(200);

/// Box and triangle tests the EPO of a tree may cost (estimated by sampling before it is
/// measured): about 10 s on this project's 2-core machine, where the trees of every strategy and
/// leaf size over a 100k-triangle mesh need 0.4e7 to 2.5e7 (0.14 to 0.65 s). A degenerate tree
/// (every box the root's) would need time quadratic in its nodes, and the EPO cannot be stopped
/// midway.
const EPO_BUDGET: f64 = 3e8;

/// Pixel `i` of `n` evenly spread over the camera's frame.
fn sample_pixel(camera: &Camera, i: usize, n: usize) -> (u32, u32) {
    let total = camera.width as usize * camera.height as usize;
    let p = (i * total / n.max(1)) as u32;
    (p % camera.width, p / camera.width)
}

/// Seconds to trace `n` sample rays through `accel` on this thread, closest hit only.
fn trace_once<A: Accelerator>(accel: &A, camera: &Camera, trace: TraceOptions, n: usize) -> f64 {
    let gen = camera.ray_gen();
    let start = Instant::now();
    for i in 0..n {
        let (x, y) = sample_pixel(camera, i, n);
        let mut ray = gen.pixel_ray(x, y);
        std::hint::black_box(accel.closest_hit(&mut ray, trace, &mut NoStats));
    }
    start.elapsed().as_secs_f64()
}

/// Nanoseconds per ray of `accel` on `n` sample rays: the fastest of `runs` runs.
fn fastest<A: Accelerator>(accel: &A, camera: &Camera, trace: TraceOptions, n: usize, runs: u32) -> f64 {
    let best = (0..runs.max(1)).map(|_| trace_once(accel, camera, trace, n)).fold(f64::INFINITY, f64::min);
    best * 1e9 / n.max(1) as f64
}

/// Nanoseconds per ray of `accel` on `n` sample rays (`Timing`).
pub fn time_tree<A: Accelerator>(accel: &A, camera: &Camera, trace: TraceOptions, n: usize) -> f64 {
    fastest(accel, camera, trace, n, RUNS)
}

/// The linear scan's time per ray: a probe of a few rays, then as many of the `max` sample rays as
/// fit in `LINEAR_BUDGET` (a scan of a million triangles takes milliseconds per ray), `RUNS` times.
pub fn time_linear(mesh: &Mesh, camera: &Camera, trace: TraceOptions, max: usize) -> (f64, usize) {
    let linear = LinearScan::new(mesh);
    let probe = 8.min(max).max(1);
    let t = trace_once(&linear, camera, trace, probe) / probe as f64;
    let n = ((LINEAR_BUDGET.as_secs_f64() / t.max(1e-9)) as usize).clamp(probe, max.max(probe));
    (fastest(&linear, camera, trace, n, RUNS), n)
}

/// The EPO of `bvh`, unless a sample of its nodes says the measure would cost more than
/// `EPO_BUDGET` node visits (then why). The sample walks the same box query as `epo::of`.
pub fn epo_bounded(bvh: &Bvh) -> Result<f64, String> {
    let n = bvh.nodes.len();
    if n == 0 {
        return Ok(0.0);
    }
    let overlaps = |a: &Aabb, b: &Aabb| !(a.max.cmplt(b.min).any() || b.max.cmplt(a.min).any());
    let samples = n.min(256);
    let mut visits = 0u64;
    let mut stack = Vec::new();
    for k in 0..samples {
        let node = k * n / samples;
        let b = bvh.nodes[node].bounds();
        stack.clear();
        stack.push(0usize);
        while let Some(m) = stack.pop() {
            let other = &bvh.nodes[m];
            visits += 1;
            if m == node || !overlaps(&other.bounds(), &b) {
                continue;
            }
            // A leaf costs a clip per triangle.
            if other.is_leaf() {
                visits += other.count as u64;
            } else {
                stack.extend([other.index as usize, other.index as usize + 1]);
            }
        }
    }
    let estimate = visits as f64 / samples as f64 * n as f64;
    if estimate > EPO_BUDGET {
        return Err(format!(
            "not measured: its boxes overlap so much that it would take about {:.0e} box and triangle tests (the limit is {EPO_BUDGET:.0e})",
            estimate
        ));
    }
    Ok(epo::of(bvh))
}

/// Everything of `tree` but its time: statistics, EPO (of `binary`, the binary tree behind it),
/// and the counted frame on `camera` (returned too, for its heatmap). `control` may stop the
/// frame between bands.
pub fn measure(
    tree: &AnyBvh,
    binary: Option<&Bvh>,
    mesh: &Mesh,
    camera: &Camera,
    trace: TraceOptions,
    control: &WorkControl,
) -> Result<(Quality, Frame), Cancelled> {
    let s = TreeStats::of(tree);
    let (epo, epo_skipped) = match binary.map(epo_bounded) {
        Some(Ok(e)) => (Some(e), None),
        Some(Err(why)) => (None, Some(why)),
        None => (None, Some("not measured: no binary tree".into())),
    };
    let settings = RenderSettings { trace, count: true, progressive: false };
    let frame = render_progressive(tree, mesh, camera, &settings, &Default::default(), control, |_, _| {})?;
    let r = frame.ray_summary();
    let q = Quality {
        layout: tree.params().layout.name(),
        nodes: s.nodes,
        leaves: s.leaves,
        max_depth: s.max_depth,
        mean_leaf_depth: s.mean_leaf_depth,
        leaf_sizes: s.leaf_size_histogram,
        references: s.references,
        sah_cost: s.sah_cost,
        epo,
        epo_skipped,
        nodes_per_ray: r.mean_nodes_visited,
        tri_tests_per_ray: r.mean_triangle_tests,
        root_nodes_per_ray: r.root_mean_nodes_visited,
        root_tri_tests_per_ray: r.root_mean_triangle_tests,
        trace_ns_per_ray: 0.0,
        speedup_over_linear: 0.0,
        memory_bytes: s.memory_bytes,
    };
    Ok((q, frame))
}

/// `q` with the time per ray of `tree` on the timing's rays, and its speed-up over the linear scan.
pub fn timed(mut q: Quality, tree: &AnyBvh, camera: &Camera, trace: TraceOptions, timing: &Timing) -> Quality {
    q.trace_ns_per_ray = time_tree(tree, camera, trace, timing.rays);
    q.speedup_over_linear = timing.linear_ns_per_ray / q.trace_ns_per_ray.max(1e-3);
    q
}

/// The leaf sizes as "size:count" words, the sizes that occur only ("1:120 2:340 4:9000"; ASCII,
/// so a spreadsheet reads the CSV's field as it is).
pub fn leaf_sizes_text(h: &[usize]) -> String {
    let words: Vec<String> = h.iter().enumerate().filter(|(_, &c)| c > 0).map(|(k, c)| format!("{k}:{c}")).collect();
    words.join(" ")
}
