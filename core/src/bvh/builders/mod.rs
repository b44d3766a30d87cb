//! The top-down build driver shared by every split strategy (pbrt-v4 §7.3, "BVH construction").
//!
//! It keeps an explicit work stack instead of recursing, so a 10M-triangle mesh or a million
//! identical triangles cannot overflow the call stack. Nodes are allocated in pairs when a node is
//! split, so the two children of a node are adjacent and an interior node needs only one index.

pub(crate) mod common;
pub mod lbvh;
pub mod morton;
pub(crate) mod ploc;
pub mod reinsert;
pub mod sbvh;
pub mod split;
pub mod strategy;
mod subtree;

use crate::bvh::builders::split::equal_count::EqualCount;
use crate::bvh::builders::split::splitter::{BuildPrim, NodeInfo, Proposal, Splitter};
use crate::bvh::node::{Bvh, BvhNode};
use crate::bvh::params::{BuildParams, BuildReport};
use crate::geometry::Aabb;
use crate::mesh::Mesh;
use crate::parallel::{region, region_if, PARTITION_MIN};
use crate::work::{Cancelled, WorkControl};
pub use common::{build_work, HEURISTIC_DEPTH_LIMIT};
use common::{leaf_is_cheaper, node_info, progress_levels, Overrides, Progress, PARALLEL_MIN_PRIMS};
use rayon::prelude::*;
use std::time::Instant;
use strategy::Builder;
use subtree::Subtree;

struct Task {
    node: u32,
    start: u32,
    end: u32,
    depth: u32,
}

impl Bvh {
    /// Build a BVH over the mesh's triangles.
    pub fn build(mesh: &Mesh, params: &BuildParams) -> Bvh {
        match Self::build_controlled(mesh, params, &WorkControl::new()) {
            Ok(bvh) => bvh,
            Err(Cancelled) => unreachable!("nobody else holds this control"),
        }
    }

    /// Build with a control: its total is set to the build's work (`build_work`), its progress
    /// advances at every split and leaf, and a cancel request stops the build within a few
    /// hundred nodes.
    pub fn build_controlled(mesh: &Mesh, params: &BuildParams, control: &WorkControl) -> Result<Bvh, Cancelled> {
        control.set_total(build_work(mesh.triangle_count(), params));
        Self::build_counted(mesh, params, control)
    }

    /// Build, advancing `control`'s progress by `build_work` without setting its total: for
    /// callers that build several BVHs under one control (the two-level BVH).
    pub(crate) fn build_counted(mesh: &Mesh, params: &BuildParams, control: &WorkControl) -> Result<Bvh, Cancelled> {
        let t0 = Instant::now();
        let params = params.clamped();
        let n = mesh.triangle_count();
        if params.strategy.follows_morton_order() {
            let progress = Progress { control, levels: progress_levels(n, &params) };
            return lbvh::build_mesh(mesh, &params, &progress)?.finish(control);
        }
        let make = |i: usize| {
            let tri = mesh.triangle(i as u32);
            let bounds = Aabb::from_points(&tri);
            BuildPrim::new(bounds, i as u32)
        };
        let mut prims: Vec<BuildPrim> = if n >= 1 << 16 {
            region(|| (0..n).into_par_iter().map(make).collect())
        } else {
            (0..n).map(make).collect()
        };
        let setup_time = t0.elapsed();
        control.check()?;

        let tri = |i: u32| mesh.triangle(i);
        let (nodes, mut report) = build_nodes(&mut prims, Some(&tri), &params, control)?;
        report.setup_time = setup_time;

        let t2 = Instant::now();
        let (prim_ids, tris) = region(|| {
            let prim_ids: Vec<u32> = prims.par_iter().with_min_len(4096).map(|p| p.index()).collect();
            let tris = prim_ids.par_iter().with_min_len(4096).map(|&i| mesh.triangle(i)).collect();
            (prim_ids, tris)
        });
        report.reorder_time = t2.elapsed();
        Bvh { nodes, prim_ids, tris, params, report }.finish(control)
    }

    /// The step after any builder (here, or the GPU's): the reinsertion its parameters ask for.
    /// Laying it out follows (`AnyBvh::finish`).
    pub fn finish(mut self, control: &WorkControl) -> Result<Bvh, Cancelled> {
        let passes = self.params.reinsert_passes;
        if passes > 0 {
            control.check()?;
            self.report.reinsertion = Some(reinsert::optimise(&mut self, passes));
        }
        Ok(self)
    }
}

