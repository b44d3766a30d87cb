//! Explain a node: why it was split where it was. For a node of the binary tree as built, its
//! figures (triangles, area against its parent's, the SAH cost of its subtree, how much its
//! children's boxes overlap) and, per axis, the SAH cost of splitting its triangles at every
//! candidate plane, with the plane each strategy chooses marked.
//!
//! The curves and the markers are not recomputed here: the node's triangles are handed to the
//! strategies' own code (`split`), whose sweeps report each plane they price through a
//! `PlaneSink`. So the curve is what the builder saw, and the marker of the tree's own strategy
//! is the split the tree has (a test checks both).
//!
//! Costs use the SAH as the builder does (Goldsmith & Salmon 1987; pbrt-v4 §7.3.2): a split costs
//! C_trav + C_isect·(A_L·n_L + A_R·n_R)/A, a leaf C_isect·n, with A the node's surface area.

use super::split::{binned_planes, sweep_planes, BuildPrim, NodeInfo, PlaneSink, Proposal};
use super::{Bvh, SahCost, SplitStrategy};
use crate::geometry::Aabb;
use serde::Serialize;

/// Where each node sits in the binary tree: what the tree view, the breadcrumb and the inspector
/// need and the nodes do not store. Computed once per tree, O(nodes).
#[derive(Clone, Debug, Default)]
pub struct Hierarchy {
    /// The parent of each node (`u32::MAX` for the root).
    pub parent: Vec<u32>,
    pub depth: Vec<u32>,
    /// The subtree's triangles, a contiguous range of the leaf order: `first..first + count`.
    pub first: Vec<u32>,
    pub count: Vec<u32>,
    /// The leaf holding each slot of the leaf order.
    pub leaf_of_slot: Vec<u32>,
    /// The slot of each mesh triangle in the leaf order (of a triangle in several leaves, an
    /// SBVH's cut triangle, its last slot: `other_slots` has the rest).
    pub slot_of_prim: Vec<u32>,
    /// The other slots of triangles in several leaves (empty unless spatial splits cut some).
    pub other_slots: std::collections::HashMap<u32, Vec<u32>>,
}

impl Hierarchy {
    pub fn of(bvh: &Bvh) -> Hierarchy {
        let n = bvh.nodes.len();
        let mut h = Hierarchy {
            parent: vec![u32::MAX; n],
            depth: vec![0; n],
            first: vec![0; n],
            count: vec![0; n],
            leaf_of_slot: vec![0; bvh.prim_ids.len()],
            slot_of_prim: vec![u32::MAX; bvh.prim_ids.len()],
            other_slots: Default::default(),
        };
        // Parents come before their children in the node array, so one pass down sets parents and
        // depths, and one pass back up sums the ranges.
        for (i, node) in bvh.nodes.iter().enumerate() {
            if node.is_leaf() {
                h.first[i] = node.index;
                h.count[i] = node.count as u32;
                for s in node.prims() {
                    h.leaf_of_slot[s] = i as u32;
                }
            } else {
                for c in [node.index, node.index + 1] {
                    h.parent[c as usize] = i as u32;
                    h.depth[c as usize] = h.depth[i] + 1;
                }
            }
        }
        for i in (0..n).rev() {
            let node = &bvh.nodes[i];
            if !node.is_leaf() {
                let (l, r) = (node.index as usize, node.index as usize + 1);
                h.first[i] = h.first[l].min(h.first[r]);
                h.count[i] = h.count[l] + h.count[r];
            }
        }
        for (slot, &prim) in bvh.prim_ids.iter().enumerate() {
            if let Some(s) = h.slot_of_prim.get_mut(prim as usize) {
                if *s != u32::MAX {
                    h.other_slots.entry(prim).or_default().push(*s);
                }
                *s = slot as u32;
            }
        }
        h
    }

