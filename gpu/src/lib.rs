//! bvhscope's GPU path on wgpu (WGSL compute shaders, headless): the BVHs bvhscope builds or
//! imports traced on the GPU with the CPU's per-ray counts, and built there. See INTEGRATION.md.

// `!(a <= b)` on floats is deliberate, as in core: true when either side is NaN, the safe side.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod binary;
mod buffers;
mod cwbvh;
mod device;
mod format;
mod kernel;
#[cfg(test)]
mod layout_tests;
mod lbvh;
mod ploc;
mod scan;
mod shaders;
mod shaders_valid;
mod sort;
mod trace;
pub mod verify;

pub use binary::{checked_depth, BinaryFormat, GpuBinaryBvh};
pub use cwbvh::{Cwbvh, CwbvhFormat, CwbvhNode, GpuCwbvh, META_INTERIOR, META_LEAF};
pub use device::{gpu_for_tests, Gpu, GpuError, GpuOptions};
pub use format::{GpuFormat, Upload};
pub use lbvh::{GpuBuildTimings, GpuLbvh, MAX_TRIANGLES};
pub use ploc::GpuPloc;
pub use trace::{GpuTrace, GpuTraceOptions, Rays, STEP_BUDGET};
// The warp view needs no GPU: it moved to core, where the heatmaps use it on either path.
pub use bvhscope_core::render::warp::{WarpGroup, WarpSize, WarpSummary, WarpView, WarpWork};

// The app keeps these in an `Arc` and uses them from its jobs' threads.
const _: () = {
    const fn shared<T: Send + Sync>() {}
    shared::<Gpu>();
    shared::<GpuBinaryBvh>();
    shared::<GpuCwbvh>();
    shared::<GpuLbvh>();
    shared::<GpuPloc>();
};
