//! A layout-independent view of a built hierarchy: what the statistics and the box overlay need,
//! the same for the binary BVH and the wide one.

use super::{BuildParams, BuildReport};
use crate::geometry::Aabb;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeKind {
    Interior,
    Leaf { count: u32 },
}

/// One node as the view presents it. `id` is unique within the tree (for colours and caching).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeView {
    pub id: usize,
    pub bounds: Aabb,
    /// Root = 0.
    pub depth: u32,
    pub kind: NodeKind,
}

pub trait TreeView {
    /// Visit every node, parents before children; `f` returns whether to visit the node's children.
    fn walk(&self, f: &mut dyn FnMut(&NodeView) -> bool);
    fn triangle_count(&self) -> usize;
    /// Bytes of nodes and primitive indices.
    fn memory_bytes(&self) -> usize;
    fn params(&self) -> &BuildParams;
    fn report(&self) -> &BuildReport;

    /// Bounds of every node at exactly `depth`, and optionally of leaves above it: what the app's
    /// box overlay draws. Subtrees below `depth` are not visited.
    fn boxes_at_depth(&self, depth: u32, include_shallower_leaves: bool) -> Vec<(usize, Aabb)> {
        let mut out = Vec::new();
        self.walk(&mut |n| {
            let leaf = matches!(n.kind, NodeKind::Leaf { .. });
            if n.depth == depth || (include_shallower_leaves && leaf && n.depth < depth) {
                out.push((n.id, n.bounds));
            }
            n.depth < depth
        });
        out
    }
}
