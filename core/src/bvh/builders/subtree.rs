//! The parallel build's subtrees and their placement in the final node array (`bvh::builders`).

use crate::bvh::node::BvhNode;
use crate::geometry::Aabb;
use rayon::prelude::*;

/// A subtree as the parallel build returns it: the top splits as a small tree of their own, the
/// subtrees below them as flat node arrays built sequentially. Written into the final array once,
/// at the end (`into_nodes`); merging arrays at every parallel level instead copied each node
/// once per level, a fifth of the build on a 2M-triangle mesh.
pub(super) enum Subtree {
    /// Node 0 is the root; child indices are local to the vector.
    Flat(Vec<BvhNode>),
    Split {
        bounds: Aabb,
        axis: u8,
        left: Box<Subtree>,
        right: Box<Subtree>,
        len: usize,
    },
}

impl Subtree {
    /// Nodes in the subtree.
    pub(super) fn len(&self) -> usize {
        match self {
            Subtree::Flat(nodes) => nodes.len(),
            Subtree::Split { len, .. } => *len,
        }
    }

    /// The flat pieces in depth-first order, left before right: the order of their leaves.
    pub(super) fn flats_mut(&mut self) -> Vec<&mut Vec<BvhNode>> {
        match self {
            Subtree::Flat(nodes) => vec![nodes],
            Subtree::Split { left, right, .. } => {
                let mut flats = left.flats_mut();
                flats.extend(right.flats_mut());
                flats
            }
        }
    }

    /// The flat array: the layout is [root, left root, right root, rest of left, rest of right]
    /// at every split, as a sequential build makes it, so each node's children stay a pair.
    pub(super) fn into_nodes(self) -> Vec<BvhNode> {
        if let Subtree::Flat(nodes) = self {
            return nodes;
        }
        crate::parallel::region(|| {
            let mut nodes = Vec::with_capacity(self.len());
            // Filled in parallel: first touch of fresh pages is much of the cost of a big array.
            nodes.par_extend(rayon::iter::repeat_n(BvhNode::leaf(Aabb::EMPTY, 0, 0), self.len()));
            let (root, rest) = nodes.split_first_mut().expect("a subtree has a root");
            self.write(root, rest, 1);
            nodes
        })
    }

    /// Write the root into `root` and the other nodes into `rest`, whose first node has global
    /// index `rest_base`.
    fn write(self, root: &mut BvhNode, rest: &mut [BvhNode], rest_base: u32) {
        match self {
            Subtree::Flat(nodes) => {
                // Local index i ≥ 1 goes to rest_base + i - 1.
                let place =
                    |n: &BvhNode| if n.is_leaf() { *n } else { BvhNode { index: n.index + rest_base - 1, ..*n } };
                *root = place(&nodes[0]);
                for (to, from) in rest.iter_mut().zip(&nodes[1..]) {
                    *to = place(from);
                }
            }
            Subtree::Split { bounds, axis, left, right, .. } => {
                *root = BvhNode::interior(bounds, rest_base, axis);
                let (pair, rests) = rest.split_at_mut(2);
                let (left_root, right_root) = pair.split_at_mut(1);
                let (left_rest, right_rest) = rests.split_at_mut(left.len() - 1);
                let right_base = rest_base + 2 + left_rest.len() as u32;
                rayon::join(
                    || left.write(&mut left_root[0], left_rest, rest_base + 2),
                    || right.write(&mut right_root[0], right_rest, right_base),
                );
            }
        }
    }
}
