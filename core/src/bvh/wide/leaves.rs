//! The wide layouts' leaves, stored for the SIMD leaf tests: a leaf of `c` triangles
//! keeps its 36·c bytes in the triangle array, but coordinate by coordinate — the `c` values of v0.x,
//! then of v0.y, …, then of v2.z — so the test's nine lanes of a group of four (or eight) are nine
//! plain loads instead of thirty-six (seventy-two) gathered floats. No padding: memory is the same as the other layouts'.
//! Everything else that reads a leaf's triangles (the one-at-a-time test, packets, checks) goes
//! through `with_leaf`, which hands it the triangles in leaf order, as the other layouts store them.

use crate::bvh::wide::wide_bvh::WideBvh;
use crate::geometry::leaf_triangle;
use glam::Vec3;
use rayon::prelude::*;

const _: () = assert!(std::mem::size_of::<[Vec3; 3]>() == 36, "nine floats per triangle, no padding");

/// The triangles' floats as one slice, nine per triangle.
#[inline(always)]
pub(crate) fn floats(tris: &[[Vec3; 3]]) -> &[f32] {
    // SAFETY: `Vec3` is `repr(C)` of three `f32`s (asserted above: 36 bytes per triangle), so the
    // array is `9 · len` floats, aligned for `f32`.
    unsafe { std::slice::from_raw_parts(tris.as_ptr().cast::<f32>(), tris.len() * 9) }
}

fn floats_mut(tris: &mut [[Vec3; 3]]) -> &mut [f32] {
    // SAFETY: as in `floats`, with the unique borrow of `tris`.
    unsafe { std::slice::from_raw_parts_mut(tris.as_mut_ptr().cast::<f32>(), tris.len() * 9) }
}

impl<const W: usize> WideBvh<W> {
    /// Rewrite every leaf's triangles coordinate by coordinate (done once, after the collapse or an
    /// import).
    pub(crate) fn store_leaves_by_coordinate(&mut self) {
        // The leaves tile the array: each slot's count at its leaf's first triangle, then the array
        // cut into the leaves' floats in one pass, and the leaves transposed on all threads.
        let mut count_at = vec![0u8; self.tris.len()];
        for n in &self.nodes {
            for s in n.slots().filter(|&s| n.count[s] > 0) {
                count_at[n.child[s] as usize] = n.count[s];
            }
        }
        let mut rest = floats_mut(&mut self.tris);
        let mut parts = Vec::new();
        let mut i = 0;
        while i < count_at.len() {
            let count = count_at[i] as usize;
            if count == 0 {
                // Not a leaf's first triangle: cannot happen in a tiled array, but stay in step.
                rest = &mut std::mem::take(&mut rest)[9..];
                i += 1;
                continue;
            }
            let (leaf, tail) = std::mem::take(&mut rest).split_at_mut(9 * count);
            parts.push((leaf, count));
            rest = tail;
            i += count;
        }
        parts.into_par_iter().for_each(|(leaf, count)| {
            let mut aos = [0f32; 9 * 16];
            let aos: &mut [f32] = if count <= 16 { &mut aos[..9 * count] } else { &mut vec![0f32; 9 * count] };
            aos.copy_from_slice(leaf);
            for k in 0..count {
                for j in 0..9 {
                    leaf[j * count + k] = aos[9 * k + j];
                }
            }
        });
    }

    /// Whether a walk with `opts` reads the stored leaves: the stored-edges test on a SIMD walk
    /// (the scalar kernel tests the triangles from their vertices).
    fn walks_stored(&self, opts: crate::bvh::TraceOptions) -> bool {
        opts.test == crate::geometry::TriangleTest::MollerTrumboreStored && self.simd != crate::cpu::Simd::Scalar
    }

    /// Make the stored leaves now if a walk with `opts` reads them (`AnyBvh::ready_for`).
    pub(crate) fn ready_for(&self, opts: crate::bvh::TraceOptions) {
        if self.walks_stored(opts) {
            let _ = self.stored_leaves();
        }
    }

    /// The stored leaves' bytes if a walk with `opts` reads them, made yet or not (`STORED_FLOATS`
    /// floats a triangle), else 0.
    pub(crate) fn walk_bytes(&self, opts: crate::bvh::TraceOptions) -> usize {
        let per = crate::geometry::stored_triangle::STORED_FLOATS * std::mem::size_of::<f32>();
        if self.walks_stored(opts) {
            self.tris.len() * per
        } else {
            0
        }
    }

    /// The leaves in the stored form of `MollerTrumboreStored` (`geometry::stored_triangle`): each
    /// leaf's triangles as v0, e1, e2 and the normal, coordinate by coordinate (the `count` values
    /// of v0.x, then of v0.y, …, of ng.z), twelve floats a triangle from its first triangle's
    /// place. Made on the first walk that asks for it (that test on this tree), then kept: 48 more
    /// bytes a triangle, paid only by a tree walked with that test.
    pub(crate) fn stored_leaves(&self) -> &[f32] {
        self.stored.get_or_init(|| {
            const F: usize = crate::geometry::stored_triangle::STORED_FLOATS;
            let mut out = vec![0f32; F * self.tris.len()];
            for n in &self.nodes {
                for s in n.slots().filter(|&s| n.count[s] > 0) {
                    let (first, count) = (n.child[s] as usize, n.count[s] as usize);
                    let leaf = &mut out[F * first..F * (first + count)];
                    self.with_leaf(first, count, |tris| {
                        for (k, t) in tris.iter().enumerate() {
                            let form = crate::geometry::stored_form(t);
                            for j in 0..F {
                                leaf[j * count + k] = form[j / 3][j % 3];
                            }
                        }
                    });
                }
            }
            out
        })
    }

    /// The `9·count` floats of the leaf at `first`, coordinate by coordinate.
    #[inline(always)]
    pub(crate) fn leaf_coords(&self, first: usize, count: usize) -> &[f32] {
        &floats(&self.tris)[9 * first..9 * (first + count)]
    }

    /// `f` of the leaf's triangles in leaf order, whatever this layout stores.
    #[inline(always)]
    pub(crate) fn with_leaf<R>(&self, first: usize, count: usize, f: impl FnOnce(&[[Vec3; 3]]) -> R) -> R {
        let coords = self.leaf_coords(first, count);
        if count <= 16 {
            let mut buf = [[Vec3::ZERO; 3]; 16];
            for (k, t) in buf[..count].iter_mut().enumerate() {
                *t = leaf_triangle(coords, count, k);
            }
            f(&buf[..count])
        } else {
            f(&(0..count).map(|k| leaf_triangle(coords, count, k)).collect::<Vec<_>>())
        }
    }

    /// Every triangle in leaf order, as the binary layout stores them (for checks).
    pub fn leaf_order_triangles(&self) -> Vec<[Vec3; 3]> {
        let mut out = self.tris.clone();
        for n in &self.nodes {
            for s in n.slots().filter(|&s| n.count[s] > 0) {
                let (first, count) = (n.child[s] as usize, n.count[s] as usize);
                self.with_leaf(first, count, |t| out[first..first + count].copy_from_slice(t));
            }
        }
        out
    }
}
