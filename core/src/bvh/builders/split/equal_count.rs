//! Equal-count split: the median centroid on the widest axis, found by selection in O(n) rather
//! than a full sort (pbrt-v4 §7.3.1, "SplitMethod::EqualCounts"). Always splits, so it is also the
//! driver's fallback when another strategy cannot.

use super::{BuildPrim, NodeInfo, Proposal, Splitter};

pub struct EqualCount;

impl EqualCount {
    /// The median split of `prims` (two or more): the axis and the partition point.
    pub fn median(prims: &mut [BuildPrim], node: &NodeInfo) -> (u8, usize) {
        let axis = node.centroid_bounds.widest_axis();
        let mid = prims.len() / 2;
        // Ties broken by index so the result does not depend on the input order's accidents.
        prims.select_nth_unstable_by(mid, |a, b| {
            a.centroid()[axis].total_cmp(&b.centroid()[axis]).then(a.index().cmp(&b.index()))
        });
        (axis as u8, mid)
    }
}

impl Splitter for EqualCount {
    fn split(&mut self, prims: &mut [BuildPrim], node: &NodeInfo) -> Proposal {
        let (axis, mid) = Self::median(prims, node);
        let plane = prims[mid].centroid()[axis as usize];
        Proposal::Split { axis, mid, weighted: None, plane }
    }
}
