//! Binned SAH: on each axis, drop centroids into `bins` equal-width bins, sweep the bins to get the
//! cost of each of the `bins - 1` planes, and keep the cheapest plane of all three axes — or make a
//! leaf when that is cheaper. Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies"
//! (RT 2007); pbrt-v4 §7.3.2.

use super::{partition, BuildPrim, NodeInfo, SplitDecision};
use crate::bvh::BuildParams;
use crate::geometry::Aabb;

/// Upper bound on the bin count (keeps the per-node bin arrays on the stack).
pub const MAX_BINS: usize = 256;

#[inline]
fn bin_of(c: f32, lo: f32, scale: f32, bins: usize) -> usize {
    // `as usize` saturates (and maps NaN to 0), so the index is always in range.
    ((c - lo) * scale).max(0.0).min((bins - 1) as f32) as usize
}

pub fn split_sah_binned(prims: &mut [BuildPrim], node: &NodeInfo, params: &BuildParams) -> SplitDecision {
    let bins = (params.sah_bins as usize).clamp(2, MAX_BINS);
    let cb = node.centroid_bounds;
    let n = prims.len();
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, plane)
    let mut counts = [0u32; MAX_BINS];
    let mut boxes = [Aabb::EMPTY; MAX_BINS];
    let mut right_area = [0f32; MAX_BINS];
    let mut right_count = [0u32; MAX_BINS];
    for axis in 0..3 {
        let extent = cb.max[axis] - cb.min[axis];
        if !(extent > 0.0) {
            continue;
        }
        let scale = bins as f32 / extent;
        counts[..bins].fill(0);
        boxes[..bins].fill(Aabb::EMPTY);
        for p in prims.iter() {
            let b = bin_of(p.centroid[axis], cb.min[axis], scale, bins);
            counts[b] += 1;
            boxes[b] = boxes[b].union(p.bounds);
        }
        // right_*[i]: everything in bins i.. ; plane i separates bins ..i from i..
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in (1..bins).rev() {
            acc = acc.union(boxes[i]);
            cnt += counts[i];
            right_area[i] = acc.area();
            right_count[i] = cnt;
        }
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in 1..bins {
            acc = acc.union(boxes[i - 1]);
            cnt += counts[i - 1];
            if cnt == 0 || right_count[i] == 0 {
                continue;
            }
            let cost = acc.area() * cnt as f32 + right_area[i] * right_count[i] as f32;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, i));
            }
        }
    }
    let Some((weighted, axis, plane)) = best else {
        return SplitDecision::Fallback; // all centroids coincide
    };
    let area = node.bounds.area();
    let split_cost = params.cost.traversal + params.cost.intersection * weighted / area;
    let leaf_cost = params.cost.intersection * n as f32;
    if n <= params.max_leaf_size as usize && leaf_cost <= split_cost {
        return SplitDecision::Leaf;
    }
    let scale = bins as f32 / (cb.max[axis] - cb.min[axis]);
    let mid = partition(prims, |p| bin_of(p.centroid[axis], cb.min[axis], scale, bins) < plane);
    SplitDecision::Split { axis: axis as u8, mid }
}
