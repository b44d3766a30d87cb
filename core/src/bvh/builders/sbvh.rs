//! SBVH: the split BVH of Stich, Friedrich & Dietrich, "Spatial Splits in Bounding Volume
//! Hierarchies" (HPG 2009). Top-down like the binned SAH, over *references* (a triangle and the
//! box of the part of it a node holds) instead of triangles: at each node the binned object split
//! is priced first, and when its two children's boxes overlap by more than α of the root's area
//! (§4.4, the overlap test) a spatial split is priced too (`split::spatial`), which cuts
//! straddling triangles so each child holds only its part. The cheaper one wins. A triangle cut by
//! spatial splits is referenced by several leaves, each with the box of its part: less overlap
//! between siblings, fewer boxes entered and triangles tested per ray, for more references.
//!
//! Reference growth is bounded: the root may add `sbvh_growth` percent of its triangles as
//! duplicates, and each split hands what is left of its budget to its children in proportion to
//! their references, so the bound holds and the tree does not depend on the thread count. With no
//! triangles to clip (the top level of two levels, over placements' boxes) only object splits are
//! made.
//!
//! `split_node` decides one node and partitions it; the build and the node inspector's replay
//! (`refs_at`, which walks from the root to a node through the same decisions) both call it, so
//! the curves the inspector draws are the ones the builder priced.

use super::common::{leaf_is_cheaper, node_info, Overrides, Progress, HEURISTIC_DEPTH_LIMIT};
use super::subtree::Subtree;
use crate::bvh::builders::split::equal_count::EqualCount;
use crate::bvh::builders::split::sah_binned::binned_planes;
use crate::bvh::builders::split::spatial::{spatial_partition, spatial_planes};
use crate::bvh::builders::split::splitter::{BuildPrim, NodeInfo, PlaneSink, Proposal};
use crate::bvh::node::BvhNode;
use crate::bvh::params::BuildParams;
use crate::geometry::Aabb;
use crate::parallel::region;
use crate::work::Cancelled;
use glam::Vec3;
use rayon::prelude::*;

/// Nodes at least this big are split in parallel (`rayon::join`), down to `PARALLEL_MAX_DEPTH`.
const PARALLEL_MIN: usize = 4096;
const PARALLEL_MAX_DEPTH: u32 = 16;
/// Nodes at least this big make their passes over references (bounds, copies) in parallel.
const PARALLEL_PASS_MIN: usize = 1 << 14;

/// The triangles spatial splits clip: the mesh's triangle of an index.
pub(super) type Triangles<'a> = &'a (dyn Fn(u32) -> [Vec3; 3] + Sync);

/// What every node of one build shares.
pub(super) struct Ctx<'a> {
    /// `None`: no spatial splits (nothing to clip).
    tri: Option<Triangles<'a>>,
    params: BuildParams,
    /// α times the root's area: the overlap above which spatial splits are priced.
    min_overlap: f32,
}

impl<'a> Ctx<'a> {
    pub(super) fn new(tri: Option<Triangles<'a>>, params: &BuildParams, root: &Aabb) -> Self {
        let area = if root.is_empty() { 0.0 } else { root.area() };
        Ctx { tri, params: *params, min_overlap: params.sbvh_alpha * area }
    }
}

/// A node's work: its references, the duplicates its subtree may still add, its share of the
/// build's progress units, its depth.
pub(crate) struct Work {
    pub refs: Vec<BuildPrim>,
    pub budget: u64,
    weight: u64,
    pub depth: u32,
}

impl Work {
    /// The root of a build over `refs` (one per triangle) with `params`' growth bound.
    pub(super) fn root(refs: Vec<BuildPrim>, params: &BuildParams) -> Work {
        let n = refs.len() as u64;
        Work { budget: n * params.sbvh_growth as u64 / 100, weight: n, depth: 0, refs }
    }
}

/// How a node was split.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum SplitKind {
    Object,
    Spatial,
    /// The driver's fallback (no useful split of a node too big for a leaf, or below the depth
    /// limit): the median reference.
    EqualCount,
}

/// What `split_node` made of a node, with the figures the inspector explains it by.
pub(super) struct Decided {
    pub outcome: Outcome,
    /// The area the object split's children's boxes share, over the root's (the α test's λ).
    pub overlap: f32,
    /// Whether a spatial split was priced here (the overlap test passed and budget was left).
    pub spatial_priced: bool,
    /// The duplicates a cheaper spatial split would have added, when that was over the budget.
    pub over_budget: Option<u64>,
    over: Overrides,
}

