//! Named sets of build and traversal options, one choice in the app and `--preset` on the command
//! line.
//!
//! `Handout` is the BVH a student writes in the lab (the Moer-lite course's handout): a binary
//! tree split at the midpoint of the widest axis, the near child chosen by the ray's direction
//! sign on the split axis, the Möller–Trumbore triangle test, one level over the whole scene. Its
//! figures are the ones to compare with a student's own renderer; the handout leaves the leaf
//! size to the student, so the preset states the value it uses.
//!
//! `Fastest` is the tree bvhscope traces fastest on a CPU: binned SAH collapsed into 8-wide nodes
//! (eight boxes per AVX2 pass), leaves of up to four triangles tested in one SIMD pass, so the SAH
//! is told that a traversal step costs three triangle tests (`FASTEST_TRAVERSAL_COST`): leaves
//! grow towards four triangles and the tree has fewer nodes. BENCHMARKS.md has the measurements.

use super::{BuildParams, Layout, SahCost, Strategy, TraceOptions, TraversalOrder};
use crate::geometry::TriangleTest;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Preset {
    Handout,
    Fastest,
}

impl Preset {
    /// The handout preset's leaf size: small, as a first BVH's leaves usually are.
    pub const HANDOUT_MAX_LEAF_SIZE: u32 = 4;
    /// The fastest preset's SAH traversal cost, relative to one triangle test (bunny, 8-wide,
    /// incoherent rays: 1 → 2.54, 2 → 2.82, 3 → 2.91, 4 → 2.82 MRays/s on one thread).
    pub const FASTEST_TRAVERSAL_COST: f32 = 3.0;

    /// The build parameters the preset sets (the bins stay at their defaults; the SAH constants
    /// too but for the fastest preset's traversal cost).
    pub fn build(self) -> BuildParams {
        match self {
            Preset::Handout => BuildParams {
                strategy: Strategy::Midpoint,
                layout: Layout::Binary,
                max_leaf_size: Self::HANDOUT_MAX_LEAF_SIZE,
                ..BuildParams::default()
            },
            Preset::Fastest => BuildParams {
                strategy: Strategy::SahBinned,
                layout: Layout::Wide8,
                max_leaf_size: 4,
                cost: SahCost { traversal: Self::FASTEST_TRAVERSAL_COST, ..SahCost::default() },
                ..BuildParams::default()
            },
        }
    }

    pub fn trace(self) -> TraceOptions {
        match self {
            Preset::Handout => {
                TraceOptions { order: TraversalOrder::SplitAxisSign, test: TriangleTest::MollerTrumbore }
            }
            Preset::Fastest => TraceOptions { order: TraversalOrder::EntryDistance, test: TriangleTest::Watertight },
        }
    }

    /// Whether a scene of several placements is traced as two levels.
    pub fn two_level(self) -> bool {
        match self {
            Preset::Handout => false,
            // One tree over the flattened scene: a ray walks one hierarchy, not two.
            Preset::Fastest => false,
        }
    }

    /// Whether `build` and `trace` (and a single level) are what the preset sets.
    pub fn is_applied(self, build: &BuildParams, trace: &TraceOptions, two_level: bool) -> bool {
        let p = self.build();
        build.strategy == p.strategy
            && build.layout == p.layout
            && build.max_leaf_size == p.max_leaf_size
            && build.cost == p.cost
            && *trace == self.trace()
            && two_level == self.two_level()
    }
}
