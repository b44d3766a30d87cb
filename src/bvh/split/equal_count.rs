//! Equal-count split: the median centroid on the widest axis, found by selection in O(n) rather
//! than a full sort (pbrt-v4 §7.3.1, "SplitMethod::EqualCounts"). Always splits, so it is also the
//! driver's fallback when another strategy cannot.

use super::{BuildPrim, NodeInfo, SplitDecision};

pub fn split_equal_count(prims: &mut [BuildPrim], node: &NodeInfo) -> SplitDecision {
    let axis = node.centroid_bounds.widest_axis();
    let mid = prims.len() / 2;
    // Ties broken by index so the result does not depend on the input order's accidents.
    prims.select_nth_unstable_by(mid, |a, b| {
        a.centroid()[axis].total_cmp(&b.centroid()[axis]).then(a.index().cmp(&b.index()))
    });
    SplitDecision::Split { axis: axis as u8, mid }
}
