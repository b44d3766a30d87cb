//! What a split strategy is (`Splitter`), what it is given (`BuildPrim`, `NodeInfo`) and what it proposes (`Proposal`); the partition every splitter shares.

use crate::geometry::Aabb;
use glam::{Vec3A, Vec4};

/// The largest bin count the binned SAH accepts.
pub const fn sah_binned_max_bins() -> usize {
    crate::bvh::builders::split::sah_binned::MAX_BINS
}

/// A split strategy at work on one tree: it proposes a split of a node's primitives, partitioning
/// them, and owns the scratch memory it reuses from node to node (no allocation per node).
pub trait Splitter: Send {
    /// Whether the strategy prices its splits with the SAH (`Proposal::weighted`). Those are asked
    /// even about nodes small enough for a leaf; the others are asked only about nodes that must
    /// be split.
    fn prices_splits(&self) -> bool {
        false
    }

    /// Propose a split of `prims`, partitioned so the first `mid` go left.
    fn split(&mut self, prims: &mut [BuildPrim], node: &NodeInfo) -> Proposal;

    /// The two sides' references of the `Proposal::Cut` this splitter has just proposed (the
    /// driver's partition step takes them when it makes the cut).
    fn take_cut(&mut self) -> (Vec<BuildPrim>, Vec<BuildPrim>) {
        unreachable!("only a splitter that proposes cuts is asked for them")
    }
}

/// A triangle as the builder sees it: its bounds in SIMD registers' layout (a box union is two
/// instructions) and its index in the mesh, in 32 bytes: the index rides in the unused fourth lane
/// of the lower corner, because every build pass (bounds, binning, partition) streams these
/// records, and 48 bytes per record cost a third more memory traffic.
#[derive(Clone, Copy, Debug)]
pub struct BuildPrim {
    /// x, y, z: the lower corner; w: the index's bits.
    min_index: Vec4,
    max: Vec3A,
}

impl BuildPrim {
    pub fn new(bounds: Aabb, index: u32) -> Self {
        Self { min_index: bounds.min.extend(f32::from_bits(index)), max: bounds.max }
    }

    /// The lower corner. glam leaves a `Vec3A`'s fourth lane unspecified, so this is free.
    #[inline(always)]
    pub fn min(&self) -> Vec3A {
        Vec3A::from_vec4(self.min_index)
    }

    #[inline(always)]
    pub fn max(&self) -> Vec3A {
        self.max
    }

    /// The triangle's index in the mesh.
    #[inline(always)]
    pub fn index(&self) -> u32 {
        self.min_index.w.to_bits()
    }

    /// Centre of the bounds (what the strategies split on).
    #[inline(always)]
    pub fn centroid(&self) -> Vec3A {
        (self.min() + self.max) * 0.5
    }

    #[inline(always)]
    pub fn bounds(&self) -> Aabb {
        Aabb { min: self.min(), max: self.max }
    }
}

/// What the builder knows about the node being split.
#[derive(Clone, Copy, Debug)]
pub struct NodeInfo {
    pub bounds: Aabb,
    pub centroid_bounds: Aabb,
    /// The duplicates a split here may add (`Proposal::Cut`): the SBVH's budget; 0 in a build
    /// whose primitives are partitioned in place.
    pub budget: u64,
}

/// A strategy's answer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Proposal {
    /// `prims[..mid]` go left: those whose centroid on `axis` lies below `plane` (for equal count,
    /// the median centroid, with ties split by index). `weighted`: for a strategy that prices its
    /// split with the SAH, the sum A_L·n_L + A_R·n_R of the two sides (the driver compares it
    /// with a leaf's cost).
    Split { axis: u8, mid: usize, weighted: Option<f32>, plane: f32 },
    /// A spatial split at `plane` on `axis`: each primitive goes to the side it lies on, and one
    /// that straddles the plane to both, each with the box of its part there (the SBVH's;
    /// proposed only within `NodeInfo::budget`). The splitter made the two sides' references
    /// already (`Splitter::take_cut`); `weighted` is A_L·n_L + A_R·n_R of those.
    Cut { axis: u8, plane: f32, weighted: f32 },
    /// No useful split (midpoint with one side empty, coincident centroids). The driver makes a
    /// leaf if the triangles fit in one, else splits by equal count and counts it in the statistics.
    None,
}

/// What a pricing strategy evaluated at a node, plane by plane: the node inspector's cost curves
/// come from the very loops that choose the split, through this sink; the build passes `()`,
/// whose `ACTIVE = false` compiles the reports away.
pub trait PlaneSink {
    const ACTIVE: bool = true;
    /// A candidate plane at `position` on `axis`, with `left` and `right` triangles on its sides,
    /// `weighted` = A_L·n_L + A_R·n_R, and `areas` = [A_L, A_R] (what a student checks the cost
    /// against, term by term).
    fn plane(&mut self, axis: usize, position: f32, left: u32, right: u32, weighted: f32, areas: [f32; 2]);
}

/// Whether `sink` records (a constant: the build's `()` compiles the reports away).
#[inline(always)]
pub(crate) fn is_active<P: PlaneSink>(_: &P) -> bool {
    P::ACTIVE
}

impl PlaneSink for () {
    const ACTIVE: bool = false;
    #[inline(always)]
    fn plane(&mut self, _: usize, _: f32, _: u32, _: u32, _: f32, _: [f32; 2]) {}
}

/// Move the elements satisfying `left` to the front; returns how many there are. Unstable; big
/// slices (the top of the tree) are partitioned in parallel, in an order that does not depend on
/// the thread count (`crate::parallel::partition`).
#[inline]
pub(crate) fn partition<T: Copy + Send + Sync>(items: &mut [T], left: impl Fn(&T) -> bool + Sync) -> usize {
    crate::parallel::partition(items, left)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_build_prim_keeps_its_bounds_and_any_index() {
        let b = Aabb::new(glam::Vec3::new(-1.0, 2.0, -3.5), glam::Vec3::new(4.0, 2.5, 0.0));
        // Includes bit patterns that are NaNs or denormals as floats.
        for index in [0, 1, 7, 1 << 23, 0x7F80_0001, 0xFFC0_0000, u32::MAX] {
            let p = BuildPrim::new(b, index);
            assert_eq!(p.index(), index);
            assert_eq!(p.bounds(), b);
            assert_eq!(glam::Vec3::from(p.centroid()), b.center());
        }
        assert_eq!(std::mem::size_of::<BuildPrim>(), 32);
    }

    #[test]
    fn partition_moves_matching_items_first() {
        let original = vec![5, 1, 8, 2, 9, 3, 7, 4, 4, 6];
        let mut v = original.clone();
        let k = partition(&mut v, |&x| x < 5);
        assert_eq!(k, 5);
        assert!(v[..k].iter().all(|&x| x < 5) && v[k..].iter().all(|&x| x >= 5));
        let (mut sorted, mut expected) = (v.clone(), original);
        sorted.sort();
        expected.sort();
        assert_eq!(sorted, expected, "a permutation: nothing lost or duplicated");
        let mut e: Vec<i32> = vec![];
        assert_eq!(partition(&mut e, |_| true), 0);
        let mut all = vec![1, 2];
        assert_eq!(partition(&mut all, |_| true), 2);
        assert_eq!(partition(&mut all, |_| false), 0);
    }
}