    /// Every slot of a triangle in the leaf order (more than one where spatial splits cut it).
    pub fn slots_of_prim(&self, prim: u32) -> impl Iterator<Item = u32> + '_ {
        let last = self.slot_of_prim.get(prim as usize).copied().filter(|&s| s != u32::MAX);
        last.into_iter().chain(self.other_slots.get(&prim).into_iter().flatten().copied())
    }

    /// The leaf that holds the part of triangle `prim` at `point` (a pixel's hit): its leaf, or of
    /// a triangle cut among several leaves the one whose box is nearest the point (holds it, but
    /// for rounding).
    pub fn leaf_of_hit(&self, bvh: &Bvh, prim: u32, point: glam::Vec3) -> Option<u32> {
        let away = |leaf: u32| {
            let b = bvh.nodes[leaf as usize].bounds();
            (glam::Vec3::from(b.min) - point).max(point - glam::Vec3::from(b.max)).max(glam::Vec3::ZERO).length()
        };
        let leaves = self.slots_of_prim(prim).filter_map(|s| self.leaf_of_slot.get(s as usize).copied());
        leaves.min_by(|&a, &b| away(a).total_cmp(&away(b)))
    }

    /// The node's ancestors from the root down, the node last: the breadcrumb.
    pub fn path(&self, node: u32) -> Vec<u32> {
        let mut out = vec![node];
        let mut n = node;
        while let Some(&p) = self.parent.get(n as usize).filter(|&&p| p != u32::MAX) {
            out.push(p);
            n = p;
        }
        out.reverse();
        out
    }

    /// The leaf that holds a mesh triangle (a pixel's hit: its leaf).
    pub fn leaf_of_prim(&self, prim: u32) -> Option<u32> {
        let slot = *self.slot_of_prim.get(prim as usize)?;
        self.leaf_of_slot.get(slot as usize).copied()
    }

    /// Whether leaf-order slot `slot` lies in `node`'s subtree.
    pub fn holds(&self, node: usize, slot: u32) -> bool {
        slot.wrapping_sub(self.first[node]) < self.count[node]
    }
}

/// The box two boxes share.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Overlap {
    pub volume: f32,
    pub area: f32,
}

impl Overlap {
    pub fn of(a: &Aabb, b: &Aabb) -> Overlap {
        let i = Aabb { min: a.min.max(b.min), max: a.max.min(b.max) };
        if (i.max.cmplt(i.min)).any() {
            return Overlap::default();
        }
        let e = i.max - i.min;
        Overlap { volume: e.x * e.y * e.z, area: i.area() }
    }
}

/// A candidate plane and the cost of splitting there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CurvePoint {
    pub position: f32,
    pub left: u32,
    pub right: u32,
    /// C_trav + C_isect·(A_L·n_L + A_R·n_R)/A.
    pub cost: f32,
}

/// Where a strategy puts its plane at this node, and what that split costs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Marker {
    pub strategy: SplitStrategy,
    pub axis: u8,
    pub position: f32,
    pub left: u32,
    pub right: u32,
    pub cost: f32,
}

/// A node of the binary tree, explained.
#[derive(Clone, Debug)]
pub struct Inspection {
    pub node: u32,
    pub depth: u32,
    pub parent: Option<u32>,
    /// The two children of an interior node.
    pub children: Option<[u32; 2]>,
    /// The axis the builder split this node on.
    pub split_axis: Option<u8>,
    pub triangles: u32,
    pub bounds: Aabb,
    pub centroid_bounds: Aabb,
    pub area: f32,
    /// The node's area over its parent's.
    pub area_ratio: Option<f32>,
    /// The SAH cost of the subtree, relative to this node's area: the expected cost of a ray that
    /// enters this node's box.
    pub subtree_sah: f64,
    /// The children's boxes' common box.
    pub child_overlap: Option<Overlap>,
    /// C_isect·n: what making this node a leaf would cost.
    pub leaf_cost: f32,
    /// Per axis (x, y, z): the exact sweep's cost at every plane between distinct centroids.
    pub sweep: [Vec<CurvePoint>; 3],
    /// Per axis: the binned SAH's cost at each plane between bins, with the bins the builder uses
    /// at a node of this size (`bins`).
    pub binned: [Vec<CurvePoint>; 3],
    pub bins: usize,
    /// Per axis: the SBVH's spatial split's cost at each plane between its bins (it cuts the
    /// triangles that straddle a plane, counting them on both sides), when it priced them here:
    /// only where the object split's children overlap by more than α of the root's area.
    pub spatial: [Vec<CurvePoint>; 3],
    /// What the SBVH does here: for an SBVH tree what its build did, for another tree what it
    /// would do with these triangles.
    pub sbvh: Option<super::sbvh::Explained>,
    /// Each strategy's plane, or none when it finds no split (all centroids on one side or
    /// coinciding: the builder then falls back to equal count).
    pub markers: Vec<(SplitStrategy, Option<Marker>)>,
    /// The cost of the split this tree made, by the curves' formula over its children's boxes as
    /// stored and their triangle counts: where an imported tree's split stands against the curves
    /// (a built tree's children's boxes are tight, so this is its strategy's marker cost).
    pub own_cost: Option<f32>,
}

