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

// The node's bounds as the builders take them, so the inspector's curves start from the same box.
use crate::bvh::builders::common::node_info;
use crate::bvh::split::{binned_planes, sweep_planes, BuildPrim, NodeInfo, PlaneSink, Proposal};
use crate::bvh::{sbvh, BuildParams, Bvh, Hierarchy, SahCost, Strategy};
use crate::geometry::Aabb;
use serde::Serialize;

/// The box two boxes share.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Overlap {
    pub volume: f32,
    pub area: f32,
}

impl Overlap {
    /// Zero for boxes that do not meet (their intersection is `EMPTY`, of no extent or area).
    pub fn of(a: &Aabb, b: &Aabb) -> Overlap {
        let i = a.intersection(*b);
        let e = i.extent();
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
    /// A_L / A and A_R / A: the chances that a ray entering the node enters each side.
    pub area_left: f32,
    pub area_right: f32,
}

/// A split's cost term by term, as a student checks it: C_trav + C_isect·(A_L/A)·n_L +
/// C_isect·(A_R/A)·n_R.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CostTerms {
    pub left: u32,
    pub right: u32,
    pub area_left: f32,
    pub area_right: f32,
    pub traversal: f32,
    pub left_term: f32,
    pub right_term: f32,
    pub cost: f32,
}

impl CostTerms {
    pub fn of(c: SahCost, left: u32, right: u32, area_left: f32, area_right: f32, cost: f32) -> CostTerms {
        CostTerms {
            left,
            right,
            area_left,
            area_right,
            traversal: c.traversal,
            left_term: c.intersection * area_left * left as f32,
            right_term: c.intersection * area_right * right as f32,
            cost,
        }
    }

    /// "n_L 34, n_R 62; A_L/A 0.412, A_R/A 0.730; cost 1.000 + 14.008 + 45.260 = 60.268".
    pub fn text(&self) -> String {
        format!(
            "n_L {}, n_R {}; A_L/A {:.3}, A_R/A {:.3}; cost = C_trav {:.3} + C_isect·A_L/A·n_L {:.3} + C_isect·A_R/A·n_R {:.3} = {:.3}",
            self.left, self.right, self.area_left, self.area_right, self.traversal, self.left_term, self.right_term, self.cost
        )
    }
}

impl CurvePoint {
    pub fn terms(&self, c: SahCost) -> CostTerms {
        CostTerms::of(c, self.left, self.right, self.area_left, self.area_right, self.cost)
    }
}

/// Where a strategy puts its plane at this node, and what that split costs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Marker {
    pub strategy: Strategy,
    pub axis: u8,
    pub position: f32,
    pub left: u32,
    pub right: u32,
    pub cost: f32,
    /// A_L / A and A_R / A of the children it makes.
    pub area_left: f32,
    pub area_right: f32,
}

impl Marker {
    pub fn terms(&self, c: SahCost) -> CostTerms {
        CostTerms::of(c, self.left, self.right, self.area_left, self.area_right, self.cost)
    }
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
    pub sbvh: Option<sbvh::NodeDecision>,
    /// Each strategy's plane, or none when it finds no split (all centroids on one side or
    /// coinciding: the builder then falls back to equal count).
    pub markers: Vec<(Strategy, Option<Marker>)>,
    /// The cost of the split this tree made, by the curves' formula over its children's boxes as
    /// stored and their triangle counts: where an imported tree's split stands against the curves
    /// (a built tree's children's boxes are tight, so this is its strategy's marker cost).
    pub own_cost: Option<f32>,
    /// The SAH constants the costs are priced with (for their terms: `CostTerms`).
    pub sah: SahCost,
    /// Its term of the tree's end-point overlap, exactly (`epo::node_term`: one walk): the same
    /// figure in the app's Node window and in `bvhscope inspect`, however big the tree.
    pub epo_share: f64,
}

/// Collects a sweep's planes as curve points.
struct Curves<'a> {
    out: &'a mut [Vec<CurvePoint>; 3],
    cost: SahCost,
    area: f32,
}

