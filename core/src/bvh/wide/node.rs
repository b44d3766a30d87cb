//! A node of the wide BVH: up to `W` child boxes in SoA order, tested together by one SIMD slab test.

use crate::geometry::slab::Boxes;
use crate::geometry::Aabb;

/// The width of the 4-wide layout (the app's default), and of the imported trees.
pub const WIDTH: usize = 4;

/// Children boxes in SoA order (`boxes`), then per slot: a child node index (interior,
/// `count == 0`) or the first triangle of a leaf (`count > 0`). Empty slots have an inverted box
/// (+inf..-inf), which every slab test misses, and are clear in `valid`. Cache-line aligned: 128
/// bytes for four children, 256 for eight (Embree's uncompressed BVH8 node is 256 bytes too).
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WideNode<const W: usize = WIDTH> {
    pub boxes: Boxes<W>,
    pub child: [u32; W],
    pub count: [u8; W],
    /// Bit k set when slot k holds a child.
    pub valid: u8,
}

const _: () = assert!(std::mem::size_of::<WideNode<4>>() == 128);

const _: () = assert!(std::mem::size_of::<WideNode<8>>() == 256);

impl<const W: usize> WideNode<W> {
    pub const EMPTY: Self = Self { boxes: Boxes::EMPTY, child: [u32::MAX; W], count: [0; W], valid: 0 };

    pub(crate) fn set(&mut self, slot: usize, b: Aabb, child: u32, count: u8) {
        let (lo, hi) = b.planes();
        self.boxes.set(slot, lo, hi);
        self.child[slot] = child;
        self.count[slot] = count;
        self.valid |= 1 << slot;
    }

    pub fn slot_bounds(&self, slot: usize) -> Aabb {
        self.boxes.bounds(slot)
    }

    /// Slot `slot`'s box as its `(min, max)` planes per axis.
    pub fn slot_planes(&self, slot: usize) -> ([f32; 3], [f32; 3]) {
        self.boxes.planes(slot)
    }

    pub fn slots(&self) -> impl Iterator<Item = usize> + '_ {
        (0..W).filter(|k| self.valid & (1 << k) != 0)
    }
}
