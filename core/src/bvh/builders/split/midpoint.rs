//! Midpoint split: cut the widest axis of the centroid bounds at its middle (pbrt-v4 §7.3.1,
//! "SplitMethod::Middle"; the handout's first BVH). When all centroids fall on one side the cut is
//! useless, and the driver falls back to an equal-count split.

use crate::bvh::builders::split::splitter::{partition, BuildPrim, NodeInfo, Proposal, Splitter};

pub struct Midpoint;

impl Splitter for Midpoint {
    fn split(&mut self, prims: &mut [BuildPrim], node: &NodeInfo) -> Proposal {
        let axis = node.centroid_bounds.widest_axis();
        let pivot = node.centroid_bounds.center()[axis];
        let mid = partition(prims, |p| p.centroid()[axis] < pivot);
        if mid == 0 || mid == prims.len() {
            Proposal::None
        } else {
            Proposal::Split { axis: axis as u8, mid, weighted: None, plane: pivot }
        }
    }
}