/// Collects a sweep's planes as curve points.
struct Curves<'a> {
    out: &'a mut [Vec<CurvePoint>; 3],
    cost: SahCost,
    area: f32,
}

impl PlaneSink for Curves<'_> {
    fn plane(&mut self, axis: usize, position: f32, left: u32, right: u32, weighted: f32) {
        let cost = split_cost(self.cost, weighted, self.area);
        self.out[axis].push(CurvePoint { position, left, right, cost });
    }
}

fn split_cost(c: SahCost, weighted: f32, area: f32) -> f32 {
    c.traversal + c.intersection * weighted / area
}

/// The tree's triangles by id (from its leaves), for the SBVH's clipping.
fn triangles_by_id(bvh: &Bvh) -> Vec<[glam::Vec3; 3]> {
    let n = bvh.prim_ids.iter().max().map_or(0, |&m| m as usize + 1);
    let mut out = vec![[glam::Vec3::ZERO; 3]; n];
    for (t, &p) in bvh.tris.iter().zip(&bvh.prim_ids) {
        out[p as usize] = *t;
    }
    out
}

/// The node's references as the builder saw them: for an SBVH tree, the parts of triangles its
/// build held there (found by replaying its decisions from the root, `sbvh::descend`); for the
/// others the node's triangles, in leaf order (every strategy's choice is independent of the
/// order). With their bounds, and the SBVH's work there.
fn node_work(bvh: &Bvh, h: &Hierarchy, tris: &[[glam::Vec3; 3]], node: usize) -> (super::sbvh::Work, NodeInfo) {
    let params = &bvh.params;
    let prims: Vec<BuildPrim> = if params.strategy == SplitStrategy::Sbvh {
        let path = h.path(node as u32);
        let steps: Vec<bool> = path.windows(2).map(|w| bvh.nodes[w[0] as usize].index != w[1]).collect();
        let root = tris.iter().enumerate().map(|(i, t)| BuildPrim::new(Aabb::from_points(t), i as u32)).collect();
        let tri = |i: u32| tris[i as usize];
        match super::sbvh::descend(root, &tri, params, &steps) {
            Some(work) => {
                let info = info_of(&work.refs);
                return (work, info);
            }
            None => Vec::new(),
        }
    } else {
        let range = h.first[node] as usize..(h.first[node] + h.count[node]) as usize;
        range.map(|s| BuildPrim::new(Aabb::from_points(&bvh.tris[s]), bvh.prim_ids[s])).collect()
    };
    let info = info_of(&prims);
    (super::sbvh::work_of(prims, params, h.depth[node]), info)
}

/// The node's triangles as the builder saw them, and their bounds (`node_work`).
#[cfg(test)]
fn node_prims(bvh: &Bvh, h: &Hierarchy, node: usize) -> (Vec<BuildPrim>, NodeInfo) {
    let tris = if bvh.params.strategy == SplitStrategy::Sbvh { triangles_by_id(bvh) } else { Vec::new() };
    let (work, info) = node_work(bvh, h, &tris, node);
    (work.refs, info)
}

fn info_of(prims: &[BuildPrim]) -> NodeInfo {
    let mut info = NodeInfo { bounds: Aabb::EMPTY, centroid_bounds: Aabb::EMPTY };
    for p in prims {
        info.bounds = info.bounds.union(p.bounds());
        info.centroid_bounds = info.centroid_bounds.grow(p.centroid());
    }
    info
}

