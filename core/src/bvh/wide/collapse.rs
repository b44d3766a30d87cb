//! The collapse of a binary BVH into `W`-wide nodes. Which binary nodes become wide nodes is
//! decided once per tree by `CollapsePlan`: the grouping of least summed surface area of the wide
//! nodes (the dynamic programme of Ylitie, Karras & Laine, "Efficient Incoherent Ray Traversal on
//! GPUs Through Compressed Wide BVHs", HPG 2017, over the binary tree's own leaves). The collapse
//! itself runs with an explicit stack, or for big trees its top levels one by one and the subtrees
//! below on rayon. The node inspector reads the same plan to say which wide node a binary node is
//! collapsed into.

use crate::bvh::node::BvhNode;
use crate::bvh::wide::node::WideNode;
use rayon::prelude::*;

/// How the collapse groups binary nodes into one wide node: the binary node at its top, the
/// interior binary nodes it swallows (the top included), and its children, each a binary leaf or
/// the top of another wide node. The node inspector says this of a node in a wide layout.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WideGroup {
    /// Children per wide node of the layout (4 or 8).
    pub width: usize,
    pub top: u32,
    pub collapsed: Vec<u32>,
    pub children: Vec<u32>,
}

/// The wide node that binary node `node` is collapsed into (for a leaf: the wide node holding it
/// as a slot), found by walking the collapse (`plan`, the same choice `from_binary` makes) from
/// the root; `parent` is each binary node's parent (`inspect::Hierarchy::parent`).
pub fn wide_group_of<const W: usize>(
    b: &[BvhNode],
    parent: &[u32],
    plan: &CollapsePlan,
    node: u32,
) -> Option<WideGroup> {
    if b.get(node as usize)?.is_leaf() && node == 0 || b[0].is_leaf() {
        return None;
    }
    // The binary path from the root down to `node`.
    let mut path = vec![node];
    while let Some(&p) = parent.get(*path.last()? as usize).filter(|&&p| p != u32::MAX) {
        path.push(p);
    }
    path.reverse();
    let mut top = 0usize;
    loop {
        let (kids, n) = plan.children::<W>(b, top);
        let kids = &kids[..n];
        // The swallowed nodes: every binary node from the top down to (not including) a child.
        let mut collapsed = vec![top as u32];
        for &k in kids {
            let mut a = parent[k] as usize;
            while a != top && !collapsed.contains(&(a as u32)) {
                collapsed.push(a as u32);
                a = parent[a] as usize;
            }
        }
        collapsed.sort_unstable();
        let children: Vec<u32> = kids.iter().map(|&k| k as u32).collect();
        let is_slot = children.contains(&node) && b[node as usize].is_leaf();
        if collapsed.contains(&node) || is_slot {
            return Some(WideGroup { width: W, top: top as u32, collapsed, children });
        }
        // Go down to the child on the path to `node`.
        top = *kids.iter().find(|&&k| path.contains(&(k as u32)))?;
    }
}

/// `wide_group_of` for a tree of `layout`'s width, with the hierarchy's plan for that width
/// (made on first use); `None` for the binary layout.
pub fn wide_group_in(
    layout: crate::bvh::Layout,
    b: &[BvhNode],
    h: &crate::bvh::Hierarchy,
    node: u32,
) -> Option<WideGroup> {
    match layout {
        crate::bvh::Layout::Binary => None,
        crate::bvh::Layout::Wide4 => wide_group_of::<4>(b, &h.parent, h.collapse_plan::<4>(b), node),
        crate::bvh::Layout::Wide8 => wide_group_of::<8>(b, &h.parent, h.collapse_plan::<8>(b), node),
    }
}

