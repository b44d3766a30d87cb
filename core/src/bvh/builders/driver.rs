//! The top-down build driver shared by every splitting strategy (pbrt-v4 §7.3, "BVH
//! construction"): the midpoint, equal count, both SAHs, and the SBVH's spatial splits.
//!
//! A node's primitives are a `Part`: a range of the build's one array, partitioned in place
//! (`InPlace`), or, for the SBVH, references of its own with a budget of duplicates
//! (`sbvh::Work`), because a spatial split puts a cut triangle in both children. The driver asks
//! the strategy's `Splitter` for a proposal, decides leaf or split by one rule (`decide`), and
//! makes the children (`children`): in place, or, for a cut, from the references the splitter
//! made. It keeps an explicit work stack instead of recursing, so a 10M-triangle mesh or a
//! million identical triangles cannot overflow the call stack; the top levels are split in
//! parallel (`build_subtree`). Nodes are allocated in pairs when a node is split, so the two
//! children of a node are adjacent and an interior node needs only one index.

use crate::bvh::builders::common::PARALLEL_MIN_PRIMS;
use crate::bvh::builders::common::{leaf_is_cheaper, node_info, Overrides, Progress, HEURISTIC_DEPTH_LIMIT};
use crate::bvh::builders::split::equal_count::EqualCount;
use crate::bvh::builders::split::splitter::{BuildPrim, NodeInfo, Proposal, Splitter};
use crate::bvh::builders::subtree::Subtree;
use crate::bvh::node::BvhNode;
use crate::bvh::params::BuildParams;
use crate::geometry::Aabb;
use crate::parallel::{region_if, PARTITION_MIN};
use crate::work::Cancelled;

/// A node's primitives as the driver holds them while it builds.
pub(super) trait Part: Sized + Send {
    /// Where a flat piece of the tree puts its leaves' primitives: nowhere for `InPlace` (they
    /// stay in the build's array), a list for references.
    type Leaves: Default + Send;

    fn prims(&self) -> &[BuildPrim];
    fn prims_mut(&mut self) -> &mut [BuildPrim];
    fn depth(&self) -> u32;

    /// The duplicates its subtree may still add (a cutting splitter's allowance; 0 when the part
    /// cannot hold more primitives than it was given).
    fn budget(&self) -> u64 {
        0
    }

    /// Its share of the build's progress units (its primitives; references share their root's).
    fn weight(&self) -> usize {
        self.prims().len()
    }

    /// The children of a split that sends `prims()[..mid]` left.
    fn split_at(self, mid: usize) -> (Self, Self);

    /// The children of a cut, each with the references the splitter made for it.
    fn cut(self, left: Vec<BuildPrim>, right: Vec<BuildPrim>) -> (Self, Self);

    /// Make it a leaf: the slot of its first primitive (in a flat piece, counted from the piece's
    /// first leaf for references; `sbvh::build` moves them when the pieces are joined).
    fn leaf(self, leaves: &mut Self::Leaves) -> u32;
}

/// A range of the build's primitive array: children partition it in place, and a leaf's
/// primitives stay where they are (every strategy but the SBVH).
pub(super) struct InPlace<'a> {
    prims: &'a mut [BuildPrim],
    /// The place of `prims[0]` in the whole array.
    first: u32,
    depth: u32,
}

impl<'a> InPlace<'a> {
    pub(super) fn root(prims: &'a mut [BuildPrim]) -> Self {
        InPlace { prims, first: 0, depth: 0 }
    }
}

impl Part for InPlace<'_> {
    type Leaves = ();

    fn prims(&self) -> &[BuildPrim] {
        self.prims
    }
    fn prims_mut(&mut self) -> &mut [BuildPrim] {
        self.prims
    }
    fn depth(&self) -> u32 {
        self.depth
    }
    fn split_at(self, mid: usize) -> (Self, Self) {
        let (l, r) = self.prims.split_at_mut(mid);
        let depth = self.depth + 1;
        (InPlace { prims: l, first: self.first, depth }, InPlace { prims: r, first: self.first + mid as u32, depth })
    }
    fn cut(self, _: Vec<BuildPrim>, _: Vec<BuildPrim>) -> (Self, Self) {
        unreachable!("a splitter cuts only within a budget, and an array partitioned in place has none")
    }
    fn leaf(self, _: &mut ()) -> u32 {
        self.first
    }
}

/// How a node was split.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum SplitKind {
    /// At the strategy's plane, each primitive to the side of its centroid.
    Object,
    /// At the strategy's plane, primitives that straddle it cut in two (SBVH).
    Spatial,
    /// The driver's fallback (no useful split of a node too big for a leaf, or below the depth
    /// limit): the median primitive.
    EqualCount,
}

