//! Named sets of build and traversal options, one choice in the app and `--preset` on the command
//! line.
//!
//! `Handout` is the BVH a student writes in the lab (the Moer-lite course's handout): a binary
//! tree split at the midpoint of the widest axis, the near child chosen by the ray's direction
//! sign on the split axis, the Möller–Trumbore triangle test, one level over the whole scene. Its
//! figures are the ones to compare with a student's own renderer; the handout leaves the leaf
//! size to the student, so the preset states the value it uses.

use super::{BuildParams, Layout, SplitStrategy, TraceOptions, TraversalOrder};
use crate::geometry::TriangleTest;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Preset {
    Handout,
}

impl Preset {
    /// The handout preset's leaf size: small, as a first BVH's leaves usually are.
    pub const HANDOUT_MAX_LEAF_SIZE: u32 = 4;

    /// The build parameters the preset sets (the SAH constants and bins stay at their defaults).
    pub fn build(self) -> BuildParams {
        match self {
            Preset::Handout => BuildParams {
                strategy: SplitStrategy::Midpoint,
                layout: Layout::Binary,
                max_leaf_size: Self::HANDOUT_MAX_LEAF_SIZE,
                ..BuildParams::default()
            },
        }
    }

    pub fn trace(self) -> TraceOptions {
        match self {
            Preset::Handout => {
                TraceOptions { order: TraversalOrder::SplitAxisSign, test: TriangleTest::MollerTrumbore }
            }
        }
    }

    /// Whether a scene of several placements is traced as two levels.
    pub fn two_level(self) -> bool {
        match self {
            Preset::Handout => false,
        }
    }

    /// Whether `build` and `trace` (and a single level) are what the preset sets.
    pub fn is_applied(self, build: &BuildParams, trace: &TraceOptions, two_level: bool) -> bool {
        let p = self.build();
        build.strategy == p.strategy
            && build.layout == p.layout
            && build.max_leaf_size == p.max_leaf_size
            && *trace == self.trace()
            && two_level == self.two_level()
    }
}
