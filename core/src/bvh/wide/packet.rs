//! The 4-wide BVH as the packet walk (`bvh::packet::walk`) sees it: its nodes' four child boxes,
//! already in SoA order, and `ChildRef`s. Why wide packets beat binary ones for primary rays: the
//! wide tree has half the levels, so a packet pops, pushes and sorts half as often, and the
//! frustum tests four children in one SIMD pass.

use super::{ChildRef, WideBvh};
use crate::bvh::packet::PacketTree;
use crate::geometry::slab::Boxes4;
use crate::geometry::Aabb;

impl PacketTree for WideBvh {
    fn prim_ids(&self) -> &[u32] {
        &self.prim_ids
    }
    fn tris(&self) -> &[[glam::Vec3; 3]] {
        &self.tris
    }
    fn root_bounds(&self) -> Aabb {
        self.root_bounds
    }
    fn root(&self) -> u32 {
        ChildRef::ROOT.raw()
    }
    #[inline(always)]
    fn is_leaf(&self, r: u32) -> bool {
        ChildRef::from_raw(r).is_leaf()
    }
    #[inline(always)]
    fn children<'a>(&'a self, r: u32, _: &'a mut Boxes4) -> (&'a Boxes4, u32, [u32; 4]) {
        let index = ChildRef::from_raw(r).node();
        let node = &self.nodes[index as usize];
        let refs = std::array::from_fn(|s| ChildRef::of(node, index, s).raw());
        (&node.boxes, node.valid as u32, refs)
    }
    #[inline(always)]
    fn leaf(&self, r: u32) -> ([f32; 3], [f32; 3], usize, usize) {
        let (index, s) = ChildRef::from_raw(r).leaf();
        let node = &self.nodes[index];
        let (lo, hi) = node.slot_planes(s);
        (lo, hi, node.child[s] as usize, node.count[s] as usize)
    }
}
