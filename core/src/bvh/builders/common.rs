//! What every builder uses: the build's progress, a node's bounds, the SAH's leaf-or-split
//! comparison, the count of nodes where the driver overrode a strategy, and the depth past which
//! every builder splits by equal count.

use crate::bvh::builders::split::splitter::{BuildPrim, NodeInfo};
use crate::bvh::node::TRAVERSAL_STACK_SIZE;
use crate::bvh::params::BuildParams;
use crate::geometry::Aabb;
use crate::work::{Cancelled, WorkControl};
use rayon::prelude::*;

/// Below this depth the strategies choose splits; deeper, every builder splits by equal count:
/// each count halves the range, so the tree depth stays under `HEURISTIC_DEPTH_LIMIT + 32`, inside
/// the traversal stack's fixed part.
pub const HEURISTIC_DEPTH_LIMIT: u32 = (TRAVERSAL_STACK_SIZE as u32) - 33;

/// Ranges at least this long are bounded in parallel.
pub(crate) const PARALLEL_MIN_PRIMS: usize = 4096;

/// The work units of building over `n` primitives, the total a build's progress reaches.
///
/// Progress counts primitives partitioned at every level, not only primitives placed in leaves:
/// counting leaves alone left the progress at 0 % while the top levels were split, half of an
/// exact-sweep build of 2M triangles. A build over n primitives is taken to have
/// L = ⌈log2(n / max leaf size)⌉ + 1 levels, and each primitive is worth L units: one for each of
/// the first L levels it is partitioned at, and the levels it skips when it reaches a leaf
/// earlier. So the progress is exact at the end (n·L), moves with every split, and a tree deeper
/// than L (midpoint on uneven meshes) only spends its last levels at the full count.
pub fn build_work(n: usize, params: &BuildParams) -> u64 {
    n as u64 * progress_levels(n, params) as u64
}

pub(super) fn progress_levels(n: usize, params: &BuildParams) -> u32 {
    let leaf = params.clamped().max_leaf_size as usize;
    let leaves = n.div_ceil(leaf).max(1);
    leaves.next_power_of_two().trailing_zeros() + 1
}

/// The build's progress: a control and the levels its primitives are counted over.
pub(crate) struct Progress<'a> {
    pub(super) control: &'a WorkControl,
    pub(super) levels: u32,
}

impl<'a> Progress<'a> {
    #[cfg(test)]
    pub(crate) fn new(control: &'a WorkControl, levels: u32) -> Self {
        Progress { control, levels }
    }

    pub(crate) fn check(&self) -> Result<(), Cancelled> {
        self.control.check()
    }

    /// The units of a split of `n` primitives at `depth` (`split`), for a caller that adds many
    /// at once (`add`): one shared counter bumped per node costs a builder whose nodes are cheap.
    pub(crate) fn split_units(&self, n: usize, depth: u32) -> u64 {
        if depth < self.levels {
            n as u64
        } else {
            0
        }
    }

    /// The units of a leaf of `n` primitives at `depth` (`leaf`).
    pub(crate) fn leaf_units(&self, n: usize, depth: u32) -> u64 {
        n as u64 * self.levels.saturating_sub(depth) as u64
    }

    pub(crate) fn add(&self, units: u64) {
        self.control.add_done(units);
    }

    /// A node of `n` primitives at `depth` was partitioned.
    pub(crate) fn split(&self, n: usize, depth: u32) {
        if depth < self.levels {
            self.control.add_done(n as u64);
        }
    }

    /// A leaf of `n` primitives was made at `depth`: the levels its primitives will not pass.
    pub(crate) fn leaf(&self, n: usize, depth: u32) {
        self.control.add_done(n as u64 * self.levels.saturating_sub(depth) as u64);
    }
}

/// The node's bounds and centroid bounds (in parallel for big ranges).
pub(crate) fn node_info(prims: &[BuildPrim]) -> NodeInfo {
    const EMPTY: NodeInfo = NodeInfo { bounds: Aabb::EMPTY, centroid_bounds: Aabb::EMPTY, budget: 0 };
    let add = |i: NodeInfo, p: &BuildPrim| NodeInfo {
        bounds: i.bounds.union(p.bounds()),
        centroid_bounds: i.centroid_bounds.grow(p.centroid()),
        budget: 0,
    };
    let merge = |a: NodeInfo, b: NodeInfo| NodeInfo {
        bounds: a.bounds.union(b.bounds),
        centroid_bounds: a.centroid_bounds.union(b.centroid_bounds),
        budget: 0,
    };
    if prims.len() >= PARALLEL_MIN_PRIMS {
        crate::parallel::region(|| prims.par_chunks(4096).map(|c| c.iter().fold(EMPTY, add)).reduce(|| EMPTY, merge))
    } else {
        prims.iter().fold(EMPTY, add)
    }
}

/// Nodes where the driver overrode or replaced the strategy's answer, and the splits that cut
/// primitives (the SBVH's spatial splits).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Overrides {
    pub fallback: u32,
    pub depth_limited: u32,
    pub cut: u32,
}

impl std::ops::AddAssign for Overrides {
    fn add_assign(&mut self, o: Overrides) {
        self.fallback += o.fallback;
        self.depth_limited += o.depth_limited;
        self.cut += o.cut;
    }
}

/// The SAH's comparison of a leaf with the best split (Goldsmith & Salmon 1987; pbrt-v4 §7.3.2): a
/// leaf costs C_isect·n; the split costs C_trav + C_isect·(A_L·n_L + A_R·n_R)/A, where `weighted`
/// is the sum in parentheses.
pub(crate) fn leaf_is_cheaper(n: usize, weighted: f32, node: &NodeInfo, params: &BuildParams) -> bool {
    let split_cost = params.cost.traversal + params.cost.intersection * weighted / node.bounds.area();
    let leaf_cost = params.cost.intersection * n as f32;
    leaf_cost <= split_cost
}