impl PlaneSink for Curves<'_> {
    fn plane(&mut self, axis: usize, position: f32, left: u32, right: u32, weighted: f32, areas: [f32; 2]) {
        let cost = split_cost(self.cost, weighted, self.area);
        let (area_left, area_right) = (areas[0] / self.area, areas[1] / self.area);
        self.out[axis].push(CurvePoint { position, left, right, cost, area_left, area_right });
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
fn node_work(bvh: &Bvh, h: &Hierarchy, tris: &[[glam::Vec3; 3]], node: usize) -> (sbvh::Work, NodeInfo) {
    let params = &bvh.params;
    let prims: Vec<BuildPrim> = if params.strategy.splits_references() {
        let path = h.path(node as u32);
        let steps: Vec<bool> = path.windows(2).map(|w| bvh.nodes[w[0] as usize].index != w[1]).collect();
        let root = tris.iter().enumerate().map(|(i, t)| BuildPrim::new(Aabb::from_points(t), i as u32)).collect();
        let tri = |i: u32| tris[i as usize];
        match sbvh::descend(root, &tri, params, &steps) {
            Some(work) => {
                let info = node_info(&work.refs);
                return (work, info);
            }
            None => Vec::new(),
        }
    } else {
        let range = h.first[node] as usize..(h.first[node] + h.count[node]) as usize;
        range.map(|s| BuildPrim::new(Aabb::from_points(&bvh.tris[s]), bvh.prim_ids[s])).collect()
    };
    let info = node_info(&prims);
    (sbvh::work_of(prims, params, h.depth[node]), info)
}

/// The node's triangles as the builder saw them, and their bounds (`node_work`).
#[cfg(test)]
fn node_prims(bvh: &Bvh, h: &Hierarchy, node: usize) -> (Vec<BuildPrim>, NodeInfo) {
    let tris = if bvh.params.strategy.splits_references() { triangles_by_id(bvh) } else { Vec::new() };
    let (work, info) = node_work(bvh, h, &tris, node);
    (work.refs, info)
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
fn marker(strategy: Strategy, prims: &[BuildPrim], info: &NodeInfo, params: &BuildParams) -> Option<Marker> {
    let area = info.bounds.area();
    if prims.len() < 2 || area <= 0.0 {
        return None;
    }
    let mut p = prims.to_vec();
    let mut splitter = strategy.splitter(params)?;
    match splitter.split(&mut p, info) {
        Proposal::Split { axis, mid, plane, .. } if mid > 0 && mid < p.len() => {
            let side = |s: &[BuildPrim]| Aabb::of(s.iter().map(BuildPrim::bounds));
            let (l, r) = (side(&p[..mid]), side(&p[mid..]));
            let weighted = l.area() * mid as f32 + r.area() * (p.len() - mid) as f32;
            Some(Marker {
                strategy,
                axis,
                position: plane,
                left: mid as u32,
                right: (p.len() - mid) as u32,
                cost: split_cost(params.cost, weighted, area),
                area_left: l.area() / area,
                area_right: r.area() / area,
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
    let tris = if params.strategy.splits_references() { triangles_by_id(bvh) } else { Vec::new() };
    let (work, info) = node_work(bvh, h, &tris, i);
    let prims = work.refs.clone();
    let mut binned = <[Vec<CurvePoint>; 3]>::default();
    let area = info.bounds.area();
    let binning = params.strategy.uses_bins();
    if binning && prims.len() >= 2 && area > 0.0 {
        let bins = params.sah_bins as usize;
        binned_planes(&mut prims.clone(), &info, bins, &mut Curves { out: &mut binned, cost: params.cost, area });
    }
    let own = if params.strategy.splits_references() {
        let tri = |i: u32| tris[i as usize];
        let e = sbvh::explain(work, &tri, &params, &bvh.root_bounds(), &mut ());
        sbvh_marker(&e, params.strategy, &params, area)
    } else {
        marker(params.strategy, &prims, &info, &params)
    };
    (own, binned)
}

/// The SBVH's split as a marker (its left and right counts are references: a cut triangle is on
/// both sides).
fn sbvh_marker(e: &sbvh::NodeDecision, strategy: Strategy, params: &BuildParams, area: f32) -> Option<Marker> {
    let s = e.split.filter(|_| area > 0.0)?;
    Some(Marker {
        strategy,
        axis: s.axis,
        position: s.plane,
        left: s.left,
        right: s.right,
        cost: split_cost(params.cost, s.weighted, area),
        area_left: s.areas[0] / area,
        area_right: s.areas[1] / area,
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
        sbvh::explain(work, &tri, &params, &bvh.root_bounds(), sink)
    });
    let markers = Strategy::ALL
        .into_iter()
        .map(|strategy| {
            let m = match (strategy, &sbvh) {
                (s, Some(e)) if s.splits_references() => sbvh_marker(e, s, &params, area),
                _ => marker(strategy, &prims, &info, &params),
            };
            (strategy, m)
        })
        .collect();
    let child_overlap =
        children.map(|[l, r]| Overlap::of(&bvh.nodes[l as usize].bounds(), &bvh.nodes[r as usize].bounds()));
    // (An SBVH subtree's leaves hold more references than its node did: its marker is its split.)
    let own_cost = children.filter(|_| area > 0.0 && !params.strategy.splits_references()).map(|[l, r]| {
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
        bins: crate::bvh::split::bins_for(count as usize, bins),
        spatial,
        sbvh,
        markers,
        own_cost,
        sah: params.cost,
        epo_share: crate::bvh::epo::node_term(bvh, h, i),
    })
}

pub mod text;

#[cfg(test)]
mod inspect_tests;