/// The SAH cost of the subtree under `node`, relative to its area (as `TreeStats` costs the whole
/// tree relative to the root's).
pub fn subtree_sah(bvh: &Bvh, node: usize) -> f64 {
    let c = bvh.params.cost;
    let area = bvh.nodes[node].bounds().area() as f64;
    if area <= 0.0 {
        return 0.0;
    }
    let mut stack = vec![node];
    let mut cost = 0f64;
    while let Some(i) = stack.pop() {
        let n = &bvh.nodes[i];
        let rel = n.bounds().area() as f64 / area;
        if n.is_leaf() {
            cost += c.intersection as f64 * n.count as f64 * rel;
        } else {
            cost += c.traversal as f64 * rel;
            stack.extend([n.index as usize, n.index as usize + 1]);
        }
    }
    cost
}

/// Where `strategy`'s own splitter cuts `prims` (a copy is partitioned), and at what cost; none
/// when it finds no split.
fn marker(
    strategy: SplitStrategy,
    prims: &[BuildPrim],
    info: &NodeInfo,
    params: &super::BuildParams,
) -> Option<Marker> {
    let area = info.bounds.area();
    if prims.len() < 2 || area <= 0.0 {
        return None;
    }
    let mut p = prims.to_vec();
    let mut splitter = strategy.splitter(params)?;
    match splitter.split(&mut p, info) {
        Proposal::Split { axis, mid, plane, .. } if mid > 0 && mid < p.len() => {
            let side = |s: &[BuildPrim]| s.iter().fold(Aabb::EMPTY, |b, q| b.union(q.bounds()));
            let (l, r) = (side(&p[..mid]), side(&p[mid..]));
            let weighted = l.area() * mid as f32 + r.area() * (p.len() - mid) as f32;
            Some(Marker {
                strategy,
                axis,
                position: plane,
                left: mid as u32,
                right: (p.len() - mid) as u32,
                cost: split_cost(params.cost, weighted, area),
            })
        }
        _ => None,
    }
}

/// The split the tree's own strategy makes at `node` (its plane, for the build replay), and for
/// the binned SAH the cost at each of its bins' planes per axis (empty otherwise).
pub fn own_split(bvh: &Bvh, h: &Hierarchy, node: u32) -> (Option<Marker>, [Vec<CurvePoint>; 3]) {
    let i = node as usize;
    if i >= bvh.nodes.len() {
        return (None, Default::default());
    }
    let params = bvh.params;
    let tris = if params.strategy == SplitStrategy::Sbvh { triangles_by_id(bvh) } else { Vec::new() };
    let (work, info) = node_work(bvh, h, &tris, i);
    let prims = work.refs.clone();
    let mut binned = <[Vec<CurvePoint>; 3]>::default();
    let area = info.bounds.area();
    let binning = matches!(params.strategy, SplitStrategy::SahBinned | SplitStrategy::Sbvh);
    if binning && prims.len() >= 2 && area > 0.0 {
        let bins = params.sah_bins as usize;
        binned_planes(&mut prims.clone(), &info, bins, &mut Curves { out: &mut binned, cost: params.cost, area });
    }
    let own = if params.strategy == SplitStrategy::Sbvh {
        let tri = |i: u32| tris[i as usize];
        let e = super::sbvh::explain(work, &tri, &params, &bvh.root_bounds(), &mut ());
        sbvh_marker(&e, &params, area)
    } else {
        marker(params.strategy, &prims, &info, &params)
    };
    (own, binned)
}

/// The SBVH's split as a marker (its left and right counts are references: a cut triangle is on
/// both sides).
fn sbvh_marker(e: &super::sbvh::Explained, params: &super::BuildParams, area: f32) -> Option<Marker> {
    let s = e.split.filter(|_| area > 0.0)?;
    Some(Marker {
        strategy: SplitStrategy::Sbvh,
        axis: s.axis,
        position: s.plane,
        left: s.left,
        right: s.right,
        cost: split_cost(params.cost, s.weighted, area),
    })
}

