//! The wide BVHs: the binary BVH collapsed into nodes of up to four or eight children (`W`) whose
//! boxes are tested together with SIMD (`traverse.rs`; the eight-wide one with AVX2 where the CPU
//! has it, chosen at run time: `crate::cpu`).
//!
//! Collapse (`collapse.rs`): which binary nodes become wide nodes is the grouping of least summed
//! surface area of the wide nodes, the SAH cost of a wide tree over the binary tree's leaves
//! (Ylitie, Karras & Laine, HPG 2017's dynamic programme, `CollapsePlan`); it replaced opening the
//! interior child of largest area first (Wald, Benthin & Boulos, RT 2008), which visited 6–7 % more
//! nodes per incoherent ray. Leaves and the triangle order are those of the binary BVH.
//!
//! Counts, against the binary tree it was collapsed from: a wide node visit counts once and one
//! box test per valid child; a leaf is reached as a child (a leaf visit, not a node visit). So for
//! a ray no hit prunes (one that hits nothing), both layouts reach the same leaves and make the same
//! triangle tests, and the wide layout visits at most as many nodes as the binary one visits
//! interior nodes; box tests have no such bound (a wide node tests its grandchildren's boxes where
//! the binary walk may have culled them at the child's). `core/tests/exact_counts.rs` checks this.
//!
//! Triangles are stored in leaf order, vertices inline (36 bytes each, no index indirection), so a
//! leaf is one contiguous read. They are not precomputed into edge form: the watertight test needs
//! the vertices themselves, and rebuilding them from stored edges would change its rounding and so
//! lose the guarantee that rays through shared edges hit.

mod collapse;
mod leaves;
pub(crate) mod node;
mod packet;
mod traverse;
pub(crate) mod wide_bvh;

#[cfg(test)]
mod kernel_tests;

pub use collapse::{wide_group_in, wide_group_of, CollapsePlan, WideGroup};

pub use node::{WideNode, WIDTH};
pub use wide_bvh::WideBvh;
