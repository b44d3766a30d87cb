//! Ray packets: up to 64 coherent rays (an 8×8 block of pixels) traced together through the
//! binary BVH with ranged traversal. Wald, Boulos & Shirley, "Ray Tracing Deformable Scenes Using
//! Dynamic Bounding Volume Hierarchies" (ACM TOG 26(1), 2007), §4: the packet walks the tree once,
//! and at each node only the rays from the first one that hits the node's box onwards stay active.
//!
//! Why it is fast for primary rays: near the top of the tree the first active rays hit nearly every
//! box the packet reaches, so a node costs one SIMD box test (four rays, eight with AVX2, sixteen with AVX-512:
//! `lanes.rs`) for all 64. When that first
//! group misses, a conservative test of the whole packet (interval arithmetic over the rays'
//! origins and inverse directions, the paper's §4.2) rejects most boxes no ray reaches before the
//! other groups are tried one by one. At a leaf every group from the first active one is
//! box-tested and its hitting rays test the leaf's triangles a group at a time
//! (`TriangleIntersector::intersect4`/`intersect8`/`intersect16`, bit for bit the single-ray test), so every ray gets the hit
//! it would get alone (the same distance; between triangles hit at exactly the same distance either
//! may be reported).
//!
//! Any-hit packets (`any_hits_packet`: shadow and ambient-occlusion rays of a block of pixels)
//! walk the same way, each ray leaving at its first hit.
//!
//! Packets are for the renderer's uncounted views of primary rays (`bvhscope render` of normals or
//! depth): heatmaps, and the app, which always counts for its hover read-out, trace single rays.
//! Incoherent rays defeat both shortcuts (they are slower in packets than alone, BENCHMARKS.md,
//! "Seventh round"), so they are traced one by one. Both layouts trace packets with the one walk
//! of this file (`walk`), over the children of their nodes as `PacketTree` presents them: the
//! binary BVH's two children, the wide BVHs' four or eight. Earlier, packets were 2×2 blocks
//! traced with all four lanes tested at every node; 8×8 ranged packets replaced them
//! (BENCHMARKS.md, "Seventh round"). The packet's state is `state.rs`, its SIMD groups `lanes.rs`.

mod lanes;
mod state;
pub(crate) mod walk;

#[cfg(test)]
mod packet_tests;

pub use crate::bvh::accel::PACKET;
pub use walk::{packet_position, PACKET_SIDE};
