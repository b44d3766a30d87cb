//! The 4-wide BVH as the packet walk (`bvh::packet::walk`) sees it: its nodes' four child boxes,
//! already in SoA order, and `ChildRef`s. Why wide packets beat binary ones for primary rays: the
//! wide tree has half the levels, so a packet pops, pushes and sorts half as often, and the
//! frustum tests four children in one SIMD pass.

use super::{ChildRef, WideBvh};
use crate::bvh::packet::PacketTree;
use crate::geometry::slab::RayInterval;
use crate::geometry::Aabb;
use glam::Vec3;
use wide::f32x4;

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
    fn slots(&self, r: u32) -> u32 {
        self.nodes[ChildRef::from_raw(r).node() as usize].valid as u32
    }
    #[inline(always)]
    fn slot_planes(&self, r: u32, slot: usize) -> ([f32; 3], [f32; 3]) {
        self.nodes[ChildRef::from_raw(r).node() as usize].boxes.planes(slot)
    }
    #[inline(always)]
    fn keys(&self, r: u32, lead: Vec3) -> [f32; 4] {
        let b = &self.nodes[ChildRef::from_raw(r).node() as usize].boxes;
        let centre = |axis: usize| f32x4::from(b.min[axis]) + f32x4::from(b.max[axis]);
        (centre(0) * f32x4::splat(lead.x) + centre(1) * f32x4::splat(lead.y) + centre(2) * f32x4::splat(lead.z))
            .to_array()
    }
    #[inline(always)]
    fn may_hit(&self, r: u32, missed: u32, frustum: &RayInterval, t_far: f32) -> u32 {
        missed & frustum.may_hit4(&self.nodes[ChildRef::from_raw(r).node() as usize].boxes, t_far)
    }
    #[inline(always)]
    fn child(&self, r: u32, slot: usize) -> u32 {
        let index = ChildRef::from_raw(r).node();
        ChildRef::of(&self.nodes[index as usize], index, slot).raw()
    }
    #[inline(always)]
    fn leaf(&self, r: u32) -> ([f32; 3], [f32; 3], usize, usize) {
        let (index, s) = ChildRef::from_raw(r).leaf();
        let node = &self.nodes[index];
        let (lo, hi) = node.slot_planes(s);
        (lo, hi, node.child[s] as usize, node.count[s] as usize)
    }
}
