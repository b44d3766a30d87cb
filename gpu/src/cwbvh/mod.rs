//! The compressed 8-wide BVH of Ylitie, Karras & Laine, "Efficient Incoherent Ray Traversal on
//! GPUs Through Compressed Wide BVHs" (HPG 2017): 80-byte nodes whose eight child boxes are
//! quantised to 8 bits per plane relative to the node's own box, children placed in slots by the
//! octant of the ray directions that meet them first, and a walk that keeps groups of hit children
//! as bit masks on its stack (shaders/cwbvh.wgsl; the same walk on the CPU in `walk.rs`).
//!
//! Built from any binary `Bvh` bvhscope makes or imports, grouped as core's 8-wide layout groups it
//! (`bvh::wide::CollapsePlan`: the wide nodes of least summed surface area, the paper's own
//! collapse without its merging of leaves). Leaves are the binary
//! tree's leaves, unchanged and of any size: where the paper packs up to three triangles per leaf
//! into a 24-bit triangle mask, a leaf child here names a record (first triangle, count) in a leaf
//! array, so that trees with larger leaves (bvhscope's default is four, an import may hold any
//! number) keep their leaves and triangle order. See `CwbvhNode` for the bytes.

pub(crate) mod gpu;
mod walk;

pub use gpu::{CwbvhFormat, GpuCwbvh};

use crate::device::GpuError;
use bvhscope_core::bvh::wide::CollapsePlan;
use bvhscope_core::bvh::Bvh;
use bvhscope_core::geometry::Aabb;
use glam::Vec3;

/// One node, 80 bytes, little-endian:
///
/// | bytes | field | meaning |
/// | --- | --- | --- |
/// | 0–11 | `p` | the node box's lower corner (3 × f32): the origin of the quantisation grid |
/// | 12–14 | `e` | per axis, the grid's cell size 2^(e−127) as a biased exponent (the bits of that float) |
/// | 15 | `imask` | bit s set when slot s holds an interior child |
/// | 16–19 | `child_base` | index of the first interior child; slot s's is `child_base` + (interior slots below s) |
/// | 20–23 | `leaf_base` | index of the node's first leaf record |
/// | 24–31 | `meta[8]` | per slot: 0 empty; `0b001_11000 \| s` (24 + s) interior; `0b001_00000 \| r` leaf record `leaf_base + r` |
/// | 32–55 | `q_lo[3][8]` | per axis, per slot: the child box's lower plane, `p + q·2^(e−127)` |
/// | 56–79 | `q_hi[3][8]` | the upper planes likewise |
///
/// Quantised planes are rounded outwards and checked as the walk decodes them (in single
/// precision, `p + q·scale`, one rounding), so each decoded box holds its child's exact box.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CwbvhNode {
    pub p: [f32; 3],
    pub e: [u8; 3],
    pub imask: u8,
    pub child_base: u32,
    pub leaf_base: u32,
    pub meta: [u8; 8],
    pub q_lo: [[u8; 8]; 3],
    pub q_hi: [[u8; 8]; 3],
}

const _: () = assert!(std::mem::size_of::<CwbvhNode>() == 80);

/// `meta` of an interior child in slot s is `INTERIOR | s` (the paper's 24 + s).
pub const META_INTERIOR: u8 = 0b0011_1000;
/// `meta` of a leaf child is `META_LEAF | r` for leaf record r of the node.
pub const META_LEAF: u8 = 0b0010_0000;

impl CwbvhNode {
    /// The cell size on `axis`.
    pub fn scale(&self, axis: usize) -> f32 {
        f32::from_bits((self.e[axis] as u32) << 23)
    }

    /// Slot `slot`'s box as the walk decodes it.
    pub fn child_box(&self, slot: usize) -> ([f32; 3], [f32; 3]) {
        let d = |q: u8, axis: usize| self.p[axis] + q as f32 * self.scale(axis);
        let lo = std::array::from_fn(|a| d(self.q_lo[a][slot], a));
        let hi = std::array::from_fn(|a| d(self.q_hi[a][slot], a));
        (lo, hi)
    }

    pub fn is_interior(&self, slot: usize) -> bool {
        self.imask & (1 << slot) != 0
    }

    /// Slots that hold a child.
    pub fn valid(&self) -> u32 {
        (0..8).filter(|&s| self.meta[s] != 0).fold(0, |m, s| m | 1 << s)
    }

    /// The index of the interior child in `slot`.
    pub fn child(&self, slot: usize) -> u32 {
        self.child_base + (self.imask as u32 & ((1u32 << slot) - 1)).count_ones()
    }

    /// The leaf record of the leaf child in `slot`.
    pub fn leaf(&self, slot: usize) -> u32 {
        self.leaf_base + (self.meta[slot] & 0x1f) as u32
    }
}