/// Which binary nodes become the wide nodes of a `W`-wide tree over the same leaves. Every leaf is
/// one slot of one wide node however the tree is grouped, so the SAH cost of the wide tree differs
/// between groupings only in its wide nodes: the plan minimises the sum of their surface areas
/// (Ylitie et al. 2017's dynamic programme, without merging leaves). Bottom up, for each binary
/// node and each number of slots `i ≤ W` it may take in its parent, the least area of the wide
/// nodes below: as one slot (a leaf, or a wide node of its own, paying its area and sharing `W`
/// slots between its two children) or sharing `i` slots between its children. On the bunny's
/// `fastest` trees this visits 6–7 % fewer nodes per incoherent ray than opening the child of
/// largest area first (Wald, Benthin & Boulos 2008), which it replaced: 1.08–1.12× on incoherent
/// rays (BENCHMARKS.md, "The SAH-optimal collapse").
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CollapsePlan {
    /// Per binary node and slot budget `i` (entry `i − 1`): 0 when the node takes one slot, else
    /// the number of slots its left child takes (its right child takes the rest).
    share: Vec<[u8; 8]>,
    /// Per interior binary node made a wide node: its left child's share of the `W` slots.
    split: Vec<u8>,
}

impl CollapsePlan {
    /// The plan of the tree under node 0 of `b`. O(nodes · W²); nodes outside that tree (none in
    /// a tree bvhscope makes) keep no plan and are never asked for.
    pub fn of<const W: usize>(b: &[BvhNode]) -> CollapsePlan {
        const { assert!(W >= 2 && W <= 8) };
        let n = b.len();
        let mut plan = CollapsePlan { share: vec![[0; 8]; n], split: vec![0; n] };
        if n == 0 {
            return plan;
        }
        // Children before their parents: the reverse of a walk from the root that lists a node
        // before its children (an imported tree need not keep children after their parents).
        let mut order = Vec::with_capacity(n);
        let mut stack = vec![0usize];
        while let Some(k) = stack.pop() {
            order.push(k);
            let l = b[k].index as usize;
            // A tree is at most `n` nodes deep in this walk; the bound keeps a malformed one
            // (a child index out of range, or a cycle) from running on.
            if !b[k].is_leaf() && l + 1 < n && order.len() < n {
                stack.extend([l, l + 1]);
            }
        }
        // `area[k][i − 1]`: the least summed area of the wide nodes under `k` given `i` slots.
        let mut area = vec![[0f32; 8]; n];
        for &k in order.iter().rev() {
            let node = &b[k];
            let (l, r) = (node.index as usize, node.index as usize + 1);
            if node.is_leaf() || r >= n {
                continue;
            }
            let (left, right) = (area[l], area[r]);
            // The least area of `i` slots shared between the two children (each takes one or
            // more), starting from `best`; the left child's share, 0 when `best` stands.
            let shared = |i: usize, best: (f32, usize)| {
                (1..i).fold(best, |best, j| {
                    let a = left[j - 1] + right[i - j - 1];
                    if a < best.0 {
                        (a, j)
                    } else {
                        best
                    }
                })
            };
            // One slot each at least, also where every area is infinite or NaN.
            let (below, j) = shared(W, (f32::INFINITY, 1));
            plan.split[k] = j as u8;
            let one = node.bounds().area() + below;
            area[k][0] = one;
            for i in 2..=W {
                let (a, j) = shared(i, (one, 0));
                area[k][i - 1] = a;
                plan.share[k][i - 1] = j as u8;
            }
        }
        plan
    }

    /// The slots binary node `k` takes when given `i`, in order.
    fn slots(&self, b: &[BvhNode], k: usize, i: usize, out: &mut [usize; 8], n: &mut usize) {
        let j = self.share[k][i - 1] as usize;
        if b[k].is_leaf() || j == 0 {
            out[*n] = k;
            *n += 1;
        } else {
            let l = b[k].index as usize;
            self.slots(b, l, j, out, n);
            self.slots(b, l + 1, i - j, out, n);
        }
    }

    /// The binary nodes a wide node over interior binary node `bin` takes as its children (leaves,
    /// or the tops of other wide nodes), and how many.
    pub fn children<const W: usize>(&self, b: &[BvhNode], bin: usize) -> ([usize; W], usize) {
        let (mut out, mut n) = ([0usize; 8], 0);
        let (j, l) = (self.split[bin] as usize, b[bin].index as usize);
        self.slots(b, l, j, &mut out, &mut n);
        self.slots(b, l + 1, W - j, &mut out, &mut n);
        let mut kids = [0usize; W];
        kids[..n].copy_from_slice(&out[..n]);
        (kids, n)
    }
}

