//! The interface shared by every acceleration structure (BVH, linear scan), so the renderer, the
//! tests and the CLI can swap one for another.

use super::packet::PACKET;
use super::TraversalStats;
use crate::geometry::{Ray, TriangleTest};

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

pub trait Accelerator: Sync {
    /// Closest hit within the ray's interval; on a hit, `ray.t_max` is the hit distance.
    fn closest_hit<S: TraversalStats>(&self, ray: &mut Ray, opts: TraceOptions, stats: &mut S) -> Option<Hit>;
    /// Whether anything is hit within the ray's interval (stops at the first hit found).
    fn any_hit<S: TraversalStats>(&self, ray: &Ray, opts: TraceOptions, stats: &mut S) -> bool;

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
}
