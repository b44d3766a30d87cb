//! The binary BVH on the GPU: core's `Bvh` uploaded as it is (its 32-byte nodes byte for byte,
//! its triangles in leaf order, its primitive ids) and walked by shaders/binary.wgsl, the CPU's
//! walk with the CPU's counts.

use crate::device::{Gpu, GpuError};
use crate::trace::{GpuTrace, GpuTraceOptions, Kernels, Rays, Stack};
use bvhscope_core::bvh::reach::{reach, Fault};
use bvhscope_core::bvh::Bvh;
use std::ops::ControlFlow;

/// A binary BVH uploaded to one GPU.
pub struct GpuBinaryBvh {
    nodes: wgpu::Buffer,
    tris: wgpu::Buffer,
    prim_ids: wgpu::Buffer,
    depth: u32,
    stack: Stack,
}

pub(crate) const KERNELS: Kernels = Kernels::new("binary", "binary.wgsl");

/// The deepest leaf's depth (edges from the root) of a well-formed binary tree, or why the tree
/// cannot be walked: a child or triangle range out of bounds, or a node reached twice (a cycle or
/// shared subtree, which the GPU walk would follow forever or twice). An empty tree (no
/// primitives) has depth 0.
pub fn checked_depth(bvh: &Bvh) -> Result<u32, GpuError> {
    let bad = |m: String| Err(GpuError::Input(format!("this BVH cannot be traced: {m}")));
    if bvh.nodes.is_empty() {
        return bad("it has no nodes".into());
    }
    if bvh.tris.len() != bvh.prim_ids.len() {
        return bad(format!("{} triangles but {} primitive ids", bvh.tris.len(), bvh.prim_ids.len()));
    }
    if bvh.prim_ids.is_empty() {
        return Ok(0);
    }
    let nodes = &bvh.nodes;
    let children = |i: usize, k: usize| (!nodes[i].is_leaf() && k < 2).then(|| nodes[i].index.wrapping_add(k as u32));
    let mut fault = None;
    let walked = reach(nodes.len(), children, |f| {
        fault = Some(f);
        ControlFlow::Break(())
    });
    match fault {
        Some(Fault::PastEnd { from, child }) => {
            return bad(format!("node {from}'s child {child} is past the last node"))
        }
        Some(Fault::Again { node, .. }) => return bad(format!("node {node} is reached twice")),
        None => {}
    }
    let reached_leaves = nodes.iter().enumerate().filter(|&(i, n)| walked.reached[i] && n.is_leaf());
    for (i, leaf) in reached_leaves {
        if leaf.index as usize + leaf.count as usize > bvh.tris.len() {
            return bad(format!("leaf {i} holds triangles past the last ({})", bvh.tris.len()));
        }
    }
    Ok(walked.depth)
}

/// A node's 32 bytes as the GPU reads them (core's `BvhNode` field by field, little-endian).
fn node_words(n: &bvhscope_core::bvh::BvhNode) -> [u32; 8] {
    let f = |x: f32| x.to_bits();
    let meta = n.count as u32 | (n.axis as u32) << 16;
    [f(n.lo[0]), f(n.lo[1]), f(n.lo[2]), f(n.hi[0]), f(n.hi[1]), f(n.hi[2]), n.index, meta]
}

/// Triangles as nine floats each, in the given (leaf) order.
pub(crate) fn triangle_floats(tris: &[[glam::Vec3; 3]]) -> Vec<[f32; 9]> {
    tris.iter().map(|t| [t[0].x, t[0].y, t[0].z, t[1].x, t[1].y, t[1].z, t[2].x, t[2].y, t[2].z]).collect()
}