pub(super) enum Outcome {
    Leaf(Vec<BuildPrim>),
    Split { kind: SplitKind, axis: u8, plane: f32, left: Work, right: Work },
}

/// Decide `work` (leaf, object split, spatial split or fallback) and partition it, reporting the
/// object split's planes to `objects` and the spatial split's to `spatials`.
pub(super) fn split_node(
    mut work: Work,
    info: &NodeInfo,
    ctx: &Ctx,
    objects: &mut impl PlaneSink,
    spatials: &mut impl PlaneSink,
) -> Decided {
    let n = work.refs.len();
    let mut decided = Decided {
        outcome: Outcome::Leaf(Vec::new()),
        overlap: 0.0,
        spatial_priced: false,
        over_budget: None,
        over: Overrides::default(),
    };
    let params = &ctx.params;
    if n <= 1 {
        decided.outcome = Outcome::Leaf(work.refs);
        return decided;
    }
    if work.depth >= HEURISTIC_DEPTH_LIMIT {
        decided.over.depth_limited += 1;
        decided.outcome = equal_count(work, info);
        return decided;
    }
    let fits = n <= params.max_leaf_size as usize;
    let object = match binned_planes(&mut work.refs, info, params.sah_bins as usize, objects) {
        Proposal::Split { axis, mid, weighted: Some(w), plane } if mid > 0 && mid < n => Some((axis, mid, w, plane)),
        _ => None,
    };
    if let Some((_, mid, _, _)) = object {
        decided.overlap = bounds_of(&work.refs[..mid]).intersection(bounds_of(&work.refs[mid..])).area();
    }
    // §4.4: spatial splits only where the object split's children overlap by more than α of the
    // root's area (or where there is no object split), and while the budget lasts.
    let mut spatial = None;
    if let Some(tri) = ctx.tri.filter(|_| work.budget > 0 && (object.is_none() || decided.overlap > ctx.min_overlap)) {
        decided.spatial_priced = true;
        let found = spatial_planes(&work.refs, tri, &info.bounds, params.sah_bins as usize, spatials);
        if let Some(s) = found.filter(|s| object.is_none_or(|(_, _, w, _)| s.weighted < w)) {
            let (l, r) = spatial_partition(&work.refs, tri, s.axis as usize, s.position);
            let added = (l.len() + r.len() - n) as u64;
            // A cut of references that all straddle the plane leaves both children as many as
            // the parent, but every such split spends budget, so the splitting ends.
            if added > work.budget {
                decided.over_budget = Some(added);
            } else if !l.is_empty() && !r.is_empty() {
                // The children as partitioned (unsplitting changes the bins' estimate) must still
                // beat the object split.
                let weighted = area_of(&l) * l.len() as f32 + area_of(&r) * r.len() as f32;
                if object.is_none_or(|(_, _, w, _)| weighted < w) {
                    spatial = Some((s.axis, s.position, weighted, l, r, added));
                }
            }
        }
    }
    let weighted = spatial.as_ref().map(|s| s.2).or(object.map(|o| o.2));
    if fits && weighted.is_none_or(|w| leaf_is_cheaper(n, w, info, params)) {
        decided.outcome = Outcome::Leaf(work.refs);
        return decided;
    }
    decided.outcome = if let Some((axis, plane, _, l, r, added)) = spatial {
        let (left, right) = share(&work, l, r, added);
        Outcome::Split { kind: SplitKind::Spatial, axis, plane, left, right }
    } else if let Some((axis, mid, _, plane)) = object {
        let r = split_off(&mut work.refs, mid);
        let l = std::mem::take(&mut work.refs);
        let (left, right) = share(&work, l, r, 0);
        Outcome::Split { kind: SplitKind::Object, axis, plane, left, right }
    } else {
        decided.over.fallback += 1;
        equal_count(work, info)
    };
    decided
}

/// The median split of a node with no useful plane (or below the depth limit).
fn equal_count(mut work: Work, info: &NodeInfo) -> Outcome {
    let (axis, mid) = EqualCount::median(&mut work.refs, info);
    let plane = work.refs[mid].centroid()[axis as usize];
    let r = split_off(&mut work.refs, mid);
    let l = std::mem::take(&mut work.refs);
    let (left, right) = share(&work, l, r, 0);
    Outcome::Split { kind: SplitKind::EqualCount, axis, plane, left, right }
}