/// What becomes of a node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Decision {
    Leaf,
    /// `prims()[..mid]` go to the left child (object and equal-count splits), or the splitter's
    /// cut references go to each side (spatial splits: `mid` unused).
    Split {
        kind: SplitKind,
        axis: u8,
        mid: usize,
        plane: f32,
    },
}

/// Leaf or split, for every strategy, decided here and nowhere else: a single triangle is a leaf;
/// below the depth limit every node is split by equal count; a node that fits in a leaf is one,
/// unless the strategy prices splits (the SAH) and its best split is cheaper; a node that does not
/// fit is split as the strategy proposes, or by equal count when it finds no useful split.
pub(super) fn decide<S: Splitter + ?Sized>(
    prims: &mut [BuildPrim],
    info: &NodeInfo,
    depth: u32,
    params: &BuildParams,
    splitter: &mut S,
    over: &mut Overrides,
) -> Decision {
    let n = prims.len();
    if n <= 1 {
        return Decision::Leaf;
    }
    let equal_count = |prims: &mut [BuildPrim]| {
        let (axis, mid) = EqualCount::median(prims, info);
        let plane = prims[mid].centroid()[axis as usize];
        Decision::Split { kind: SplitKind::EqualCount, axis, mid, plane }
    };
    if depth >= HEURISTIC_DEPTH_LIMIT {
        over.depth_limited += 1;
        return equal_count(prims);
    }
    let fits = n <= params.max_leaf_size as usize;
    if fits && !splitter.prices_splits() {
        return Decision::Leaf;
    }
    let leaf_first = |weighted: Option<f32>| fits && weighted.is_none_or(|w| leaf_is_cheaper(n, w, info, params));
    match splitter.split(prims, info) {
        // A split must leave both sides non-empty.
        Proposal::Split { axis, mid, weighted, plane } if mid > 0 && mid < n => {
            if leaf_first(weighted) {
                Decision::Leaf
            } else {
                Decision::Split { kind: SplitKind::Object, axis, mid, plane }
            }
        }
        Proposal::Cut { axis, plane, weighted } => {
            if leaf_first(Some(weighted)) {
                Decision::Leaf
            } else {
                Decision::Split { kind: SplitKind::Spatial, axis, mid: 0, plane }
            }
        }
        // No useful split, but the triangles fit in a leaf: that is the best we can do (e.g. the
        // two halves of a quad whose diagonal spans its box share a centroid).
        _ if fits => Decision::Leaf,
        _ => {
            over.fallback += 1;
            equal_count(prims)
        }
    }
}

/// The children of a node `decide` split (not a leaf): the reference duplication of a spatial
/// split happens here, with the references `splitter` made when it proposed the cut.
pub(super) fn children<P: Part, S: Splitter + ?Sized>(part: P, decision: &Decision, splitter: &mut S) -> (P, P) {
    match *decision {
        Decision::Split { kind: SplitKind::Spatial, .. } => {
            let (l, r) = splitter.take_cut();
            part.cut(l, r)
        }
        Decision::Split { mid, .. } => part.split_at(mid),
        Decision::Leaf => unreachable!("a leaf has no children"),
    }
}

/// A splitter for one thread of a build (each parallel node and each flat piece makes its own:
/// splitters keep scratch memory from node to node).
pub(super) type MakeSplitter<'s> = dyn Fn() -> Box<dyn Splitter + 's> + Sync + 's;

/// What every node of one build shares.
pub(super) struct Driver<'d, 's> {
    pub params: &'d BuildParams,
    pub progress: &'d Progress<'d>,
    pub splitter: &'d MakeSplitter<'s>,
}

impl Driver<'_, '_> {
    /// The node's bounds, and the budget a cutting splitter may spend there.
    fn info<P: Part>(part: &P) -> NodeInfo {
        NodeInfo { budget: part.budget(), ..node_info(part.prims()) }
    }

    /// Decide the node and count it in the progress: its children, or `Err` with the leaf it is.
    fn step<P: Part, S: Splitter + ?Sized>(
        &self,
        mut part: P,
        info: &NodeInfo,
        splitter: &mut S,
        over: &mut Overrides,
    ) -> Result<(u8, P, P), P> {
        let (weight, depth) = (part.weight(), part.depth());
        match decide(part.prims_mut(), info, depth, self.params, splitter, over) {
            Decision::Leaf => {
                self.progress.leaf(weight, depth);
                Err(part)
            }
            d @ Decision::Split { kind, axis, .. } => {
                self.progress.split(weight, depth);
                over.cut += u32::from(kind == SplitKind::Spatial);
                let (l, r) = children(part, &d, splitter);
                Ok((axis, l, r))
            }
        }
    }
}

