//! The top-down build driver shared by every split strategy (pbrt-v4 §7.3, "BVH construction").
//!
//! It keeps an explicit work stack instead of recursing, so a 10M-triangle mesh or a million
//! identical triangles cannot overflow the call stack. Nodes are allocated in pairs when a node is
//! split, so the two children of a node are adjacent and an interior node needs only one index.

use super::node::{Bvh, BvhNode, TRAVERSAL_STACK_SIZE};
use super::split::{BuildPrim, EqualCount, NodeInfo, Proposal, SplitStrategy, Splitter};
use super::subtree::Subtree;
use crate::geometry::Aabb;
use crate::mesh::Mesh;
use crate::options::{MAX_LEAF_SIZE, PLOC_RADIUS, REINSERT_PASSES, SAH_BINS, SBVH_ALPHA, SBVH_GROWTH, TRAVERSAL_COST};
use crate::work::{Cancelled, WorkControl};
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Below this depth a node is always split by equal count, whatever the strategy says. Equal
/// count halves the range, so the tree depth stays under `HEURISTIC_DEPTH_LIMIT + 32`, inside the
/// traversal's fixed stack, even for adversarial inputs where midpoint splits peel off one
/// triangle at a time.
pub const HEURISTIC_DEPTH_LIMIT: u32 = (TRAVERSAL_STACK_SIZE as u32) - 33;

/// Cost constants of the surface area heuristic (Goldsmith & Salmon 1987; MacDonald & Booth 1990).
/// The defaults, 1 and 1, make the normalised SAH cost of a tree read as "expected traversal steps
/// plus triangle tests per ray that hits the root box". They are parameters because the right
/// ratio depends on the traversal code; the builder and the statistics use the same values.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SahCost {
    /// Cost of visiting an interior node (one step: two child box tests).
    pub traversal: f32,
    /// Cost of one ray–triangle test.
    pub intersection: f32,
}

impl Default for SahCost {
    fn default() -> Self {
        Self { traversal: TRAVERSAL_COST.default, intersection: 1.0 }
    }
}

/// How the built tree is laid out for traversal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Layout {
    /// The binary BVH as built: two children per node, the handout's structure.
    Binary,
    /// The binary BVH collapsed into 4-wide nodes traversed with SIMD box tests (`bvh::wide`).
    #[default]
    Wide4,
}

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct BuildParams {
    pub strategy: SplitStrategy,
    /// Most triangles in a leaf (default 4). The SAH strategies may stop earlier when a leaf is
    /// cheaper than a split; no strategy makes a larger leaf.
    pub max_leaf_size: u32,
    /// Bins per axis for `SahBinned` (default 16); nodes of fewer than three triangles per bin
    /// use n/3 bins (at least 4, never more than asked for).
    pub sah_bins: u32,
    pub cost: SahCost,
    pub layout: Layout,
    /// PLOC's neighbour search: clusters each side in Morton order (default 16).
    pub ploc_radius: u32,
    /// Passes of reinsertion after the build (`bvh::reinsert`; 0, the default: none).
    pub reinsert_passes: u32,
    /// SBVH: spatial splits are priced where the object split's children share more than this
    /// fraction of the root's surface area (Stich et al.'s α; default 1e-5).
    pub sbvh_alpha: f32,
    /// SBVH: at most this many percent more references than triangles (default 30).
    pub sbvh_growth: u32,
}

impl Default for BuildParams {
    fn default() -> Self {
        Self {
            strategy: SplitStrategy::SahBinned,
            max_leaf_size: MAX_LEAF_SIZE.default,
            sah_bins: SAH_BINS.default,
            cost: SahCost::default(),
            layout: Layout::default(),
            ploc_radius: PLOC_RADIUS.default,
            reinsert_passes: REINSERT_PASSES.default,
            sbvh_alpha: SBVH_ALPHA.default,
            sbvh_growth: SBVH_GROWTH.default,
        }
    }
}

impl BuildParams {
    pub fn with_strategy(strategy: SplitStrategy) -> Self {
        Self { strategy, ..Self::default() }
    }
}

/// What the build did and how long each phase took.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct BuildReport {
    /// Triangle bounds and centroids.
    pub setup_time: Duration,
    /// The top-down splitting.
    pub split_time: Duration,
    /// Copying triangles into leaf order.
    pub reorder_time: Duration,
    /// Collapsing the binary tree into wide nodes (wide layout only).
    pub collapse_time: Duration,
    /// Nodes where the strategy found no useful split (midpoint with an empty side, SAH with
    /// coincident centroids) and an equal-count split was used instead.
    pub fallback_splits: u32,
    /// Nodes split by equal count because they were deeper than `HEURISTIC_DEPTH_LIMIT`.
    pub depth_limited_splits: u32,
    /// SBVH: nodes split by a spatial split (the others by object splits).
    pub spatial_splits: u32,
    /// The reinsertion pass after the build, when asked for (`BuildParams::reinsert_passes`).
    pub reinsertion: Option<super::reinsert::Reinsertion>,
}

