//! What every GPU walk shares: the options, where rays come from (a camera's pixels, generated on
//! the GPU as core's `RayGen::pixel_ray` makes them, or a list), the traversal stack's variant, the
//! kernels compiled per variant, and the run in batches that fit the adapter's buffer limit, with
//! hits and counts read back in core's types.

use crate::device::{Gpu, GpuError};
use crate::kernel::{Bind, Kernel};
use crate::shaders::source;
use bvhscope_core::bvh::{Hit, RayCounters, TraversalOrder};
use bvhscope_core::geometry::{Ray, TriangleTest};
use bvhscope_core::render::Camera;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How a GPU walk runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct GpuTraceOptions {
    /// The near child's rule (binary nodes; CWBVH orders its children by octant instead).
    pub order: TraversalOrder,
    /// Keep and read back per-ray counts (core's `RayCounters`: nodes, box tests, leaves, triangles).
    pub counted: bool,
    /// Round every product on its own as the CPU does (see `xm` in shaders/common.wgsl); off, the
    /// compiler may fuse them (faster on some GPUs, results may differ in the last place).
    pub exact: bool,
    /// The ray–triangle test: core's watertight test or Möller–Trumbore's (the handout's).
    pub test: TriangleTest,
}

impl Default for GpuTraceOptions {
    fn default() -> Self {
        Self { order: TraversalOrder::EntryDistance, counted: true, exact: true, test: TriangleTest::Watertight }
    }
}

/// The rays of a GPU walk.
#[derive(Clone, Copy, Debug)]
pub enum Rays<'a> {
    /// One ray through each pixel's centre, row by row from the top (`Camera::ray_gen().pixel_ray`).
    Camera(&'a Camera),
    /// Any rays, each with its own interval.
    List(&'a [Ray]),
}

impl Rays<'_> {
    pub fn len(&self) -> usize {
        match self {
            Rays::Camera(c) => c.width as usize * c.height as usize,
            Rays::List(r) => r.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Ray `i`: the list's, or the camera's pixel `i` (row by row), as the GPU makes it.
    pub fn ray(&self, i: usize) -> Ray {
        match self {
            Rays::Camera(c) => c.ray_gen().pixel_ray(i as u32 % c.width, i as u32 / c.width),
            Rays::List(r) => r[i],
        }
    }
}

/// What a GPU walk found: per ray (per pixel, row by row, for a camera) its closest hit and,
/// when counted, its work.
#[derive(Clone, Debug, Default)]
pub struct GpuTrace {
    pub hits: Vec<Option<Hit>>,
    /// Empty unless the walk was counted.
    pub counters: Vec<RayCounters>,
    /// From submitting the walks to their end, read-backs left out (summed over batches).
    pub gpu_time: Duration,
    /// How many dispatches the rays took (more than one where a buffer would pass the limit).
    pub batches: u32,
    /// The rays (by index) whose walk reached the step budget (`STEP_BUDGET` in
    /// shaders/entry.wgsl) and stopped unfinished: their hit is `None` and their counts partial
    /// until the host finishes them on the CPU (`GpuTrace::finish`). Never a miss.
    pub unfinished: Vec<usize>,
    /// How many rays were finished on the CPU (`finish`).
    pub cpu_finished: usize,
}

/// The most steps one GPU walk may take (shaders/entry.wgsl's `STEP_BUDGET`): nodes visited (a
/// CWBVH node with its eight slots), stack entries popped and triangles tested.
pub const STEP_BUDGET: u32 = 16384;

impl GpuTrace {
    /// Finish the unfinished rays with `cpu`, the same walk on the CPU (the ray, by index, to its
    /// closest hit and counts), in parallel: afterwards every hit and count is the CPU's walk's.
    pub fn finish(&mut self, cpu: impl Fn(usize) -> (Option<Hit>, RayCounters) + Sync) {
        use rayon::prelude::*;
        let done: Vec<(Option<Hit>, RayCounters)> = self.unfinished.par_iter().map(|&i| cpu(i)).collect();
        for (&i, (hit, c)) in self.unfinished.iter().zip(done) {
            self.hits[i] = hit;
            if let Some(slot) = self.counters.get_mut(i) {
                *slot = c;
            }
        }
        self.cpu_finished += self.unfinished.len();
        self.unfinished.clear();
    }
}

/// The uniform block of shaders/common.wgsl (`Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct Params {
    pub(crate) origin: [f32; 4],
    pub(crate) forward: [f32; 4],
    pub(crate) right: [f32; 4],
    pub(crate) up: [f32; 4],
    pub(crate) root_lo: [f32; 4],
    pub(crate) root_hi: [f32; 4],
    pub(crate) inv_w: f32,
    pub(crate) inv_h: f32,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) count: u32,
    pub(crate) offset: u32,
    pub(crate) stack_stride: u32,
    pub(crate) never: u32,
}