/// Explain `node` of `bvh` (a node id of the binary tree as built).
pub fn inspect(bvh: &Bvh, h: &Hierarchy, node: u32) -> Option<Inspection> {
    let i = node as usize;
    let n = bvh.nodes.get(i)?;
    // The SBVH clips triangles: it needs them by id (for any tree: its marker is on every one).
    let tris = triangles_by_id(bvh);
    let (work, info) = node_work(bvh, h, &tris, i);
    let prims = work.refs.clone();
    let bounds = n.bounds();
    let area = info.bounds.area();
    let parent = (h.parent[i] != u32::MAX).then_some(h.parent[i]);
    let children = (!n.is_leaf()).then_some([n.index, n.index + 1]);
    let params = bvh.params;
    let count = prims.len() as u32;
    let (mut sweep, mut binned) = (<[Vec<CurvePoint>; 3]>::default(), <[Vec<CurvePoint>; 3]>::default());
    let bins = params.sah_bins as usize;
    if count >= 2 && area > 0.0 {
        sweep_planes(&mut prims.clone(), &info, &mut Curves { out: &mut sweep, cost: params.cost, area });
        binned_planes(&mut prims.clone(), &info, bins, &mut Curves { out: &mut binned, cost: params.cost, area });
    }
    let mut spatial = <[Vec<CurvePoint>; 3]>::default();
    let sbvh = (count >= 1).then(|| {
        let tri = |i: u32| tris[i as usize];
        let sink = &mut Curves { out: &mut spatial, cost: params.cost, area: area.max(f32::MIN_POSITIVE) };
        super::sbvh::explain(work, &tri, &params, &bvh.root_bounds(), sink)
    });
    let markers = SplitStrategy::ALL
        .into_iter()
        .map(|strategy| {
            let m = match (strategy, &sbvh) {
                (SplitStrategy::Sbvh, Some(e)) => sbvh_marker(e, &params, area),
                _ => marker(strategy, &prims, &info, &params),
            };
            (strategy, m)
        })
        .collect();
    let child_overlap =
        children.map(|[l, r]| Overlap::of(&bvh.nodes[l as usize].bounds(), &bvh.nodes[r as usize].bounds()));
    // (An SBVH subtree's leaves hold more references than its node did: its marker is its split.)
    let own_cost = children.filter(|_| area > 0.0 && params.strategy != SplitStrategy::Sbvh).map(|[l, r]| {
        let side = |c: u32| bvh.nodes[c as usize].bounds().area() * h.count[c as usize] as f32;
        params.cost.traversal + params.cost.intersection * (side(l) + side(r)) / area
    });
    Some(Inspection {
        node,
        depth: h.depth[i],
        parent,
        children,
        split_axis: children.map(|_| n.axis),
        triangles: count,
        bounds,
        centroid_bounds: info.centroid_bounds,
        area: bounds.area(),
        area_ratio: parent.map(|p| {
            let pa = bvh.nodes[p as usize].bounds().area();
            if pa > 0.0 {
                bounds.area() / pa
            } else {
                1.0
            }
        }),
        subtree_sah: subtree_sah(bvh, i),
        child_overlap,
        leaf_cost: params.cost.intersection * count as f32,
        sweep,
        binned,
        bins: super::split::bins_for(count as usize, bins),
        spatial,
        sbvh,
        markers,
        own_cost,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildParams, Layout};
    use crate::mesh::generate;

    fn built(strategy: SplitStrategy, leaf: u32) -> (Bvh, Hierarchy) {
        let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
        let bvh = Bvh::build(
            &mesh,
            &BuildParams { strategy, layout: Layout::Binary, max_leaf_size: leaf, ..BuildParams::default() },
        );
        let h = Hierarchy::of(&bvh);
        (bvh, h)
    }

    /// The wide layout's binary tree, built again, is the one a binary build makes: the node ids
    /// the inspector shows are the same in both layouts.
    #[test]
    fn a_wide_trees_binary_tree_is_the_binary_build() {
        let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
        let params = BuildParams { layout: Layout::Wide4, ..BuildParams::default() };
        let wide = crate::bvh::AnyBvh::build(&mesh, &params);
        let binary = Bvh::build(&mesh, &BuildParams { layout: Layout::Binary, ..params });
        let again = wide.binary_tree(&mesh);
        assert!(again.nodes == binary.nodes && again.prim_ids == binary.prim_ids);
    }

    #[test]
    fn the_hierarchy_knows_parents_depths_and_ranges() {
        let (bvh, h) = built(SplitStrategy::SahBinned, 4);
        assert_eq!((h.first[0], h.count[0]), (0, bvh.prim_ids.len() as u32));
        for (i, n) in bvh.nodes.iter().enumerate().filter(|(_, n)| !n.is_leaf()) {
            let (l, r) = (n.index as usize, n.index as usize + 1);
            assert_eq!((h.parent[l], h.parent[r]), (i as u32, i as u32));
            assert_eq!(h.depth[l], h.depth[i] + 1);
            assert_eq!(h.first[l], h.first[i], "the left child's range starts the parent's");
            assert_eq!(h.first[r], h.first[l] + h.count[l], "the right one follows it");
        }
        assert!(h.other_slots.is_empty(), "no triangle in two leaves");
        for (prim, _) in bvh.prim_ids.iter().enumerate() {
            let leaf = h.leaf_of_prim(prim as u32).unwrap();
            let path = h.path(leaf);
            assert_eq!(path[0], 0);
            assert!(path.iter().all(|&a| h.holds(a as usize, h.slot_of_prim[prim])));
        }
    }

    /// The marker of the tree's own strategy is the split the tree has, at every interior node
    /// where the strategy found one (elsewhere the builder fell back to equal count): the same
    /// axis, the left child's triangles on the left, and the plane between the two children's
    /// centroids. The inspector runs the builder's code, not a copy of it.
    #[test]
    fn each_trees_own_strategy_marks_the_split_it_made() {
        for strategy in SplitStrategy::ALL.into_iter().filter(|s| s.splits_top_down()) {
            let (bvh, h) = built(strategy, 2);
            let mut checked = 0;
            for (i, n) in bvh.nodes.iter().enumerate().filter(|(_, n)| !n.is_leaf()) {
                let ins = inspect(&bvh, &h, i as u32).unwrap();
                let Some(m) = ins.markers.iter().find(|(s, _)| *s == strategy).unwrap().1 else { continue };
                let (l, r) = (n.index as usize, n.index as usize + 1);
                assert_eq!((m.axis, m.left, m.right), (n.axis, h.count[l], h.count[r]), "{strategy:?} node {i}");
                let centroids = |c: usize| {
                    let range = h.first[c] as usize..(h.first[c] + h.count[c]) as usize;
                    range.map(|s| Aabb::from_points(&bvh.tris[s]).center()[m.axis as usize]).collect::<Vec<_>>()
                };
                let (left, right) = (centroids(l), centroids(r));
                if strategy == SplitStrategy::EqualCount {
                    assert!(left.iter().all(|&c| c <= m.position) && right.iter().all(|&c| c >= m.position));
                } else {
                    assert!(left.iter().all(|&c| c < m.position), "{strategy:?} node {i}");
                    assert!(right.iter().all(|&c| c >= m.position), "{strategy:?} node {i}");
                }
                checked += 1;
            }
            let interior = bvh.nodes.iter().filter(|n| !n.is_leaf()).count();
            assert!(checked * 10 >= interior * 9, "{strategy:?}: {checked} of {interior} nodes have a marker");
        }
    }

    /// What the build replay shows of a split (the tree's own strategy's plane, and the binned
    /// SAH's bins) is what the inspector shows.
    #[test]
    fn own_split_is_the_inspectors_marker_of_the_trees_strategy() {
        for strategy in SplitStrategy::ALL {
            let (bvh, h) = built(strategy, 4);
            for node in [0u32, 1, 2, 3] {
                let ins = inspect(&bvh, &h, node).unwrap();
                let (m, binned) = own_split(&bvh, &h, node);
                assert_eq!(m, ins.markers.iter().find(|(s, _)| *s == strategy).unwrap().1, "{strategy:?} {node}");
                let binning = matches!(strategy, SplitStrategy::SahBinned | SplitStrategy::Sbvh);
                let want = if binning { ins.binned.clone() } else { Default::default() };
                assert_eq!(binned, want);
            }
        }
    }

    /// An SBVH tree's inspector replays its build: at every interior node the SBVH marker is the
    /// split the tree has (its axis, and as many references on each side as the children hold
    /// when they are inspected in turn), spatial splits among them, and where the SBVH priced
    /// spatial planes the curve's cheapest point is no dearer than its split.
    #[test]
    fn an_sbvh_trees_inspector_replays_its_build() {
        let mesh = generate::diagonal_rods(3, 6, 6.0, 0.03, 0.2);
        let params = BuildParams {
            strategy: SplitStrategy::Sbvh,
            layout: Layout::Binary,
            sbvh_growth: 100,
            ..Default::default()
        };
        let bvh = Bvh::build(&mesh, &params);
        let h = Hierarchy::of(&bvh);
        let (mut spatial, mut curves) = (0, 0);
        for (i, n) in bvh.nodes.iter().enumerate().filter(|(_, n)| !n.is_leaf()) {
            let ins = inspect(&bvh, &h, i as u32).unwrap();
            let m = ins.markers.iter().find(|(s, _)| *s == SplitStrategy::Sbvh).unwrap().1.unwrap();
            let count = |c: u32| inspect(&bvh, &h, c).unwrap().triangles;
            assert_eq!((m.axis, m.left, m.right), (n.axis, count(n.index), count(n.index + 1)), "node {i}");
            let e = ins.sbvh.unwrap();
            if e.split.unwrap().kind == crate::bvh::sbvh::SplitKind::Spatial {
                spatial += 1;
                let cheapest = ins.spatial.iter().flatten().map(|p| p.cost).fold(f32::INFINITY, f32::min);
                assert!(cheapest <= m.cost * 1.0001, "node {i}: the bins' best {cheapest}, the split {}", m.cost);
            }
            curves += (!ins.spatial.iter().all(Vec::is_empty)) as u32;
            assert_eq!(ins.spatial.iter().all(Vec::is_empty), !e.spatial_priced, "node {i}");
        }
        assert!(spatial >= 5 && curves >= spatial, "{spatial} spatial splits, {curves} spatial curves");
        assert_eq!(spatial, bvh.report.spatial_splits, "the replay finds every spatial split the build made");
        assert_eq!(inspect(&bvh, &h, 0).unwrap().triangles as usize, mesh.triangle_count());
        // A cut triangle's hit point selects the leaf holding that part of it.
        let (&prim, others) = h.other_slots.iter().next().expect("cut triangles");
        let mut parts = 0;
        for &slot in others.iter().chain([&h.slot_of_prim[prim as usize]]) {
            let leaf = h.leaf_of_slot[slot as usize];
            let b = bvh.nodes[leaf as usize].bounds();
            let t = bvh.tris[slot as usize];
            let inside = (0..=20)
                .flat_map(|i| (0..=20 - i).map(move |j| (i as f32 / 20.0, j as f32 / 20.0)))
                .map(|(u, v)| t[0] * (1.0 - u - v) + t[1] * u + t[2] * v)
                .find(|p| {
                    let others_hold = h.slots_of_prim(prim).filter(|&s| s != slot).any(|s| {
                        let o = bvh.nodes[h.leaf_of_slot[s as usize] as usize].bounds();
                        (0..3).all(|a| o.min[a] <= p[a] && p[a] <= o.max[a])
                    });
                    (0..3).all(|a| b.min[a] < p[a] && p[a] < b.max[a]) && !others_hold
                });
            if let Some(p) = inside {
                assert_eq!(h.leaf_of_hit(&bvh, prim, p), Some(leaf), "the part at {p:?}");
                parts += 1;
            }
        }
        assert!(parts >= 2, "{parts} parts of triangle {prim} found inside their own leaf only");
    }

    /// A built tree's own split cost, from its children's stored boxes, is the cost its
    /// strategy's marker gives on the curve (both SAH strategies; the boxes are tight).
    #[test]
    fn own_cost_is_the_strategys_marker_cost_for_a_built_tree() {
        for strategy in [SplitStrategy::SahSweep, SplitStrategy::SahBinned] {
            let (bvh, h) = built(strategy, 4);
            for node in [0u32, 1, 2, 3, 4] {
                let ins = inspect(&bvh, &h, node).unwrap();
                let m = ins.markers.iter().find(|(s, _)| *s == strategy).unwrap().1.unwrap();
                let own = ins.own_cost.unwrap();
                assert!((own - m.cost).abs() <= 1e-4 * m.cost, "{strategy:?} {node}: {own} vs {}", m.cost);
            }
        }
    }

    /// Every point of the sweep's curve is the SAH cost of the partition its plane makes, worked
    /// out by brute force; the sweep SAH's marker is the curve's minimum; midpoint's sits at the
    /// middle of the centroid bounds on their widest axis; binned points lie at bin boundaries.
    #[test]
    fn curves_and_markers_match_a_brute_force_sah() {
        let (bvh, h) = built(SplitStrategy::Midpoint, 4);
        let c = bvh.params.cost;
        for node in [0u32, 1, 2, 5, 9] {
            let ins = inspect(&bvh, &h, node).unwrap();
            let (prims, info) = node_prims(&bvh, &h, node as usize);
            let area = info.bounds.area();
            for axis in 0..3 {
                assert!(!ins.sweep[axis].is_empty(), "node {node} axis {axis}");
                let mut sorted = prims.clone();
                sorted.sort_by(|a, b| a.centroid()[axis].total_cmp(&b.centroid()[axis]));
                for p in &ins.sweep[axis] {
                    // The plane between the left-th and the next centroid (no two equal there).
                    let (l, r) = sorted.split_at(p.left as usize);
                    let (last, next) = (l[l.len() - 1].centroid()[axis], r[0].centroid()[axis]);
                    assert!(last < next && last <= p.position && p.position <= next, "node {node} axis {axis}");
                    assert_eq!(p.left + p.right, prims.len() as u32);
                    let bounds = |s: &[BuildPrim]| s.iter().fold(Aabb::EMPTY, |b, q| b.union(q.bounds()));
                    let weighted = bounds(l).area() * l.len() as f32 + bounds(r).area() * r.len() as f32;
                    let brute = c.traversal + c.intersection * weighted / area;
                    assert!((p.cost - brute).abs() <= 1e-5 * brute, "{} against {brute}", p.cost);
                }
                let distinct = sorted.windows(2).filter(|w| w[0].centroid()[axis] < w[1].centroid()[axis]).count();
                assert_eq!(ins.sweep[axis].len(), distinct, "a point between every two distinct centroids");
                let (lo, step) =
                    (info.centroid_bounds.min[axis], info.centroid_bounds.extent()[axis] / ins.bins as f32);
                for p in &ins.binned[axis] {
                    let k = (p.position - lo) / step;
                    assert!((k - k.round()).abs() < 1e-3, "a binned plane at a bin boundary: {k}");
                }
            }
            let marker = |s| ins.markers.iter().find(|(m, _)| *m == s).unwrap().1.unwrap();
            let sweep = marker(SplitStrategy::SahSweep);
            let min = ins.sweep.iter().flatten().map(|p| p.cost).fold(f32::INFINITY, f32::min);
            assert_eq!(sweep.cost, min, "node {node}: the sweep takes the curve's minimum");
            let mid = marker(SplitStrategy::Midpoint);
            let w = info.centroid_bounds.widest_axis();
            assert_eq!(mid.axis as usize, w);
            assert_eq!(mid.position, info.centroid_bounds.center()[w]);
            let binned = marker(SplitStrategy::SahBinned);
            let bmin = ins.binned.iter().flatten().map(|p| p.cost).fold(f32::INFINITY, f32::min);
            assert_eq!(binned.cost, bmin, "node {node}: the binned SAH takes its bins' minimum");
            assert!(sweep.cost <= binned.cost && sweep.cost <= mid.cost);
        }
    }
}
