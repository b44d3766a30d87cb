//! The wide BVHs as the packet walk (`bvh::packet::walk`) sees them: their nodes' child boxes,
//! already in SoA order (tested four at a time), and `ChildRef`s. Why wide packets beat binary ones for primary rays: the
//! wide tree has half the levels, so a packet pops, pushes and sorts half as often, and the
//! frustum tests four children in one SIMD pass.

use crate::bvh::packet::walk::PacketTree;
use crate::bvh::wide::wide_bvh::{ChildRef, WideBvh};
use crate::geometry::{slab::Boxes4, slab_packet::RayInterval, Aabb};
use glam::Vec3;
use wide::f32x4;

impl<const W: usize> PacketTree for WideBvh<W> {
    /// The tree's kernel choice (`with_simd`): groups of sixteen rays where it is AVX-512, in both
    /// widths (the 4-wide walk of single rays has no AVX-512 kernel; its packets do).
    fn simd(&self) -> crate::cpu::Simd {
        self.simd
    }
    fn prim_ids(&self) -> &[u32] {
        &self.prim_ids
    }
    #[inline(always)]
    fn with_leaf<R>(&self, start: usize, count: usize, f: impl FnOnce(&[[glam::Vec3; 3]]) -> R) -> R {
        WideBvh::with_leaf(self, start, count, f)
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
    fn keys(&self, r: u32, lead: Vec3) -> [f32; 8] {
        let b = &self.nodes[ChildRef::from_raw(r).node() as usize].boxes;
        let mut keys = [0.0; 8];
        for h in 0..W / 4 {
            let (min, max) = (quarter(&b.min, h), quarter(&b.max, h));
            let centre = |axis: usize| f32x4::from(min[axis]) + f32x4::from(max[axis]);
            let k =
                centre(0) * f32x4::splat(lead.x) + centre(1) * f32x4::splat(lead.y) + centre(2) * f32x4::splat(lead.z);
            keys[4 * h..4 * h + 4].copy_from_slice(&k.to_array());
        }
        keys
    }
    #[inline(always)]
    fn may_hit(&self, r: u32, missed: u32, frustum: &RayInterval, t_far: f32) -> u32 {
        let b = &self.nodes[ChildRef::from_raw(r).node() as usize].boxes;
        let mut m = 0;
        for h in (0..W / 4).filter(|h| missed >> (4 * h) & 0b1111 != 0) {
            m |= frustum.may_hit4(&Boxes4 { min: quarter(&b.min, h), max: quarter(&b.max, h) }, t_far) << (4 * h);
        }
        missed & m
    }
    #[inline(always)]
    fn child(&self, r: u32, slot: usize) -> u32 {
        let index = ChildRef::from_raw(r).node();
        ChildRef::of(&self.nodes[index as usize], index, slot).raw()
    }
    #[inline(always)]
    fn leaf(&self, r: u32) -> ([f32; 3], [f32; 3], usize, usize) {
        let (index, s) = ChildRef::from_raw(r).leaf::<W>();
        let node = &self.nodes[index];
        let (lo, hi) = node.slot_planes(s);
        (lo, hi, node.child[s] as usize, node.count[s] as usize)
    }
}

/// Slots `4h..4h + 4` of each axis' planes.
#[inline(always)]
fn quarter<const W: usize>(planes: &[[f32; W]; 3], h: usize) -> [[f32; 4]; 3] {
    planes.map(|p| [p[4 * h], p[4 * h + 1], p[4 * h + 2], p[4 * h + 3]])
}