/// The children's work: the budget left after `added` duplicates and the progress weight.
///
/// Progress is shared by reference count. The budget follows the rays: each child's share is its
/// part of A_L·n_L + A_R·n_R, the SAH's estimate of the work rays do under it (a child of small
/// pieces needs no spatial splits). But cutting a group of long triangles pays only when every
/// one of them is cut (one left whole keeps its side's box as big as before), which takes about
/// one duplicate per reference. So when neither share reaches that, shares that would each be too
/// small to cut anything are not handed out evenly: the child with the larger SAH weight gets
/// up to one duplicate per reference, the other the rest.
fn share(parent: &Work, l: Vec<BuildPrim>, r: Vec<BuildPrim>, added: u64) -> (Work, Work) {
    let (nl, nr) = (l.len() as u64, r.len() as u64);
    let weight = |s: &[BuildPrim]| area_of(s) as f64 * s.len() as f64;
    let budget = parent.budget - added;
    let (bl, br) = if budget == 0 {
        (0, 0)
    } else {
        let (wl, wr) = (weight(&l), weight(&r));
        let share = if wl + wr > 0.0 { wl / (wl + wr) } else { nl as f64 / (nl + nr) as f64 };
        let bl = ((budget as f64 * share) as u64).min(budget);
        if bl < nl && budget - bl < nr {
            if wl >= wr {
                let bl = budget.min(nl);
                (bl, budget - bl)
            } else {
                let br = budget.min(nr);
                (budget - br, br)
            }
        } else {
            (bl, budget - bl)
        }
    };
    let wl = parent.weight * nl / (nl + nr);
    let depth = parent.depth + 1;
    (Work { refs: l, budget: bl, weight: wl, depth }, Work { refs: r, budget: br, weight: parent.weight - wl, depth })
}

/// The box of some references (in parallel chunks for many: exact unions, any order).
fn bounds_of(refs: &[BuildPrim]) -> Aabb {
    let of = |r: &[BuildPrim]| Aabb::of(r.iter().map(BuildPrim::bounds));
    if refs.len() >= PARALLEL_PASS_MIN {
        region(|| refs.par_chunks(PARALLEL_PASS_MIN / 4).map(of).reduce(|| Aabb::EMPTY, |a, b| a.union(b)))
    } else {
        of(refs)
    }
}

/// `refs` cut at `mid`: the references from `mid` on, copied in parallel for big nodes (the
/// root's right half is millions of references).
fn split_off(refs: &mut Vec<BuildPrim>, mid: usize) -> Vec<BuildPrim> {
    if refs.len() < PARALLEL_PASS_MIN {
        return refs.split_off(mid);
    }
    let right: Vec<BuildPrim> = region(|| refs[mid..].par_iter().copied().collect());
    refs.truncate(mid);
    right
}

fn area_of(refs: &[BuildPrim]) -> f32 {
    bounds_of(refs).area()
}

/// Splits of each kind in a build.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Kinds {
    pub over: Overrides,
    pub spatial: u32,
}

impl Kinds {
    fn add(&mut self, d: &Decided) {
        self.over += d.over;
        if matches!(d.outcome, Outcome::Split { kind: SplitKind::Spatial, .. }) {
            self.spatial += 1;
        }
    }
    fn merge(mut self, o: Kinds) -> Kinds {
        self.over += o.over;
        self.spatial += o.spatial;
        self
    }
}

/// Build the SBVH over `refs` (one per triangle, `refs[i]` of triangle i's bounds). Returns the
/// nodes, the references in leaf order (longer than `refs` by the duplicates) and the split counts.
pub(super) fn build(
    refs: Vec<BuildPrim>,
    tri: Option<Triangles>,
    params: &BuildParams,
    progress: &Progress,
) -> Result<(Vec<BvhNode>, Vec<BuildPrim>, Kinds), Cancelled> {
    let root = node_info(&refs);
    let ctx = Ctx::new(tri, params, &root.bounds);
    let (mut tree, pieces, kinds) = build_subtree(Work::root(refs, params), &ctx, progress)?;
    // Each flat piece numbered its leaves' references from 0, and the pieces' references are in
    // depth-first (left before right) order, as the pieces are: each piece's leaves move by the
    // references before it, and the pieces are copied one after the other, both in parallel.
    let mut flats = tree.flats_mut();
    debug_assert_eq!(flats.len(), pieces.len());
    let offsets: Vec<u32> =
        pieces.iter().scan(0, |sum, p| Some(std::mem::replace(sum, *sum + p.len() as u32))).collect();
    region(|| {
        flats.par_iter_mut().zip(offsets).for_each(|(nodes, offset)| {
            // (An empty mesh's root is an empty leaf, whose count of 0 reads as interior: unmoved.)
            nodes.iter_mut().filter(|n| n.is_leaf()).for_each(|n| n.index += offset);
        })
    });
    let out = crate::parallel::concat(pieces, 0);
    Ok((tree.into_nodes(), out, kinds))
}