/// The camera's ray generator as core's `Camera::ray_gen` makes it (`RayGen::parts`), for the GPU
/// to finish per pixel as `RayGen::pixel_ray` does.
fn camera_params(cam: &Camera) -> Result<Params, GpuError> {
    cam.validate().map_err(|e| GpuError::Input(e.to_string()))?;
    let g = cam.ray_gen().parts();
    let v = |v: glam::Vec3| [v.x, v.y, v.z, 0.0];
    Ok(Params {
        origin: v(g.origin),
        forward: v(g.forward),
        right: v(g.right),
        up: v(g.up),
        inv_w: g.inv_w,
        inv_h: g.inv_h,
        width: cam.width,
        height: cam.height,
        ..Params::default()
    })
}

/// The GPU form of a ray (shaders/common.wgsl's `RayIn`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct RayIn {
    pub(crate) o: [f32; 3],
    pub(crate) t_min: f32,
    pub(crate) d: [f32; 3],
    pub(crate) t_max: f32,
}

/// Where a walk keeps its stack: in private memory of a fixed size, or `stride` entries per
/// invocation in a global buffer (a tree deeper than any private stack here).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Stack {
    Private(u32),
    Global(u32),
}

/// Private stacks up to this many entries (1 KB per invocation); deeper walks use global memory.
const PRIVATE_MAX: u32 = 128;

impl Stack {
    /// The stack for walks that hold at most `entries` at once. A walk pushes at most one entry
    /// a step, so never more than the step budget: a 100,000-deep chain needs no 800 kB a ray.
    pub(crate) fn for_entries(entries: u32) -> Stack {
        match entries.min(STEP_BUDGET) {
            0..=32 => Stack::Private(32),
            33..=64 => Stack::Private(64),
            65..=PRIVATE_MAX => Stack::Private(PRIVATE_MAX),
            n => Stack::Global(n),
        }
    }

    fn stride(self) -> u32 {
        match self {
            Stack::Private(_) => 0,
            Stack::Global(n) => n,
        }
    }
}

/// A node format's kernels: its WGSL walk (defining `walk` and `prim_of`) compiled per stack
/// variant and options, once each.
pub(crate) struct Kernels {
    format: &'static str,
    /// Its walk's file in `shaders/` (a row of `shaders::SHADERS`).
    pub(crate) walk_file: &'static str,
}

impl Kernels {
    pub(crate) const fn new(format: &'static str, walk_file: &'static str) -> Kernels {
        Kernels { format, walk_file }
    }

    /// The whole module: shared parts, the adapter's edge fallback (doubles or not), the stack,
    /// the walk, the entries.
    pub(crate) fn source(&self, f64: bool, stack: Stack) -> String {
        let edge = if f64 { source("edge_f64.wgsl") } else { source("edge_f32.wgsl") };
        let stack_src = match stack {
            Stack::Private(n) => source("stack_private.wgsl").replace("{STACK_SIZE}", &n.to_string()),
            Stack::Global(_) => source("stack_global.wgsl").to_string(),
        };
        crate::kernel::module(&[
            source("common.wgsl"),
            source("triangle.wgsl"),
            edge,
            source("leaf.wgsl"),
            &stack_src,
            source(self.walk_file),
            source("entry.wgsl"),
        ])
    }

