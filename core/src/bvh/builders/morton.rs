//! Morton order: Morton, "A Computer Oriented Geodetic Data Base and a New Technique in File
//! Sequencing" (IBM 1966). Each primitive's centroid gets a 30-bit code, 10 bits per axis of the
//! grid over the centroids' bounds, interleaved x, y, z from the top; sorting by code lays the
//! primitives along a space-filling curve, and a range of sorted codes splits where its highest
//! differing bit flips (an axis-aligned plane of the grid). The LBVH is built from the sort alone,
//! PLOC starts from it, and the build replay draws the curve (`MortonOrder`).

use crate::bvh::builders::split::splitter::BuildPrim;
use crate::bvh::node::Bvh;
use crate::geometry::Aabb;
use glam::Vec3A;
use rayon::prelude::*;

/// Bits per axis of the 30-bit code.
pub(crate) const BITS: u32 = 10;

/// Spread the low 21 bits of `v` so that bit i lands on bit 3i (the code uses the low `BITS`).
fn spread(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// The Morton code of point `p` in the grid over `lo` with `scale` cells per unit.
pub(super) fn morton(p: Vec3A, lo: Vec3A, scale: Vec3A) -> u64 {
    let max = ((1u32 << BITS) - 1) as f32;
    let q = ((p - lo) * scale).clamp(Vec3A::ZERO, Vec3A::splat(max));
    spread(q.x as u64) << 2 | spread(q.y as u64) << 1 | spread(q.z as u64)
}

/// The axis a code bit belongs to (x on bits 3i + 2, y on 3i + 1, z on 3i).
fn axis_of(bit: u32) -> u8 {
    2 - (bit % 3) as u8
}

/// A sort record: the code in the high half, where the primitive was in the low half (8 bytes:
/// half the memory traffic of a 16-byte record in each of the sort's passes).
#[derive(Clone, Copy)]
pub(super) struct Keyed(pub(super) u64);

impl Keyed {
    pub(super) fn code(self) -> u64 {
        self.0 >> 32
    }
    pub(super) fn slot(self) -> usize {
        self.0 as u32 as usize
    }
}

impl rdst::RadixKey for Keyed {
    /// Only the code's bytes are sorted on (`in_triangle_order` then orders equal codes).
    const LEVELS: usize = 4;
    #[inline]
    fn get_level(&self, level: usize) -> u8 {
        (self.0 >> (32 + level * 8)) as u8
    }
}

/// Records sorted by code, with each run of equal codes put in triangle (slot) order. The radix
/// sort is unstable and multi-threaded: on its own it left equal codes in an order that could
/// change with the thread count, and the tree with it. With this the tree is the same on any
/// machine, and it is the GPU's LBVH's (a stable sort) node for node. Sorting on all eight bytes
/// instead did the same at 15 % more build time on a 2M-triangle mesh; runs of equal codes are
/// short, so this pass costs little next to the sort.
pub(super) fn in_triangle_order(keyed: &mut [Keyed]) {
    keyed.par_chunk_by_mut(|a, b| a.code() == b.code()).for_each(|run| {
        if run.len() > 1 {
            run.sort_unstable_by_key(|k| k.0);
        }
    });
}

/// Where a range of sorted codes is split, and on which axis: `None` when all codes are equal.
pub(super) fn split_of(codes: &[u64]) -> Option<(usize, u8)> {
    let (a, b) = (codes[0], codes[codes.len() - 1]);
    if a == b {
        return None;
    }
    let bit = 63 - (a ^ b).leading_zeros();
    let mask = 1u64 << bit;
    // The codes share every bit above `bit`: those without it come first.
    Some((codes.partition_point(|c| c & mask == 0), axis_of(bit)))
}

/// Where a range of equal codes is split: Karras's tie-break (HPG 2012, §4), which takes a
/// primitive's place in the sorted order as the rest of its key, so the range `first..first +
/// len` of sorted places splits where the highest bit in which its first and last places differ
/// flips. The tree over a run of equal codes is then the radix tree of their places, which the
/// GPU's LBVH builds in parallel, node by node, as it builds the rest (a cut in the middle needed
/// one invocation to walk the whole run, and a run of 5,000 identical triangles passed the
/// driver's loop limit). The split within the range: at least 1, at most `len - 1`.
pub(super) fn tie_split(first: usize, len: usize) -> usize {
    debug_assert!(len >= 2);
    let (a, b) = (first as u64, (first + len - 1) as u64);
    let bit = 63 - (a ^ b).leading_zeros();
    ((b >> bit << bit) - a) as usize
}

/// Sort `prims` by the Morton codes of their centroids in the grid over the centroid bounds;
/// the codes in that order.
pub(super) fn sort(prims: &mut Vec<BuildPrim>) -> Vec<u64> {
    // Every step splits the records among the threads (rdst's radix sort too): one parallel
    // region for issue 37's serial fraction.
    crate::parallel::region(|| {
        let (lo, scale) = grid(prims.par_iter().map(|p| p.centroid()));
        let mut keyed: Vec<Keyed> = prims
            .par_iter()
            .with_min_len(4096)
            .enumerate()
            .map(|(i, p)| Keyed(morton(p.centroid(), lo, scale) << 32 | i as u64))
            .collect();
        rdst::RadixSort::radix_sort_unstable(&mut keyed);
        in_triangle_order(&mut keyed);
        // The sorted records replace the vector (a copy back into it cost a pass over all of them).
        *prims = keyed.par_iter().with_min_len(4096).map(|k| prims[k.slot()]).collect();
        keyed.par_iter().with_min_len(4096).map(|k| k.code()).collect()
    })
}

/// The Morton grid over the centroids' bounds: its lower corner and cells per unit.
pub(super) fn grid(centroids: impl rayon::iter::IndexedParallelIterator<Item = Vec3A>) -> (Vec3A, Vec3A) {
    let centroids =
        centroids.with_min_len(4096).fold(|| Aabb::EMPTY, |b, c| b.grow(c)).reduce(|| Aabb::EMPTY, |a, b| a.union(b));
    let extent = centroids.max - centroids.min;
    let cells = ((1u32 << BITS) - 1) as f32;
    (centroids.min, Vec3A::select(extent.cmpgt(Vec3A::ZERO), Vec3A::splat(cells) / extent, Vec3A::ZERO))
}

/// An LBVH tree's Morton order, for the build replay: its leaf order *is* the sort, so each leaf
/// slot's triangle centroid and code (computed again with the build's grid and `morton`), in slot
/// order, are the curve the build followed, and each split is where a bit of the codes flips.
pub struct MortonOrder {
    /// The triangle centroids in leaf order: the Morton curve.
    pub centroids: Vec<glam::Vec3>,
    /// Their codes (non-decreasing: `of` checks).
    pub codes: Vec<u64>,
    /// Running sums of the centroids (`sums[i]`: of slots `..i`), for `mean`.
    sums: Vec<glam::DVec3>,
}

/// Where the codes of a range split: the bit, its axis (0 = x) and its level of the grid (1 =
/// halves, 2 = quarters, … down to `BITS`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MortonSplit {
    pub bit: u32,
    pub axis: u8,
    pub level: u32,
    /// Slots before the flip (the left child's).
    pub left: u32,
}

