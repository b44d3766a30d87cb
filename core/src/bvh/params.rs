//! What a build is asked for and what it reports: the strategy and its numbers (every one described
//! for users in `crate::options`), the SAH's constants, the layout, and the report of the phases.

use super::split::SplitStrategy;
use crate::options::{MAX_LEAF_SIZE, PLOC_RADIUS, REINSERT_PASSES, SAH_BINS, SBVH_ALPHA, SBVH_GROWTH, TRAVERSAL_COST};
use std::time::Duration;

/// Cost constants of the surface area heuristic (Goldsmith & Salmon 1987; MacDonald & Booth 1990).
/// The defaults, 1 and 1, make the normalised SAH cost of a tree read as "expected traversal steps
/// plus triangle tests per ray that hits the root box". They are parameters because the right
/// ratio depends on the traversal code; the builder and the statistics use the same values.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SahCost {
    /// Cost of visiting an interior node (one step: two child box tests).
    pub traversal: f32,
    /// Cost of one ray–triangle test.
    pub intersection: f32,
}

impl SahCost {
    /// Bottom-up leaf gathering (PLOC's layout, reinsertion's collapse): a subtree over `count`
    /// triangles in a box of `area`, whose two children cost `children` (their SAH costs summed,
    /// in area units), costs the cheaper of a leaf (C_isect·n·A, only when `count` fits a leaf of
    /// `max_leaf`) and a split (C_trav·A + children). Returns the cost and whether it is a leaf.
    pub(super) fn leaf_or_split(&self, area: f64, count: u32, children: f64, max_leaf: u32) -> (f64, bool) {
        let split = self.traversal as f64 * area + children;
        let as_leaf = self.intersection as f64 * count as f64 * area;
        if count <= max_leaf && as_leaf <= split {
            (as_leaf, true)
        } else {
            (split, false)
        }
    }
}

impl Default for SahCost {
    fn default() -> Self {
        Self { traversal: TRAVERSAL_COST.default, intersection: 1.0 }
    }
}

/// How the built tree is laid out for traversal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Layout {
    /// The binary BVH as built: two children per node, the handout's structure.
    Binary,
    /// The binary BVH collapsed into 4-wide nodes traversed with SIMD box tests (`bvh::wide`).
    #[default]
    Wide4,
    /// Collapsed into 8-wide nodes: eight child boxes in one AVX2 pass where the CPU has it
    /// (`crate::cpu`), two passes of four elsewhere.
    Wide8,
}

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct BuildParams {
    pub strategy: SplitStrategy,
    /// Most triangles in a leaf (default 4). The SAH strategies may stop earlier when a leaf is
    /// cheaper than a split; no strategy makes a larger leaf.
    pub max_leaf_size: u32,
    /// Bins per axis for `SahBinned` (default 16); nodes of fewer than three triangles per bin
    /// use n/3 bins (at least 4, never more than asked for).
    pub sah_bins: u32,
    pub cost: SahCost,
    pub layout: Layout,
    /// PLOC's neighbour search: clusters each side in Morton order (default 16).
    pub ploc_radius: u32,
    /// Passes of reinsertion after the build (`bvh::reinsert`; 0, the default: none).
    pub reinsert_passes: u32,
    /// SBVH: spatial splits are priced where the object split's children share more than this
    /// fraction of the root's surface area (Stich et al.'s α; default 1e-5).
    pub sbvh_alpha: f32,
    /// SBVH: at most this many percent more references than triangles (default 30).
    pub sbvh_growth: u32,
}

impl Default for BuildParams {
    fn default() -> Self {
        Self {
            strategy: SplitStrategy::SahBinned,
            max_leaf_size: MAX_LEAF_SIZE.default,
            sah_bins: SAH_BINS.default,
            cost: SahCost::default(),
            layout: Layout::default(),
            ploc_radius: PLOC_RADIUS.default,
            reinsert_passes: REINSERT_PASSES.default,
            sbvh_alpha: SBVH_ALPHA.default,
            sbvh_growth: SBVH_GROWTH.default,
        }
    }
}

impl BuildParams {
    pub fn with_strategy(strategy: SplitStrategy) -> Self {
        Self { strategy, ..Self::default() }
    }
}

/// What the build did and how long each phase took.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct BuildReport {
    /// Triangle bounds and centroids.
    pub setup_time: Duration,
    /// The top-down splitting.
    pub split_time: Duration,
    /// Copying triangles into leaf order.
    pub reorder_time: Duration,
    /// Collapsing the binary tree into wide nodes (wide layout only).
    pub collapse_time: Duration,
    /// Nodes where the strategy found no useful split (midpoint with an empty side, SAH with
    /// coincident centroids) and an equal-count split was used instead.
    pub fallback_splits: u32,
    /// Nodes split by equal count because they were deeper than `HEURISTIC_DEPTH_LIMIT`.
    pub depth_limited_splits: u32,
    /// SBVH: nodes split by a spatial split (the others by object splits).
    pub spatial_splits: u32,
    /// The reinsertion pass after the build, when asked for (`BuildParams::reinsert_passes`).
    pub reinsertion: Option<super::reinsert::Reinsertion>,
}

impl BuildReport {
    pub fn total_time(&self) -> Duration {
        let optimise = self.reinsertion.map_or(Duration::ZERO, |r| r.time);
        self.setup_time + self.split_time + self.reorder_time + self.collapse_time + optimise
    }
}

impl BuildParams {
    /// The parameters with every field in the range the builder accepts.
    pub(super) fn clamped(&self) -> BuildParams {
        BuildParams {
            max_leaf_size: MAX_LEAF_SIZE.clamp(self.max_leaf_size),
            sah_bins: SAH_BINS.clamp(self.sah_bins),
            ploc_radius: PLOC_RADIUS.clamp(self.ploc_radius),
            reinsert_passes: REINSERT_PASSES.clamp(self.reinsert_passes),
            sbvh_alpha: SBVH_ALPHA.clamp(self.sbvh_alpha),
            sbvh_growth: SBVH_GROWTH.clamp(self.sbvh_growth),
            cost: SahCost { traversal: TRAVERSAL_COST.clamp(self.cost.traversal), ..self.cost },
            ..*self
        }
    }
}