/// Collapse the subtree under interior binary node `root` with an explicit stack; node 0 of the
/// result is its wide root, child indices are local. `expected` binary nodes are under the root.
pub(super) fn collapse_sequential<const W: usize>(
    b: &[BvhNode],
    plan: &CollapsePlan,
    root: usize,
    expected: usize,
) -> Vec<WideNode<W>> {
    // Each wide node takes the place of up to W − 1 binary interior nodes (half the nodes are
    // interior); reserving that up front avoids regrowing a vector of big nodes.
    let mut nodes = Vec::with_capacity(expected / (2 * (W - 1)) + 1);
    nodes.push(WideNode::EMPTY);
    let mut stack = vec![(root, 0usize)]; // (binary node, wide node to fill)
    while let Some((bin, wide)) = stack.pop() {
        let (kids, n) = plan.children::<W>(b, bin);
        for (slot, &k) in kids[..n].iter().enumerate() {
            let node = &b[k];
            if node.is_leaf() {
                nodes[wide].set(slot, node.bounds(), node.index, node.count as u8);
            } else {
                let child = nodes.len();
                nodes.push(WideNode::EMPTY);
                nodes[wide].set(slot, node.bounds(), child as u32, 0);
                stack.push((k, child));
            }
        }
    }
    nodes
}

/// Binary trees at least this big are collapsed in parallel ...
pub(super) const PARALLEL_MIN_NODES: usize = 1 << 15;
/// ... their top wide levels one by one, the subtrees below (up to W³) on rayon.
const PARALLEL_DEPTH: u32 = 3;

/// A collapsed subtree as the parallel collapse returns it, written into one array at the end.
pub(super) enum WideTree<const W: usize> {
    /// Node 0 is the root; child indices are local to the vector.
    Flat(Vec<WideNode<W>>),
    /// A wide node whose interior slots are filled in by `into_nodes`, and its interior children.
    Node { node: WideNode<W>, kids: Vec<(usize, WideTree<W>)>, len: usize },
}

pub(super) fn collapse_parallel<const W: usize>(
    b: &[BvhNode],
    plan: &CollapsePlan,
    bin: usize,
    depth: u32,
) -> WideTree<W> {
    if depth >= PARALLEL_DEPTH {
        // Binary nodes under this one, guessed: a near-balanced tree splits them about W ways
        // per wide level. `collapse_sequential` reserves a wide node per six of them; if the guess
        // is short, its vector grows.
        return WideTree::Flat(collapse_sequential(b, plan, bin, b.len() >> (W.trailing_zeros() * depth)));
    }
    let (kids, n) = plan.children::<W>(b, bin);
    let mut node = WideNode::EMPTY;
    let mut interior = Vec::new();
    for (slot, &k) in kids[..n].iter().enumerate() {
        let c = &b[k];
        // Interior slots get their child index when the tree is written out.
        node.set(slot, c.bounds(), if c.is_leaf() { c.index } else { u32::MAX }, c.count as u8);
        if !c.is_leaf() {
            interior.push((slot, k));
        }
    }
    let kids: Vec<(usize, WideTree<W>)> =
        interior.into_par_iter().map(|(slot, k)| (slot, collapse_parallel(b, plan, k, depth + 1))).collect();
    let len = 1 + kids.iter().map(|(_, t)| t.len()).sum::<usize>();
    WideTree::Node { node, kids, len }
}

impl<const W: usize> WideTree<W> {
    fn len(&self) -> usize {
        match self {
            WideTree::Flat(nodes) => nodes.len(),
            WideTree::Node { len, .. } => *len,
        }
    }

    /// One array, each subtree contiguous after its parent (child subtrees in slot order).
    pub(super) fn into_nodes(self) -> Vec<WideNode<W>> {
        let mut nodes = Vec::with_capacity(self.len());
        // Filled in parallel: first touch of fresh pages is much of the cost of a big array.
        nodes.par_extend(rayon::iter::repeat_n(WideNode::EMPTY, self.len()));
        self.write(&mut nodes, 0);
        nodes
    }

