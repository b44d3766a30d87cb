//! A CWBVH uploaded to the GPU and walked by shaders/cwbvh.wgsl.

use super::Cwbvh;
use crate::binary::triangle_floats;
use crate::device::{Gpu, GpuError};
use crate::trace::{GpuTrace, GpuTraceOptions, Kernels, Rays, Stack};

pub(crate) const KERNELS: Kernels = Kernels::new("cwbvh", "cwbvh.wgsl");

/// A compressed wide BVH on one GPU.
pub struct GpuCwbvh {
    nodes: wgpu::Buffer,
    leaves: wgpu::Buffer,
    tris: wgpu::Buffer,
    prim_ids: wgpu::Buffer,
    root: bvhscope_core::geometry::Aabb,
    depth: u32,
    stack: Stack,
}

impl GpuCwbvh {
    /// Upload `tree`; sizes are checked against the adapter's limit before anything is uploaded.
    pub fn upload(gpu: &Gpu, tree: &Cwbvh) -> Result<GpuCwbvh, GpuError> {
        gpu.check_size("the CWBVH's nodes", tree.nodes.len() as u64 * 80)?;
        gpu.check_size("the BVH's triangles", tree.tris.len() as u64 * 36)?;
        let nodes = gpu.upload("cwbvh nodes", &tree.nodes)?;
        let leaves = gpu.upload("cwbvh leaves", &tree.leaves)?;
        let tris = gpu.upload("triangles", &triangle_floats(&tree.tris))?;
        let prim_ids = gpu.upload("primitive ids", &tree.prim_ids)?;
        gpu.check()?;
        // One stack entry (a group of children) per level at most.
        let stack = Stack::for_entries(tree.depth.max(1));
        Ok(GpuCwbvh { nodes, leaves, tris, prim_ids, root: tree.root_bounds, depth: tree.depth, stack })
    }

    /// Levels of wide nodes below the root.
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// Closest hits of `rays` (and their counts when `opts.counted`; `opts.order` does not apply:
    /// children are visited in the ray's octant order).
    pub fn trace(&self, gpu: &Gpu, rays: Rays, opts: GpuTraceOptions) -> Result<GpuTrace, GpuError> {
        let opts = GpuTraceOptions { order: Default::default(), ..opts };
        KERNELS.run(
            gpu,
            &[&self.nodes, &self.leaves, &self.tris, &self.prim_ids],
            Some(self.root),
            self.stack,
            rays,
            opts,
        )
    }
}