/// A compressed wide BVH over one mesh, with its own copy of the triangles in leaf order.
#[derive(Clone, Debug)]
pub struct Cwbvh {
    /// Node 0 is the root.
    pub nodes: Vec<CwbvhNode>,
    /// Leaf records: (first triangle in leaf order, triangle count).
    pub leaves: Vec<[u32; 2]>,
    /// The tree's exact bounds: the walk's first box test (the nodes store their children's).
    pub root_bounds: Aabb,
    pub prim_ids: Vec<u32>,
    pub tris: Vec<[Vec3; 3]>,
    /// Levels of wide nodes below the root (what sizes the walk's stack).
    pub depth: u32,
}

/// The smallest allowed biased exponent: cells of 2^-100 keep every q·scale a normal float.
const E_MIN: i32 = 27;

/// The exponent byte of the smallest power-of-two cell with which `p + 255·cell` reaches `hi`
/// in single precision.
fn exponent(p: f32, hi: f32) -> u8 {
    let extent = (hi as f64 - p as f64).max(0.0);
    let mut e = if extent > 0.0 { ((extent / 255.0).log2().ceil() as i32 + 127).max(E_MIN) } else { E_MIN };
    while e < 254 && p + 255.0 * f32::from_bits((e as u32) << 23) < hi {
        e += 1;
    }
    e as u8
}

/// The quantised planes of `lo..hi` on a grid at `p` with cell `scale`: rounded outwards, then
/// moved until the decoded planes (`p + q·scale`, as the walk computes them) hold the box.
fn quantise(p: f32, scale: f32, lo: f32, hi: f32) -> (u8, u8) {
    let decode = |q: u32| p + q as f32 * scale;
    let mut q_lo = (((lo as f64 - p as f64) / scale as f64).floor().clamp(0.0, 255.0)) as u32;
    while q_lo > 0 && decode(q_lo) > lo {
        q_lo -= 1;
    }
    let mut q_hi = (((hi as f64 - p as f64) / scale as f64).ceil().clamp(0.0, 255.0)) as u32;
    while q_hi < 255 && decode(q_hi) < hi {
        q_hi += 1;
    }
    (q_lo as u8, q_hi as u8)
}

/// Ylitie et al. §3.1: child c goes to slot s so that rays whose direction has the signs of
/// octant s (bit k of s set: negative along axis k) meet it early. cost(c, s) is the offset of
/// c's centre from the node's centre along octant s's diagonal; the cheapest free pairs are
/// taken first.
fn assign_slots(node: &Aabb, children: &[Aabb]) -> [Option<usize>; 8] {
    let centre = node.center();
    let mut pairs = Vec::with_capacity(children.len() * 8);
    for (c, b) in children.iter().enumerate() {
        let d = b.center() - centre;
        for s in 0..8 {
            let sign = |k: usize| if s & (1 << k) != 0 { -1.0 } else { 1.0 };
            pairs.push((d.x * sign(0) + d.y * sign(1) + d.z * sign(2), c, s));
        }
    }
    // Stable: equal costs keep child order, then slot order, so the layout is deterministic.
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut slots, mut placed) = ([None; 8], vec![false; children.len()]);
    for (_, c, s) in pairs {
        if slots[s].is_none() && !placed[c] {
            slots[s] = Some(c);
            placed[c] = true;
        }
    }
    slots
}

impl Cwbvh {
    /// Collapse, place and quantise `bvh` (checked as the binary upload checks it).
    pub fn from_bvh(bvh: &Bvh) -> Result<Cwbvh, GpuError> {
        Self::build(bvh, &mut |_, _, _| {})
    }

    /// `from_bvh`, telling `placed(wide node, slot, binary node)` where each binary node went.
    fn build(bvh: &Bvh, placed: &mut dyn FnMut(usize, usize, usize)) -> Result<Cwbvh, GpuError> {
        crate::binary::checked_depth(bvh)?;
        let b = &bvh.nodes;
        let root_bounds = if bvh.prim_ids.is_empty() { Aabb::EMPTY } else { b[0].bounds() };
        let mut out = Cwbvh {
            nodes: Vec::new(),
            leaves: Vec::new(),
            root_bounds,
            prim_ids: bvh.prim_ids.clone(),
            tris: bvh.tris.clone(),
            depth: 0,
        };
        if bvh.prim_ids.is_empty() {
            out.nodes.push(CwbvhNode::zeroed());
            return Ok(out);
        }
        // (wide node index, its binary node or, for a leaf root, the leaf itself, its level).
        let plan = CollapsePlan::of::<8>(b);
        let mut queue = std::collections::VecDeque::from([(0usize, 0usize, 0u32)]);
        out.nodes.push(CwbvhNode::zeroed());
        while let Some((w, i, level)) = queue.pop_front() {
            out.depth = out.depth.max(level);
            let kids = if b[i].is_leaf() {
                vec![i]
            } else {
                let (kids, n) = plan.children::<8>(b, i);
                kids[..n].to_vec()
            };
            let boxes: Vec<Aabb> = kids.iter().map(|&k| b[k].bounds()).collect();
            let node_box = Aabb::of(boxes.iter().copied());
            let slots = assign_slots(&node_box, &boxes);
            let (lo, hi) = node_box.planes();
            let mut n = CwbvhNode {
                p: lo,
                child_base: out.nodes.len() as u32,
                leaf_base: out.leaves.len() as u32,
                ..CwbvhNode::zeroed()
            };
            for axis in 0..3 {
                n.e[axis] = exponent(lo[axis], hi[axis]);
            }
            for (s, c) in slots.iter().enumerate() {
                let Some(c) = *c else { continue };
                let (clo, chi) = boxes[c].planes();
                for axis in 0..3 {
                    (n.q_lo[axis][s], n.q_hi[axis][s]) = quantise(lo[axis], n.scale(axis), clo[axis], chi[axis]);
                }
                let child = &b[kids[c]];
                placed(w, s, kids[c]);
                if child.is_leaf() {
                    n.meta[s] = META_LEAF | (out.leaves.len() as u32 - n.leaf_base) as u8;
                    out.leaves.push([child.index, child.count as u32]);
                } else {
                    n.meta[s] = META_INTERIOR | s as u8;
                    n.imask |= 1 << s;
                    let index = out.nodes.len();
                    out.nodes.push(CwbvhNode::zeroed());
                    queue.push_back((index, kids[c], level + 1));
                }
            }
            out.nodes[w] = n;
        }
        Ok(out)
    }

