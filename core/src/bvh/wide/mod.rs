//! The wide BVHs: the binary BVH collapsed into nodes of up to four or eight children (`W`) whose
//! boxes are tested together with SIMD (`traverse.rs`; the eight-wide one with AVX2 where the CPU
//! has it, chosen at run time: `crate::cpu`).
//!
//! Collapse: starting from a binary node, its two children are taken; then, while fewer than `W`,
//! the interior child of largest surface area is replaced by its own two children. Opening the
//! largest box first removes the most expected traversal cost under the SAH; the rule is the
//! greedy collapse of Wald, Benthin & Boulos, "Getting Rid of Packets" (RT 2008), and Pinto,
//! "Fast BVH collapse" (2010). Leaves and the triangle order are those of the binary BVH.
//!
//! Counts, against the binary tree it was collapsed from: a wide node visit counts once and one
//! box test per valid child; a leaf is reached as a child (a leaf visit, not a node visit). So for
//! a ray no hit prunes (one that hits nothing), both layouts reach the same leaves and make the same
//! triangle tests, and the wide layout visits at most as many nodes as the binary one visits
//! interior nodes; box tests have no such bound (a wide node tests its grandchildren's boxes where
//! the binary walk may have culled them at the child's). `core/tests/exact_counts.rs` checks this.
//!
//! Triangles are stored in leaf order, vertices inline (36 bytes each, no index indirection), so a
//! leaf is one contiguous read. They are not precomputed into edge form: the watertight test needs
//! the vertices themselves, and rebuilding them from stored edges would change its rounding and so
//! lose the guarantee that rays through shared edges hit.

mod packet;
mod traverse;

use super::node::{Bvh, BvhNode};
use super::tree::{NodeKind, NodeView, TreeView};
use super::{BuildParams, BuildReport};
use crate::geometry::slab::Boxes;
use crate::geometry::Aabb;
use glam::Vec3;
use rayon::prelude::*;
use std::time::Instant;

/// The width of the 4-wide layout (the app's default), and of the imported trees.
pub const WIDTH: usize = 4;

/// Children boxes in SoA order (`boxes`), then per slot: a child node index (interior,
/// `count == 0`) or the first triangle of a leaf (`count > 0`). Empty slots have an inverted box
/// (+inf..-inf), which every slab test misses, and are clear in `valid`. Cache-line aligned: 128
/// bytes for four children, 256 for eight (Embree's uncompressed BVH8 node is 256 bytes too).
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WideNode<const W: usize = WIDTH> {
    pub boxes: Boxes<W>,
    pub child: [u32; W],
    pub count: [u8; W],
    /// Bit k set when slot k holds a child.
    pub valid: u8,
}

const _: () = assert!(std::mem::size_of::<WideNode<4>>() == 128);
const _: () = assert!(std::mem::size_of::<WideNode<8>>() == 256);

impl<const W: usize> WideNode<W> {
    pub const EMPTY: Self = Self { boxes: Boxes::EMPTY, child: [u32::MAX; W], count: [0; W], valid: 0 };

    pub(crate) fn set(&mut self, slot: usize, b: Aabb, child: u32, count: u8) {
        let (lo, hi) = b.planes();
        self.boxes.set(slot, lo, hi);
        self.child[slot] = child;
        self.count[slot] = count;
        self.valid |= 1 << slot;
    }

    pub fn slot_bounds(&self, slot: usize) -> Aabb {
        self.boxes.bounds(slot)
    }

    /// Slot `slot`'s box as its `(min, max)` planes per axis.
    pub fn slot_planes(&self, slot: usize) -> ([f32; 3], [f32; 3]) {
        self.boxes.planes(slot)
    }

    pub fn slots(&self) -> impl Iterator<Item = usize> + '_ {
        (0..W).filter(|k| self.valid & (1 << k) != 0)
    }
}

/// A reference to a wide node's child, as the single-ray and the packet walks carry it on their
/// stacks, encoded here once: an interior child is its node index; a leaf is `LEAF | node·W +
/// slot`, the node and slot that hold it (its first triangle and count are read from that node,
/// which is still in cache when the leaf is reached). The top bit is free: a tree of 2³¹ wide
/// nodes would need 256 GB; a leaf's node number has 28 bits left for eight slots (2²⁸ nodes of
/// 256 bytes: 64 GB).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ChildRef(u32);