    /// Write into `out`, whose first node has global index `base`.
    fn write(self, out: &mut [WideNode<W>], base: u32) {
        match self {
            WideTree::Flat(nodes) => {
                for (to, from) in out.iter_mut().zip(nodes) {
                    *to = from;
                    for slot in 0..W {
                        if to.valid & (1 << slot) != 0 && to.count[slot] == 0 {
                            to.child[slot] += base;
                        }
                    }
                }
            }
            WideTree::Node { mut node, kids, .. } => {
                let (root, mut rest) = out.split_first_mut().expect("room for the node");
                let mut jobs = Vec::with_capacity(kids.len());
                let mut next = base + 1;
                for (slot, tree) in kids {
                    node.child[slot] = next;
                    let len = tree.len();
                    let (mine, others) = rest.split_at_mut(len);
                    jobs.push((tree, mine, next));
                    next += len as u32;
                    rest = others;
                }
                *root = node;
                jobs.into_par_iter().for_each(|(tree, out, base)| tree.write(out, base));
            }
        }
    }
}

#[cfg(test)]
mod tests {

    /// Every interior binary node is collapsed into exactly one wide node, every leaf is a slot
    /// of one, and the groups are as many as the wide nodes the collapse makes.
    #[test]
    fn every_binary_node_has_its_wide_group() {
        let mesh = crate::mesh::generate::torus_knot(2, 3, 0.3, 64, 8);
        let binary = crate::bvh::Bvh::build(
            &mesh,
            &crate::bvh::BuildParams { layout: crate::bvh::Layout::Binary, ..Default::default() },
        );
        let h = crate::bvh::Hierarchy::of(&binary);
        let mut tops = std::collections::HashSet::new();
        let mut swallowed = 0;
        for (i, n) in binary.nodes.iter().enumerate() {
            let g = super::wide_group_in(crate::bvh::Layout::Wide4, &binary.nodes, &h, i as u32).expect("a group");
            assert!((2..=WIDTH).contains(&g.children.len()));
            if n.is_leaf() {
                assert!(g.children.contains(&(i as u32)));
            } else {
                assert!(g.collapsed.contains(&(i as u32)));
                if g.top == i as u32 {
                    swallowed += g.collapsed.len();
                }
            }
            tops.insert(g.top);
        }
        let interior = binary.nodes.iter().filter(|n| !n.is_leaf()).count();
        assert_eq!(swallowed, interior, "each interior node swallowed once");
        let wide = WideBvh::from_binary(binary);
        assert_eq!(tops.len(), wide.nodes.len());
    }

    /// The wide nodes' summed surface area under the plan is the least of every grouping: on small
    /// random trees, each set of interior binary nodes that could be the wide nodes' tops (the
    /// root among them, each top with at most `W` children) is tried, and none is below the
    /// plan's. Fails if the programme shares slots wrongly or reads a child's row off by one.
    #[test]
    fn the_plan_is_the_grouping_of_least_area() {
        fn case<const W: usize>(b: &[BvhNode]) {
            let interior: Vec<usize> = (0..b.len()).filter(|&k| !b[k].is_leaf()).collect();
            assert!((4..=16).contains(&interior.len()), "{} interior nodes", interior.len());
            // Children of top `t` when the tops are `is_top`: the nodes below it down to a leaf
            // or another top.
            let kids = |t: usize, is_top: &dyn Fn(usize) -> bool| {
                let (mut out, mut stack) = (Vec::new(), vec![b[t].index as usize, b[t].index as usize + 1]);
                while let Some(k) = stack.pop() {
                    if b[k].is_leaf() || is_top(k) {
                        out.push(k);
                    } else {
                        stack.extend([b[k].index as usize, b[k].index as usize + 1]);
                    }
                }
                out.len()
            };
            let mut least = f32::INFINITY;
            for set in 0u32..1 << (interior.len() - 1) {
                let is_top =
                    |k: usize| k == 0 || interior[1..].iter().position(|&i| i == k).is_some_and(|p| set >> p & 1 == 1);
                let tops: Vec<usize> = interior.iter().copied().filter(|&k| is_top(k)).collect();
                // Only tops reachable as wide nodes count; an unreachable one would be swallowed.
                if tops.iter().all(|&t| kids(t, &is_top) <= W) {
                    least = least.min(tops.iter().map(|&t| b[t].bounds().area()).sum());
                }
            }
            let plan = CollapsePlan::of::<W>(b);
            let (mut got, mut stack) = (0.0, vec![0usize]);
            while let Some(t) = stack.pop() {
                got += b[t].bounds().area();
                let (k, n) = plan.children::<W>(b, t);
                assert!((2..=W).contains(&n));
                stack.extend(k[..n].iter().filter(|&&k| !b[k].is_leaf()));
            }
            assert!(got <= least * (1.0 + 1e-5), "W = {W}: the plan's {got} against {least}");
        }
        let mut rng = crate::random::Rng::new(7);
        for _ in 0..40 {
            let tris = 6 + rng.below(12) as u32;
            let positions: Vec<glam::Vec3> =
                (0..3 * tris).map(|_| glam::Vec3::new(rng.unit(), rng.unit(), rng.unit()) * 10.0).collect();
            let mesh = crate::mesh::Mesh::from_triangles(
                "random",
                positions,
                (0..tris).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
            );
            let params = BuildParams { layout: crate::bvh::Layout::Binary, max_leaf_size: 1, ..Default::default() };
            let b = Bvh::build(&mesh, &params).nodes;
            if (4..=16).contains(&b.iter().filter(|n| !n.is_leaf()).count()) {
                case::<4>(&b);
                case::<8>(&b);
            }
        }
    }

