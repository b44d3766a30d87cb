//! Tree statistics of a built BVH: size, depth, leaf sizes, SAH cost, build time.
//!
//! SAH cost (Goldsmith & Salmon 1987; MacDonald & Booth 1990) of the whole tree, normalised by the
//! root's surface area: Σ_interior C_trav·A(n)/A(root) + Σ_leaves C_isect·N(l)·A(l)/A(root). For a
//! ray hitting the root box with a uniformly random origin and direction, it estimates the expected
//! traversal steps plus triangle tests (with unit constants), ignoring early termination.

use super::tree::{NodeKind, TreeView};
use crate::bvh::params::SahCost;
use std::time::Duration;

#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct TreeStats {
    /// Different triangles in the leaves.
    pub triangles: usize,
    /// Triangle references in the leaves: more than `triangles` where spatial splits (SBVH) cut
    /// triangles, each part referenced by its own leaf.
    pub references: usize,
    /// SBVH: nodes split by a spatial split.
    pub spatial_splits: u32,
    pub nodes: usize,
    pub interior_nodes: usize,
    pub leaves: usize,
    /// Depth of the deepest leaf (root = 0).
    pub max_depth: u32,
    /// Mean depth over leaves.
    pub mean_leaf_depth: f64,
    /// `leaf_size_histogram[k]` = number of leaves with k triangles.
    pub leaf_size_histogram: Vec<usize>,
    pub sah_cost: f64,
    pub sah_constants: SahCost,
    pub memory_bytes: usize,
    /// What a walk with the chosen triangle test keeps beside the tree (`AnyBvh::walk_bytes`: the
    /// wide tree's stored leaves for the stored-edges test), set by the caller who knows the
    /// test; `of` leaves it 0.
    pub walk_bytes: usize,
    pub build_setup_ms: f64,
    pub build_split_ms: f64,
    pub build_reorder_ms: f64,
    pub build_total_ms: f64,
    pub fallback_splits: u32,
    pub depth_limited_splits: u32,
    /// End-point overlap of the binary tree as built (`bvh::epo`), when it was computed: it costs
    /// a box query per node, so `of` leaves it out and the callers that show it add it.
    pub epo: Option<f64>,
    /// Where the EPO was estimated rather than summed (`epo::Epo`): two standard errors of it.
    pub epo_error: Option<f64>,
    /// How long measuring the EPO took (ms), where it was measured.
    pub epo_ms: Option<f64>,
    /// The reinsertion after the build, if one was asked for (its SAH cost before and after).
    pub reinsertion: Option<super::reinsert::Reinsertion>,
    /// The SIMD kernels a wide layout's walk runs on this CPU ("avx512", "avx2", "simd4", "scalar").
    pub simd: Option<&'static str>,
}

/// A time in milliseconds as the statistics print it: two decimals under 10 ms, so a fast build
/// does not read as 0.0, one above.
impl TreeStats {
    /// References per triangle (1 unless spatial splits cut triangles).
    pub fn references_per_triangle(&self) -> f64 {
        self.references as f64 / self.triangles.max(1) as f64
    }
}

pub fn fmt_ms(ms: f64) -> String {
    if ms < 10.0 {
        format!("{ms:.2}")
    } else {
        format!("{ms:.1}")
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

impl TreeStats {
    /// Statistics of any hierarchy (binary or wide). `nodes` counts interior nodes and leaves.
    pub fn of(tree: &(impl TreeView + ?Sized)) -> TreeStats {
        Self::over(tree, None)
    }

    /// `of`, with the SAH cost normalised by `yardstick`'s area (the mesh's box) instead of the
    /// tree's own root box: the one yardstick of a comparison. A root box larger than the mesh's
    /// (a degenerate triangle kept far away) then costs what it costs (its area over the mesh's
    /// is above 1) instead of shrinking every other term. For a tree whose root box is the mesh's
    /// it is `of`.
    pub fn against(tree: &(impl TreeView + ?Sized), yardstick: &crate::geometry::Aabb) -> TreeStats {
        Self::over(tree, Some(yardstick.area() as f64))
    }

    fn over(tree: &(impl TreeView + ?Sized), area: Option<f64>) -> TreeStats {
        let c = tree.params().cost;
        let report = tree.report();
        let mut root_area = 0f64;
        let mut s = TreeStats {
            triangles: tree.distinct_triangles(),
            references: tree.triangle_count(),
            spatial_splits: report.spatial_splits,
            sah_constants: c,
            memory_bytes: tree.memory_bytes(),
            build_setup_ms: ms(report.setup_time),
            build_split_ms: ms(report.split_time),
            build_reorder_ms: ms(report.reorder_time + report.collapse_time),
            build_total_ms: ms(report.total_time()),
            fallback_splits: report.fallback_splits,
            depth_limited_splits: report.depth_limited_splits,
            reinsertion: report.reinsertion,
            simd: tree.simd().map(crate::cpu::Simd::name),
            ..Default::default()
        };
        let mut depth_sum = 0u64;
        let mut cost = 0f64;
        tree.visit_nodes(&mut |n| {
            if n.depth == 0 {
                root_area = area.unwrap_or(n.bounds.area() as f64);
            }
            let rel = if root_area > 0.0 { n.bounds.area() as f64 / root_area } else { 0.0 };
            s.nodes += 1;
            if let NodeKind::Leaf { count } = n.kind {
                s.leaves += 1;
                depth_sum += n.depth as u64;
                s.max_depth = s.max_depth.max(n.depth);
                let k = count as usize;
                if s.leaf_size_histogram.len() <= k {
                    s.leaf_size_histogram.resize(k + 1, 0);
                }
                s.leaf_size_histogram[k] += 1;
                cost += c.intersection as f64 * k as f64 * rel;
            } else {
                s.interior_nodes += 1;
                cost += c.traversal as f64 * rel;
            }
            true
        });
        s.mean_leaf_depth = if s.leaves > 0 { depth_sum as f64 / s.leaves as f64 } else { 0.0 };
        s.sah_cost = cost;
        s
    }
}
