//! Reinsertion: Bittner, Hapala & Havran, "Fast Insertion-Based Optimization of Bounding Volume
//! Hierarchies" (Computer Graphics Forum 2013). A finished binary tree is improved in place: a
//! node is taken out (its parent goes, its sibling takes the parent's place, the boxes above
//! shrink) and put back where it costs least (a new parent joins it with the node found by a
//! branch-and-bound search from the root), whenever that lowers the SAH cost. Nodes are tried
//! largest box first, pass after pass, until a pass frees almost nothing or the passes asked for
//! are done. The budget is in passes, not time, so a build is the same tree every time (the tree
//! view builds a 4-wide tree's binary tree again and must find the same one).
//!
//! Bittner et al. optimise trees of one triangle per leaf, so leaves of several triangles are first
//! split into small subtrees of one-triangle leaves (not an SBVH's, whose leaves hold clipped
//! parts of triangles), and after the passes every subtree of at most the leaf size whose
//! triangles cost less as one leaf by the SAH is gathered into one again (`collapse`). On the
//! bunny this took the reduction from 4.2 % to 12.3 % on midpoint trees (BENCHMARKS.md).
//!
//! During the passes only interior boxes change (the leaves stay), so a move's gain is in
//! interior area: C_trav × (the area freed by the removal − the area the insertion adds), over
//! the root's area, which never changes.

use crate::bvh::node::{Bvh, BvhNode};
use crate::bvh::params::BuildParams;
use crate::bvh::stats::TreeStats;
use crate::geometry::Aabb;
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::time::{Duration, Instant};

const NONE: u32 = u32::MAX;

/// What an optimisation did.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Reinsertion {
    pub sah_before: f64,
    pub sah_after: f64,
    /// Nodes moved.
    pub moves: u32,
    /// Passes over the nodes.
    pub passes: u32,
    pub time: Duration,
}

impl Reinsertion {
    /// "SAH cost 31.459 to 31.102 (-1.1 %), 4974 moves in 4 passes, 360 ms": what the build panel
    /// and `bvhscope stats` say of it.
    pub fn summary(&self) -> String {
        format!(
            "SAH cost {:.3} to {:.3} ({:+.1} %), {} moves in {} passes, {:.0} ms",
            self.sah_before,
            self.sah_after,
            100.0 * (self.sah_after / self.sah_before - 1.0),
            self.moves,
            self.passes,
            self.time.as_secs_f64() * 1e3
        )
    }
}

/// The tree with parent links, as reinsertion edits it.
struct Tree {
    parent: Vec<u32>,
    /// Children of an interior node; `[NONE, NONE]` for a leaf.
    kids: Vec<[u32; 2]>,
    bounds: Vec<Aabb>,
    /// A leaf's triangles in the original leaf order.
    leaf: Vec<(u32, u16)>,
    root: u32,
}

impl Tree {
    /// The tree of `bvh`; with `split_leaves`, each leaf of several triangles becomes a small
    /// subtree of one-triangle leaves, so single triangles can move too (`layout` gathers them
    /// into leaves again where the SAH prefers).
    fn of(bvh: &Bvh, split_leaves: bool) -> Tree {
        let n = bvh.nodes.len();
        let mut t = Tree {
            parent: vec![NONE; n],
            kids: vec![[NONE; 2]; n],
            bounds: bvh.nodes.iter().map(|b| b.bounds()).collect(),
            leaf: bvh.nodes.iter().map(|b| (b.index, b.count)).collect(),
            root: 0,
        };
        for (i, b) in bvh.nodes.iter().enumerate().filter(|(_, b)| !b.is_leaf()) {
            t.kids[i] = [b.index, b.index + 1];
            t.parent[b.index as usize] = i as u32;
            t.parent[b.index as usize + 1] = i as u32;
        }
        if split_leaves {
            for i in 0..n {
                let b = &bvh.nodes[i];
                if b.is_leaf() && b.count > 1 {
                    t.split_leaf(i as u32, bvh);
                }
            }
        }
        t
    }

    fn push(&mut self, kids: [u32; 2], bounds: Aabb, leaf: (u32, u16)) -> u32 {
        let i = self.kids.len() as u32;
        self.parent.push(NONE);
        self.kids.push(kids);
        self.bounds.push(bounds);
        self.leaf.push(leaf);
        for k in kids.into_iter().filter(|&k| k != NONE) {
            self.parent[k as usize] = i;
        }
        i
    }