/// Subtrees at least `PARALLEL_MIN_PRIMS` big are split in parallel (`rayon::join`) down to this
/// depth, which bounds the recursion; deeper work uses the explicit stack.
const PARALLEL_MAX_DEPTH: u32 = 16;

/// The subtree over `part`: its nodes (child indices local to it), its leaves' primitives as
/// pieces in depth-first order (one per flat piece: `Subtree::flats_mut`), and the nodes where
/// the driver overrode the strategy.
pub(super) fn build_subtree<P: Part>(part: P, d: &Driver) -> Result<(Subtree, Vec<P::Leaves>, Overrides), Cancelled> {
    let n = part.prims().len();
    if n < PARALLEL_MIN_PRIMS || part.depth() >= PARALLEL_MAX_DEPTH {
        let (nodes, leaves, over) = build_sequential(part, d)?;
        return Ok((Subtree::Flat(nodes), vec![leaves], over));
    }
    // Below PARTITION_MIN, one of many subtrees built side by side, each on one thread from here
    // (issue 37's serial fraction counts the bigger nodes' own work, outside their parallel passes).
    region_if(n < PARTITION_MIN, || build_parallel(part, d))
}

/// `build_subtree` for a node that is split here, its children in parallel.
fn build_parallel<P: Part>(part: P, d: &Driver) -> Result<(Subtree, Vec<P::Leaves>, Overrides), Cancelled> {
    d.progress.check()?;
    let info = Driver::info(&part);
    let mut over = Overrides::default();
    let mut splitter = (d.splitter)();
    let (axis, l, r) = match d.step(part, &info, &mut *splitter, &mut over) {
        Ok(split) => split,
        Err(part) => {
            // (Not reached for nodes this big, which never fit a leaf.)
            let mut leaves = P::Leaves::default();
            let n = part.prims().len() as u16;
            let first = part.leaf(&mut leaves);
            return Ok((Subtree::Flat(vec![BvhNode::leaf(info.bounds, first, n)]), vec![leaves], over));
        }
    };
    drop(splitter);
    let (left, right) = rayon::join(|| build_subtree(l, d), || build_subtree(r, d));
    let ((left, mut pieces, lo), (right, right_pieces, ro)) = (left?, right?);
    pieces.extend(right_pieces);
    over += lo;
    over += ro;
    let len = 1 + left.len() + right.len();
    Ok((Subtree::Split { bounds: info.bounds, axis, left: Box::new(left), right: Box::new(right), len }, pieces, over))
}

/// Build a subtree with an explicit work stack (no recursion, however deep the tree).
pub(super) fn build_sequential<P: Part>(
    root: P,
    d: &Driver,
) -> Result<(Vec<BvhNode>, P::Leaves, Overrides), Cancelled> {
    let mut nodes = Vec::with_capacity((2 * root.prims().len() / d.params.max_leaf_size.max(1) as usize).max(1));
    nodes.push(BvhNode::leaf(Aabb::EMPTY, 0, 0));
    let mut leaves = P::Leaves::default();
    let mut over = Overrides::default();
    if root.prims().is_empty() {
        nodes[0] = BvhNode::leaf(Aabb::EMPTY, root.leaf(&mut leaves), 0); // every ray misses its empty box
        return Ok((nodes, leaves, over));
    }
    let mut splitter = (d.splitter)();
    let mut stack = vec![(0usize, root)];
    let mut steps = 0u32;
    while let Some((slot, part)) = stack.pop() {
        steps += 1;
        if steps.is_multiple_of(256) {
            d.progress.check()?;
        }
        let info = Driver::info(&part);
        match d.step(part, &info, &mut *splitter, &mut over) {
            Ok((axis, l, r)) => {
                let left = nodes.len();
                nodes.push(BvhNode::leaf(Aabb::EMPTY, 0, 0));
                nodes.push(BvhNode::leaf(Aabb::EMPTY, 0, 0));
                nodes[slot] = BvhNode::interior(info.bounds, left as u32, axis);
                // Right pushed first so the left subtree is laid out right after its parent pair.
                stack.push((left + 1, r));
                stack.push((left, l));
            }
            Err(part) => {
                let n = part.prims().len() as u16;
                nodes[slot] = BvhNode::leaf(info.bounds, part.leaf(&mut leaves), n);
            }
        }
    }
    Ok((nodes, leaves, over))
}