/// A binary BVH over arbitrary boxes (the top level of a two-level BVH, whose "primitives" are
/// instances): the nodes, and for each leaf slot the index of its box in `boxes`. Leaf `index`
/// fields point into that order, as they point into `Bvh::prim_ids` for triangles. Progress
/// advances by `build_work(boxes.len(), params)`; the total is the caller's to set.
pub fn build_over_boxes(
    boxes: &[Aabb],
    params: &BuildParams,
    control: &WorkControl,
) -> Result<(Vec<BvhNode>, Vec<u32>, BuildReport), Cancelled> {
    let t0 = Instant::now();
    let params = params.clamped();
    let mut prims: Vec<BuildPrim> = boxes.iter().enumerate().map(|(i, b)| BuildPrim::new(*b, i as u32)).collect();
    let setup_time = t0.elapsed();
    // No triangles to clip: an SBVH top level makes object splits only.
    let (nodes, mut report) = build_nodes(&mut prims, None, &params, control)?;
    report.setup_time = setup_time;
    Ok((nodes, prims.iter().map(|p| p.index()).collect(), report))
}

/// The top-down splitting over prepared primitives, which it leaves in leaf order (the SBVH's
/// references replace them: more than one per triangle where spatial splits cut triangles of
/// `tri`).
fn build_nodes(
    prims: &mut Vec<BuildPrim>,
    tri: Option<sbvh::Triangles>,
    params: &BuildParams,
    control: &WorkControl,
) -> Result<(Vec<BvhNode>, BuildReport), Cancelled> {
    let t1 = Instant::now();
    let progress = Progress { control, levels: progress_levels(prims.len(), params) };
    let (tree, over) = match params.strategy.builder() {
        Builder::SpatialSplits => {
            let (nodes, refs, kinds) = sbvh::build(std::mem::take(prims), tri, params, &progress)?;
            *prims = refs;
            let report = BuildReport {
                split_time: t1.elapsed(),
                fallback_splits: kinds.over.fallback,
                depth_limited_splits: kinds.over.depth_limited,
                spatial_splits: kinds.spatial,
                ..Default::default()
            };
            return Ok((nodes, report));
        }
        Builder::Morton => {
            let (tree, fallback) = lbvh::build(prims, params, &progress)?;
            (tree, Overrides { fallback, depth_limited: 0 })
        }
        Builder::Clustering => {
            let (tree, _) = ploc::build(prims, params, params.ploc_radius as usize, &progress)?;
            (tree, Overrides::default())
        }
        Builder::TopDown(_) => build_subtree(prims, 0, 0, params, &progress)?,
    };
    let nodes = tree.into_nodes();
    Ok((
        nodes,
        BuildReport {
            split_time: t1.elapsed(),
            fallback_splits: over.fallback,
            depth_limited_splits: over.depth_limited,
            ..Default::default()
        },
    ))
}

/// What becomes of a node.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Decision {
    Leaf,
    /// `prims[..mid]` go to the left child.
    Split {
        axis: u8,
        mid: usize,
    },
}

/// Leaf or split, for every strategy, decided here and nowhere else: a single triangle is a leaf;
/// below the depth limit every node is split by equal count; a node that fits in a leaf is one,
/// unless the strategy prices splits (the SAH) and its best split is cheaper; a node that does not
/// fit is split as the strategy proposes, or by equal count when it finds no useful split.
fn decide(
    range: &mut [BuildPrim],
    info: &NodeInfo,
    depth: u32,
    params: &BuildParams,
    splitter: &mut dyn Splitter,
    over: &mut Overrides,
) -> Decision {
    let n = range.len();
    if n == 1 {
        return Decision::Leaf;
    }
    let equal_count = |range: &mut [BuildPrim]| {
        let (axis, mid) = EqualCount::median(range, info);
        Decision::Split { axis, mid }
    };
    if depth >= HEURISTIC_DEPTH_LIMIT {
        over.depth_limited += 1;
        return equal_count(range);
    }
    let fits = n <= params.max_leaf_size as usize;
    if fits && !splitter.prices_splits() {
        return Decision::Leaf;
    }
    match splitter.split(range, info) {
        // A split must leave both sides non-empty.
        Proposal::Split { axis, mid, weighted, .. } if mid > 0 && mid < n => {
            if fits && weighted.is_none_or(|w| leaf_is_cheaper(n, w, info, params)) {
                Decision::Leaf
            } else {
                Decision::Split { axis, mid }
            }
        }
        // No useful split, but the triangles fit in a leaf: that is the best we can do (e.g. the
        // two halves of a quad whose diagonal spans its box share a centroid).
        _ if fits => Decision::Leaf,
        _ => {
            over.fallback += 1;
            equal_count(range)
        }
    }
}

/// Subtrees at least `PARALLEL_MIN_PRIMS` big are split in parallel (`rayon::join`) down to this
/// depth, which bounds the recursion; deeper work uses the explicit stack.
const PARALLEL_MAX_DEPTH: u32 = 16;