    /// Leaf `i` as a balanced subtree of one-triangle leaves, `i` its root.
    fn split_leaf(&mut self, i: u32, bvh: &Bvh) {
        let (first, count) = self.leaf[i as usize];
        let mut level: Vec<u32> = (first..first + count as u32)
            .map(|s| self.push([NONE; 2], Aabb::from_points(&bvh.tris[s as usize]), (s, 1)))
            .collect();
        while level.len() > 2 {
            level = level
                .chunks(2)
                .map(|c| match *c {
                    [a, b] => {
                        let bounds = self.bounds[a as usize].union(self.bounds[b as usize]);
                        self.push([a, b], bounds, (0, 0))
                    }
                    _ => c[0],
                })
                .collect();
        }
        self.kids[i as usize] = [level[0], level[1]];
        self.leaf[i as usize] = (0, 0);
        for k in [level[0], level[1]] {
            self.parent[k as usize] = i;
        }
    }

    fn is_leaf(&self, i: u32) -> bool {
        self.kids[i as usize][0] == NONE
    }

    fn sibling(&self, i: u32) -> u32 {
        let k = self.kids[self.parent[i as usize] as usize];
        if k[0] == i {
            k[1]
        } else {
            k[0]
        }
    }

    fn replace_child(&mut self, parent: u32, old: u32, new: u32) {
        let k = &mut self.kids[parent as usize];
        if k[0] == old {
            k[0] = new;
        } else {
            k[1] = new;
        }
        self.parent[new as usize] = parent;
    }

    /// Recompute the boxes from `i` up to the root.
    fn refit(&mut self, mut i: u32) {
        while i != NONE {
            let [l, r] = self.kids[i as usize];
            self.bounds[i as usize] = self.bounds[l as usize].union(self.bounds[r as usize]);
            i = self.parent[i as usize];
        }
    }

    /// Σ area over interior nodes.
    fn interior_area(&self) -> f64 {
        (0..self.kids.len() as u32).filter(|&i| !self.is_leaf(i)).map(|i| self.bounds[i as usize].area() as f64).sum()
    }
}

/// A search entry: a node, and the area its ancestors would grow by if `x` went below it.
#[derive(PartialEq)]
struct Candidate {
    bound: f32,
    induced: f32,
    node: u32,
}

impl Eq for Candidate {}

