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

/// The CWBVH format: made from the binary tree, walked on the CPU by its own walk (`walk.rs`),
/// whose counts are the reference for the GPU's.
pub struct CwbvhFormat {
    cpu: Cwbvh,
    gpu: GpuCwbvh,
}

impl CwbvhFormat {
    /// `bvh` encoded as a CWBVH and uploaded (`GPU_NODES`' upload for the CWBVH format).
    pub fn upload(
        gpu: &Gpu,
        bvh: std::borrow::Cow<'_, bvhscope_core::bvh::Bvh>,
    ) -> Result<Box<dyn crate::format::GpuFormat>, GpuError> {
        let cpu = Cwbvh::from_bvh(&bvh)?;
        let on_gpu = GpuCwbvh::upload(gpu, &cpu)?;
        Ok(Box::new(CwbvhFormat { cpu, gpu: on_gpu }))
    }
}

impl crate::format::GpuFormat for CwbvhFormat {
    fn own_nodes(&self) -> Option<usize> {
        Some(self.cpu.nodes.len())
    }

    fn trace(&self, gpu: &Gpu, rays: Rays, opts: GpuTraceOptions) -> Result<GpuTrace, GpuError> {
        self.gpu.trace(gpu, rays, opts)
    }

    fn cpu_walk(
        &self,
        ray: &mut bvhscope_core::geometry::Ray,
        trace: bvhscope_core::bvh::TraceOptions,
    ) -> (Option<bvhscope_core::bvh::Hit>, bvhscope_core::bvh::RayCounters) {
        self.cpu.trace_cpu(ray, trace.test)
    }

    fn cpu_counts(
        &self,
        _cpu: &bvhscope_core::bvh::SceneBvh,
        camera: &bvhscope_core::render::Camera,
        trace: bvhscope_core::bvh::TraceOptions,
    ) -> Vec<bvhscope_core::bvh::RayCounters> {
        use rayon::prelude::*;
        let gen = camera.ray_gen();
        (0..camera.width * camera.height)
            .into_par_iter()
            .map(|i| self.cpu.trace_cpu(&mut gen.pixel_ray(i % camera.width, i / camera.width), trace.test).1)
            .collect()
    }
}
