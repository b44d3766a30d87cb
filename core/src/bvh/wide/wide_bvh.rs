//! The wide BVH and its node: the tree `traverse.rs` walks, collapsed from a binary BVH by `collapse.rs`.

use crate::bvh::node::Bvh;
use crate::bvh::params::{BuildParams, BuildReport};
use crate::bvh::tree::{NodeKind, TreeNode, TreeView};
use crate::bvh::wide::collapse::{collapse_parallel, collapse_sequential, CollapsePlan, PARALLEL_MIN_NODES};
use crate::bvh::wide::node::{WideNode, WIDTH};
use crate::geometry::Aabb;
use glam::Vec3;
use std::time::Instant;

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
    /// The triangles in leaf order, 36 bytes each. Each leaf's bytes hold its triangles coordinate
    /// by coordinate (`leaves.rs`); read them through `with_leaf` or `leaf_order_triangles`.
    pub tris: Vec<[Vec3; 3]>,
    pub root_bounds: Aabb,
    pub params: BuildParams,
    pub report: BuildReport,
    /// The box kernels this tree's walk uses (`crate::cpu`): the CPU's best unless a test or
    /// `BVHSCOPE_SIMD` asks for a more portable one. Only the eight-wide walk has a choice.
    pub simd: crate::cpu::Simd,
    /// The leaves in `MollerTrumboreStored`'s form (`leaves.rs`, `stored_leaves`): made by the
    /// first walk with that test, then kept; empty until then.
    pub(crate) stored: std::sync::OnceLock<Vec<f32>>,
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
            collapse_sequential(b, &CollapsePlan::of::<W>(b), 0, b.len())
        } else {
            collapse_parallel(b, &CollapsePlan::of::<W>(b), 0, 0).into_nodes()
        };
        let layout = if W == 8 { crate::bvh::Layout::Wide8 } else { crate::bvh::Layout::Wide4 };
        let params = BuildParams { layout, ..bvh.params };
        let simd = crate::cpu::Simd::chosen();
        let (prim_ids, tris, report) = (bvh.prim_ids, bvh.tris, bvh.report);
        let mut wide = WideBvh { nodes, prim_ids, tris, root_bounds, params, report, simd, stored: Default::default() };
        wide.store_leaves_by_coordinate();
        wide.report.collapse_time = start.elapsed();
        wide
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

impl<const W: usize> TreeView for WideBvh<W> {
    /// The root is node 0 with the whole box; each valid slot is a child: an interior wide node
    /// (id = its index) or a leaf (id = nodes.len() + W·parent + slot).
    fn visit_nodes(&self, f: &mut dyn FnMut(&TreeNode) -> bool) {
        let root_kind = if self.prim_ids.is_empty() { NodeKind::Leaf { count: 0 } } else { NodeKind::Interior };
        if !f(&TreeNode { id: 0, bounds: self.root_bounds, depth: 0, kind: root_kind }) || self.prim_ids.is_empty() {
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
                    f(&TreeNode { id, bounds, depth: d, kind: NodeKind::Leaf { count: node.count[slot] as u32 } });
                } else {
                    let c = node.child[slot] as usize;
                    if f(&TreeNode { id: c, bounds, depth: d, kind: NodeKind::Interior }) {
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
        // Nodes, primitive ids and the triangles in leaf order (the BVH's own copy). Not the stored
        // leaves a walk with `MollerTrumboreStored` makes: whether they exist depends on what was
        // walked, and a figure must not (the app counts before it renders, `stats` after its
        // rays); `AnyBvh::bytes_for` counts them for that test.
        self.nodes.len() * std::mem::size_of::<WideNode<W>>()
            + self.prim_ids.len() * 4
            + self.tris.len() * std::mem::size_of::<[Vec3; 3]>()
    }

    fn params(&self) -> &BuildParams {
        &self.params
    }

    /// The kernels the walk runs: for eight children the tree's choice (AVX-512, AVX2, two SSE/NEON
    /// passes or scalar); four children are tested in one four-lane pass, their leaves with AVX2
    /// where the CPU has it (the 4-wide walk has no AVX-512 kernel).
    fn simd(&self) -> Option<crate::cpu::Simd> {
        Some(if W == 4 { self.simd.min(crate::cpu::Simd::Avx2) } else { self.simd })
    }

    fn report(&self) -> &BuildReport {
        &self.report
    }
}
