//! Full-sweep SAH: on each axis, sort the centroids and evaluate the SAH between every pair of
//! neighbours — the exact object-split optimum for this node. MacDonald & Booth, "Heuristics for
//! ray tracing using space subdivision" (The Visual Computer, 1990); Wald 2007 §3 for the sweep.
//! O(n log n) per node; use the binned version for big meshes in interactive work. Big nodes (the
//! top of the tree) are sorted and swept in parallel (`sweep_parallel`), to the same split.

use crate::bvh::builders::split::splitter::{is_active, BuildPrim, NodeInfo, PlaneSink, Proposal, Splitter};
use crate::bvh::params::BuildParams;
use crate::geometry::Aabb;
use crate::parallel::{region, PARTITION_MIN};
use rayon::prelude::*;

/// Sorted by centroid, ties by index: a total order over distinct indices, so the parallel sort
/// of a big node gives the one order the serial sort gives.
fn sort_on(prims: &mut [BuildPrim], axis: usize) {
    let order = |a: &BuildPrim, b: &BuildPrim| {
        a.centroid()[axis].total_cmp(&b.centroid()[axis]).then(a.index().cmp(&b.index()))
    };
    if prims.len() >= PARTITION_MIN {
        region(|| prims.par_sort_unstable_by(order));
    } else {
        prims.sort_unstable_by(order);
    }
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
        if n >= PARTITION_MIN && !is_active(sink) {
            let found = sweep_parallel(prims, axis, right_area);
            if found.is_some_and(|(c, _)| best.is_none_or(|(b, _, _)| c < b)) {
                let (cost, mid) = found.expect("checked");
                best = Some((cost, axis, mid));
            }
            continue;
        }
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

/// The sweep of one axis over sorted `prims` in fixed chunks: each chunk's box, the boxes of the
/// chunks before and after it (unions are exact, so each plane's boxes and costs are the serial
/// sweep's to the bit), then each chunk's planes in parallel. The cheapest plane (the first of
/// equal ones, as the serial sweep keeps) with its cost.
fn sweep_parallel(prims: &[BuildPrim], axis: usize, right_area: &mut [f32]) -> Option<(f32, usize)> {
    const CHUNK: usize = 1 << 14;
    let n = prims.len();
    let boxes: Vec<Aabb> =
        region(|| prims.par_chunks(CHUNK).map(|c| Aabb::of(c.iter().map(BuildPrim::bounds))).collect());
    // before[c]: the union of chunks ..c; after[c]: of chunks c + 1.. (one thread: one box a chunk).
    let (mut before, mut after) = (vec![Aabb::EMPTY; boxes.len()], vec![Aabb::EMPTY; boxes.len()]);
    for c in 1..boxes.len() {
        before[c] = before[c - 1].union(boxes[c - 1]);
        let k = boxes.len() - 1 - c;
        after[k] = after[k + 1].union(boxes[k + 1]);
    }
    // right_area[i] = area of prims[i..]
    region(|| {
        right_area.par_chunks_mut(CHUNK).zip(prims.par_chunks(CHUNK)).zip(&after).for_each(|((areas, c), &tail)| {
            let mut acc = tail;
            for (a, p) in areas.iter_mut().zip(c).rev() {
                acc = acc.union(p.bounds());
                *a = acc.area();
            }
        })
    });
    let chunk_best = |c: usize| {
        let mut acc = before[c];
        let mut best: Option<(f32, usize)> = None;
        for i in (c * CHUNK).max(1)..((c + 1) * CHUNK).min(n) {
            acc = acc.union(prims[i - 1].bounds());
            if prims[i - 1].centroid()[axis] == prims[i].centroid()[axis] {
                continue;
            }
            let cost = acc.area() * i as f32 + right_area[i] * (n - i) as f32;
            if best.is_none_or(|(b, _)| cost < b) {
                best = Some((cost, i));
            }
        }
        best
    };
    let bests: Vec<Option<(f32, usize)>> = region(|| (0..boxes.len()).into_par_iter().map(chunk_best).collect());
    // In order: the first chunk's best unless a later one is strictly cheaper, as the serial loop.
    bests.into_iter().flatten().fold(
        None,
        |best, (cost, i)| {
            if best.is_none_or(|(b, _)| cost < b) {
                Some((cost, i))
            } else {
                best
            }
        },
    )
}
