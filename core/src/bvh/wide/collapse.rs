//! The collapse of a binary BVH into `W`-wide nodes: the greedy rule (open the interior child of
//! largest surface area until the node has `W` children; Wald, Benthin & Boulos 2008), run with an
//! explicit stack, or for big trees its top levels one by one and the subtrees below on rayon. The
//! node inspector walks the same rule to say which wide node a binary node is collapsed into.

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
/// as a slot), found by walking the collapse (`wide_children`, the same choice `from_binary`
/// makes) from the root; `parent` is each binary node's parent (`inspect::Hierarchy::parent`).
pub fn wide_group_of<const W: usize>(b: &[BvhNode], parent: &[u32], node: u32) -> Option<WideGroup> {
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
        let (kids, n) = wide_children::<W>(b, top);
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

/// `wide_group_of` for a tree of `layout`'s width; `None` for the binary layout.
pub fn wide_group_in(layout: crate::bvh::Layout, b: &[BvhNode], parent: &[u32], node: u32) -> Option<WideGroup> {
    match layout {
        crate::bvh::Layout::Binary => None,
        crate::bvh::Layout::Wide4 => wide_group_of::<4>(b, parent, node),
        crate::bvh::Layout::Wide8 => wide_group_of::<8>(b, parent, node),
    }
}

/// The binary nodes a wide node over interior binary node `bin` takes as its children: its two
/// children, then, while fewer than `W`, the interior one of largest surface area replaced by
/// its own two.
pub fn wide_children<const W: usize>(b: &[BvhNode], bin: usize) -> ([usize; W], usize) {
    let mut kids = [0usize; W];
    kids[0] = b[bin].index as usize;
    kids[1] = kids[0] + 1;
    let mut n = 2;
    while n < W {
        let open = (0..n)
            .filter(|&k| !b[kids[k]].is_leaf())
            .max_by(|&x, &y| b[kids[x]].bounds().area().total_cmp(&b[kids[y]].bounds().area()));
        let Some(k) = open else { break };
        let first = b[kids[k]].index as usize;
        kids[k] = first;
        kids[n] = first + 1;
        n += 1;
    }
    (kids, n)
}

/// Collapse the subtree under interior binary node `root` with an explicit stack; node 0 of the
/// result is its wide root, child indices are local. `expected` binary nodes are under the root.
pub(super) fn collapse_sequential<const W: usize>(b: &[BvhNode], root: usize, expected: usize) -> Vec<WideNode<W>> {
    // Each wide node takes the place of up to W − 1 binary interior nodes (half the nodes are
    // interior); reserving that up front avoids regrowing a vector of big nodes.
    let mut nodes = Vec::with_capacity(expected / (2 * (W - 1)) + 1);
    nodes.push(WideNode::EMPTY);
    let mut stack = vec![(root, 0usize)]; // (binary node, wide node to fill)
    while let Some((bin, wide)) = stack.pop() {
        let (kids, n) = wide_children::<W>(b, bin);
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

pub(super) fn collapse_parallel<const W: usize>(b: &[BvhNode], bin: usize, depth: u32) -> WideTree<W> {
    if depth >= PARALLEL_DEPTH {
        // Binary nodes under this one, guessed: a near-balanced tree splits them about W ways
        // per wide level. `collapse_sequential` reserves a wide node per six of them; if the guess
        // is short, its vector grows.
        return WideTree::Flat(collapse_sequential(b, bin, b.len() >> (W.trailing_zeros() * depth)));
    }
    let (kids, n) = wide_children::<W>(b, bin);
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
        interior.into_par_iter().map(|(slot, k)| (slot, collapse_parallel(b, k, depth + 1))).collect();
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
            let g = super::wide_group_of::<4>(&binary.nodes, &h.parent, i as u32).expect("a group");
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
        let sequential =
            WideBvh { nodes: collapse_sequential(&binary.nodes, 0, binary.nodes.len()), ..parallel.clone() };
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
