//! bvhscope: the desktop app and the command line over the core (`bvhscope-core`, re-exported here
//! so `bvhscope::bvh`, `bvhscope::render` … name the same things everywhere).

pub use bvhscope_core::{bvh, cpu, dump, explain, files, geometry, lesson, mesh, options, random, render, scene, work};

#[cfg(feature = "gui")]
pub mod app;
pub mod cli;
pub mod gpu_path;
