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
//! (eight boxes per AVX2 pass), its leaves as large as one SIMD pass of the CPU's kernel family
//! tests (`Preset::fastest_leaves`): up to sixteen triangles where the CPU has AVX-512, eight with
//! AVX2, four elsewhere. The SAH is told that a traversal step costs as much as that many triangle
//! tests would (10, 5 or 3), so leaves grow towards that size and the tree has fewer nodes. On
//! AVX-512 the sixteen-triangle leaves were as fast or faster on every mesh of `versus` (primary
//! single rays 0.98–1.14×, incoherent 1.02–1.15×, at 46–49 bytes per triangle instead of 60–68:
//! BENCHMARKS.md, "The fastest preset by kernel family"); with AVX2 the leaves of eight, one pass
//! of `geometry::triangle8`, against leaves of four: bunny primary 1.01×, incoherent 1.15×, 55
//! bytes per triangle instead of 62 (BENCHMARKS.md, "AVX2 a family of its own").

use crate::bvh::accel::{TraceOptions, TraversalOrder};
use crate::bvh::params::{BuildParams, Layout, SahCost, Strategy};
use crate::cpu::Simd;
use crate::geometry::TriangleTest;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Preset {
    Handout,
    Fastest,
}

impl Preset {
    /// The handout preset's leaf size: small, as a first BVH's leaves usually are.
    pub const HANDOUT_MAX_LEAF_SIZE: u32 = 4;
    /// The fastest preset's largest leaf and SAH traversal cost (relative to one triangle test)
    /// for a kernel family: sixteen triangles, one AVX-512 leaf test (two masked 256-bit passes since
    /// 2026-12-03; cost 10: BENCH_KERNEL_LEAVES's
    /// best of 8, 10 and 12); eight, one AVX2 pass (cost 5: bunny, one thread, 8:4, 8:5, 8:7 and
    /// 6:4 within 2 % of each other on primary rays, 8:5 kept); or four, one pass of four lanes (cost 3:
    /// bunny, 8-wide, incoherent rays, 1 → 2.54, 2 → 2.82, 3 → 2.91, 4 → 2.82 MRays/s on one
    /// thread).
    pub fn fastest_leaves(simd: Simd) -> (u32, f32) {
        match simd {
            Simd::Avx512 => (16, 10.0),
            Simd::Avx2 => (8, 5.0),
            Simd::Scalar | Simd::Simd4 => (4, 3.0),
        }
    }

    /// The build parameters the preset sets (the bins stay at their defaults; the SAH constants
    /// too but for the fastest preset's traversal cost). The fastest preset's depend on the kernel
    /// family this process traces with (`Simd::chosen`), so one machine always builds one tree.
    pub fn build(self) -> BuildParams {
        match self {
            Preset::Handout => BuildParams {
                strategy: Strategy::Midpoint,
                layout: Layout::Binary,
                max_leaf_size: Self::HANDOUT_MAX_LEAF_SIZE,
                ..BuildParams::default()
            },
            Preset::Fastest => {
                let (max_leaf_size, traversal) = Self::fastest_leaves(Simd::chosen());
                BuildParams {
                    strategy: Strategy::SahBinned,
                    layout: Layout::Wide8,
                    max_leaf_size,
                    cost: SahCost { traversal, ..SahCost::default() },
                    ..BuildParams::default()
                }
            }
        }
    }

    pub fn trace_options(self) -> TraceOptions {
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
            && *trace == self.trace_options()
            && two_level == self.two_level()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fastest tree follows the kernel family this process traces with: leaves of sixteen
    /// where one AVX-512 pass tests them, eight for one AVX2 pass, four elsewhere; and the preset
    /// reads as applied to it.
    #[test]
    fn the_fastest_tree_is_chosen_by_kernel_family() {
        assert_eq!(Preset::fastest_leaves(Simd::Avx512), (16, 10.0));
        assert_eq!(Preset::fastest_leaves(Simd::Avx2), (8, 5.0));
        for simd in [Simd::Scalar, Simd::Simd4] {
            assert_eq!(Preset::fastest_leaves(simd), (4, 3.0), "{simd:?}");
        }
        let p = Preset::Fastest.build();
        assert_eq!((p.max_leaf_size, p.cost.traversal), Preset::fastest_leaves(Simd::chosen()));
        assert!(Preset::Fastest.is_applied(&p, &Preset::Fastest.trace_options(), false));
    }
}
