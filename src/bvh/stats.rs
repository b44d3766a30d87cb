//! Tree statistics of a built BVH: size, depth, leaf sizes, SAH cost, build time.
//!
//! SAH cost (Goldsmith & Salmon 1987; MacDonald & Booth 1990) of the whole tree, normalised by the
//! root's surface area: Σ_interior C_trav·A(n)/A(root) + Σ_leaves C_isect·N(l)·A(l)/A(root). For a
//! ray hitting the root box with a uniformly random origin and direction, it estimates the expected
//! traversal steps plus triangle tests (with unit constants), ignoring early termination.

use super::{Bvh, SahCost};
use std::time::Duration;

#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct TreeStats {
    pub triangles: usize,
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
    pub build_setup_ms: f64,
    pub build_split_ms: f64,
    pub build_reorder_ms: f64,
    pub build_total_ms: f64,
    pub fallback_splits: u32,
    pub depth_limited_splits: u32,
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

impl TreeStats {
    pub fn of(bvh: &Bvh) -> TreeStats {
        let c = bvh.params.cost;
        let root_area = bvh.root_bounds().area() as f64;
        let mut s = TreeStats {
            triangles: bvh.prim_ids.len(),
            nodes: bvh.nodes.len(),
            sah_constants: c,
            memory_bytes: bvh.memory_bytes(),
            build_setup_ms: ms(bvh.report.setup_time),
            build_split_ms: ms(bvh.report.split_time),
            build_reorder_ms: ms(bvh.report.reorder_time),
            build_total_ms: ms(bvh.report.total_time()),
            fallback_splits: bvh.report.fallback_splits,
            depth_limited_splits: bvh.report.depth_limited_splits,
            ..Default::default()
        };
        let mut depth_sum = 0u64;
        let mut cost = 0f64;
        bvh.for_each_node(|_, n, depth| {
            let rel = if root_area > 0.0 { n.bounds.area() as f64 / root_area } else { 0.0 };
            if n.is_leaf() {
                s.leaves += 1;
                depth_sum += depth as u64;
                s.max_depth = s.max_depth.max(depth);
                let k = n.count as usize;
                if s.leaf_size_histogram.len() <= k {
                    s.leaf_size_histogram.resize(k + 1, 0);
                }
                s.leaf_size_histogram[k] += 1;
                cost += c.intersection as f64 * k as f64 * rel;
            } else {
                s.interior_nodes += 1;
                cost += c.traversal as f64 * rel;
            }
        });
        s.mean_leaf_depth = if s.leaves > 0 { depth_sum as f64 / s.leaves as f64 } else { 0.0 };
        s.sah_cost = cost;
        s
    }
}