/// The subtree over `work`, its references as pieces in depth-first order (one per flat piece of
/// the subtree: concatenating them at every level copied the top levels' references once per
/// level, on one thread), and its split counts.
fn build_subtree(
    work: Work,
    ctx: &Ctx,
    progress: &Progress,
) -> Result<(Subtree, Vec<Vec<BuildPrim>>, Kinds), Cancelled> {
    if work.refs.len() < PARALLEL_MIN || work.depth >= PARALLEL_MAX_DEPTH {
        // One of many subtrees built side by side, unless the depth limit made it (issue 37's
        // serial fraction).
        let small = work.refs.len() < PARALLEL_PASS_MIN;
        let sequential = || build_sequential(work, ctx, progress);
        let (nodes, refs, kinds) = if small { region(sequential)? } else { sequential()? };
        return Ok((Subtree::Flat(nodes), vec![refs], kinds));
    }
    if work.refs.len() < PARALLEL_PASS_MIN {
        return region(|| build_parallel(work, ctx, progress));
    }
    build_parallel(work, ctx, progress)
}

/// `build_subtree` for a node split here, its children in parallel.
fn build_parallel(
    work: Work,
    ctx: &Ctx,
    progress: &Progress,
) -> Result<(Subtree, Vec<Vec<BuildPrim>>, Kinds), Cancelled> {
    progress.check()?;
    let info = node_info(&work.refs);
    let (weight, depth) = (work.weight, work.depth);
    let decided = split_node(work, &info, ctx, &mut (), &mut ());
    let mut kinds = Kinds::default();
    kinds.add(&decided);
    match decided.outcome {
        Outcome::Leaf(refs) => {
            // (Not reached for nodes this big, which never fit a leaf; kept for completeness.)
            progress.leaf(weight as usize, depth);
            let leaf = BvhNode::leaf(info.bounds, 0, refs.len() as u16);
            Ok((Subtree::Flat(vec![leaf]), vec![refs], kinds))
        }
        Outcome::Split { axis, left, right, .. } => {
            progress.add(progress.split_units(weight as usize, depth));
            let (l, r) = rayon::join(|| build_subtree(left, ctx, progress), || build_subtree(right, ctx, progress));
            let ((lt, mut pieces, lk), (rt, right_pieces, rk)) = (l?, r?);
            pieces.extend(right_pieces);
            let len = 1 + lt.len() + rt.len();
            let tree = Subtree::Split { bounds: info.bounds, axis, left: Box::new(lt), right: Box::new(rt), len };
            Ok((tree, pieces, kinds.merge(lk).merge(rk)))
        }
    }
}

/// A subtree with an explicit stack; leaves' references appended in depth-first order, each
/// leaf's first reference its place in that list.
fn build_sequential(
    work: Work,
    ctx: &Ctx,
    progress: &Progress,
) -> Result<(Vec<BvhNode>, Vec<BuildPrim>, Kinds), Cancelled> {
    let mut nodes = vec![BvhNode::leaf(Aabb::EMPTY, 0, 0)];
    let mut out = Vec::with_capacity(work.refs.len() + work.budget as usize);
    let mut kinds = Kinds::default();
    let mut stack = vec![(0usize, work)];
    let mut steps = 0u32;
    while let Some((slot, work)) = stack.pop() {
        steps += 1;
        if steps.is_multiple_of(256) {
            progress.check()?;
        }
        if work.refs.is_empty() {
            continue; // an empty mesh: one empty leaf
        }
        let info = node_info(&work.refs);
        let (weight, depth) = (work.weight, work.depth);
        let decided = split_node(work, &info, ctx, &mut (), &mut ());
        kinds.add(&decided);
        match decided.outcome {
            Outcome::Leaf(refs) => {
                // Numbered within this piece; `build` adds the references of the pieces before.
                nodes[slot] = BvhNode::leaf(info.bounds, out.len() as u32, refs.len() as u16);
                progress.leaf(weight as usize, depth);
                out.extend(refs);
            }
            Outcome::Split { axis, left, right, .. } => {
                let first = nodes.len();
                nodes.push(BvhNode::leaf(Aabb::EMPTY, 0, 0));
                nodes.push(BvhNode::leaf(Aabb::EMPTY, 0, 0));
                nodes[slot] = BvhNode::interior(info.bounds, first as u32, axis);
                progress.add(progress.split_units(weight as usize, depth));
                stack.push((first + 1, right));
                stack.push((first, left));
            }
        }
    }
    Ok((nodes, out, kinds))
}

