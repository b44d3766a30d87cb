//! What the app and the CLI trace: one BVH over the whole (flattened) scene, or the two-level BVH
//! over the scene's mesh placements. Both give the same triangle ids, so the flattened mesh shades
//! either.

use super::tree::TreeView;
use super::{Accelerator, AnyBvh, BuildParams, Hit, TraceOptions, TraversalStats, TwoLevelBvh};
use crate::geometry::{Ray, TriangleIntersector};
use crate::mesh::Mesh;
use crate::work::{Cancelled, WorkControl};
use glam::Affine3A;

/// How to build a scene's acceleration structure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneBuild {
    /// The single BVH's parameters, or the bottom level's (each mesh's BVH).
    pub bvh: BuildParams,
    /// Some: build two levels, with these parameters for the top level.
    pub top: Option<BuildParams>,
}

impl SceneBuild {
    /// "SAH binned, wide4", or "top SAH binned / Midpoint, binary" for two levels: the strategy and
    /// layout, as the statistics columns and exported images name a build.
    pub fn label(&self) -> String {
        let one = format!("{}, {}", self.bvh.strategy.label(), self.bvh.layout.name());
        match self.top {
            Some(top) => format!("top {} / {one}", top.strategy.label()),
            None => one,
        }
    }
}

/// A scene's meshes and their placements (mesh index, object-to-world transform).
pub type Placements<'a> = (&'a [&'a Mesh], &'a [(u32, Affine3A)]);

#[derive(Clone, Debug)]
pub enum SceneBvh {
    Single(AnyBvh),
    TwoLevel(TwoLevelBvh),
}

impl SceneBvh {
    /// Build over `flat` (single level) or over `meshes` placed by `placements` (two levels, when
    /// `build.top` is given and there are placements; otherwise the single level is built).
    pub fn build(
        flat: &Mesh,
        instances: Option<Placements>,
        build: &SceneBuild,
        control: &WorkControl,
    ) -> Result<SceneBvh, Cancelled> {
        match (build.top, instances) {
            (Some(top), Some((meshes, placements))) => {
                Ok(SceneBvh::TwoLevel(TwoLevelBvh::build(meshes, placements, &top, &build.bvh, control)?))
            }
            _ => Ok(SceneBvh::Single(AnyBvh::build_controlled(flat, &build.bvh, control)?)),
        }
    }

    /// What this was built with.
    pub fn build_params(&self) -> SceneBuild {
        match self {
            SceneBvh::Single(b) => SceneBuild { bvh: *b.params(), top: None },
            SceneBvh::TwoLevel(t) => SceneBuild { bvh: t.bottom_params, top: Some(t.top.params) },
        }
    }

    /// The single BVH, or the top level of two.
    pub fn tree(&self) -> &dyn TreeView {
        match self {
            SceneBvh::Single(b) => b,
            SceneBvh::TwoLevel(t) => &t.top,
        }
    }

    pub fn two_level(&self) -> Option<&TwoLevelBvh> {
        match self {
            SceneBvh::TwoLevel(t) => Some(t),
            SceneBvh::Single(_) => None,
        }
    }

    /// Bytes of every node and index array (each mesh BVH once).
    pub fn memory_bytes(&self) -> usize {
        match self {
            SceneBvh::Single(b) => b.memory_bytes(),
            SceneBvh::TwoLevel(t) => t.memory_bytes(),
        }
    }

    /// Total build time.
    pub fn build_time(&self) -> std::time::Duration {
        match self {
            SceneBvh::Single(b) => b.report().total_time(),
            SceneBvh::TwoLevel(t) => t.bottom_time + t.top_time,
        }
    }
}

impl Accelerator for SceneBvh {
    #[inline]
    fn trace<T: TriangleIntersector, const BY_DISTANCE: bool, const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        match self {
            SceneBvh::Single(b) => b.trace::<T, BY_DISTANCE, ANY, S>(ray, stats),
            SceneBvh::TwoLevel(t) => t.trace::<T, BY_DISTANCE, ANY, S>(ray, stats),
        }
    }

    fn traces_packets(&self) -> bool {
        matches!(self, SceneBvh::Single(b) if b.traces_packets())
    }

    #[inline]
    fn closest_hits(&self, rays: &mut [Ray], hits: &mut [Option<Hit>], opts: TraceOptions) {
        match self {
            SceneBvh::Single(b) => b.closest_hits(rays, hits, opts),
            SceneBvh::TwoLevel(t) => t.closest_hits(rays, hits, opts),
        }
    }
}