impl MortonOrder {
    /// The order of an LBVH tree as built (`None` for other strategies, or after reinsertion,
    /// which moves subtrees out of Morton order).
    pub fn of(bvh: &Bvh) -> Option<MortonOrder> {
        if !bvh.params.strategy.follows_morton_order() || bvh.report.reinsertion.is_some() {
            return None;
        }
        let prims: Vec<BuildPrim> =
            bvh.tris.iter().zip(&bvh.prim_ids).map(|(t, &i)| BuildPrim::new(Aabb::from_points(t), i)).collect();
        let (lo, scale) = grid(prims.par_iter().map(|p| p.centroid()));
        let codes: Vec<u64> = prims.iter().map(|p| morton(p.centroid(), lo, scale)).collect();
        if !codes.windows(2).all(|w| w[0] <= w[1]) {
            return None;
        }
        let centroids: Vec<glam::Vec3> = prims.iter().map(|p| p.centroid().into()).collect();
        let mut sums = Vec::with_capacity(centroids.len() + 1);
        sums.push(glam::DVec3::ZERO);
        for c in &centroids {
            sums.push(*sums.last().expect("pushed above") + c.as_dvec3());
        }
        Some(MortonOrder { centroids, codes, sums })
    }

    /// The mean centroid of slots `first..first + count`: where a stretch of the curve (a node of
    /// the tree) sits, so the frontier's means in order are the curve at the replay's resolution.
    pub fn mean(&self, first: u32, count: u32) -> glam::Vec3 {
        let (a, b) = (first as usize, (first + count) as usize);
        ((self.sums[b] - self.sums[a]) / count.max(1) as f64).as_vec3()
    }