impl ChildRef {
    const LEAF: u32 = 1 << 31;
    /// The root node.
    pub(crate) const ROOT: ChildRef = ChildRef(0);

    /// Slot `slot` of node `index` (`node`).
    #[inline(always)]
    pub(crate) fn of<const W: usize>(node: &WideNode<W>, index: u32, slot: usize) -> Self {
        if node.count[slot] > 0 {
            ChildRef(Self::LEAF | index << W.trailing_zeros() | slot as u32)
        } else {
            ChildRef(node.child[slot])
        }
    }

    #[inline(always)]
    pub(crate) fn is_leaf(self) -> bool {
        self.0 & Self::LEAF != 0
    }

    /// The index of an interior child.
    #[inline(always)]
    pub(crate) fn node(self) -> u32 {
        self.0
    }

    /// The node and slot of a leaf in a `W`-wide tree.
    #[inline(always)]
    pub(crate) fn leaf<const W: usize>(self) -> (usize, usize) {
        (((self.0 & !Self::LEAF) >> W.trailing_zeros()) as usize, (self.0 as usize & (W - 1)))
    }

    /// The bits, for a stack entry.
    #[inline(always)]
    pub(crate) fn raw(self) -> u32 {
        self.0
    }

    #[inline(always)]
    pub(crate) fn from_raw(bits: u32) -> Self {
        ChildRef(bits)
    }
}

/// A BVH with `W`-wide nodes (4 or 8). Node 0 is the root.
#[derive(Clone, Debug)]
pub struct WideBvh<const W: usize = WIDTH> {
    pub nodes: Vec<WideNode<W>>,
    pub prim_ids: Vec<u32>,
    pub tris: Vec<[Vec3; 3]>,
    pub root_bounds: Aabb,
    pub params: BuildParams,
    pub report: BuildReport,
    /// The box kernels this tree's walk uses (`crate::cpu`): the CPU's best unless a test or
    /// `BVHSCOPE_SIMD` asks for a more portable one. Only the eight-wide walk has a choice.
    pub simd: crate::cpu::Simd,
}

impl<const W: usize> WideBvh<W> {
    /// This tree walked with the kernels of `simd` (or the best below it this CPU has).
    pub fn with_simd(mut self, simd: crate::cpu::Simd) -> Self {
        self.simd = simd.available();
        self
    }

    /// Collapse a binary BVH into `W`-wide nodes (its triangle arrays are moved, not copied).
    pub fn collapse(bvh: Bvh) -> WideBvh<W> {
        const { assert!(W == 4 || W == 8, "four or eight children") };
        let start = Instant::now();
        let root_bounds = bvh.root_bounds();
        let b = &bvh.nodes;
        let nodes = if b[0].is_leaf() || bvh.prim_ids.is_empty() {
            let mut root = WideNode::EMPTY;
            if b[0].count > 0 {
                root.set(0, b[0].bounds(), b[0].index, b[0].count as u8);
            }
            vec![root]
        } else if b.len() < PARALLEL_MIN_NODES {
            collapse_sequential(b, 0, b.len())
        } else {
            collapse_parallel(b, 0, 0).into_nodes()
        };
        let mut report = bvh.report;
        report.collapse_time = start.elapsed();
        let layout = if W == 8 { super::Layout::Wide8 } else { super::Layout::Wide4 };
        let params = BuildParams { layout, ..bvh.params };
        let simd = crate::cpu::Simd::chosen();
        WideBvh { nodes, prim_ids: bvh.prim_ids, tris: bvh.tris, root_bounds, params, report, simd }
    }
}

impl WideBvh {
    /// Collapse a binary BVH into the 4-wide layout.
    pub fn from_binary(bvh: Bvh) -> WideBvh {
        Self::collapse(bvh)
    }
}