impl BuildReport {
    pub fn total_time(&self) -> Duration {
        let optimise = self.reinsertion.map_or(Duration::ZERO, |r| r.time);
        self.setup_time + self.split_time + self.reorder_time + self.collapse_time + optimise
    }
}

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
        if params.strategy == SplitStrategy::Lbvh {
            let progress = Progress { control, levels: progress_levels(n, &params) };
            let (nodes, prim_ids, tris, report) = super::lbvh::build_mesh(mesh, &params, &progress)?;
            return Self::finish(Bvh { nodes, prim_ids, tris, params, report }, control);
        }
        let make = |i: usize| {
            let tri = mesh.triangle(i as u32);
            let bounds = Aabb::from_points(&tri);
            BuildPrim::new(bounds, i as u32)
        };
        let mut prims: Vec<BuildPrim> =
            if n >= 1 << 16 { (0..n).into_par_iter().map(make).collect() } else { (0..n).map(make).collect() };
        let setup_time = t0.elapsed();
        control.check()?;

        let tri = |i: u32| mesh.triangle(i);
        let (nodes, mut report) = build_nodes(&mut prims, Some(&tri), &params, control)?;
        report.setup_time = setup_time;

        let t2 = Instant::now();
        let prim_ids: Vec<u32> = prims.iter().map(|p| p.index()).collect();
        let tris = prim_ids.par_iter().with_min_len(4096).map(|&i| mesh.triangle(i)).collect();
        report.reorder_time = t2.elapsed();
        Self::finish(Bvh { nodes, prim_ids, tris, params, report }, control)
    }

    /// The reinsertion after a build, if asked for.
    fn finish(mut bvh: Bvh, control: &WorkControl) -> Result<Bvh, Cancelled> {
        let passes = bvh.params.reinsert_passes;
        if passes > 0 {
            control.check()?;
            bvh.report.reinsertion = Some(super::reinsert::optimise(&mut bvh, passes));
        }
        Ok(bvh)
    }
}

impl BuildParams {
    /// The parameters with every field in the range the builder accepts.
    fn clamped(&self) -> BuildParams {
        BuildParams {
            max_leaf_size: MAX_LEAF_SIZE.clamp(self.max_leaf_size),
            sah_bins: SAH_BINS.clamp(self.sah_bins),
            ploc_radius: PLOC_RADIUS.clamp(self.ploc_radius),
            reinsert_passes: REINSERT_PASSES.clamp(self.reinsert_passes),
            sbvh_alpha: SBVH_ALPHA.clamp(self.sbvh_alpha),
            sbvh_growth: SBVH_GROWTH.clamp(self.sbvh_growth),
            cost: SahCost { traversal: TRAVERSAL_COST.clamp(self.cost.traversal), ..self.cost },
            ..*self
        }
    }
}

/// The work units of building over `n` primitives, the total a build's progress reaches.
///
/// Progress counts primitives partitioned at every level, not only primitives placed in leaves:
/// counting leaves alone left the progress at 0 % while the top levels were split, half of an
/// exact-sweep build of 2M triangles. A build over n primitives is taken to have
/// L = ⌈log2(n / max leaf size)⌉ + 1 levels, and each primitive is worth L units: one for each of
/// the first L levels it is partitioned at, and the levels it skips when it reaches a leaf
/// earlier. So the progress is exact at the end (n·L), moves with every split, and a tree deeper
/// than L (midpoint on uneven meshes) only spends its last levels at the full count.
pub fn build_work(n: usize, params: &BuildParams) -> u64 {
    n as u64 * progress_levels(n, params) as u64
}

fn progress_levels(n: usize, params: &BuildParams) -> u32 {
    let leaf = params.clamped().max_leaf_size as usize;
    let leaves = n.div_ceil(leaf).max(1);
    leaves.next_power_of_two().trailing_zeros() + 1
}

/// The build's progress: a control and the levels its primitives are counted over.
pub(super) struct Progress<'a> {
    control: &'a WorkControl,
    levels: u32,
}

impl<'a> Progress<'a> {
    #[cfg(test)]
    pub(super) fn new(control: &'a WorkControl, levels: u32) -> Self {
        Progress { control, levels }
    }

    pub(super) fn check(&self) -> Result<(), Cancelled> {
        self.control.check()
    }