impl GpuBinaryBvh {
    /// Check `bvh` (`checked_depth`) and upload it; sizes are checked against the adapter's limit
    /// before anything is uploaded.
    pub fn upload(gpu: &Gpu, bvh: &Bvh) -> Result<GpuBinaryBvh, GpuError> {
        let depth = checked_depth(bvh)?;
        gpu.check_size("the BVH's nodes", bvh.nodes.len() as u64 * 32)?;
        gpu.check_size("the BVH's triangles", bvh.tris.len() as u64 * 36)?;
        let nodes: Vec<[u32; 8]> = bvh.nodes.iter().map(node_words).collect();
        let nodes = gpu.upload("binary nodes", &nodes)?;
        let tris = gpu.upload("triangles", &triangle_floats(&bvh.tris))?;
        let prim_ids = gpu.upload("primitive ids", &bvh.prim_ids)?;
        gpu.check()?;
        // The walk holds at most one entry per level below the root.
        let stack = Stack::for_entries(depth.max(1));
        Ok(GpuBinaryBvh { nodes, tris, prim_ids, depth, stack })
    }

    /// The deepest leaf's depth (what sizes the stack).
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// Whether the walk's stack lives in global memory (a tree deeper than a private stack holds).
    pub fn global_stack(&self) -> bool {
        matches!(self.stack, Stack::Global(_))
    }

    /// Closest hits of `rays` (and their counts when `opts.counted`).
    pub fn trace(&self, gpu: &Gpu, rays: Rays, opts: GpuTraceOptions) -> Result<GpuTrace, GpuError> {
        KERNELS.run(gpu, &[&self.nodes, &self.tris, &self.prim_ids], None, self.stack, rays, opts)
    }

    /// `trace` with the walk's stack forced into global memory (tests of the deep-tree path on a
    /// shallow tree).
    pub fn trace_with_global_stack(&self, gpu: &Gpu, rays: Rays, opts: GpuTraceOptions) -> Result<GpuTrace, GpuError> {
        let stack = Stack::Global(self.depth.clamp(1, crate::trace::STEP_BUDGET));
        KERNELS.run(gpu, &[&self.nodes, &self.tris, &self.prim_ids], None, stack, rays, opts)
    }
}

/// The binary format: the tree as built, walked on the CPU by core's own walk and renderer.
pub struct BinaryFormat {
    cpu: Bvh,
    gpu: GpuBinaryBvh,
}

impl BinaryFormat {
    /// `bvh` uploaded as it is (`GPU_NODES`' upload for the binary format).
    pub fn upload(gpu: &Gpu, bvh: std::borrow::Cow<'_, Bvh>) -> Result<Box<dyn crate::format::GpuFormat>, GpuError> {
        let on_gpu = GpuBinaryBvh::upload(gpu, &bvh)?;
        Ok(Box::new(BinaryFormat { cpu: bvh.into_owned(), gpu: on_gpu }))
    }
}

impl crate::format::GpuFormat for BinaryFormat {
    fn own_nodes(&self) -> Option<usize> {
        None
    }

    fn trace(&self, gpu: &Gpu, rays: Rays, opts: GpuTraceOptions) -> Result<GpuTrace, GpuError> {
        self.gpu.trace(gpu, rays, opts)
    }

    fn cpu_walk(
        &self,
        ray: &mut bvhscope_core::geometry::Ray,
        trace: bvhscope_core::bvh::TraceOptions,
    ) -> (Option<bvhscope_core::bvh::Hit>, bvhscope_core::bvh::RayCounters) {
        let mut c = bvhscope_core::bvh::RayCounters::ZERO;
        let hit = bvhscope_core::bvh::Accelerator::closest_hit(&self.cpu, ray, trace, &mut c);
        (hit, c)
    }

    fn cpu_counts(
        &self,
        cpu: &bvhscope_core::bvh::SceneBvh,
        camera: &bvhscope_core::render::Camera,
        trace: bvhscope_core::bvh::TraceOptions,
    ) -> Vec<bvhscope_core::bvh::RayCounters> {
        use bvhscope_core::render::{render, RenderSettings};
        let settings = RenderSettings { trace, count: true, progressive: false, secondary: None };
        render(cpu, cpu, camera, &settings).traced().map(|(_, c)| c).collect()
    }
}
