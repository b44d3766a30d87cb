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
    /// … and the work of the rays that entered the tree over those that enter the mesh's box
    /// (`Frame::ray_summary_in`: the same rays for every tree).
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
/// on the calling thread (as a student's renderer does). A busy machine only ever adds time, and
/// unevenly (two identical trees timed one after the other differed by 2×): so a tree is timed
/// in the same rounds as bvhscope's SAH tree of its layout, piece by piece (`PIECE` rays, the
/// two trees alternately first), each piece's fastest of `RUNS` runs kept; the figure compared
/// is the ratio of the two sums, which a load on the machine leaves alone, and a tree's time per
/// ray is that ratio times the SAH tree's time, timed once per layout: bvhscope's own trees are
/// timed so too, each beside the SAH tree, so a reference and a student's copy of it read alike
/// (issue 59). The linear scan is
/// timed once for the class, on as many of the rays as fit in a fifth of a second per run, and
/// the SAH tree's speed-up over it carries each tree's ratio into a speed-up of its own.
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

/// Rays timed as one piece: some 50 to 500 µs of tracing, short beside a time slice of the
/// scheduler, so most runs of a piece are not interrupted and its fastest run is a clean one.
pub const PIECE: usize = 256;

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

/// The `n` sample rays, from `first` on (of `total`).
fn sample_rays(camera: &Camera, first: usize, n: usize, total: usize) -> Vec<crate::geometry::Ray> {
    let gen = camera.ray_gen();
    (first..first + n)
        .map(|i| {
            let (x, y) = sample_pixel(camera, i, total);
            gen.pixel_ray(x, y)
        })
        .collect()
}

/// A tree's closest-hit query on one ray, as the timing calls it (`tracer`).
pub type Tracer<'a> = &'a dyn Fn(&mut crate::geometry::Ray);

/// `accel`'s closest-hit query with `trace`'s options, for `time_together`.
pub fn tracer<A: Accelerator + ?Sized>(accel: &A, trace: TraceOptions) -> impl Fn(&mut crate::geometry::Ray) + '_ {
    move |ray| {
        std::hint::black_box(accel.closest_hit(ray, trace, &mut NoStats));
    }
}

/// Seconds to trace `rays` through `tree` on this thread.
fn trace_once(tree: Tracer, rays: &[crate::geometry::Ray]) -> f64 {
    let start = Instant::now();
    for r in rays {
        tree(&mut r.clone());
    }
    start.elapsed().as_secs_f64()
}

/// Nanoseconds per ray of each of `trees` on `n` sample rays, timed in the same rounds: piece by
/// piece, every tree on the piece `RUNS` times in a rotating order, each piece's fastest run
/// kept (`Timing`). `control` is heard between runs: a tree whose boxes all overlap takes a
/// millisecond a ray.
pub fn time_together(
    trees: &[Tracer],
    camera: &Camera,
    n: usize,
    control: &WorkControl,
) -> Result<Vec<f64>, Cancelled> {
    let n = n.max(1);
    let mut sums = vec![0f64; trees.len()];
    let mut first = 0;
    while first < n {
        let rays = sample_rays(camera, first, PIECE.min(n - first), n);
        let mut best = vec![f64::INFINITY; trees.len()];
        for run in 0..RUNS as usize {
            for k in 0..trees.len() {
                control.check()?;
                let t = (k + run) % trees.len();
                best[t] = best[t].min(trace_once(trees[t], &rays));
            }
        }
        for (s, b) in sums.iter_mut().zip(&best) {
            *s += b;
        }
        first += rays.len();
    }
    Ok(sums.into_iter().map(|s| s * 1e9 / n as f64).collect())
}

/// The linear scan's time per ray: a probe of a few rays, then as many of the `max` sample rays as
/// fit in `LINEAR_BUDGET` (a scan of a million triangles takes milliseconds per ray), `RUNS` times.
pub fn time_linear(mesh: &Mesh, camera: &Camera, trace: TraceOptions, max: usize) -> (f64, usize) {
    let linear = LinearScan::new(mesh);
    let scan = tracer(&linear, trace);
    let probe = 8.min(max).max(1);
    let t = trace_once(&scan, &sample_rays(camera, 0, probe, max.max(probe))) / probe as f64;
    let n = ((LINEAR_BUDGET.as_secs_f64() / t.max(1e-9)) as usize).clamp(probe, max.max(probe));
    let rays = sample_rays(camera, 0, n, n);
    let best = (0..RUNS).map(|_| trace_once(&scan, &rays)).fold(f64::INFINITY, f64::min);
    (best * 1e9 / n as f64, n)
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
/// and the counted frame on `camera` (returned too, for its heatmap), the SAH cost and the
/// per-ray figures against the mesh's box. `control` may stop the
/// frame between bands. With `secondary`, the frame returned for the heatmap is of those rays (a
/// second frame); the figures stay the camera rays'.
pub fn measure(
    tree: &AnyBvh,
    binary: Option<&Bvh>,
    mesh: &Mesh,
    camera: &Camera,
    trace: TraceOptions,
    secondary: Option<crate::render::SecondaryRays>,
    control: &WorkControl,
) -> Result<(Quality, Frame), Cancelled> {
    // One yardstick for every tree of the class: the mesh's box (what its triangles span), not
    // each tree's own root box (`TreeStats::against`, `Frame::ray_summary_in`).
    let yardstick = mesh.bounds();
    let s = TreeStats::against(tree, &yardstick);
    let (epo, epo_skipped) = match binary.map(epo_bounded) {
        Some(Ok(e)) => (Some(e), None),
        Some(Err(why)) => (None, Some(why)),
        None => (None, Some("not measured: no binary tree".into())),
    };
    let settings = RenderSettings { trace, count: true, progressive: false, secondary: None };
    let frame = render_progressive(tree, mesh, camera, &settings, &Default::default(), control, |_, _| {})?;
    let r = frame.ray_summary_in(camera, &yardstick);
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
    let frame = match secondary {
        None => frame,
        Some(s) => {
            let settings = RenderSettings { secondary: Some(s), ..settings };
            render_progressive(tree, mesh, camera, &settings, &Default::default(), control, |_, _| {})?
        }
    };
    Ok((q, frame))
}

/// `q` with its time per ray (`ns_per_ray`) and its speed-up over the linear scan: the SAH tree's
/// (`sah_speedup`, timed once for the class) over this tree's time relative to the SAH tree's
/// (`versus_sah`, timed in the same rounds), so a busy moment of the machine moves neither.
pub fn timed(mut q: Quality, ns_per_ray: f64, versus_sah: f64, sah_speedup: f64) -> Quality {
    q.trace_ns_per_ray = ns_per_ray;
    q.speedup_over_linear = sah_speedup / versus_sah.max(1e-9);
    q
}

/// The leaf sizes as "size:count" words, the sizes that occur only ("1:120 2:340 4:9000"; ASCII,
/// so a spreadsheet reads the CSV's field as it is).
pub fn leaf_sizes_text(h: &[usize]) -> String {
    let words: Vec<String> = h.iter().enumerate().filter(|(_, &c)| c > 0).map(|(k, c)| format!("{k}:{c}")).collect();
    words.join(" ")
}