impl Ord for Candidate {
    fn cmp(&self, o: &Self) -> Ordering {
        // The smallest lower bound first.
        o.bound.total_cmp(&self.bound)
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// Where `x` (detached) costs least to insert: the node it would join, and the cost (the new
/// parent's area plus the growth of every box above it).
fn best_place(t: &Tree, x: Aabb, heap: &mut BinaryHeap<Candidate>) -> (u32, f32) {
    let ax = x.area();
    let mut best = (NONE, f32::INFINITY);
    heap.clear();
    heap.push(Candidate { bound: ax, induced: 0.0, node: t.root });
    while let Some(c) = heap.pop() {
        if c.bound >= best.1 {
            break; // every other entry costs at least as much
        }
        let b = t.bounds[c.node as usize];
        let joined = b.union(x).area();
        let cost = c.induced + joined;
        if cost < best.1 {
            best = (c.node, cost);
        }
        if !t.is_leaf(c.node) {
            let induced = c.induced + joined - b.area();
            let bound = induced + ax;
            if bound < best.1 {
                for k in t.kids[c.node as usize] {
                    heap.push(Candidate { bound, induced, node: k });
                }
            }
        }
    }
    best
}

/// Take `x` out and put it back where it costs least; whether it moved.
fn reinsert(t: &mut Tree, x: u32, heap: &mut BinaryHeap<Candidate>) -> bool {
    let p = t.parent[x as usize];
    if p == NONE || t.parent[p as usize] == NONE {
        return false; // the root, or a child of the root (its parent cannot go)
    }
    let (s, g) = (t.sibling(x), t.parent[p as usize]);
    // What the removal frees: the parent's area, and the area the boxes above lose.
    let before: Vec<(u32, Aabb)> = {
        let mut v = Vec::new();
        let mut a = g;
        while a != NONE {
            v.push((a, t.bounds[a as usize]));
            a = t.parent[a as usize];
        }
        v
    };
    let freed_parent = t.bounds[p as usize].area();
    t.replace_child(g, p, s);
    t.refit(g);
    let shrink: f32 = before.iter().map(|&(a, b)| b.area() - t.bounds[a as usize].area()).sum();
    let gain = freed_parent + shrink;
    let xb = t.bounds[x as usize];
    let (n, cost) = best_place(t, xb, heap);
    // Put it back at `n` (the sibling's place when nothing is better: the tree as it was).
    let moved = n != s && cost < gain * (1.0 - 1e-6);
    let n = if moved { n } else { s };
    let q = p; // the freed parent becomes the new one
    let np = t.parent[n as usize];
    t.kids[q as usize] = [n, x];
    t.parent[x as usize] = q;
    if np == NONE {
        t.root = q;
        t.parent[q as usize] = NONE;
    } else {
        t.replace_child(np, n, q);
    }
    t.parent[n as usize] = q;
    t.refit(q);
    moved
}

/// Improve `bvh`'s tree by at most `passes` passes of reinsertion.
pub fn optimise(bvh: &mut Bvh, passes: u32) -> Reinsertion {
    let start = Instant::now();
    let sah = |b: &Bvh| TreeStats::of(b).sah_cost;
    let mut report = Reinsertion { sah_before: sah(bvh), sah_after: 0.0, ..Default::default() };
    if bvh.nodes.len() < 5 || passes == 0 {
        report.sah_after = report.sah_before;
        return report;
    }
    // Single triangles move, not only whole leaves (Bittner et al. optimise trees of one triangle
    // per leaf); an SBVH's leaves hold clipped parts of triangles, whose boxes are not the
    // triangles', so they stay whole.
    let split_leaves = !bvh.params.strategy.splits_references();
    let mut t = Tree::of(bvh, split_leaves);
    let mut heap = BinaryHeap::new();
    let mut order: Vec<u32> = Vec::with_capacity(t.kids.len());
    while report.passes < passes {
        report.passes += 1;
        let area_before = t.interior_area();
        order.clear();
        order.extend(0..t.kids.len() as u32);
        order.sort_unstable_by(|&a, &b| t.bounds[b as usize].area().total_cmp(&t.bounds[a as usize].area()));
        let mut moved = 0;
        for &x in &order {
            moved += reinsert(&mut t, x, &mut heap) as u32;
        }
        report.moves += moved;
        // A pass that frees less than a millionth of the area is the end.
        if moved == 0 || area_before - t.interior_area() < 1e-6 * area_before {
            break;
        }
    }
    layout(&t, bvh, split_leaves);
    report.sah_after = sah(bvh);
    report.time = start.elapsed();
    report
}

/// Write the tree back in bvhscope's layout (children a pair, parents first, depth first) with its
/// triangles in the new leaf order; each interior node's axis is the one its children's centres
/// are furthest apart on, the lower child first.
fn layout(t: &Tree, bvh: &mut Bvh, gather_leaves: bool) {
    // (An SBVH's leaves are not gathered: two parts of one cut triangle would share a leaf.)
    let gather = if gather_leaves { collapse(t, &bvh.params) } else { vec![false; t.kids.len()] };
    let mut nodes = vec![BvhNode::leaf(Aabb::EMPTY, 0, 0)];
    let (mut prim_ids, mut tris) = (Vec::with_capacity(bvh.prim_ids.len()), Vec::with_capacity(bvh.tris.len()));
    let mut stack = vec![(t.root, 0usize)];
    let mut under = Vec::new();
    while let Some((i, slot)) = stack.pop() {
        let b = t.bounds[i as usize];
        if t.is_leaf(i) || gather[i as usize] {
            // A leaf, or a subtree worth one leaf: its leaves' triangles, in order.
            let at = prim_ids.len() as u32;
            under.clear();
            under.push(i);
            while let Some(u) = under.pop() {
                if t.is_leaf(u) {
                    let (first, count) = t.leaf[u as usize];
                    let range = first as usize..first as usize + count as usize;
                    prim_ids.extend_from_slice(&bvh.prim_ids[range.clone()]);
                    tris.extend_from_slice(&bvh.tris[range]);
                } else {
                    let [l, r] = t.kids[u as usize];
                    under.extend([r, l]);
                }
            }
            nodes[slot] = BvhNode::leaf(b, at, (prim_ids.len() as u32 - at) as u16);
            continue;
        }
        let [mut l, mut r] = t.kids[i as usize];
        let d = t.bounds[r as usize].center() - t.bounds[l as usize].center();
        let axis = if d.x.abs() >= d.y.abs() && d.x.abs() >= d.z.abs() {
            0
        } else if d.y.abs() >= d.z.abs() {
            1
        } else {
            2
        };
        if d[axis] < 0.0 {
            std::mem::swap(&mut l, &mut r);
        }
        let left = nodes.len();
        nodes.extend([BvhNode::leaf(Aabb::EMPTY, 0, 0); 2]);
        nodes[slot] = BvhNode::interior(b, left as u32, axis as u8);
        stack.push((r, left + 1));
        stack.push((l, left));
    }
    (bvh.nodes, bvh.prim_ids, bvh.tris) = (nodes, prim_ids, tris);
}

/// Which interior nodes become leaves: those of at most the leaf size whose triangles as one
/// leaf cost no more by the SAH than the subtree below them (decided bottom-up, as PLOC's layout
/// does), so single-triangle leaves that reinsertion left side by side are gathered again.
fn collapse(t: &Tree, params: &BuildParams) -> Vec<bool> {
    let ci = params.cost.intersection as f64;
    let n = t.kids.len();
    let (mut count, mut cost, mut gather) = (vec![0u32; n], vec![0f64; n], vec![false; n]);
    // Parents before children, then backwards: children before parents.
    let mut order = vec![t.root];
    let mut k = 0;
    while k < order.len() {
        let i = order[k];
        if !t.is_leaf(i) {
            order.extend(t.kids[i as usize]);
        }
        k += 1;
    }
    for &i in order.iter().rev() {
        let i = i as usize;
        let area = t.bounds[i].area() as f64;
        if t.is_leaf(i as u32) {
            count[i] = t.leaf[i].1 as u32;
            cost[i] = ci * count[i] as f64 * area;
            continue;
        }
        let [l, r] = t.kids[i].map(|c| c as usize);
        count[i] = count[l] + count[r];
        (cost[i], gather[i]) = params.cost.leaf_or_split(area, count[i], cost[l] + cost[r], params.max_leaf_size);
    }
    gather
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::accel::{Accelerator, TraceOptions};
    use crate::bvh::counters::NoStats;
    use crate::bvh::linear::LinearScan;
    use crate::bvh::params::Strategy;
    use crate::bvh::params::{BuildParams, Layout};

    /// Reinsertion lowers an LBVH tree's SAH cost (blocky Morton splits leave much to move),
    /// keeps every triangle once, keeps boxes tight, and every ray still finds the linear scan's hit.
    #[test]
    fn reinsertion_lowers_the_cost_and_keeps_the_hits() {
        let mesh = crate::mesh::generate::torus_knot(2, 3, 0.3, 96, 8);
        let params = BuildParams { strategy: Strategy::Lbvh, layout: Layout::Binary, ..BuildParams::default() };
        let mut bvh = Bvh::build(&mesh, &params);
        let r = optimise(&mut bvh, 8);
        assert!(r.sah_after < 0.97 * r.sah_before, "{r:?}");
        assert!(r.moves > 0);
        // Leaves were split for the passes and gathered again, within the leaf size.
        assert!(bvh.nodes.iter().all(|n| n.count as u32 <= params.max_leaf_size));
        let (leaves, several) =
            (bvh.nodes.iter().filter(|n| n.is_leaf()).count(), bvh.nodes.iter().filter(|n| n.count >= 2).count());
        assert!(several * 4 >= leaves, "{several} of {leaves} leaves hold several triangles");
        let mut ids = bvh.prim_ids.clone();
        ids.sort();
        assert!(ids.iter().copied().eq(0..mesh.triangle_count() as u32));
        for n in bvh.nodes.iter().filter(|n| !n.is_leaf()) {
            let (l, r) = (bvh.nodes[n.index as usize].bounds(), bvh.nodes[n.index as usize + 1].bounds());
            assert_eq!(n.bounds(), l.union(r));
        }
        let linear = LinearScan::new(&mesh);
        let b = mesh.bounds();
        for (o, d) in crate::random::Rng::rays_at(3, 3000, (b.min.into(), b.max.into())) {
            let ray = crate::geometry::Ray::new(o, d);
            let t = |h: Option<crate::bvh::Hit>| h.map(|h| h.t);
            let a = bvh.closest_hit(&mut ray.clone(), TraceOptions::default(), &mut NoStats);
            let b = linear.closest_hit(&mut ray.clone(), TraceOptions::default(), &mut NoStats);
            assert_eq!(t(a), t(b));
        }
    }

    /// No pass leaves the tree as it was; the same passes give the same tree.
    #[test]
    fn passes_are_the_budget_and_the_result_is_deterministic() {
        let mesh = crate::mesh::generate::torus_knot(2, 3, 0.3, 32, 8);
        let built = Bvh::build(&mesh, &BuildParams { layout: Layout::Binary, ..BuildParams::default() });
        let mut same = built.clone();
        assert_eq!(optimise(&mut same, 0).moves, 0);
        assert!(same.nodes == built.nodes);
        let (mut a, mut b) = (built.clone(), built);
        let (ra, rb) = (optimise(&mut a, 2), optimise(&mut b, 2));
        assert!(ra.passes <= 2 && a.nodes == b.nodes && a.prim_ids == b.prim_ids && ra.moves == rb.moves);
    }
}
