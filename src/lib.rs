//! bvhscope's core: geometry, mesh loading, BVH construction and traversal, statistics and the
//! ray-cast renderer. Nothing here knows about the GUI; the app and the CLI are thin layers on top.

#[cfg(feature = "gui")]
pub mod app;
pub mod bvh;
pub mod cli;
pub mod geometry;
pub mod mesh;
pub mod render;
pub mod work;
