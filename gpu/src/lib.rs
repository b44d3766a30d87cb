//! bvhscope's GPU path on wgpu (WGSL compute shaders, headless): the BVHs bvhscope builds or
//! imports traced on the GPU with the CPU's per-ray counts, and built there. See INTEGRATION.md.

mod binary;
mod buffers;
mod device;
mod kernel;
mod trace;

pub use binary::{checked_depth, GpuBinaryBvh};
pub use device::{gpu_for_tests, Gpu, GpuError, GpuOptions};
pub use trace::{GpuTrace, GpuTraceOptions, Rays};
