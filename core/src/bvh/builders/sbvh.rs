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
//! The SBVH is built by the top-down driver (`driver`) with `SpatialSplits` as its splitter;
//! what is its own is here: a node's references as the driver's `Part` (`Work`), with the budget
//! each split hands down (`share`), and the node inspector's replay (`descend`, `explain`), which
//! walks from the root to a node through the driver's own `decide`, so the curves the inspector
//! draws are the ones the builder priced.

use crate::bvh::builders::common::{node_info, Overrides, Progress};
use crate::bvh::builders::driver::{build_subtree, children, decide, Decision, Driver, MakeSplitter, Part, SplitKind};
use crate::bvh::builders::split::spatial::{area_of, Triangles};
use crate::bvh::builders::split::spatial_splits::SpatialSplits;
use crate::bvh::builders::split::splitter::{BuildPrim, NodeInfo, PlaneSink, Proposal, Splitter};
use crate::bvh::node::BvhNode;
use crate::bvh::params::BuildParams;
use crate::geometry::Aabb;
use crate::parallel::region;
use crate::work::Cancelled;
use rayon::prelude::*;

/// Nodes at least this big copy their references in parallel.
const PARALLEL_PASS_MIN: usize = 1 << 14;

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
    pub(crate) fn root(refs: Vec<BuildPrim>, params: &BuildParams) -> Work {
        let n = refs.len() as u64;
        Work { budget: n * params.sbvh_growth as u64 / 100, weight: n, depth: 0, refs }
    }
}

impl Part for Work {
    type Leaves = Vec<BuildPrim>;

    fn prims(&self) -> &[BuildPrim] {
        &self.refs
    }
    fn prims_mut(&mut self) -> &mut [BuildPrim] {
        &mut self.refs
    }
    fn depth(&self) -> u32 {
        self.depth
    }
    fn budget(&self) -> u64 {
        self.budget
    }
    fn weight(&self) -> usize {
        self.weight as usize
    }
    fn split_at(mut self, mid: usize) -> (Self, Self) {
        let r = split_off(&mut self.refs, mid);
        let l = std::mem::take(&mut self.refs);
        share(&self, l, r, 0)
    }
    fn cut(self, l: Vec<BuildPrim>, r: Vec<BuildPrim>) -> (Self, Self) {
        let added = (l.len() + r.len() - self.refs.len()) as u64;
        share(&self, l, r, added)
    }
    fn leaf(self, leaves: &mut Vec<BuildPrim>) -> u32 {
        let first = leaves.len() as u32;
        leaves.extend(self.refs);
        first
    }
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

/// Build the SBVH over `refs` (one per triangle, `refs[i]` of triangle i's bounds) with the
/// driver (`splitter`: `SpatialSplits`). Returns the nodes, the references in leaf order (longer
/// than `refs` by the duplicates) and the driver's counts (`Overrides::cut`: spatial splits).
pub(super) fn build<'s>(
    refs: Vec<BuildPrim>,
    params: &BuildParams,
    progress: &Progress,
    splitter: &MakeSplitter<'s>,
) -> Result<(Vec<BvhNode>, Vec<BuildPrim>, Overrides), Cancelled> {
    let d = Driver { params, progress, splitter };
    let (mut tree, pieces, over) = build_subtree(Work::root(refs, params), &d)?;
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
    Ok((tree.into_nodes(), out, over))
}

/// The work of the node at the end of `path` (from the root, each step `true` for the right
/// child) as the build had it, found by walking down through the driver's own `decide` and
/// `children` from `refs`, the root's references in the build's order (triangle i's bounds at
/// place i). `None` when the path runs past a leaf.
pub(crate) fn descend(refs: Vec<BuildPrim>, tri: Triangles, params: &BuildParams, path: &[bool]) -> Option<Work> {
    let root = node_info(&refs);
    let mut splitter = SpatialSplits::new(Some(tri), params, &root.bounds);
    let mut work = Work::root(refs, params);
    for &right in path {
        let info = NodeInfo { budget: work.budget, ..node_info(&work.refs) };
        let d = decide(&mut work.refs, &info, work.depth, params, &mut splitter, &mut Overrides::default());
        if d == Decision::Leaf {
            return None;
        }
        let (l, r) = children(work, &d, &mut splitter);
        work = if right { r } else { l };
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
pub(crate) fn explain<S: PlaneSink + Send>(
    mut work: Work,
    tri: Triangles,
    params: &BuildParams,
    root: &Aabb,
    spatials: &mut S,
) -> NodeDecision {
    let mut splitter = SpatialSplits::new(Some(tri), params, root);
    let info = NodeInfo { budget: work.budget, ..node_info(&work.refs) };
    let budget = work.budget;
    let mut reporting = Reporting { splitter: &mut splitter, spatials };
    let d = decide(&mut work.refs, &info, work.depth, params, &mut reporting, &mut Overrides::default());
    let figures = splitter.figures;
    let split = match d {
        Decision::Split { kind, axis, plane, .. } => {
            let (left, right) = children(work, &d, &mut splitter);
            Some(DecidedSplit {
                kind,
                axis,
                plane,
                left: left.refs.len() as u32,
                right: right.refs.len() as u32,
                weighted: [&left.refs, &right.refs].iter().map(|s| area_of(s) * s.len() as f32).sum(),
                areas: [area_of(&left.refs), area_of(&right.refs)],
            })
        }
        Decision::Leaf => None,
    };
    let area = if root.is_empty() { 0.0 } else { root.area() };
    NodeDecision {
        budget,
        overlap_ratio: if area > 0.0 { figures.overlap / area } else { 0.0 },
        spatial_priced: figures.spatial_priced,
        over_budget: figures.over_budget,
        split,
    }
}

/// `SpatialSplits` with its spatial planes reported to a sink (the inspector's curves).
struct Reporting<'r, 'a, S> {
    splitter: &'r mut SpatialSplits<'a>,
    spatials: &'r mut S,
}

impl<S: PlaneSink + Send> Splitter for Reporting<'_, '_, S> {
    fn prices_splits(&self) -> bool {
        true
    }
    fn split(&mut self, prims: &mut [BuildPrim], node: &NodeInfo) -> Proposal {
        self.splitter.propose(prims, node, &mut (), self.spatials)
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
