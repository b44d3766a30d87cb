//! A build played back split by split. A top-down build starts from one leaf holding every
//! triangle and splits nodes until the tree is done; after k splits the tree is still a correct
//! BVH whose frontier nodes (those not split yet) act as leaves over all their triangles. The
//! replay takes the splits of the finished binary tree in breadth-first order (the root first,
//! then both its children, then theirs: how the tree unfolds level by level; the parallel build's
//! own order is not deterministic), and `PartialBvh` is the tree after the first k, traced by the
//! same binary walk as the finished one. The SAH cost of each partial tree is kept, so the cost can
//! be plotted against k.

use crate::bvh::traverse::{test_triangles, walk, walk_from, MeshLevel};
use crate::bvh::{Accelerator, Bvh, BvhNode, Hierarchy, Hit, NoStats, TraversalStats};
use crate::geometry::{Ray, TriangleIntersector};
use std::sync::Arc;

/// The splits of a finished binary tree in replay order, and the SAH cost after each.
pub struct Replay {
    pub tree: Arc<Bvh>,
    pub hierarchy: Hierarchy,
    /// Interior nodes in the order they are split.
    pub order: Vec<u32>,
    /// `sah[k]`: the SAH cost (normalised by the root's area, as `TreeStats`) of the tree after
    /// the first k splits; `sah[order.len()]` is the finished tree's.
    pub sah: Vec<f64>,
}

impl Replay {
    pub fn of(tree: Arc<Bvh>) -> Replay {
        let hierarchy = Hierarchy::of(&tree);
        let nodes = &tree.nodes;
        let mut order = Vec::new();
        let mut level = vec![0u32];
        while !level.is_empty() {
            let mut next = Vec::new();
            for &n in &level {
                let node = &nodes[n as usize];
                if !node.is_leaf() {
                    order.push(n);
                    next.extend([node.index, node.index + 1]);
                }
            }
            level = next;
        }
        // Each split replaces a leaf's cost by the node's traversal cost and its children's leaf costs.
        let c = tree.params.cost;
        let root = nodes.first().map_or(0.0, |n| n.bounds().area() as f64);
        let rel = |n: u32| if root > 0.0 { nodes[n as usize].bounds().area() as f64 / root } else { 0.0 };
        let leaf = |n: u32| c.intersection as f64 * hierarchy.count[n as usize] as f64 * rel(n);
        let mut cost = if nodes.is_empty() { 0.0 } else { leaf(0) };
        let mut sah = vec![cost];
        for &n in &order {
            let l = nodes[n as usize].index;
            cost += c.traversal as f64 * rel(n) - leaf(n) + leaf(l) + leaf(l + 1);
            sah.push(cost);
        }
        Replay { tree, hierarchy, order, sah }
    }

    pub fn splits(&self) -> usize {
        self.order.len()
    }

    /// The tree after the first `k` splits (at most all of them).
    pub fn partial(&self, k: usize) -> PartialBvh {
        let k = k.min(self.order.len());
        let mut split = vec![false; self.tree.nodes.len()];
        for &n in &self.order[..k] {
            split[n as usize] = true;
        }
        // The finished tree's nodes, so ids stay the same; the ones reached become leaves unless
        // split, each leaf naming its entry of `ranges`. Nodes below the frontier are not reached.
        let mut nodes = self.tree.nodes.clone();
        let (mut ranges, mut frontier_node) = (Vec::new(), Vec::new());
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            if split[n] {
                let l = nodes[n].index as usize;
                stack.extend([l, l + 1]);
            } else {
                let b = nodes[n].bounds();
                nodes[n] = BvhNode::leaf(b, ranges.len() as u32, 1);
                ranges.push((self.hierarchy.first[n], self.hierarchy.count[n]));
                frontier_node.push(n as u32);
            }
        }
        PartialBvh { tree: self.tree.clone(), nodes, ranges, frontier_node, splits: k }
    }
}

