//! Full-sweep SAH: on each axis, sort the centroids and evaluate the SAH between every pair of
//! neighbours — the exact object-split optimum for this node. MacDonald & Booth, "Heuristics for
//! ray tracing using space subdivision" (The Visual Computer, 1990); Wald 2007 §3 for the sweep.
//! O(n log n) per node; use the binned version for big meshes in interactive work.

use super::{is_active, BuildPrim, NodeInfo, PlaneSink, Proposal, Splitter};
use crate::bvh::BuildParams;
use crate::geometry::Aabb;

fn sort_on(prims: &mut [BuildPrim], axis: usize) {
    prims.sort_unstable_by(|a, b| a.centroid()[axis].total_cmp(&b.centroid()[axis]).then(a.index().cmp(&b.index())));
}

/// The exact sweep, with its scratch: the area of every suffix of the sorted primitives.
pub struct SahSweep {
    right_area: Vec<f32>,
}

impl SahSweep {
    pub fn new(_params: &BuildParams) -> Self {
        Self { right_area: Vec::new() }
    }
}

impl Splitter for SahSweep {
    fn prices_splits(&self) -> bool {
        true
    }

    fn split(&mut self, prims: &mut [BuildPrim], node: &NodeInfo) -> Proposal {
        sweep(prims, node, &mut self.right_area, &mut ())
    }
}

/// The sweep over `prims` (reordered), reporting every candidate plane to `sink`: the node
/// inspector's exact cost curve. The plane between two neighbouring centroids is reported at
/// their midpoint.
pub fn sweep_planes(prims: &mut [BuildPrim], node: &NodeInfo, sink: &mut impl PlaneSink) -> Proposal {
    sweep(prims, node, &mut Vec::new(), sink)
}

fn sweep(prims: &mut [BuildPrim], node: &NodeInfo, right_area: &mut Vec<f32>, sink: &mut impl PlaneSink) -> Proposal {
    let n = prims.len();
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
            if is_active(sink) {
                let plane = (prims[i - 1].centroid()[axis] + prims[i].centroid()[axis]) * 0.5;
                sink.plane(axis, plane, i as u32, (n - i) as u32, cost, [acc.area(), right_area[i]]);
            }
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, i));
            }
        }
    }
    let Some((weighted, axis, mid)) = best else {
        return Proposal::None;
    };
    if sorted_on != Some(axis) {
        sort_on(prims, axis);
    }
    let plane = (prims[mid - 1].centroid()[axis] + prims[mid].centroid()[axis]) * 0.5;
    Proposal::Split { axis: axis as u8, mid, weighted: Some(weighted), plane }
}
