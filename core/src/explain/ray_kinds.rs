//! Which tree wins for which rays: every tree counted and timed on the same list of rays of each
//! kind (camera rays, shadow, ambient-occlusion and bounce rays from the camera rays' hits), and
//! how well a tree's SAH cost and EPO rank the trees by the work they measure. `compare
//! --ray-kind all` prints it.
//!
//! Camera rays are the most coherent rays there are; the rays after the first hit are not, and
//! the SAH cost, which assumes rays spread uniformly over the scene, predicts their cost less well
//! than it predicts nothing at all for camera rays alone (Aila, Karras & Laine, "On Quality
//! Metrics of Bounding Volume Hierarchies", HPG 2013, where EPO comes from).

use crate::bvh::{Accelerator, NoStats, RayCounters, TraceOptions};
use crate::geometry::Ray;
use crate::render::{Camera, RayKind};
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Summed work of a list of rays (sums of `u64`: a linear scan's triangle tests over a million
/// rays pass `u32`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Work {
    pub rays: u64,
    pub hits: u64,
    pub nodes_visited: u64,
    pub box_tests: u64,
    pub triangle_tests: u64,
}

impl Work {
    fn of(c: &RayCounters, hit: bool) -> Self {
        Self {
            rays: 1,
            hits: hit as u64,
            nodes_visited: c.nodes_visited as u64,
            box_tests: c.box_tests as u64,
            triangle_tests: c.triangle_tests as u64,
        }
    }

    fn plus(a: Self, b: Self) -> Self {
        Self {
            rays: a.rays + b.rays,
            hits: a.hits + b.hits,
            nodes_visited: a.nodes_visited + b.nodes_visited,
            box_tests: a.box_tests + b.box_tests,
            triangle_tests: a.triangle_tests + b.triangle_tests,
        }
    }

    /// Means per ray: nodes visited, triangle tests, and the SAH cost model's combined cost.
    pub fn per_ray(&self, cost: crate::bvh::SahCost) -> (f64, f64, f64) {
        let n = self.rays.max(1) as f64;
        let (nodes, tris) = (self.nodes_visited as f64 / n, self.triangle_tests as f64 / n);
        (nodes, tris, cost.traversal as f64 * nodes + cost.intersection as f64 * tris)
    }
}

/// The rays of one kind for one camera and seed.
pub struct KindRays {
    pub kind: RayKind,
    pub rays: Vec<Ray>,
}

impl KindRays {
    /// The camera's rays, one per pixel, row by row.
    pub fn primary(camera: &Camera) -> Self {
        let gen = camera.ray_gen();
        let rays = (0..camera.height).flat_map(|y| (0..camera.width).map(move |x| (x, y)));
        Self { kind: RayKind::Primary, rays: rays.map(|(x, y)| gen.pixel_ray(x, y)).collect() }
    }

    /// Trace ray `i` as its kind asks (any hit for shadow and ao rays), counting into `stats`.
    #[inline]
    fn trace<A: Accelerator + ?Sized, S: crate::bvh::TraversalStats>(
        &self,
        accel: &A,
        i: usize,
        opts: TraceOptions,
        stats: &mut S,
    ) -> bool {
        self.kind.trace(accel, &self.rays[i], opts, stats)
    }

    /// The work of every ray of the list (or of `n` evenly spread ones), summed.
    pub fn count<A: Accelerator + ?Sized>(&self, accel: &A, opts: TraceOptions, n: usize) -> Work {
        let n = n.min(self.rays.len());
        (0..n)
            .into_par_iter()
            .with_min_len(256)
            .map(|k| {
                let mut c = RayCounters::ZERO;
                let hit = self.trace(accel, self.spread(k, n), opts, &mut c);
                Work::of(&c, hit)
            })
            .reduce(Work::default, Work::plus)
    }

    /// Ray `k` of `n` evenly spread over the list.
    fn spread(&self, k: usize, n: usize) -> usize {
        k * self.rays.len() / n.max(1)
    }

    /// The time to trace `n` evenly spread rays of the list one at a time on the current pool.
    pub fn time<A: Accelerator + ?Sized>(&self, accel: &A, opts: TraceOptions, n: usize) -> Duration {
        let n = n.min(self.rays.len());
        let start = Instant::now();
        (0..n).into_par_iter().with_min_len(256).for_each(|k| {
            std::hint::black_box(self.trace(accel, self.spread(k, n), opts, &mut NoStats));
        });
        start.elapsed()
    }

    /// A slow tracer's (the linear scan's) time per ray: on the whole list when projected to fit
    /// `budget`, else on an evenly spread sample of about a fifth of the budget's worth. Returns
    /// (seconds per ray, rays timed).
    pub fn time_per_ray_within<A: Accelerator + ?Sized>(
        &self,
        accel: &A,
        opts: TraceOptions,
        budget: Duration,
    ) -> (f64, usize) {
        let total = self.rays.len();
        let probe = 256.min(total).max(1);
        let t = self.time(accel, opts, probe).as_secs_f64().max(1e-9);
        let n = if t * total as f64 / probe as f64 <= budget.as_secs_f64() {
            total
        } else {
            ((budget.as_secs_f64() / 5.0 / t) * probe as f64).clamp(probe as f64, total as f64) as usize
        };
        let t = self.time(accel, opts, n).as_secs_f64();
        (t / n.max(1) as f64, n)
    }
}