/// The tree after some splits of a replay: frontier nodes are leaves over all their triangles.
pub struct PartialBvh {
    pub tree: Arc<Bvh>,
    /// The finished tree's nodes with the frontier turned into leaves; a leaf's `index` is its
    /// entry in `ranges`.
    pub nodes: Vec<BvhNode>,
    /// Per leaf: the first slot of its triangles in the leaf order, and how many.
    pub ranges: Vec<(u32, u32)>,
    /// Per leaf: its node in the finished tree (whose subtree holds the same triangles).
    pub frontier_node: Vec<u32>,
    pub splits: usize,
}

impl PartialBvh {
    /// The frontier (every leaf of the partial tree), as node ids of the finished tree.
    pub fn frontier(&self) -> Vec<u32> {
        let mut out = Vec::new();
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if node.is_leaf() {
                out.push(n as u32);
            } else {
                stack.extend([node.index as usize, node.index as usize + 1]);
            }
        }
        out
    }
}

impl Accelerator for PartialBvh {
    /// The binary walk of the finished tree (`traverse::walk`), over the partial nodes. A frontier
    /// leaf tests every one of its triangles, and is counted so; but for a closest hit it need not
    /// pay for them: the nearest of its triangles is found by walking the finished tree's subtree
    /// under it (the same triangles), and its tests are counted as the leaf's. The counts and the
    /// hit's distance are those of testing them all (a test holds them equal); early frames of a
    /// big mesh, whose frontier leaves hold tens of thousands of triangles, trace as fast as the
    /// finished tree. A trace (`Trace`, which lists each triangle test) and an any-hit query test
    /// them one by one.
    fn trace<T: TriangleIntersector, const BY_DISTANCE: bool, const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        let t = &*self.tree;
        let (mut prepared, mut best) = (None, None);
        walk::<MeshLevel, BY_DISTANCE, S>(&self.nodes, ray, stats, |entry, ray, stats| {
            let (first, count) = self.ranges[entry.start];
            let range = first as usize..(first + count) as usize;
            let ids = |i: usize| t.prim_ids[i];
            if ANY || S::STEPS || count <= FAST_FRONTIER {
                return test_triangles::<T, ANY, S>(
                    &t.tris[range.clone()],
                    range.start,
                    ray,
                    stats,
                    &mut prepared,
                    &mut best,
                    ids,
                );
            }
            stats.triangle_tests(count);
            // The finished subtree under the frontier node, without counting.
            let node = self.frontier_node[entry.start] as usize;
            walk_from::<MeshLevel, BY_DISTANCE, NoStats>(&t.nodes, node, ray, &mut NoStats, |r, ray, _| {
                let first = r.start;
                test_triangles::<T, false, NoStats>(&t.tris[r], first, ray, &mut NoStats, &mut prepared, &mut best, ids)
            });
            false
        });
        best.map(|(i, h)| Hit { t: h.t, u: h.u, v: h.v, prim: t.prim_ids[i] })
    }
}