    /// How slots `first..first + count` split: at the highest bit where their codes differ
    /// (`None` when all are equal: the build then split the range by its places, `tie_split`).
    pub fn split(&self, first: u32, count: u32) -> Option<MortonSplit> {
        let codes = self.codes.get(first as usize..(first + count) as usize)?;
        let (mid, axis) = split_of(codes)?;
        let bit = 63 - (codes[0] ^ codes[codes.len() - 1]).leading_zeros();
        Some(MortonSplit { bit, axis, level: BITS - bit / 3, left: mid as u32 })
    }
}

#[cfg(test)]
mod morton_order_tests {
    use super::MortonOrder;
    use crate::bvh::hierarchy::Hierarchy;
    use crate::bvh::node::Bvh;
    use crate::bvh::params::Strategy;
    use crate::bvh::params::{BuildParams, Layout};
    use crate::mesh::generate;

    /// The leaf order of an LBVH tree is its Morton order, and every split of the tree (not a
    /// fallback) is where the order says: the left child holds the slots before the bit flips.
    #[test]
    fn an_lbvh_trees_leaf_order_is_its_morton_order_and_splits_follow_it() {
        let mesh = generate::torus_knot(2, 3, 0.3, 256, 12);
        let params = BuildParams { strategy: Strategy::Lbvh, layout: Layout::Binary, ..Default::default() };
        let bvh = Bvh::build(&mesh, &params);
        let order = MortonOrder::of(&bvh).expect("an LBVH tree");
        assert_eq!(order.centroids.len(), bvh.prim_ids.len());
        let h = Hierarchy::of(&bvh);
        let mut checked = 0;
        for (i, n) in bvh.nodes.iter().enumerate().filter(|(_, n)| !n.is_leaf()) {
            let s = order.split(h.first[i], h.count[i]).expect("distinct codes");
            assert_eq!((s.left, s.axis), (h.count[n.index as usize], n.axis), "node {i}");
            assert!(s.level >= 1 && s.level <= super::BITS);
            checked += 1;
        }
        assert!(checked > 1000);
        let sah = Bvh::build(&mesh, &BuildParams { layout: Layout::Binary, ..Default::default() });
        assert!(MortonOrder::of(&sah).is_none(), "other strategies have no Morton order");
        let reinserted = Bvh::build(&mesh, &BuildParams { reinsert_passes: 1, ..params });
        assert!(MortonOrder::of(&reinserted).is_none(), "nor has a tree reinsertion changed");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_interleave_x_y_z_from_the_top() {
        assert_eq!(spread(0b101), 0b1_000_001);
        assert_eq!(spread(0x1f_ffff).count_ones(), 21);
        let (lo, scale) = (Vec3A::ZERO, Vec3A::splat(((1u32 << BITS) - 1) as f32));
        // The far corner on x only sets x's bits: 3i + 2.
        let x = morton(Vec3A::new(1.0, 0.0, 0.0), lo, scale);
        assert_eq!(x, spread((1 << BITS) - 1) << 2);
        assert_eq!(axis_of(3 * BITS - 1), 0, "the top bit is x's");
        assert_eq!((axis_of(3 * BITS - 2), axis_of(3 * BITS - 3)), (1, 2));
    }

    #[test]
    fn a_range_splits_where_its_highest_differing_bit_flips() {
        let codes = [0b0001, 0b0011, 0b0100, 0b0110, 0b0111];
        assert_eq!(split_of(&codes).map(|s| s.0), Some(2), "bit 2 flips between 0b0011 and 0b0100");
        assert_eq!(split_of(&[5, 5, 5]), None);
        // Equal codes: by the highest bit of their places that flips (Karras's tie-break).
        assert_eq!(tie_split(0, 5000), 4096);
        assert_eq!(tie_split(4096, 904), 512, "places 4096..5000 split at 4608");
        assert_eq!(tie_split(6, 2), 1);
        assert_eq!(tie_split(7, 2), 1, "7 and 8 differ in bit 3");
        for first in 0..40 {
            for len in 2..40 {
                let m = tie_split(first, len);
                assert!((1..len).contains(&m), "{first} {len}: {m}");
            }
        }
    }
}
