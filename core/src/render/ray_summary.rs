//! A frame's per-ray work summed up (`RaySummary`): means over all its rays and over those that
//! entered the tree, on the tree's own root box or on one yardstick for a comparison.

use crate::render::frame::Frame;
use rayon::prelude::*;

/// Per-ray work over the traced rays of a frame: means over all rays (hit and missed), and over
/// the rays that entered the root box. Most primary rays of a small mesh in a wide view miss the
/// root box at the cost of one box test, which dilutes the all-ray means towards zero and hides
/// the difference between strategies; the root-box means are the work of the rays that met the
/// tree (the rays the SAH cost is about).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct RaySummary {
    pub rays: u64,
    pub hits: u64,
    pub mean_nodes_visited: f64,
    pub max_nodes_visited: u32,
    pub mean_box_tests: f64,
    pub mean_triangle_tests: f64,
    pub max_triangle_tests: u32,
    /// Two-level BVH: top-level nodes visited and instances entered per ray (0 for one BVH).
    pub mean_top_nodes_visited: f64,
    pub mean_instances_entered: f64,
    /// Rays that entered the root box (visited at least one node: every traversal tests the
    /// root box first and visits nothing when it misses).
    pub root_rays: u64,
    /// Means over the `root_rays` (0 when there are none).
    pub root_mean_nodes_visited: f64,
    pub root_mean_box_tests: f64,
    pub root_mean_triangle_tests: f64,
}

impl RaySummary {
    /// Share of the rays that entered the root box (0 when nothing was traced).
    pub fn root_fraction(&self) -> f64 {
        self.root_rays as f64 / self.rays.max(1) as f64
    }
}

impl Frame {
    pub fn ray_summary(&self) -> RaySummary {
        let (mut s, root) = self.summed();
        let r = s.root_rays.max(1) as f64;
        (s.root_mean_nodes_visited, s.root_mean_box_tests, s.root_mean_triangle_tests) =
            (root[0] as f64 / r, root[1] as f64 / r, root[2] as f64 / r);
        s
    }

    /// `ray_summary` on one yardstick for every tree of a comparison: its root-box figures are
    /// the work of every ray that entered this tree's root box over the number of rays that
    /// enter `yardstick` (the mesh's box, `camera`'s rays), not this tree's root box. A tree
    /// whose root box is larger than the mesh's (a degenerate triangle kept far away, a loose
    /// box) lets more rays in; over its own root box those rays' cheap walks would dilute its
    /// means and rank it ahead of a better tree. For a tree whose root box is the mesh's it is
    /// `ray_summary`.
    /// A frame of secondary rays has its own yardstick: every secondary ray leaves the surface,
    /// inside every tree's root box, so its summary is `ray_summary`.
    pub fn ray_summary_in(&self, camera: &super::Camera, yardstick: &crate::geometry::Aabb) -> RaySummary {
        if self.ray_kind().0.is_secondary() {
            return self.ray_summary();
        }
        let (mut s, root) = self.summed();
        let gen = camera.ray_gen();
        let step = self.stride.max(1);
        let (cols, rows) = if self.stride == 0 { (0, 0) } else { self.grid_size() };
        let entering: u64 = crate::parallel::region(|| {
            (0..rows)
                .into_par_iter()
                .map(|gy| {
                    (0..cols).filter(|&gx| yardstick.intersect(&gen.pixel_ray(gx * step, gy * step)).is_some()).count()
                        as u64
                })
                .sum()
        });
        s.root_rays = entering;
        let r = entering.max(1) as f64;
        (s.root_mean_nodes_visited, s.root_mean_box_tests, s.root_mean_triangle_tests) =
            (root[0] as f64 / r, root[1] as f64 / r, root[2] as f64 / r);
        s
    }

    /// The summary's all-ray figures, and the sums of nodes, box tests and triangle tests over
    /// the rays that entered the root box (their count in `root_rays`). In a frame of secondary
    /// rays the rays are the secondary rays (`per_hit` from each pixel whose camera ray hit, their
    /// counts summed in the pixel's counters), `hits` the pixels whose camera ray hit, and the
    /// maxima those of a pixel's mean.
    fn summed(&self) -> (RaySummary, [u64; 3]) {
        let mut s = RaySummary::default();
        let (mut nodes, mut boxes, mut tris, mut top, mut inst) = (0u64, 0u64, 0u64, 0u64, 0u64);
        let mut root = [0u64; 3];
        let per_hit = self.ray_kind().1;
        for (p, c) in self.traced() {
            let rays = match per_hit {
                0 => 1,
                _ if !p.is_hit() => continue,
                n => n,
            };
            s.rays += rays as u64;
            s.hits += p.is_hit() as u64;
            nodes += c.nodes_visited as u64;
            boxes += c.box_tests as u64;
            tris += c.triangle_tests as u64;
            top += c.top_nodes_visited as u64;
            inst += c.instances_entered as u64;
            if c.nodes_visited > 0 {
                s.root_rays += rays as u64;
                root[0] += c.nodes_visited as u64;
                root[1] += c.box_tests as u64;
                root[2] += c.triangle_tests as u64;
            }
            s.max_nodes_visited = s.max_nodes_visited.max(c.nodes_visited / rays);
            s.max_triangle_tests = s.max_triangle_tests.max(c.triangle_tests / rays);
        }
        let n = s.rays.max(1) as f64;
        s.mean_nodes_visited = nodes as f64 / n;
        s.mean_box_tests = boxes as f64 / n;
        s.mean_triangle_tests = tris as f64 / n;
        s.mean_top_nodes_visited = top as f64 / n;
        s.mean_instances_entered = inst as f64 / n;
        (s, root)
    }
}