    /// The kernel for these options, binding `tree_buffers` buffers of the tree after the rays',
    /// compiled once. What a format's kernel needs is read from the format, never from its name:
    /// the tree's buffers are those its `trace` hands to `run`, and the traversal order is set
    /// where its walk declares `override BY_DISTANCE` (a walk that orders its children otherwise,
    /// as the CWBVH's by octant, does not).
    fn get(
        &self,
        gpu: &Gpu,
        stack: Stack,
        camera: bool,
        opts: GpuTraceOptions,
        tree_buffers: usize,
    ) -> Result<Arc<Kernel>, GpuError> {
        let key = format!("{} {stack:?} camera={camera} {opts:?} tree={tree_buffers}", self.format);
        gpu.compiled(key, || {
            let source = self.source(gpu.has_f64(), stack);
            let binds = [Bind::Uniform, Bind::Read, Bind::ReadWrite, Bind::ReadWrite, Bind::ReadWrite];
            let mut binds = binds.to_vec();
            binds.extend(std::iter::repeat_n(Bind::Read, tree_buffers));
            let by_distance = (opts.order == TraversalOrder::EntryDistance) as u8 as f64;
            // The shader's `TEST`: its index in core's list of tests, as `triangle.wgsl` numbers them.
            let test = TriangleTest::ALL.iter().position(|&t| t == opts.test).unwrap_or(0) as f64;
            let mut constants =
                vec![("COUNTED", opts.counted as u8 as f64), ("EXACT", opts.exact as u8 as f64), ("TEST", test)];
            if crate::shaders::source(self.walk_file).contains("override BY_DISTANCE") {
                constants.push(("BY_DISTANCE", by_distance));
            }
            let entry = if camera { "trace_camera" } else { "trace_list" };
            Kernel::new(gpu, &format!("{} {entry}", self.format), &source, entry, &binds, &constants)
        })
    }

    /// Trace `rays` against the tree in `tree` (bound from binding 5 on) with the stack `stack`;
    /// `root` is the tree's box for the formats whose walk tests it from the parameters.
    pub(crate) fn run(
        &self,
        gpu: &Gpu,
        tree: &[&wgpu::Buffer],
        root: Option<bvhscope_core::geometry::Aabb>,
        stack: Stack,
        rays: Rays,
        opts: GpuTraceOptions,
    ) -> Result<GpuTrace, GpuError> {
        let (root_lo, root_hi) = match root {
            Some(b) if !b.is_empty() => {
                let (lo, hi) = b.planes();
                ([lo[0], lo[1], lo[2], 1.0], [hi[0], hi[1], hi[2], 0.0])
            }
            _ => ([f32::INFINITY, f32::INFINITY, f32::INFINITY, 0.0], [f32::NEG_INFINITY; 4]),
        };
        let camera = matches!(rays, Rays::Camera(_));
        let kernel = self.get(gpu, stack, camera, opts, tree.len())?;
        let n = rays.len();
        let mut out = GpuTrace {
            hits: Vec::with_capacity(n),
            counters: Vec::with_capacity(if opts.counted { n } else { 0 }),
            ..GpuTrace::default()
        };
        // Bytes per ray in each buffer the batch allocates; the largest decides the batch.
        let stride = stack.stride() as u64;
        let per_ray = [16u64, 32, if opts.counted { 16 } else { 0 }, stride * 8];
        let worst = per_ray.iter().copied().max().unwrap_or(16);
        let max_rays = gpu.max_buffer_bytes() / worst;
        if max_rays == 0 {
            return Err(match stack {
                Stack::Global(depth) => GpuError::TooDeep { depth, bytes: stride * 8, limit: gpu.max_buffer_bytes() },
                Stack::Private(_) => {
                    gpu.check_size("one ray's results", worst).err().unwrap_or(GpuError::Input("no room".into()))
                }
            });
        }
        let dummy = gpu.storage("unused", 16)?;
        match rays {
            Rays::Camera(cam) => {
                let base = camera_params(cam)?;
                let rows_per = (max_rays / cam.width as u64).min(cam.height as u64);
                if rows_per == 0 {
                    gpu.check_size("one row of the frame's results", cam.width as u64 * worst)?;
                }
                let mut row = 0;
                while row < cam.height {
                    let rows = (rows_per as u32).min(cam.height - row);
                    let p = Params { count: rows, offset: row, stack_stride: stack.stride(), root_lo, root_hi, ..base };
                    let groups = (cam.width.div_ceil(8), rows.div_ceil(8));
                    self.batch(
                        gpu,
                        &kernel,
                        tree,
                        &dummy,
                        p,
                        groups,
                        (cam.width * rows) as usize,
                        stack,
                        opts,
                        &mut out,
                    )?;
                    row += rows;
                }
            }
            Rays::List(list) => {
                for chunk in list.chunks(max_rays.min(u32::MAX as u64 / 2) as usize) {
                    let up: Vec<RayIn> = chunk
                        .iter()
                        .map(|r| RayIn { o: r.origin().into(), t_min: r.t_min, d: r.dir().into(), t_max: r.t_max })
                        .collect();
                    let rays_buf = gpu.upload("rays", &up)?;
                    let p = Params {
                        count: chunk.len() as u32,
                        stack_stride: stack.stride(),
                        root_lo,
                        root_hi,
                        ..Params::default()
                    };
                    let groups = gpu.grid(chunk.len() as u32, 64);
                    self.batch(gpu, &kernel, tree, &rays_buf, p, groups, chunk.len(), stack, opts, &mut out)?;
                }
            }
        }
        Ok(out)
    }