/// The splitter of a top-down strategy (`build_nodes` sends the others to their own builders).
fn top_down(params: &BuildParams) -> Box<dyn split::Splitter> {
    params.strategy.splitter(params).expect("build_nodes builds only top-down strategies with the driver")
}

/// Build the subtree over `prims`, which start at `offset` in the full primitive array. Leaf
/// indices are global, child indices local to the subtree.
fn build_subtree(
    prims: &mut [BuildPrim],
    offset: u32,
    depth: u32,
    params: &BuildParams,
    progress: &Progress,
) -> Result<(Subtree, Overrides), Cancelled> {
    if prims.len() < PARALLEL_MIN_PRIMS || depth >= PARALLEL_MAX_DEPTH {
        return flat(prims, offset, depth, params, progress);
    }
    // Below PARTITION_MIN, one of many subtrees built side by side, each on one thread from here
    // (issue 37's serial fraction counts the bigger nodes' own work, outside their parallel passes).
    region_if(prims.len() < PARTITION_MIN, || build_parallel(prims, offset, depth, params, progress))
}

/// `build_sequential`'s nodes as a subtree.
fn flat(
    prims: &mut [BuildPrim],
    offset: u32,
    depth: u32,
    params: &BuildParams,
    progress: &Progress,
) -> Result<(Subtree, Overrides), Cancelled> {
    build_sequential(prims, offset, depth, params, progress).map(|(nodes, over)| (Subtree::Flat(nodes), over))
}

/// `build_subtree` for a node that is split here, its children in parallel.
fn build_parallel(
    prims: &mut [BuildPrim],
    offset: u32,
    depth: u32,
    params: &BuildParams,
    progress: &Progress,
) -> Result<(Subtree, Overrides), Cancelled> {
    progress.check()?;
    let info = node_info(prims);
    let mut over = Overrides::default();
    let decision = decide(prims, &info, depth, params, &mut *top_down(params), &mut over);
    let Decision::Split { axis, mid } = decision else {
        return flat(prims, offset, depth, params, progress);
    };
    progress.split(prims.len(), depth);
    let (l, r) = prims.split_at_mut(mid);
    let (left, right) = rayon::join(
        || build_subtree(l, offset, depth + 1, params, progress),
        || build_subtree(r, offset + mid as u32, depth + 1, params, progress),
    );
    let ((left, lo), (right, ro)) = (left?, right?);
    over += lo;
    over += ro;
    let len = 1 + left.len() + right.len();
    Ok((Subtree::Split { bounds: info.bounds, axis, left: Box::new(left), right: Box::new(right), len }, over))
}

/// Build a subtree with an explicit work stack (no recursion, however deep the tree).
fn build_sequential(
    prims: &mut [BuildPrim],
    offset: u32,
    depth0: u32,
    params: &BuildParams,
    progress: &Progress,
) -> Result<(Vec<BvhNode>, Overrides), Cancelled> {
    let mut nodes = Vec::with_capacity((2 * prims.len() / params.max_leaf_size.max(1) as usize).max(1));
    nodes.push(BvhNode::leaf(Aabb::EMPTY, offset, 0));
    let mut over = Overrides::default();
    if prims.is_empty() {
        return Ok((nodes, over)); // one empty leaf: every ray misses its empty box
    }
    let mut splitter = top_down(params);
    let mut stack = vec![Task { node: 0, start: 0, end: prims.len() as u32, depth: depth0 }];
    let mut steps = 0u32;
    while let Some(task) = stack.pop() {
        steps += 1;
        if steps.is_multiple_of(256) {
            progress.check()?;
        }
        let range = &mut prims[task.start as usize..task.end as usize];
        let info = node_info(range);
        let n = range.len();
        match decide(range, &info, task.depth, params, &mut *splitter, &mut over) {
            Decision::Split { axis, mid } => {
                let left = nodes.len() as u32;
                nodes.push(BvhNode::leaf(Aabb::EMPTY, 0, 0));
                nodes.push(BvhNode::leaf(Aabb::EMPTY, 0, 0));
                nodes[task.node as usize] = BvhNode::interior(info.bounds, left, axis);
                progress.split(n, task.depth);
                let mid = task.start + mid as u32;
                let depth = task.depth + 1;
                // Right pushed first so the left subtree is laid out right after its parent pair.
                stack.push(Task { node: left + 1, start: mid, end: task.end, depth });
                stack.push(Task { node: left, start: task.start, end: mid, depth });
            }
            Decision::Leaf => {
                nodes[task.node as usize] = BvhNode::leaf(info.bounds, offset + task.start, n as u16);
                progress.leaf(n, task.depth);
            }
        }
    }
    Ok((nodes, over))
}

#[cfg(test)]
mod builders_tests;
