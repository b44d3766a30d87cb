//! bvhscope's core: geometry, mesh loading, BVH construction and traversal, statistics and the
//! ray-cast renderer, and the table of the options a user sets. Nothing here knows about a GUI or a
//! command line: the app and the CLI (the `bvhscope` crate) are thin layers on top.

// `!(a <= b)` on floats is deliberate throughout: it is true when either side is NaN, which is how
// NaN input is made to fall on the safe side (a miss, an empty interval, a rejected value).
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bvh;
pub mod cpu;
pub mod dump;
pub mod explain;
pub mod files;
pub mod geometry;
pub mod json;
pub mod lesson;
pub mod mesh;
pub mod options;
pub mod parallel;
pub mod random;
pub mod render;
pub mod scene;
pub mod work;

/// Where unit tests write their files (shared with the integration tests by `#[path]`).
#[cfg(test)]
#[path = "../tests/common/scratch.rs"]
pub(crate) mod scratch;
