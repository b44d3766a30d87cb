//! The strategies, and the one table that says what each is: how it builds and which numbers it
//! reads. The driver, the node inspector, the build panel, the CLI and the scene files ask these
//! methods; none of them names a strategy to decide what it does. A new strategy is a variant
//! here, its row in `REGISTRY`, its names in `crate::options`, and its splitter's file
//! (ARCHITECTURE.md, "Adding a strategy").

use crate::bvh::builders::split::equal_count::EqualCount;
use crate::bvh::builders::split::midpoint::Midpoint;
use crate::bvh::builders::split::sah_binned::SahBinned;
use crate::bvh::builders::split::sah_sweep::SahSweep;
use crate::bvh::builders::split::spatial::Triangles;
use crate::bvh::builders::split::spatial_splits::SpatialSplits;
use crate::bvh::builders::split::splitter::Splitter;
use crate::bvh::params::{BuildParams, Param, Strategy};
use crate::geometry::Aabb;

/// What a splitter is made from: the build's parameters and, for one that cuts triangles, the
/// triangles and the root's box.
pub struct Setup<'a> {
    pub params: &'a BuildParams,
    /// `None`: nothing to clip (the top level of two levels, the inspector's markers).
    pub tri: Option<Triangles<'a>>,
    /// The root's box (measured only for a build over references; else empty).
    pub root: Aabb,
}

/// A strategy's splitter for a build.
pub type MakeSplitter = for<'a> fn(&Setup<'a>) -> Box<dyn Splitter + 'a>;

/// How a strategy builds.
#[derive(Clone, Copy)]
pub enum Builder {
    /// Top-down by the driver (`builders::driver`), node by node, with a splitter made for the
    /// build. `references`: over references of its own (`sbvh::Work`), which its splitter's cuts
    /// duplicate, rather than in place in the build's array.
    TopDown { make: MakeSplitter, references: bool },
    /// The hierarchy of the sorted Morton codes (`lbvh`): no plane is chosen at a node.
    Morton,
    /// Bottom-up clustering in Morton order (`ploc`).
    Clustering,
}

/// A strategy split top-down in place.
const fn in_place(make: MakeSplitter) -> Builder {
    Builder::TopDown { make, references: false }
}

struct Entry {
    strategy: Strategy,
    builder: Builder,
    /// The numbers it reads besides those every build reads (`Param::every_build`).
    params: &'static [Param],
}

const REGISTRY: [Entry; 7] = [
    Entry { strategy: Strategy::Midpoint, builder: in_place(|_| Box::new(Midpoint)), params: &[] },
    Entry { strategy: Strategy::EqualCount, builder: in_place(|_| Box::new(EqualCount)), params: &[] },
    Entry {
        strategy: Strategy::SahBinned,
        builder: in_place(|s| Box::new(SahBinned::new(s.params))),
        params: &[Param::SahBins],
    },
    Entry { strategy: Strategy::SahSweep, builder: in_place(|s| Box::new(SahSweep::new(s.params))), params: &[] },
    Entry { strategy: Strategy::Lbvh, builder: Builder::Morton, params: &[] },
    Entry { strategy: Strategy::Ploc, builder: Builder::Clustering, params: &[Param::PlocRadius] },
    Entry {
        strategy: Strategy::Sbvh,
        builder: Builder::TopDown {
            make: |s| Box::new(SpatialSplits::new(s.tri, s.params, &s.root)),
            references: true,
        },
        params: &[Param::SahBins, Param::SbvhAlpha, Param::SbvhGrowth],
    },
];

impl Param {
    /// Whether every build reads it, whatever its strategy (the leaf size, the SAH's constant,
    /// and reinsertion, which works on any binary tree).
    pub fn every_build(self) -> bool {
        matches!(self, Param::MaxLeafSize | Param::ReinsertPasses | Param::TraversalCost)
    }
}

impl Strategy {
    fn entry(self) -> &'static Entry {
        REGISTRY.iter().find(|e| e.strategy == self).expect("every strategy has its row")
    }

    pub fn builder(self) -> Builder {
        self.entry().builder
    }

    /// A splitter of this strategy for `setup`; `None` for a builder that does not split node by
    /// node at a plane it chooses there.
    pub fn splitter_for<'a>(self, setup: &Setup<'a>) -> Option<Box<dyn Splitter + 'a>> {
        match self.builder() {
            Builder::TopDown { make, .. } => Some(make(setup)),
            _ => None,
        }
    }

    /// `splitter_for` a build with `params` and no triangles to clip.
    pub fn splitter(self, params: &BuildParams) -> Option<Box<dyn Splitter + '_>> {
        self.splitter_for(&Setup { params, tri: None, root: Aabb::EMPTY })
    }

    /// Whether the top-down driver builds with this strategy's splitter.
    pub fn splits_top_down(self) -> bool {
        matches!(self.builder(), Builder::TopDown { .. })
    }

    /// Whether its leaves hold references (parts of triangles) rather than triangles: a triangle
    /// may be in several leaves, and a node's triangles are found by replaying the build.
    pub fn splits_references(self) -> bool {
        matches!(self.builder(), Builder::TopDown { references: true, .. })
    }

    /// Whether its tree's leaf order is its Morton order (an LBVH's, not reinserted).
    pub fn follows_morton_order(self) -> bool {
        matches!(self.builder(), Builder::Morton)
    }

    /// Whether it prices splits at bins (`Param::SahBins`).
    pub fn uses_bins(self) -> bool {
        self.reads(Param::SahBins)
    }

    /// The numbers it reads besides those every build reads.
    pub fn params(self) -> &'static [Param] {
        self.entry().params
    }

    /// Whether a build with this strategy reads `p`.
    pub fn reads(self, p: Param) -> bool {
        p.every_build() || self.params().contains(&p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_strategy_has_one_row() {
        for (i, e) in REGISTRY.iter().enumerate() {
            assert!(REGISTRY[..i].iter().all(|f| f.strategy != e.strategy), "{:?} twice", e.strategy);
            assert!(e.params.iter().all(|p| !p.every_build()), "{:?}: a number every build reads", e.strategy);
        }
        assert_eq!(REGISTRY.len(), Strategy::ALL.len());
        assert!(Strategy::Sbvh.splits_references() && !Strategy::SahBinned.splits_references());
        assert!(Strategy::Sbvh.uses_bins() && !Strategy::Ploc.uses_bins());
        assert!(Strategy::Ploc.reads(Param::PlocRadius) && !Strategy::Lbvh.reads(Param::PlocRadius));
    }
}