    /// Bytes the walk reads from: nodes, leaf records, primitive ids and triangles.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * 80 + self.leaves.len() * 8 + self.prim_ids.len() * 4 + self.tris.len() * 36
    }
}

use bytemuck::Zeroable;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantised_planes_hold_the_box_they_stand_for() {
        for &(p, hi) in &[(0.0f32, 1.0f32), (-3.7, 12.25), (1e6, 1e6 + 3.0), (0.1, 0.1), (-1e-3, 5e-4)] {
            let e = exponent(p, hi);
            let scale = f32::from_bits((e as u32) << 23);
            assert!(p + 255.0 * scale >= hi);
            assert!(e as i32 == E_MIN || p + 255.0 * (scale * 0.5) < hi, "the smallest cell that reaches");
            for k in 0..50 {
                let a = p + (hi - p) * (k as f32 / 50.0);
                let b = a + (hi - a) * 0.37;
                let (ql, qh) = quantise(p, scale, a, b);
                assert!(p + ql as f32 * scale <= a && p + qh as f32 * scale >= b, "{p} {hi}: {a}..{b} -> {ql}..{qh}");
            }
        }
    }

    /// Every decoded slot box holds the box of the binary node placed there, for every strategy and
    /// leaf size; a leaf slot names the binary leaf's own triangles.
    #[test]
    fn decoded_boxes_hold_the_binary_boxes_they_stand_for() {
        use bvhscope_core::bvh::{BuildParams, Layout, Strategy};
        let mesh = bvhscope_core::mesh::generate::torus_knot(2, 3, 0.3, 96, 8);
        for strategy in [Strategy::Midpoint, Strategy::SahBinned, Strategy::Lbvh, Strategy::Ploc, Strategy::Sbvh] {
            for max_leaf_size in [1, 4, 12] {
                let params = BuildParams { strategy, max_leaf_size, layout: Layout::Binary, ..BuildParams::default() };
                let bvh = Bvh::build(&mesh, &params);
                let mut places = Vec::new();
                let w = Cwbvh::build(&bvh, &mut |w, s, b| places.push((w, s, b))).unwrap();
                assert_eq!(places.len(), w.nodes.len() - 1 + w.leaves.len(), "every child placed once");
                for (i, s, b) in places {
                    let n = &w.nodes[i];
                    let (lo, hi) = n.child_box(s);
                    let decoded = Aabb::new(Vec3::from_array(lo), Vec3::from_array(hi));
                    assert!(decoded.contains_box(&bvh.nodes[b].bounds()), "{strategy:?}: node {i} slot {s}");
                    assert_eq!(n.is_interior(s), !bvh.nodes[b].is_leaf());
                    if bvh.nodes[b].is_leaf() {
                        assert_eq!(w.leaves[n.leaf(s) as usize], [bvh.nodes[b].index, bvh.nodes[b].count as u32]);
                    }
                }
            }
        }
    }

    #[test]
    fn each_child_goes_to_the_octant_that_meets_it_first() {
        let node = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        // The child at -x,-y,-z is met first by rays going +x,+y,+z: octant 0.
        let kids = [Aabb::new(Vec3::splat(-1.0), Vec3::splat(-0.5)), Aabb::new(Vec3::splat(0.5), Vec3::splat(1.0))];
        let slots = assign_slots(&node, &kids);
        assert_eq!(slots[0], Some(0));
        assert_eq!(slots[7], Some(1));
        assert_eq!(slots.iter().flatten().count(), 2);
    }
}
