//! A node format the GPU walks, as the GPU path uses it: the tree uploaded in that format, its walk
//! on the GPU, and the same walk on the CPU, which finishes the rays a GPU walk leaves at its step
//! budget and is the reference for the GPU's counts. Each format implements it in its own file
//! (`binary.rs`, `cwbvh/gpu.rs`) beside its shader; the GPU path's table of formats (`GPU_NODES`
//! in the `bvhscope` crate) names the upload that makes one, and nothing else matches on formats.

use crate::device::{Gpu, GpuError};
use crate::trace::{GpuTrace, GpuTraceOptions, Rays};
use bvhscope_core::bvh::{Hit, RayCounters, SceneBvh, TraceOptions};
use bvhscope_core::geometry::Ray;
use bvhscope_core::render::Camera;

/// A tree uploaded in one node format, with its CPU form.
pub trait GpuFormat: Send + Sync {
    /// How many nodes of its own the format made from the binary tree (`None`: the binary tree's
    /// own nodes are walked).
    fn own_nodes(&self) -> Option<usize>;

    /// Closest hits of `rays` on the GPU (and their counts when `opts.counted`).
    fn trace(&self, gpu: &Gpu, rays: Rays, opts: GpuTraceOptions) -> Result<GpuTrace, GpuError>;

    /// One ray's walk on the CPU, with its counts: the walk the GPU's must equal.
    fn cpu_walk(&self, ray: &mut Ray, trace: TraceOptions) -> (Option<Hit>, RayCounters);

    /// The per-pixel counts (row by row) of the CPU walk for `camera`; `cpu` is the binary tree's
    /// scene, for a format whose CPU walk is core's own renderer.
    fn cpu_counts(&self, cpu: &SceneBvh, camera: &Camera, trace: TraceOptions) -> Vec<RayCounters>;
}

/// How a format is made from the binary tree: the row of the GPU path's table names it. The tree
/// comes borrowed or owned as the scene has it, so a format that keeps it moves it, not copies it.
pub type Upload = fn(&Gpu, std::borrow::Cow<'_, bvhscope_core::bvh::Bvh>) -> Result<Box<dyn GpuFormat>, GpuError>;
