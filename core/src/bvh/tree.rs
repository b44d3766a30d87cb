//! A layout-independent view of a built hierarchy: what the statistics and the box overlay need,
//! the same for the binary BVH and the wide one.

use crate::bvh::params::{BuildParams, BuildReport};
use crate::geometry::Aabb;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeKind {
    Interior,
    Leaf { count: u32 },
}

/// One node as a `TreeView` walk presents it. `id` is unique within the tree (for colours and caching).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeNode {
    pub id: usize,
    pub bounds: Aabb,
    /// Root = 0.
    pub depth: u32,
    pub kind: NodeKind,
}

pub trait TreeView {
    /// Visit every node, parents before children; `f` returns whether to visit the node's children.
    fn visit_nodes(&self, f: &mut dyn FnMut(&TreeNode) -> bool);
    /// Triangle references in leaves: the triangles, plus the duplicates of any cut by spatial
    /// splits (SBVH).
    fn triangle_count(&self) -> usize;
    /// Different triangles in leaves (a triangle referenced by several leaves counted once).
    fn distinct_triangles(&self) -> usize {
        self.triangle_count()
    }
    /// Bytes of nodes, primitive indices and the triangles the tree keeps.
    fn memory_bytes(&self) -> usize;
    /// The SIMD kernels its walk runs (`crate::cpu`), for a wide layout; `None` for the binary one.
    fn simd(&self) -> Option<crate::cpu::Simd> {
        None
    }
    fn params(&self) -> &BuildParams;
    fn report(&self) -> &BuildReport;

    /// Bounds of every node at exactly `depth`, and optionally of leaves above it: what the app's
    /// box overlay draws. Subtrees below `depth` are not visited.
    fn boxes_at_depth(&self, depth: u32, include_shallower_leaves: bool) -> Vec<(usize, Aabb)> {
        let mut out = Vec::new();
        self.visit_nodes(&mut |n| {
            let leaf = matches!(n.kind, NodeKind::Leaf { .. });
            if n.depth == depth || (include_shallower_leaves && leaf && n.depth < depth) {
                out.push((n.id, n.bounds));
            }
            n.depth < depth
        });
        out
    }
}

/// Different values among leaf slots' triangle ids.
pub(crate) fn distinct(prim_ids: &[u32]) -> usize {
    let Some(&max) = prim_ids.iter().max() else { return 0 };
    let mut seen = vec![false; max as usize + 1];
    prim_ids.iter().filter(|&&p| !std::mem::replace(&mut seen[p as usize], true)).count()
}
