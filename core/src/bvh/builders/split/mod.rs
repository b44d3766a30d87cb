//! Split strategies: given the primitives of one node, propose where to split and partition the
//! primitives accordingly. One file per strategy, each a `Splitter` that keeps the scratch memory it
//! reuses from node to node; the driver that calls them, and decides leaf or split, is
//! `bvh::builders::driver`.

pub(crate) mod equal_count;
pub(crate) mod midpoint;
pub(crate) mod sah_binned;
pub(crate) mod sah_sweep;
pub(crate) mod spatial;
pub(crate) mod spatial_splits;
pub(crate) mod splitter;

pub use equal_count::EqualCount;
pub use midpoint::Midpoint;
pub use sah_binned::{binned_planes, bins_for, SahBinned};
pub use sah_sweep::{sweep_planes, SahSweep};
pub use spatial::{spatial_partition, spatial_planes, split_reference, SpatialSplit};

pub use splitter::{sah_binned_max_bins, BuildPrim, NodeInfo, PlaneSink, Proposal, Splitter};
