//! The wide BVH: the binary BVH collapsed into nodes of up to four children whose boxes are tested
//! together with SIMD (`traverse.rs`).
//!
//! Collapse: starting from a binary node, its two children are taken; then, while fewer than four,
//! the interior child of largest surface area is replaced by its own two children. Opening the
//! largest box first removes the most expected traversal cost under the SAH; the rule is the
//! greedy collapse of Wald, Benthin & Boulos, "Getting Rid of Packets" (RT 2008), and Pinto,
//! "Fast BVH collapse" (2010). Leaves and the triangle order are those of the binary BVH.
//!
//! Triangles are stored in leaf order, vertices inline (36 bytes each, no index indirection), so a
//! leaf is one contiguous read. They are not precomputed into edge form: the watertight test needs
//! the vertices themselves, and rebuilding them from stored edges would change its rounding and so
//! lose the guarantee that rays through shared edges hit.

mod traverse;

use super::node::Bvh;
use super::tree::{NodeKind, NodeView, TreeView};
use super::{BuildParams, BuildReport};
use crate::geometry::Aabb;
use glam::Vec3;
use rayon::prelude::*;
use std::time::Instant;

pub const WIDTH: usize = 4;

/// Children boxes in SoA order (`min[axis][slot]`), then per slot: a child node index (interior,
/// `count == 0`) or the first triangle of a leaf (`count > 0`). Empty slots have an inverted box
/// (+inf..-inf), which every slab test misses, and are clear in `valid`.
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WideNode {
    pub min: [[f32; WIDTH]; 3],
    pub max: [[f32; WIDTH]; 3],
    pub child: [u32; WIDTH],
    pub count: [u8; WIDTH],
    /// Bit k set when slot k holds a child.
    pub valid: u8,
    pub _pad: [u8; 11],
}

const _: () = assert!(std::mem::size_of::<WideNode>() == 128);

impl WideNode {
    pub const EMPTY: WideNode = WideNode {
        min: [[f32::INFINITY; WIDTH]; 3],
        max: [[f32::NEG_INFINITY; WIDTH]; 3],
        child: [u32::MAX; WIDTH],
        count: [0; WIDTH],
        valid: 0,
        _pad: [0; 11],
    };

    fn set(&mut self, slot: usize, b: Aabb, child: u32, count: u8) {
        for axis in 0..3 {
            self.min[axis][slot] = b.min[axis];
            self.max[axis][slot] = b.max[axis];
        }
        self.child[slot] = child;
        self.count[slot] = count;
        self.valid |= 1 << slot;
    }

    pub fn slot_bounds(&self, slot: usize) -> Aabb {
        Aabb::new(
            Vec3::new(self.min[0][slot], self.min[1][slot], self.min[2][slot]),
            Vec3::new(self.max[0][slot], self.max[1][slot], self.max[2][slot]),
        )
    }

    pub fn slots(&self) -> impl Iterator<Item = usize> + '_ {
        (0..WIDTH).filter(|k| self.valid & (1 << k) != 0)
    }
}

/// A BVH with 4-wide nodes. Node 0 is the root.
#[derive(Clone, Debug)]
pub struct WideBvh {
    pub nodes: Vec<WideNode>,
    pub prim_ids: Vec<u32>,
    pub tris: Vec<[Vec3; 3]>,
    pub root_bounds: Aabb,
    pub params: BuildParams,
    pub report: BuildReport,
}

impl WideBvh {
    /// Collapse a binary BVH (its triangle arrays are moved, not copied).
    pub fn from_binary(bvh: Bvh) -> WideBvh {
        let start = Instant::now();
        let root_bounds = bvh.root_bounds();
        let b = &bvh.nodes;
        // Each wide node takes the place of up to three binary interior nodes (of which a binary
        // tree of k nodes has (k - 1) / 2); reserving that third up front avoids regrowing a vector
        // of 128-byte nodes several times on big meshes.
        let mut nodes = Vec::with_capacity(b.len() / 6 + 1);
        // Touched in parallel first: faulting in the fresh pages of a big array is a good part of
        // the collapse's time, and it splits over threads.
        nodes.par_extend(rayon::iter::repeat_n(WideNode::EMPTY, b.len() / 6 + 1));
        nodes.truncate(1);
        if b[0].is_leaf() || bvh.prim_ids.is_empty() {
            if b[0].count > 0 {
                nodes[0].set(0, b[0].bounds, b[0].index, b[0].count as u8);
            }
        } else {
            let mut stack = vec![(0usize, 0usize)]; // (binary node, wide node to fill)
            while let Some((bin, wide)) = stack.pop() {
                let mut kids = [0usize; WIDTH];
                let (l, r) = (b[bin].index as usize, b[bin].index as usize + 1);
                kids[0] = l;
                kids[1] = r;
                let mut n = 2;
                while n < WIDTH {
                    let open = (0..n)
                        .filter(|&k| !b[kids[k]].is_leaf())
                        .max_by(|&x, &y| b[kids[x]].bounds.area().total_cmp(&b[kids[y]].bounds.area()));
                    let Some(k) = open else { break };
                    let first = b[kids[k]].index as usize;
                    kids[k] = first;
                    kids[n] = first + 1;
                    n += 1;
                }
                for (slot, &k) in kids[..n].iter().enumerate() {
                    let node = &b[k];
                    if node.is_leaf() {
                        nodes[wide].set(slot, node.bounds, node.index, node.count as u8);
                    } else {
                        let child = nodes.len();
                        nodes.push(WideNode::EMPTY);
                        nodes[wide].set(slot, node.bounds, child as u32, 0);
                        stack.push((k, child));
                    }
                }
            }
        }
        let mut report = bvh.report;
        report.collapse_time = start.elapsed();
        let params = BuildParams { layout: super::Layout::Wide4, ..bvh.params };
        WideBvh { nodes, prim_ids: bvh.prim_ids, tris: bvh.tris, root_bounds, params, report }
    }
}

impl TreeView for WideBvh {
    /// The root is node 0 with the whole box; each valid slot is a child: an interior wide node
    /// (id = its index) or a leaf (id = nodes.len() + 4·parent + slot).
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
                    let id = self.nodes.len() + WIDTH * i + slot;
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

    fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<WideNode>() + self.prim_ids.len() * 4
    }

    fn params(&self) -> &BuildParams {
        &self.params
    }

    fn report(&self) -> &BuildReport {
        &self.report
    }
}