/// Frontier leaves of at most this many triangles are tested one by one (as fast as walking
/// their subtree).
const FAST_FRONTIER: u32 = 8;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildParams, Layout, LinearScan, NoStats, RayCounters, Strategy, TraceOptions, TreeStats};
    use crate::mesh::generate;
    use glam::Vec3;

    /// A fixed pseudo-random set through the scene's box.
    fn rays(b: &crate::geometry::Aabb, n: usize) -> Vec<Ray> {
        crate::random::Rng::rays_at(12345, n, (b.min.into(), b.max.into()))
            .into_iter()
            .map(|(o, d)| Ray::new(o, d))
            .collect()
    }

    /// The partial tree as a plain `Bvh` whose frontier leaves hold their triangles (what a build
    /// stopped after k splits is): the reference the fast frontier is held to.
    fn as_plain_bvh(p: &PartialBvh) -> Bvh {
        let mut nodes = p.nodes.clone();
        // The frontier: the reached leaves (the nodes below it are the finished tree's, unreached).
        for i in p.frontier() {
            let n = &p.nodes[i as usize];
            let (first, count) = p.ranges[n.index as usize];
            nodes[i as usize] = BvhNode::leaf(n.bounds(), first, count as u16);
        }
        let t = &*p.tree;
        Bvh { nodes, prim_ids: t.prim_ids.clone(), tris: t.tris.clone(), params: t.params, report: Default::default() }
    }

    /// A frontier leaf's triangles found through the finished subtree under it give the counts and
    /// the hit distance of testing them all, for every ray, at every step, in both orders.
    #[test]
    fn the_fast_frontier_counts_and_hits_as_testing_every_triangle() {
        let mesh = generate::torus_knot(2, 3, 0.3, 96, 8);
        for strategy in [Strategy::SahBinned, Strategy::Midpoint, Strategy::Sbvh] {
            let params = BuildParams { strategy, layout: Layout::Binary, ..BuildParams::default() };
            let tree = Arc::new(Bvh::build(&mesh, &params));
            let replay = Replay::of(tree.clone());
            let rays = rays(&tree.root_bounds(), 400);
            for k in [0, 1, 3, 10, 40, replay.splits() / 2] {
                let p = replay.partial(k);
                let plain = as_plain_bvh(&p);
                for order in [crate::bvh::TraversalOrder::EntryDistance, crate::bvh::TraversalOrder::SplitAxisSign] {
                    let opts = TraceOptions { order, ..TraceOptions::default() };
                    for r in &rays {
                        let (mut a, mut b) = (RayCounters::default(), RayCounters::default());
                        let fast = p.closest_hit(&mut r.clone(), opts, &mut a);
                        let all = plain.closest_hit(&mut r.clone(), opts, &mut b);
                        assert_eq!(a, b, "{strategy:?} after {k} splits, {order:?}");
                        assert_eq!(fast.map(|h| h.t), all.map(|h| h.t), "{strategy:?} after {k} splits");
                    }
                }
            }
        }
    }

    /// At every step the partial tree finds the linear scan's hits (it is a correct BVH); at its
    /// last step it is the finished tree: the same counts for every ray and the same SAH cost.
    #[test]
    fn partial_trees_are_correct_and_the_last_is_the_finished_tree() {
        let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
        for strategy in Strategy::ALL {
            let tree = Arc::new(Bvh::build(
                &mesh,
                &BuildParams { strategy, layout: Layout::Binary, ..BuildParams::default() },
            ));
            let replay = Replay::of(tree.clone());
            let n = replay.splits();
            assert_eq!(n, tree.nodes.iter().filter(|x| !x.is_leaf()).count());
            let rays = rays(&tree.root_bounds(), 300);
            let linear = LinearScan::new(&mesh);
            let opts = TraceOptions::default();
            let want: Vec<Option<Hit>> =
                rays.iter().map(|r| linear.closest_hit(&mut r.clone(), opts, &mut NoStats)).collect();
            let mut k = 0;
            loop {
                let p = replay.partial(k);
                assert_eq!(p.frontier().len(), k + 1, "each split turns one leaf into two");
                for (r, w) in rays.iter().zip(&want) {
                    let got = p.closest_hit(&mut r.clone(), opts, &mut NoStats);
                    assert_eq!(got.map(|h| h.t), w.map(|h| h.t), "{strategy:?} after {k} splits");
                }
                if k == n {
                    break;
                }
                k = (k * 2 + 1).min(n);
            }
            let last = replay.partial(n);
            for r in &rays {
                let (mut a, mut b) = (RayCounters::default(), RayCounters::default());
                let ha = last.closest_hit(&mut r.clone(), opts, &mut a);
                let hb = tree.closest_hit(&mut r.clone(), opts, &mut b);
                assert_eq!((ha, a), (hb, b), "{strategy:?}: the last step is the finished tree");
            }
            let finished = TreeStats::of(&*tree).sah_cost;
            assert!((replay.sah[n] - finished).abs() <= 1e-9 * finished, "{} vs {finished}", replay.sah[n]);
            assert_eq!(replay.sah[0], mesh.triangle_count() as f64, "one leaf of every triangle");
            // The root alone: every ray that enters it tests every triangle.
            let mut c = RayCounters::default();
            let p0 = replay.partial(0);
            let r = Ray::new(tree.root_bounds().center() + Vec3::new(0.0, 0.0, 10.0), Vec3::new(0.0, 0.0, -1.0));
            p0.closest_hit(&mut r.clone(), opts, &mut c);
            assert_eq!((c.nodes_visited, c.leaves_visited, c.triangle_tests), (1, 1, mesh.triangle_count() as u32));
        }
    }
}
