//! The flat BVH: 32-byte nodes in one array, children of a node stored next to each other, and
//! the triangles reordered so each leaf is a contiguous range (the handout's `orderedShapes`).

use crate::bvh::params::{BuildParams, BuildReport};
use crate::geometry::Aabb;
use glam::Vec3;

/// Depth of the traversal stack's fixed part. The builder keeps the trees it makes shallower than
/// this (see `builders::HEURISTIC_DEPTH_LIMIT`), so their walks never leave it; an imported tree of
/// any depth spills onto the heap (`stack::TraversalStack`).
pub const TRAVERSAL_STACK_SIZE: usize = 128;

/// One node: 24 bytes of bounds (the box's lower and upper planes), then either the first of two
/// adjacent children (interior, `count == 0`) or the first of `count` triangles (leaf).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhNode {
    pub lo: [f32; 3],
    pub hi: [f32; 3],
    /// Interior: index of the left child (the right one follows it). Leaf: first triangle.
    pub index: u32,
    /// Number of triangles; 0 marks an interior node.
    pub count: u16,
    /// Split axis of an interior node (0 = x, 1 = y, 2 = z); the handout's ordering rule reads it.
    pub axis: u8,
    pub _pad: u8,
}

const _: () = assert!(std::mem::size_of::<BvhNode>() == 32);

impl BvhNode {
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    pub fn leaf(bounds: Aabb, first: u32, count: u16) -> Self {
        let (lo, hi) = bounds.planes();
        Self { lo, hi, index: first, count, axis: 0, _pad: 0 }
    }

    pub fn interior(bounds: Aabb, left: u32, axis: u8) -> Self {
        let (lo, hi) = bounds.planes();
        Self { lo, hi, index: left, count: 0, axis, _pad: 0 }
    }

    /// The node's box.
    #[inline(always)]
    pub fn bounds(&self) -> Aabb {
        Aabb::new(Vec3::from_array(self.lo), Vec3::from_array(self.hi))
    }

    /// The slab test of the node's box (`geometry::slab::OneRay`).
    #[inline(always)]
    pub fn slab(&self, ray: &crate::geometry::slab::OneRay, t_min: f32, t_max: f32) -> (f32, f32) {
        ray.one_box(&self.lo, &self.hi, t_min, t_max)
    }

    /// The triangle range of a leaf.
    pub fn prims(&self) -> std::ops::Range<usize> {
        self.index as usize..self.index as usize + self.count as usize
    }
}

/// A built BVH over one mesh.
#[derive(Clone, Debug)]
pub struct Bvh {
    /// Node 0 is the root.
    pub nodes: Vec<BvhNode>,
    /// Leaf order → the mesh's triangle index.
    pub prim_ids: Vec<u32>,
    /// Triangle vertices in leaf order, so a leaf reads contiguous memory.
    pub tris: Vec<[Vec3; 3]>,
    pub params: BuildParams,
    pub report: BuildReport,
}

impl Bvh {
    pub fn root_bounds(&self) -> Aabb {
        self.nodes[0].bounds()
    }

    /// Bytes a ray's walk reads from: the nodes, the primitive index array and the triangles,
    /// which the BVH keeps in leaf order (its own copy, 36 bytes each).
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<BvhNode>()
            + self.prim_ids.len() * 4
            + self.tris.len() * std::mem::size_of::<[Vec3; 3]>()
    }
}

/// Visit a binary node array parents first (the `TreeView` walk of every binary tree); an `empty`
/// tree's root is a leaf with no primitives.
pub(crate) fn walk_nodes(nodes: &[BvhNode], empty: bool, f: &mut dyn FnMut(&super::tree::TreeNode) -> bool) {
    use super::tree::{NodeKind, TreeNode};
    let mut stack = vec![(0usize, 0u32)];
    while let Some((i, depth)) = stack.pop() {
        let n = &nodes[i];
        let kind = if n.is_leaf() || empty { NodeKind::Leaf { count: n.count as u32 } } else { NodeKind::Interior };
        let descend = f(&TreeNode { id: i, bounds: n.bounds(), depth, kind });
        if descend && kind == NodeKind::Interior {
            stack.push((n.index as usize + 1, depth + 1));
            stack.push((n.index as usize, depth + 1));
        }
    }
}

impl super::tree::TreeView for Bvh {
    fn visit_nodes(&self, f: &mut dyn FnMut(&super::tree::TreeNode) -> bool) {
        walk_nodes(&self.nodes, self.prim_ids.is_empty(), f)
    }

    fn triangle_count(&self) -> usize {
        self.prim_ids.len()
    }

    fn distinct_triangles(&self) -> usize {
        super::tree::distinct(&self.prim_ids)
    }

    fn memory_bytes(&self) -> usize {
        Bvh::memory_bytes(self)
    }

    fn params(&self) -> &BuildParams {
        &self.params
    }

    fn report(&self) -> &BuildReport {
        &self.report
    }
}
