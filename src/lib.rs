//! bvhscope's core: geometry, mesh loading, BVH construction and traversal, statistics and the
//! ray-cast renderer. Nothing here knows about the GUI; the app and the CLI are thin layers on top.

// `!(a <= b)` on floats is deliberate throughout: it is true when either side is NaN, which is how
// NaN input is made to fall on the safe side (a miss, an empty interval, a rejected value).
#![allow(clippy::neg_cmp_op_on_partial_ord)]

#[cfg(feature = "gui")]
pub mod app;
pub mod bvh;
pub mod cli;
pub mod geometry;
pub mod mesh;
pub mod render;
pub mod scene;
pub mod work;
