//! Ray packets over the 4-wide BVH: the ranged traversal of `bvh::packet` (Wald, Boulos & Shirley
//! 2007, §4) with four children per node. For each child the packet finds the first group of
//! four rays that hits its box, starting from the node's own first group; children no group hits
//! are dropped, the others are visited nearest first along the packet's leading direction.
//!
//! Why it beats binary packets for primary rays: the wide tree has half the levels, so a packet
//! pops, pushes and sorts half as often. Each child is first tested against the node's first
//! group; the children it misses are put to the packet's frustum, one SIMD test for the four boxes,
//! before the following groups are tried. Leaves are the binary BVH's, tested the same way: every
//! group from the leaf's first one, its hitting rays with the four-ray triangle test (bit for bit
//! the single-ray test), so each ray gets the hit it would get alone.

use super::{WideBvh, WIDTH};
use crate::bvh::packet::{Packet, PacketWalk};
use crate::bvh::stack::TraversalStack;
use crate::bvh::{Hit, TRAVERSAL_STACK_SIZE};
use crate::geometry::{Ray, TriangleIntersector};
use std::mem::MaybeUninit;
use wide::f32x4;

/// Deepest stack a packet can need: at most three pushes per level, as for single rays.
const STACK: usize = 3 * TRAVERSAL_STACK_SIZE + 4;

/// A child reference as in `traverse.rs`: a node index, or `LEAF | (node·4 + slot)`.
const LEAF: u32 = 1 << 31;

impl PacketWalk for WideBvh {
    fn has_no_triangles(&self) -> bool {
        self.prim_ids.is_empty()
    }

    fn walk<T: TriangleIntersector>(&self, rays: &mut [Ray], hits: &mut [Option<Hit>]) {
        // Children are ordered by their centres along the first ray's direction: for coherent rays
        // that is front to back (the order only affects speed, never the result).
        let lead = rays[0].dir();
        let lead = [f32x4::splat(lead.x), f32x4::splat(lead.y), f32x4::splat(lead.z)];
        let mut slot = MaybeUninit::uninit();
        let packet = Packet::<T>::new_in(&mut slot, rays);
        let mut t_far = packet.t_far();
        // (child reference, first group that may hit it).
        let mut stack = TraversalStack::<STACK, (u32, u8)>::new();
        let (mut cur, mut first) = (0u32, 0usize);
        loop {
            if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                let centre = |axis: usize| f32x4::from(node.min[axis]) + f32x4::from(node.max[axis]);
                let key = (centre(0) * lead[0] + centre(1) * lead[1] + centre(2) * lead[2]).to_array();
                // The hit children as (key, reference, first group), kept sorted far to near.
                let mut hit = [(0f32, 0u32, 0u8); WIDTH];
                let mut n = 0;
                let mut add = |s: usize, g: usize| {
                    let r = if node.count[s] > 0 { LEAF | (cur << 2 | s as u32) } else { node.child[s] };
                    let mut j = n;
                    while j > 0 && hit[j - 1].0 < key[s] {
                        hit[j] = hit[j - 1];
                        j -= 1;
                    }
                    hit[j] = (key[s], r, g as u8);
                    n += 1;
                };
                // Most children are hit by the node's first group; the others are first put to
                // the frustum, then to the following groups one by one.
                let mut missed = 0u32;
                let mut todo = node.valid as u32;
                while todo != 0 {
                    let s = todo.trailing_zeros() as usize;
                    todo &= todo - 1;
                    let (lo, hi) = node.slot_planes(s);
                    if packet.group_hits(first, lo, hi) != 0 {
                        add(s, first);
                    } else {
                        missed |= 1 << s;
                    }
                }
                if missed != 0 && first + 1 < packet.n_groups {
                    missed &= packet.frustum.may_hit4(&node.min, &node.max, t_far);
                    while missed != 0 {
                        let s = missed.trailing_zeros() as usize;
                        missed &= missed - 1;
                        let (lo, hi) = node.slot_planes(s);
                        let mut g = first + 1;
                        while g < packet.n_groups && packet.group_hits(g, lo, hi) == 0 {
                            g += 1;
                        }
                        if g < packet.n_groups {
                            add(s, g);
                        }
                    }
                }
                if n > 0 {
                    for &(_, r, g) in &hit[..n - 1] {
                        stack.push((r, g));
                    }
                    (cur, first) = (hit[n - 1].1, hit[n - 1].2 as usize);
                    continue;
                }
            } else {
                let (index, s) = ((cur & !LEAF) >> 2, (cur & 3) as usize);
                let node = &self.nodes[index as usize];
                let (lo, hi) = node.slot_planes(s);
                let (start, count) = (node.child[s] as usize, node.count[s] as usize);
                if packet.leaf_groups(first, lo, hi, &self.tris[start..start + count], start) {
                    t_far = packet.t_far();
                }
            }
            let Some((r, g)) = stack.pop() else { break };
            (cur, first) = (r, g as usize);
        }
        packet.finish(&self.prim_ids, hits);
    }
}