    /// The units of a split of `n` primitives at `depth` (`split`), for a caller that adds many
    /// at once (`add`): one shared counter bumped per node costs a builder whose nodes are cheap.
    pub(super) fn split_units(&self, n: usize, depth: u32) -> u64 {
        if depth < self.levels {
            n as u64
        } else {
            0
        }
    }

    /// The units of a leaf of `n` primitives at `depth` (`leaf`).
    pub(super) fn leaf_units(&self, n: usize, depth: u32) -> u64 {
        n as u64 * self.levels.saturating_sub(depth) as u64
    }

    pub(super) fn add(&self, units: u64) {
        self.control.add_done(units);
    }

    /// A node of `n` primitives at `depth` was partitioned.
    pub(super) fn split(&self, n: usize, depth: u32) {
        if depth < self.levels {
            self.control.add_done(n as u64);
        }
    }

    /// A leaf of `n` primitives was made at `depth`: the levels its primitives will not pass.
    pub(super) fn leaf(&self, n: usize, depth: u32) {
        self.control.add_done(n as u64 * self.levels.saturating_sub(depth) as u64);
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
    tri: Option<super::sbvh::Triangles>,
    params: &BuildParams,
    control: &WorkControl,
) -> Result<(Vec<BvhNode>, BuildReport), Cancelled> {
    let t1 = Instant::now();
    let progress = Progress { control, levels: progress_levels(prims.len(), params) };
    if params.strategy == SplitStrategy::Sbvh {
        let (nodes, refs, kinds) = super::sbvh::build(std::mem::take(prims), tri, params, &progress)?;
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
    let (tree, over) = match params.strategy {
        SplitStrategy::Lbvh => {
            let (tree, fallback) = super::lbvh::build(prims, params, &progress)?;
            (tree, Overrides { fallback, depth_limited: 0 })
        }
        SplitStrategy::Ploc => {
            let (tree, _) = super::ploc::build(prims, params, params.ploc_radius as usize, &progress)?;
            (tree, Overrides::default())
        }
        _ => build_subtree(prims, 0, 0, params, &progress)?,
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

/// The node's bounds and centroid bounds (in parallel for big ranges).
pub(super) fn node_info(prims: &[BuildPrim]) -> NodeInfo {
    const EMPTY: NodeInfo = NodeInfo { bounds: Aabb::EMPTY, centroid_bounds: Aabb::EMPTY };
    let add = |i: NodeInfo, p: &BuildPrim| NodeInfo {
        bounds: i.bounds.union(p.bounds()),
        centroid_bounds: i.centroid_bounds.grow(p.centroid()),
    };
    let merge = |a: NodeInfo, b: NodeInfo| NodeInfo {
        bounds: a.bounds.union(b.bounds),
        centroid_bounds: a.centroid_bounds.union(b.centroid_bounds),
    };
    if prims.len() >= PARALLEL_MIN_PRIMS {
        prims.par_chunks(4096).map(|c| c.iter().fold(EMPTY, add)).reduce(|| EMPTY, merge)
    } else {
        prims.iter().fold(EMPTY, add)
    }
}

/// Nodes where the driver overrode or replaced the strategy's answer.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Overrides {
    pub fallback: u32,
    pub depth_limited: u32,
}

impl std::ops::AddAssign for Overrides {
    fn add_assign(&mut self, o: Overrides) {
        self.fallback += o.fallback;
        self.depth_limited += o.depth_limited;
    }
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

/// The SAH's comparison of a leaf with the best split (Goldsmith & Salmon 1987; pbrt-v4 §7.3.2): a
/// leaf costs C_isect·n; the split costs C_trav + C_isect·(A_L·n_L + A_R·n_R)/A, where `weighted`
/// is the sum in parentheses.
pub(super) fn leaf_is_cheaper(n: usize, weighted: f32, node: &NodeInfo, params: &BuildParams) -> bool {
    let split_cost = params.cost.traversal + params.cost.intersection * weighted / node.bounds.area();
    let leaf_cost = params.cost.intersection * n as f32;
    leaf_cost <= split_cost
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

/// Subtrees at least this big are split in parallel (`rayon::join`) ...
const PARALLEL_MIN_PRIMS: usize = 4096;
/// ... down to this depth, which bounds the recursion; deeper work uses the explicit stack.
const PARALLEL_MAX_DEPTH: u32 = 16;

/// The splitter of a top-down strategy (`build_nodes` sends the others to their own builders).
fn top_down(params: &BuildParams) -> Box<dyn super::split::Splitter> {
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
    let sequential = |prims: &mut [BuildPrim]| {
        build_sequential(prims, offset, depth, params, progress).map(|(nodes, over)| (Subtree::Flat(nodes), over))
    };
    if prims.len() < PARALLEL_MIN_PRIMS || depth >= PARALLEL_MAX_DEPTH {
        return sequential(prims);
    }
    progress.check()?;
    let info = node_info(prims);
    let mut over = Overrides::default();
    let decision = decide(prims, &info, depth, params, &mut *top_down(params), &mut over);
    let Decision::Split { axis, mid } = decision else {
        return sequential(prims);
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
mod tests {
    use super::*;
    use crate::mesh::generate::torus;

    #[test]
    fn the_parallel_build_lays_out_the_same_tree_as_the_sequential_one() {
        // Big enough for several parallel levels (and parallel binning at the root).
        let mesh = torus(2.0, 0.5, 256, 160);
        assert!(mesh.triangle_count() > 16 * PARALLEL_MIN_PRIMS);
        // (LBVH's own parallel build is compared with its one-thread build in `bvh::lbvh`.)
        for strategy in SplitStrategy::ALL.into_iter().filter(|&s| s != SplitStrategy::SahSweep && s.splits_top_down())
        {
            let params = BuildParams::with_strategy(strategy).clamped();
            let bvh = Bvh::build(&mesh, &params);
            let mut prims: Vec<BuildPrim> = (0..mesh.triangle_count())
                .map(|i| BuildPrim::new(Aabb::from_points(&mesh.triangle(i as u32)), i as u32))
                .collect();
            let progress = Progress { control: &WorkControl::new(), levels: 1 };
            let (nodes, _) = build_sequential(&mut prims, 0, 0, &params, &progress).unwrap();
            assert_eq!(bvh.nodes.len(), nodes.len(), "{strategy:?}");
            assert!(bvh.nodes == nodes, "{strategy:?}: the same nodes in the same places");
            assert!(bvh.prim_ids.iter().copied().eq(prims.iter().map(|p| p.index())), "{strategy:?}");
        }
    }

    #[test]
    fn build_reports_progress_and_can_be_cancelled() {
        let mesh = torus(2.0, 0.5, 64, 32);
        for strategy in SplitStrategy::ALL {
            for max_leaf_size in [1, 4, 16] {
                let control = WorkControl::new();
                let params = BuildParams { max_leaf_size, ..BuildParams::with_strategy(strategy) };
                let bvh = Bvh::build_controlled(&mesh, &params, &control).unwrap();
                let n = mesh.triangle_count() as u64;
                assert!(control.total() >= n * 8, "4096 triangles pass at least 8 levels");
                assert_eq!(control.done(), control.total(), "{strategy:?}/{max_leaf_size}: the work adds up");
                assert_eq!(
                    super::super::tree::distinct(&bvh.prim_ids),
                    mesh.triangle_count(),
                    "every triangle in a leaf"
                );
            }
        }

        let cancelled = WorkControl::new();
        cancelled.cancel();
        assert_eq!(Bvh::build_controlled(&mesh, &BuildParams::default(), &cancelled).unwrap_err(), Cancelled);
    }

    #[test]
    fn progress_moves_at_the_first_split_not_only_at_the_first_leaf() {
        // The exact sweep's first splits of a million triangles are the slow part of its build;
        // progress that counted only triangles placed in leaves stayed at 0 through them.
        let mesh = torus(2.0, 0.5, 1024, 512);
        let n = mesh.triangle_count() as u64;
        let control = WorkControl::new();
        let first_seen = std::thread::scope(|s| {
            let build = s
                .spawn(|| Bvh::build_controlled(&mesh, &BuildParams::with_strategy(SplitStrategy::SahSweep), &control));
            let mut seen = 0;
            while seen == 0 && !build.is_finished() {
                seen = control.done();
            }
            control.cancel();
            let _ = build.join().expect("the build thread does not panic");
            seen
        });
        assert!(
            first_seen >= n,
            "the root's split counts its {n} triangles at once (first progress seen: {first_seen})"
        );
        assert!(first_seen < control.total(), "and is only part of the work");
    }

    #[test]
    fn a_build_cancelled_while_running_stops() {
        // A million triangles: the build runs long enough to be cancelled once it has made leaves.
        let mesh = torus(2.0, 0.5, 1024, 512);
        let control = WorkControl::new();
        let result = std::thread::scope(|s| {
            let build = s
                .spawn(|| Bvh::build_controlled(&mesh, &BuildParams::with_strategy(SplitStrategy::SahSweep), &control));
            while control.done() == 0 && !build.is_finished() {
                std::thread::yield_now();
            }
            control.cancel();
            build.join().expect("the build thread does not panic")
        });
        assert_eq!(result.unwrap_err(), Cancelled, "cancelled part-way, after {} units", control.done());
        assert!(control.done() < control.total());
    }
}