/// Spearman's rank correlation of two equally long lists (ties take their mean rank): 1 when
/// `b` orders the items exactly as `a` does, −1 when exactly the other way; `None` with fewer
/// than three items or when either list is constant.
pub fn spearman(a: &[f64], b: &[f64]) -> Option<f64> {
    assert_eq!(a.len(), b.len(), "pairs");
    if a.len() < 3 {
        return None;
    }
    let (ra, rb) = (ranks(a), ranks(b));
    let mean = (a.len() as f64 + 1.0) / 2.0;
    let (mut num, mut da, mut db) = (0.0, 0.0, 0.0);
    for (x, y) in ra.iter().zip(&rb) {
        num += (x - mean) * (y - mean);
        da += (x - mean) * (x - mean);
        db += (y - mean) * (y - mean);
    }
    (da > 0.0 && db > 0.0).then(|| num / (da * db).sqrt())
}

/// Ranks from 1, ties sharing the mean of their ranks.
fn ranks(v: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..v.len()).collect();
    order.sort_by(|&i, &j| v[i].total_cmp(&v[j]));
    let mut r = vec![0.0; v.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j + 1 < order.len() && v[order[j + 1]] == v[order[i]] {
            j += 1;
        }
        for &k in &order[i..=j] {
            r[k] = (i + j) as f64 / 2.0 + 1.0;
        }
        i = j + 1;
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{AnyBvh, BuildParams, LinearScan};
    use crate::render::{render, RenderSettings, SecondaryRays, SecondarySpec};

    #[test]
    fn spearman_ranks_orders_not_values() {
        assert_eq!(spearman(&[1.0, 2.0, 3.0, 4.0], &[10.0, 20.0, 35.0, 1000.0]), Some(1.0));
        assert_eq!(spearman(&[1.0, 2.0, 3.0, 4.0], &[4.0, 3.0, 2.0, 1.0]), Some(-1.0));
        // Ties share their mean rank: ranks (1.5, 1.5, 3) against (1, 2, 3).
        let r = spearman(&[5.0, 5.0, 7.0], &[1.0, 2.0, 3.0]).unwrap();
        assert!((r - 0.866_025).abs() < 1e-5, "{r}");
        assert_eq!(spearman(&[1.0, 1.0, 1.0], &[1.0, 2.0, 3.0]), None);
        assert_eq!(spearman(&[1.0, 2.0], &[1.0, 2.0]), None);
    }

    #[test]
    fn a_kinds_rays_are_the_heatmaps_rays_and_count_as_the_frame_does() {
        let mesh = crate::mesh::generate::torus_knot(2, 3, 0.25, 96, 12);
        let camera = Camera::framing(&mesh.bounds(), 48, 32);
        let tree = AnyBvh::build(&mesh, &BuildParams::default());
        let opts = TraceOptions::default();
        let primary = render(&tree, &mesh, &camera, &RenderSettings { count: true, ..Default::default() });
        let list = KindRays::primary(&camera);
        let work = list.count(&tree, opts, list.rays.len());
        let sum = primary.traced().fold(Work::default(), |a, (s, c)| Work::plus(a, Work::of(&c, s.is_hit())));
        assert_eq!(work, sum);
        for kind in [RayKind::Shadow, RayKind::Ao, RayKind::Bounce] {
            let sec = SecondaryRays::new(SecondarySpec::default().of_kind(kind), &mesh.bounds(), &camera);
            let frame = render(
                &tree,
                &mesh,
                &camera,
                &RenderSettings { count: true, secondary: Some(sec), ..Default::default() },
            );
            let list = KindRays { kind, rays: sec.frame_rays(&primary, &camera, usize::MAX).rays };
            assert_eq!(list.rays.len() as u64, frame.ray_summary().rays);
            let work = list.count(&tree, opts, list.rays.len());
            let (nodes, tris) =
                frame.traced().fold((0, 0), |(n, t), (_, c)| (n + c.nodes_visited as u64, t + c.triangle_tests as u64));
            assert_eq!(
                (work.nodes_visited, work.triangle_tests),
                (nodes, tris),
                "{kind:?}: the list's counts are the frame's"
            );
            // The linear scan answers the same (any hit or closest), and some rays hit, some not.
            let linear = LinearScan::new(&mesh);
            assert_eq!(work.hits, list.count(&linear, opts, list.rays.len()).hits, "{kind:?}");
            assert!(work.hits > 0 && work.hits < work.rays, "{kind:?}: {work:?}");
        }
    }
}
