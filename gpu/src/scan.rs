//! Exclusive prefix sums on the GPU (shaders/scan.wgsl), the building block of the radix sort's
//! digit offsets and of the LBVH's run and leaf numbering.

use crate::device::{Gpu, GpuError};
use crate::kernel::{Bind, Kernel};
use std::sync::Arc;

/// Elements per block of the first pass.
pub(crate) const BLOCK: u32 = 4096;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct ScanParams {
    pub(crate) len: u32,
    pub(crate) blocks: u32,
    pub(crate) pad: [u32; 2],
}

pub(crate) struct Scan {
    blocks: Arc<Kernel>,
    sums: Arc<Kernel>,
    add: Arc<Kernel>,
}

impl Scan {
    pub(crate) fn new(gpu: &Gpu) -> Result<Scan, GpuError> {
        let src = crate::shaders::source("scan.wgsl");
        let binds = [Bind::Uniform, Bind::ReadWrite, Bind::ReadWrite];
        let k = |entry: &'static str| {
            gpu.compiled(format!("scan {entry}"), || Kernel::new(gpu, entry, src, entry, &binds, &[]))
        };
        Ok(Scan { blocks: k("scan_blocks")?, sums: k("scan_sums")?, add: k("add_sums")? })
    }

    /// Bytes of the scratch buffer `record` needs for `len` elements.
    pub(crate) fn scratch_bytes(len: u32) -> u64 {
        len.div_ceil(BLOCK).max(1) as u64 * 4
    }

    /// Record the exclusive scan of `data[..len]`, in place; `scratch` holds `scratch_bytes(len)`.
    /// Scan one element more than the values (a zero) and it ends with their total.
    pub(crate) fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        data: &wgpu::Buffer,
        len: u32,
        scratch: &wgpu::Buffer,
    ) {
        let blocks = len.div_ceil(BLOCK).max(1);
        let p = gpu.uniform("scan parameters", &ScanParams { len, blocks, pad: [0; 2] });
        let grid = gpu.grid(blocks, 1);
        for (k, groups) in [(&self.blocks, grid), (&self.sums, (1, 1)), (&self.add, grid)] {
            let bind = k.bind(gpu, &[&p, data, scratch]);
            k.dispatch(encoder, &bind, groups);
        }
    }
}