    /// One dispatch over `n` rays and the read-back of its results into `out`.
    #[allow(clippy::too_many_arguments)]
    fn batch(
        &self,
        gpu: &Gpu,
        kernel: &Kernel,
        tree: &[&wgpu::Buffer],
        rays: &wgpu::Buffer,
        p: Params,
        groups: (u32, u32),
        n: usize,
        stack: Stack,
        opts: GpuTraceOptions,
        out: &mut GpuTrace,
    ) -> Result<(), GpuError> {
        let params = gpu.uniform("trace parameters", &p);
        let hits = gpu.storage("hits", n as u64 * 16)?;
        let counts =
            if opts.counted { gpu.storage("counts", n as u64 * 16)? } else { gpu.storage("counts (unused)", 16)? };
        let gstack = match stack {
            Stack::Global(stride) => gpu.storage("traversal stack", n as u64 * stride as u64 * 8)?,
            Stack::Private(_) => gpu.storage("traversal stack (unused)", 16)?,
        };
        let mut buffers = vec![&params, rays, &hits, &counts, &gstack];
        buffers.extend_from_slice(tree);
        let bind = kernel.bind(gpu, &buffers);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        kernel.dispatch(&mut encoder, &bind, groups);
        // The rays' and parameters' writes go with the next submission: flush them first, so the
        // time is the walk's.
        gpu.queue.submit([]);
        gpu.wait()?;
        let start = Instant::now();
        gpu.queue.submit([encoder.finish()]);
        gpu.wait()?;
        out.gpu_time += start.elapsed();
        out.batches += 1;
        let mut parts = vec![(&hits, n as u64 * 16)];
        if opts.counted {
            parts.push((&counts, n as u64 * 16));
        }
        let data = gpu.download_bytes(&parts)?;
        let h: Vec<[u32; 4]> = bytemuck::pod_collect_to_vec(&data[0]);
        for [t, u, v, prim] in h {
            match prim {
                u32::MAX => out.hits.push(None),
                0xffff_fffd => {
                    out.unfinished.push(out.hits.len());
                    out.hits.push(None)
                }
                0xffff_fffe => {
                    return Err(GpuError::Rejected(
                        "a ray's walk passed the end of its stack (a bug: please report)".into(),
                    ))
                }
                _ => {
                    out.hits.push(Some(Hit { t: f32::from_bits(t), u: f32::from_bits(u), v: f32::from_bits(v), prim }))
                }
            }
        }
        if opts.counted {
            let c: Vec<[u32; 4]> = bytemuck::pod_collect_to_vec(&data[1]);
            out.counters.extend(c.into_iter().map(|[nodes, boxes, leaves, tris]| RayCounters {
                nodes_visited: nodes,
                box_tests: boxes,
                leaves_visited: leaves,
                triangle_tests: tris,
                ..RayCounters::ZERO
            }));
        }
        Ok(())
    }
}