impl<const W: usize> WideBvh<W> {
    /// The box of a node as a trace names it (`bvh::trace::NodeId`): a leaf's is its slot's in
    /// its parent; a wide node's is the slot that refers to it (the root's, the tree's bounds).
    pub fn node_box(&self, id: crate::bvh::NodeId) -> Option<crate::geometry::Aabb> {
        match id {
            crate::bvh::NodeId::Node(0) => Some(self.root_bounds),
            crate::bvh::NodeId::Node(i) => self.nodes.iter().find_map(|n| {
                (0..W)
                    .find(|&s| n.valid & (1 << s) != 0 && n.count[s] == 0 && n.child[s] == i)
                    .map(|s| n.boxes.bounds(s))
            }),
            crate::bvh::NodeId::Leaf { node, slot } => {
                self.nodes.get(node as usize).map(|n| n.boxes.bounds(slot as usize))
            }
        }
    }
}

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
pub fn wide_group_in(layout: super::Layout, b: &[BvhNode], parent: &[u32], node: u32) -> Option<WideGroup> {
    match layout {
        super::Layout::Binary => None,
        super::Layout::Wide4 => wide_group_of::<4>(b, parent, node),
        super::Layout::Wide8 => wide_group_of::<8>(b, parent, node),
    }
}

/// The binary nodes a wide node over interior binary node `bin` takes as its children: its two
/// children, then, while fewer than `W`, the interior one of largest surface area replaced by
/// its own two.
fn wide_children<const W: usize>(b: &[BvhNode], bin: usize) -> ([usize; W], usize) {
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
fn collapse_sequential<const W: usize>(b: &[BvhNode], root: usize, expected: usize) -> Vec<WideNode<W>> {
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
const PARALLEL_MIN_NODES: usize = 1 << 15;
/// ... their top wide levels one by one, the subtrees below (up to W³) on rayon.
const PARALLEL_DEPTH: u32 = 3;

/// A collapsed subtree as the parallel collapse returns it, written into one array at the end.
enum WideTree<const W: usize> {
    /// Node 0 is the root; child indices are local to the vector.
    Flat(Vec<WideNode<W>>),
    /// A wide node whose interior slots are filled in by `into_nodes`, and its interior children.
    Node { node: WideNode<W>, kids: Vec<(usize, WideTree<W>)>, len: usize },
}

fn collapse_parallel<const W: usize>(b: &[BvhNode], bin: usize, depth: u32) -> WideTree<W> {
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
    fn into_nodes(self) -> Vec<WideNode<W>> {
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

impl<const W: usize> TreeView for WideBvh<W> {
    /// The root is node 0 with the whole box; each valid slot is a child: an interior wide node
    /// (id = its index) or a leaf (id = nodes.len() + W·parent + slot).
    fn walk(&self, f: &mut dyn FnMut(&NodeView) -> bool) {
        let root_kind = if self.prim_ids.is_empty() { NodeKind::Leaf { count: 0 } } else { NodeKind::Interior };
        if !f(&NodeView { id: 0, bounds: self.root_bounds, depth: 0, kind: root_kind }) || self.prim_ids.is_empty() {
            return;
        }
        let mut stack = vec![(0usize, 0u32)];
        while let Some((i, depth)) = stack.pop() {
            let node = &self.nodes[i];
            for slot in node.slots() {
                let bounds = node.slot_bounds(slot);
                let d = depth + 1;
                if node.count[slot] > 0 {
                    let id = self.nodes.len() + W * i + slot;
                    f(&NodeView { id, bounds, depth: d, kind: NodeKind::Leaf { count: node.count[slot] as u32 } });
                } else {
                    let c = node.child[slot] as usize;
                    if f(&NodeView { id: c, bounds, depth: d, kind: NodeKind::Interior }) {
                        stack.push((c, d));
                    }
                }
            }
        }
    }

    fn triangle_count(&self) -> usize {
        self.prim_ids.len()
    }

    fn distinct_triangles(&self) -> usize {
        crate::bvh::tree::distinct(&self.prim_ids)
    }

    fn memory_bytes(&self) -> usize {
        // Nodes, primitive ids and the triangles in leaf order (the BVH's own copy).
        self.nodes.len() * std::mem::size_of::<WideNode<W>>()
            + self.prim_ids.len() * 4
            + self.tris.len() * std::mem::size_of::<[Vec3; 3]>()
    }

    fn params(&self) -> &BuildParams {
        &self.params
    }

    fn report(&self) -> &BuildReport {
        &self.report
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
        let h = crate::bvh::inspect::Hierarchy::of(&binary);
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
    use crate::bvh::BuildParams;

    /// The tree as (depth, bounds, kind) in walk order, which follows slots, not node indices.
    fn shape(w: &WideBvh) -> Vec<(u32, Aabb, NodeKind)> {
        let mut out = Vec::new();
        w.walk(&mut |v| {
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