/// The work of the node at the end of `path` (from the root, each step `true` for the right
/// child) as the build had it, found by walking down through the build's own `split_node` from
/// `refs`, the root's references in the build's order (triangle i's bounds at place i). `None`
/// when the path runs past a leaf.
pub(crate) fn descend(refs: Vec<BuildPrim>, tri: Triangles, params: &BuildParams, path: &[bool]) -> Option<Work> {
    let root = node_info(&refs);
    let ctx = Ctx::new(Some(tri), params, &root.bounds);
    let mut work = Work::root(refs, params);
    for &right in path {
        let info = node_info(&work.refs);
        match split_node(work, &info, &ctx, &mut (), &mut ()).outcome {
            Outcome::Split { left, right: r, .. } => work = if right { r } else { left },
            Outcome::Leaf(_) => return None,
        }
    }
    Some(work)
}

/// A node's references, the duplicates it may still add and its depth: for a tree of another
/// strategy, its triangles whole with a fresh budget (what the SBVH would do with them).
pub(crate) fn work_of(refs: Vec<BuildPrim>, params: &BuildParams, depth: u32) -> Work {
    Work { depth, ..Work::root(refs, params) }
}

/// What the SBVH builder decides at `work` (a tree whose root box is `root`), with the spatial
/// split's planes reported to `spatials`: the node inspector's explanation.
pub(crate) fn explain(
    work: Work,
    tri: Triangles,
    params: &BuildParams,
    root: &Aabb,
    spatials: &mut impl PlaneSink,
) -> NodeDecision {
    let ctx = Ctx::new(Some(tri), params, root);
    let info = node_info(&work.refs);
    let budget = work.budget;
    let decided = split_node(work, &info, &ctx, &mut (), spatials);
    let split = match &decided.outcome {
        Outcome::Split { kind, axis, plane, left, right } => Some(DecidedSplit {
            kind: *kind,
            axis: *axis,
            plane: *plane,
            left: left.refs.len() as u32,
            right: right.refs.len() as u32,
            weighted: [&left.refs, &right.refs].iter().map(|s| area_of(s) * s.len() as f32).sum(),
            areas: [area_of(&left.refs), area_of(&right.refs)],
        }),
        Outcome::Leaf(_) => None,
    };
    let area = if root.is_empty() { 0.0 } else { root.area() };
    NodeDecision {
        budget,
        overlap_ratio: if area > 0.0 { decided.overlap / area } else { 0.0 },
        spatial_priced: decided.spatial_priced,
        over_budget: decided.over_budget,
        split,
    }
}

/// What the SBVH builder made of a node (`explain`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeDecision {
    /// Duplicates its subtree could still add.
    pub budget: u64,
    /// λ / A(root): the object split's children's common area over the root's (spatial splits
    /// are priced when it exceeds α).
    pub overlap_ratio: f32,
    pub spatial_priced: bool,
    /// The duplicates the cheaper spatial split needed, when they were more than the budget.
    pub over_budget: Option<u64>,
    /// `None`: a leaf.
    pub split: Option<DecidedSplit>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DecidedSplit {
    pub kind: SplitKind,
    pub axis: u8,
    pub plane: f32,
    /// References of each child (a cut triangle in both).
    pub left: u32,
    pub right: u32,
    /// A_L·n_L + A_R·n_R of the children made.
    pub weighted: f32,
    /// [A_L, A_R].
    pub areas: [f32; 2],
}

#[cfg(test)]
#[path = "sbvh_tests.rs"]
mod tests;