    /// A malformed node array (a cycle back to the root, a child index out of range) gives a plan
    /// and does not hang: the walk that orders the nodes stops at their number.
    #[test]
    fn a_malformed_tree_neither_hangs_nor_panics() {
        let node = |index: u32, count: u16| BvhNode { lo: [0.0; 3], hi: [1.0; 3], index, count, axis: 0, _pad: 0 };
        let cycle = [node(1, 0), node(0, 0), node(0, 1)];
        let _ = CollapsePlan::of::<8>(&cycle);
        let out_of_range = [node(7, 0), node(0, 1)];
        let _ = CollapsePlan::of::<4>(&out_of_range);
    }

    use super::*;
    use crate::bvh::node::Bvh;
    use crate::bvh::params::BuildParams;
    use crate::bvh::tree::{NodeKind, TreeView};
    use crate::bvh::wide::node::WIDTH;
    use crate::bvh::wide::wide_bvh::WideBvh;
    use crate::geometry::Aabb;

    /// The tree as (depth, bounds, kind) in walk order, which follows slots, not node indices.
    fn shape(w: &WideBvh) -> Vec<(u32, Aabb, NodeKind)> {
        let mut out = Vec::new();
        w.visit_nodes(&mut |v| {
            out.push((v.depth, v.bounds, v.kind));
            true
        });
        out
    }

    #[test]
    fn the_parallel_collapse_makes_the_same_tree_as_the_sequential_one() {
        let mesh = crate::mesh::generate::torus(2.0, 0.5, 256, 160);
        let binary = Bvh::build(&mesh, &BuildParams { layout: crate::bvh::Layout::Binary, ..Default::default() });
        assert!(binary.nodes.len() >= PARALLEL_MIN_NODES, "big enough to collapse in parallel");
        let parallel = WideBvh::from_binary(binary.clone());
        let plan = CollapsePlan::of::<WIDTH>(&binary.nodes);
        let sequential =
            WideBvh { nodes: collapse_sequential(&binary.nodes, &plan, 0, binary.nodes.len()), ..parallel.clone() };
        assert_eq!(parallel.nodes.len(), sequential.nodes.len());
        assert!(shape(&parallel) == shape(&sequential), "the same nodes under the same parents");
        // Every interior slot points at a distinct node, and every node but the root is pointed at once.
        let mut seen = vec![0u32; parallel.nodes.len()];
        for n in &parallel.nodes {
            for slot in n.slots().filter(|&s| n.count[s] == 0) {
                seen[n.child[slot] as usize] += 1;
            }
        }
        assert_eq!(seen[0], 0);
        assert!(seen[1..].iter().all(|&c| c == 1));
    }
}
