//! Full-sweep SAH: on each axis, sort the centroids and evaluate the SAH between every pair of
//! neighbours — the exact object-split optimum for this node. MacDonald & Booth, "Heuristics for
//! ray tracing using space subdivision" (The Visual Computer, 1990); Wald 2007 §3 for the sweep.
//! O(n log n) per node; use the binned version for big meshes in interactive work.

use super::{leaf_is_cheaper, BuildPrim, NodeInfo, SplitDecision, SplitScratch};
use crate::bvh::BuildParams;
use crate::geometry::Aabb;

fn sort_on(prims: &mut [BuildPrim], axis: usize) {
    prims.sort_unstable_by(|a, b| a.centroid()[axis].total_cmp(&b.centroid()[axis]).then(a.index().cmp(&b.index())));
}

pub fn split_sah_sweep(
    prims: &mut [BuildPrim],
    node: &NodeInfo,
    params: &BuildParams,
    scratch: &mut SplitScratch,
) -> SplitDecision {
    let n = prims.len();
    let right_area = &mut scratch.areas;
    right_area.clear();
    right_area.resize(n, 0.0);
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, mid)
    let mut sorted_on = None;
    for axis in 0..3 {
        if !(node.centroid_bounds.max[axis] > node.centroid_bounds.min[axis]) {
            continue;
        }
        sort_on(prims, axis);
        sorted_on = Some(axis);
        // right_area[i] = area of prims[i..]
        let mut acc = Aabb::EMPTY;
        for i in (1..n).rev() {
            acc = acc.union(prims[i].bounds());
            right_area[i] = acc.area();
        }
        let mut acc = Aabb::EMPTY;
        for i in 1..n {
            acc = acc.union(prims[i - 1].bounds());
            // Only split between distinct centroids, so the split is a plane, as in the binned case.
            if prims[i - 1].centroid()[axis] == prims[i].centroid()[axis] {
                continue;
            }
            let cost = acc.area() * i as f32 + right_area[i] * (n - i) as f32;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, i));
            }
        }
    }
    let Some((weighted, axis, mid)) = best else {
        return SplitDecision::Fallback;
    };
    if leaf_is_cheaper(n, weighted, node, params) {
        return SplitDecision::Leaf;
    }
    if sorted_on != Some(axis) {
        sort_on(prims, axis);
    }
    SplitDecision::Split { axis: axis as u8, mid }
}
