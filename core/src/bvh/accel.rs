//! The interface shared by every acceleration structure (BVH, linear scan), so the renderer, the
//! tests and the CLI can swap one for another.

use crate::bvh::counters::TraversalStats;
use crate::geometry::{Ray, TriangleIntersector, TriangleTest};

/// Most rays in one packet (`Accelerator::closest_hits`): an 8×8 pixel tile.
pub const PACKET: usize = 64;

/// A closest hit: distance, barycentrics and the mesh's triangle index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
    pub prim: u32,
}

impl Hit {
    pub fn triangle_hit(&self) -> crate::geometry::TriangleHit {
        crate::geometry::TriangleHit { t: self.t, u: self.u, v: self.v }
    }
}

/// Which child a traversal visits first at an interior node.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum TraversalOrder {
    /// The handout's rule: the ray's direction sign on the node's split axis picks the near child.
    SplitAxisSign,
    /// The child whose box the ray enters first (needs both entry distances, which we have).
    #[default]
    EntryDistance,
}

/// Run-time choices of a query; each combination is its own compiled loop.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct TraceOptions {
    pub order: TraversalOrder,
    pub test: TriangleTest,
}

/// Runs `$body` with the triangle test as type `$t` and the near-child rule as const `$bd` (true:
/// entry distance) that `$opts` ask for: the one place where run-time options become compiled
/// loops. Every combination is its own loop, so no choice costs a branch per node or triangle.
macro_rules! dispatch {
    ($opts:expr, |$t:ident, $bd:ident| $body:expr) => {{
        use $crate::bvh::TraversalOrder as O;
        use $crate::geometry::{MollerTrumbore, MollerTrumboreStored, TriangleTest as Test, Watertight};
        match ($opts.test, $opts.order) {
            (Test::Watertight, O::EntryDistance) => {
                type $t = Watertight;
                const $bd: bool = true;
                $body
            }
            (Test::Watertight, O::SplitAxisSign) => {
                type $t = Watertight;
                const $bd: bool = false;
                $body
            }
            (Test::MollerTrumbore, O::EntryDistance) => {
                type $t = MollerTrumbore;
                const $bd: bool = true;
                $body
            }
            (Test::MollerTrumbore, O::SplitAxisSign) => {
                type $t = MollerTrumbore;
                const $bd: bool = false;
                $body
            }
            (Test::MollerTrumboreStored, O::EntryDistance) => {
                type $t = MollerTrumboreStored;
                const $bd: bool = true;
                $body
            }
            (Test::MollerTrumboreStored, O::SplitAxisSign) => {
                type $t = MollerTrumboreStored;
                const $bd: bool = false;
                $body
            }
        }
    }};
}
pub(crate) use dispatch;

/// What can be traced: every BVH layout, the two-level BVH and the linear scan. An implementation
/// writes `trace`, its traversal compiled for one combination of options; `closest_hit` and
/// `any_hit`, written here once, pick the combination the run-time options ask for.
pub trait Accelerator: Sync {
    /// The traversal for triangle test `T`, near-child rule `BY_DISTANCE` (entry distance; else
    /// the sign of the ray on the node's split axis; structures without the choice ignore it),
    /// query `ANY` (stop at the first hit found) and statistics sink `S`. On a hit, `ray.t_max`
    /// is the hit distance.
    fn trace<T: TriangleIntersector, const BY_DISTANCE: bool, const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit>;

    /// Closest hit within the ray's interval; on a hit, `ray.t_max` is the hit distance.
    #[inline]
    fn closest_hit<S: TraversalStats>(&self, ray: &mut Ray, opts: TraceOptions, stats: &mut S) -> Option<Hit> {
        dispatch!(opts, |T, BY_DISTANCE| self.trace::<T, BY_DISTANCE, false, S>(ray, stats))
    }

    /// Whether anything is hit within the ray's interval (stops at the first hit found).
    #[inline]
    fn any_hit<S: TraversalStats>(&self, ray: &Ray, opts: TraceOptions, stats: &mut S) -> bool {
        let mut r = *ray;
        dispatch!(opts, |T, BY_DISTANCE| self.trace::<T, BY_DISTANCE, true, S>(&mut r, stats)).is_some()
    }

    /// Whether `closest_hits` traces a real packet (faster for coherent rays than single rays);
    /// when false, callers should trace single rays.
    fn traces_packets(&self) -> bool {
        false
    }

    /// Closest hits of up to `PACKET` (64) coherent rays, an 8×8 pixel block best listed in the
    /// order of `packet::packet_position`, with the same results as `closest_hit` on each:
    /// `hits[k]` for `rays[k]` (the slices are equally long). BVHs trace them as one packet
    /// (`bvh::packet`); the default traces them one by one. Uncounted: heatmaps trace single rays.
    fn closest_hits(&self, rays: &mut [Ray], hits: &mut [Option<Hit>], opts: TraceOptions) {
        assert!(rays.len() <= PACKET && hits.len() == rays.len(), "a packet holds at most {PACKET} rays");
        for (ray, hit) in rays.iter_mut().zip(hits) {
            *hit = self.closest_hit(ray, opts, &mut super::NoStats);
        }
    }

    /// Whether each of up to `PACKET` rays hits anything within its interval (`occluded[k]` for
    /// `rays[k]`), the same as `any_hit` on each: shadow and ambient-occlusion rays of a block of
    /// pixels. BVHs trace them as one packet that lets each ray go at its first hit
    /// (`bvh::packet`); the default traces them one by one. Uncounted, as `closest_hits`.
    fn any_hits(&self, rays: &[Ray], occluded: &mut [bool], opts: TraceOptions) {
        assert!(rays.len() <= PACKET && occluded.len() == rays.len(), "a packet holds at most {PACKET} rays");
        for (ray, o) in rays.iter().zip(occluded) {
            *o = self.any_hit(ray, opts, &mut super::NoStats);
        }
    }
}
