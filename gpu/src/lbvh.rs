//! The LBVH built on the GPU (Lauterbach et al., "Fast BVH Construction on GPUs", EG 2009; the
//! hierarchy by Karras's parallel emission, HPG 2012), node for node the tree core's
//! `bvh::lbvh` builds, downloaded as a `Bvh`.
//!
//! Phases, each timed: codes (the centroids' bounds on the GPU, the grid from them on the host as
//! core computes it, each triangle's 30-bit code), sort (a stable radix sort of code–triangle
//! pairs, so equal codes stay in triangle order), emission (runs of equal codes, Karras's tree
//! over the distinct codes, where core's leaves start), boxes (bottom-up with atomic counters,
//! checked, and every node written where core puts it), download (nodes and primitive ids read
//! back, the triangles gathered in leaf order on the host). Every buffer is sized from the
//! triangle count and checked against the adapter's limit before anything is uploaded.

use crate::device::{Gpu, GpuError};
use crate::kernel::KernelSet;
use crate::scan::Scan;
use crate::sort::RadixSort;
use bvhscope_core::bvh::params::MAX_LEAF_SIZE;
use bvhscope_core::bvh::{BuildParams, BuildReport, Bvh, BvhNode, Strategy};
use bvhscope_core::geometry::Aabb;
use bvhscope_core::mesh::Mesh;
use std::time::{Duration, Instant};

/// How long each phase of a GPU build took (wall time on the host, each phase waited for).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GpuBuildTimings {
    /// The triangles to the GPU.
    pub upload: Duration,
    pub codes: Duration,
    pub sort: Duration,
    pub emission: Duration,
    pub boxes: Duration,
    /// Nodes and ids back, triangles gathered into leaf order.
    pub download: Duration,
    /// LBVH: passes of the box check (1 when no parent read a sibling's box early).
    pub verify_passes: u32,
    /// PLOC: clustering rounds.
    pub rounds: u32,
}

impl GpuBuildTimings {
    pub fn total(&self) -> Duration {
        self.upload + self.codes + self.sort + self.emission + self.boxes + self.download
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct LParams {
    pub(crate) lo: [f32; 4],
    pub(crate) scale: [f32; 4],
    pub(crate) n: u32,
    pub(crate) max_leaf: u32,
    pub(crate) pad: [u32; 2],
}

/// The LBVH builder's kernels on one device.
pub struct GpuLbvh {
    kernels: KernelSet,
    sort: RadixSort,
    scan: Scan,
}

/// Each kernel and the bindings it uses (shaders/lbvh.wgsl numbers them).
const KERNELS: [(&str, &[u32]); 9] = [
    ("bounds", &[0, 1, 4]),
    ("codes", &[0, 1, 2, 3]),
    ("run_flags", &[0, 2, 5]),
    ("runs", &[0, 2, 5, 6, 7]),
    ("karras", &[0, 4, 5, 6, 7, 8]),
    ("leaf_flags", &[0, 5, 8, 11]),
    ("boxes", &[0, 1, 3, 5, 8, 9, 10]),
    ("verify", &[0, 4, 5, 8, 9]),
    ("emit", &[0, 1, 3, 5, 8, 9, 11, 12]),
];

/// The most triangles one build takes: Morton order is kept in u32 indices and the scans' second
/// pass runs in one workgroup.
pub const MAX_TRIANGLES: usize = 1 << 28;

/// The buffers of the Morton order (upload, codes, sort) over `n` triangles: (binding, what,
/// bytes); shared by the LBVH and PLOC builds.
pub(crate) fn morton_sizes(n: u64) -> Vec<(Option<u32>, &'static str, u64)> {
    let mut v = vec![
        (Some(1), "the build's triangles", 36 * n),
        (Some(2), "the build's Morton codes", 4 * n),
        (Some(3), "the build's primitive order", 4 * n),
        (None, "the sort's second code buffer", 4 * n),
        (None, "the sort's second order buffer", 4 * n),
        (Some(4), "the build's counters", 32),
    ];
    for (what, bytes) in RadixSort::scratch_sizes(n as u32) {
        v.push((None, what, bytes));
    }
    v
}

/// The buffers of an LBVH build over `n` triangles.
fn buffer_sizes(n: u64) -> Vec<(Option<u32>, &'static str, u64)> {
    let nodes = 2 * n.max(1) - 1;
    let mut v = morton_sizes(n);
    v.extend([
        (Some(5), "the LBVH's runs of equal codes", 4 * (n + 1)),
        (Some(6), "the LBVH's run starts", 4 * (n + 1)),
        (Some(7), "the LBVH's run codes", 4 * n),
        (Some(8), "the LBVH's Karras nodes", 24 * nodes),
        (Some(9), "the LBVH's Karras boxes", 24 * nodes),
        (Some(10), "the LBVH's arrival counters", 4 * n),
        (Some(11), "the LBVH's leaf starts", 4 * (n + 1)),
        (Some(12), "the LBVH's output nodes", 32 * nodes),
        (None, "the scans' sums", Scan::scratch_bytes(n as u32 + 1)),
    ]);
    v
}

/// The mesh's triangles as nine floats each, in mesh order.
pub(crate) fn triangle_floats(mesh: &Mesh) -> Vec<[f32; 9]> {
    (0..mesh.triangle_count() as u32)
        .map(|i| {
            let [a, b, c] = mesh.triangle(i);
            [a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z]
        })
        .collect()
}

/// The LBVH's WGSL module: the builders' boxes, then its kernels.
pub(crate) fn source() -> String {
    crate::kernel::module(&[crate::shaders::source("boxes.wgsl"), crate::shaders::source("lbvh.wgsl")])
}

/// Decode `lbvh.wgsl`'s `ordered` words.
fn unordered(u: u32) -> f32 {
    f32::from_bits(if u & 0x8000_0000 != 0 { u & 0x7fff_ffff } else { !u })
}

impl GpuLbvh {
    pub fn new(gpu: &Gpu) -> Result<GpuLbvh, GpuError> {
        let kernels = KernelSet::new(gpu, "lbvh", &source(), &KERNELS, 1)?;
        Ok(GpuLbvh { kernels, sort: RadixSort::new(gpu)?, scan: Scan::new(gpu)? })
    }

    /// Refuse a mesh whose build would pass one storage buffer's limit, naming the buffer.
    pub fn check_size(gpu: &Gpu, triangles: usize) -> Result<(), GpuError> {
        if triangles > MAX_TRIANGLES {
            return Err(GpuError::Input(format!(
                "the GPU LBVH takes at most {MAX_TRIANGLES} triangles ({triangles} given)"
            )));
        }
        buffer_sizes(triangles as u64).iter().try_for_each(|&(_, what, bytes)| gpu.check_size(what, bytes))
    }

    fn record(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        entry: &str,
        bufs: &[Option<wgpu::Buffer>],
        threads: u32,
    ) {
        let buffer = |b: u32| bufs[b as usize].as_ref().expect("every bound buffer is made");
        self.kernels.record(gpu, enc, entry, buffer, threads);
    }

    /// Upload `mesh`'s triangles and sort them by Morton code as core's LBVH does (phases upload,
    /// codes, sort): the buffers at bindings 0 (parameters), 1 (triangles), 2 (sorted codes), 3
    /// (triangle order) and 4 (counters); the caller has checked the sizes.
    pub(crate) fn morton_order(
        &self,
        gpu: &Gpu,
        mesh: &Mesh,
        max_leaf: u32,
        t: &mut GpuBuildTimings,
    ) -> Result<Vec<Option<wgpu::Buffer>>, GpuError> {
        let n32 = mesh.triangle_count() as u32;
        let start = Instant::now();
        let sizes = morton_sizes(n32 as u64);
        let mut bufs: Vec<Option<wgpu::Buffer>> = (0..13).map(|_| None).collect();
        bufs[1] = Some(gpu.upload(sizes[0].1, &triangle_floats(mesh))?);
        bufs[2] = Some(gpu.storage(sizes[1].1, sizes[1].2)?);
        bufs[3] = Some(gpu.storage(sizes[2].1, sizes[2].2)?);
        let stats = [u32::MAX, u32::MAX, u32::MAX, 0, 0, 0, 0, 0];
        bufs[4] = Some(gpu.upload(sizes[5].1, &stats)?);
        let tmp_keys = gpu.storage(sizes[3].1, sizes[3].2)?;
        let tmp_vals = gpu.storage(sizes[4].1, sizes[4].2)?;
        let sort_scratch = RadixSort::scratch(gpu, n32)?;
        let mut p = LParams { lo: [0.0; 4], scale: [0.0; 4], n: n32, max_leaf, pad: [0; 2] };
        bufs[0] = Some(gpu.uniform("LBVH parameters", &p));
        gpu.wait()?;
        t.upload = start.elapsed();
        let buf = |bufs: &[Option<wgpu::Buffer>], i: usize| bufs[i].as_ref().expect("made above").clone();

        // Codes: the centroids' bounds, the grid as core's morton::grid makes it, the codes.
        let start = Instant::now();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.record(gpu, &mut enc, "bounds", &bufs, n32);
        gpu.queue.submit([enc.finish()]);
        let words: Vec<u32> = gpu.download(&buf(&bufs, 4), 6)?;
        let (lo, hi): (Vec<f32>, Vec<f32>) =
            (words[..3].iter().map(|&u| unordered(u)).collect(), words[3..].iter().map(|&u| unordered(u)).collect());
        for k in 0..3 {
            let extent = hi[k] - lo[k];
            p.lo[k] = lo[k];
            p.scale[k] = if extent > 0.0 { 1023.0 / extent } else { 0.0 };
        }
        gpu.queue.write_buffer(&buf(&bufs, 0), 0, bytemuck::bytes_of(&p));
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.record(gpu, &mut enc, "codes", &bufs, n32);
        gpu.queue.submit([enc.finish()]);
        gpu.wait()?;
        t.codes = start.elapsed();

        let start = Instant::now();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.sort.record(gpu, &mut enc, n32, 30, &buf(&bufs, 2), &buf(&bufs, 3), &tmp_keys, &tmp_vals, &sort_scratch);
        gpu.queue.submit([enc.finish()]);
        gpu.wait()?;
        t.sort = start.elapsed();
        Ok(bufs)
    }

    /// Build core's LBVH of `mesh` with `params` (its `max_leaf_size`; reinsertion is left to the
    /// caller, as `Bvh::build` runs it after any builder).
    pub fn build(&self, gpu: &Gpu, mesh: &Mesh, params: &BuildParams) -> Result<(Bvh, GpuBuildTimings), GpuError> {
        let params = BuildParams {
            strategy: Strategy::Lbvh,
            max_leaf_size: MAX_LEAF_SIZE.clamp(params.max_leaf_size),
            ..*params
        };
        let n = mesh.triangle_count();
        let mut t = GpuBuildTimings::default();
        if n == 0 {
            // core's tree of an empty mesh: one empty leaf.
            let nodes = vec![BvhNode::leaf(Aabb::EMPTY, 0, 0)];
            return Ok((Bvh { nodes, prim_ids: vec![], tris: vec![], params, report: BuildReport::default() }, t));
        }
        Self::check_size(gpu, n)?;
        let n32 = n as u32;
        let mut bufs = self.morton_order(gpu, mesh, params.max_leaf_size, &mut t)?;
        for &(b, what, bytes) in &buffer_sizes(n as u64) {
            if let Some(b) = b.filter(|&b| b > 4) {
                bufs[b as usize] = Some(gpu.storage(what, bytes)?);
            }
        }
        let scan_scratch = gpu.storage("the scans' sums", Scan::scratch_bytes(n32 + 1))?;
        let buf = |bufs: &[Option<wgpu::Buffer>], i: usize| bufs[i].as_ref().expect("made above").clone();

        let start = Instant::now();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.record(gpu, &mut enc, "run_flags", &bufs, n32 + 1);
        self.scan.record(gpu, &mut enc, &buf(&bufs, 5), n32 + 1, &scan_scratch);
        self.record(gpu, &mut enc, "runs", &bufs, n32);
        self.record(gpu, &mut enc, "karras", &bufs, n32);
        self.record(gpu, &mut enc, "leaf_flags", &bufs, 2 * n32 - 1);
        self.scan.record(gpu, &mut enc, &buf(&bufs, 11), n32 + 1, &scan_scratch);
        gpu.queue.submit([enc.finish()]);
        gpu.wait()?;
        t.emission = start.elapsed();

        let start = Instant::now();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.record(gpu, &mut enc, "boxes", &bufs, n32);
        gpu.queue.submit([enc.finish()]);
        loop {
            t.verify_passes += 1;
            if t.verify_passes > 64 {
                return Err(GpuError::Rejected(
                    "the LBVH's boxes did not settle in 64 passes (a bug: please report)".into(),
                ));
            }
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            self.record(gpu, &mut enc, "verify", &bufs, n32);
            gpu.queue.submit([enc.finish()]);
            let s: Vec<u32> = gpu.download(&buf(&bufs, 4), 8)?;
            if s[7] == 0 {
                break;
            }
            gpu.queue.write_buffer(&buf(&bufs, 4), 28, bytemuck::bytes_of(&0u32));
        }
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.record(gpu, &mut enc, "emit", &bufs, 2 * n32 - 1);
        gpu.queue.submit([enc.finish()]);
        gpu.wait()?;
        t.boxes = start.elapsed();

        let start = Instant::now();
        let leaves = gpu.download_bytes(&[(&buf(&bufs, 11), 4 * (n as u64 + 1)), (&buf(&bufs, 4), 32)])?;
        let leaf_count = u32::from_le_bytes(leaves[0][4 * n..4 * n + 4].try_into().expect("4 bytes"));
        let fallback = u32::from_le_bytes(leaves[1][24..28].try_into().expect("4 bytes"));
        let node_count = 2 * leaf_count as u64 - 1;
        let data = gpu.download_bytes(&[(&buf(&bufs, 12), 32 * node_count), (&buf(&bufs, 3), 4 * n as u64)])?;
        let words: Vec<[u32; 8]> = bytemuck::pod_collect_to_vec(&data[0]);
        let nodes = words
            .iter()
            .map(|w| {
                let f = |i: usize| f32::from_bits(w[i]);
                BvhNode {
                    lo: [f(0), f(1), f(2)],
                    hi: [f(3), f(4), f(5)],
                    index: w[6],
                    count: (w[7] & 0xffff) as u16,
                    axis: (w[7] >> 16) as u8,
                    _pad: 0,
                }
            })
            .collect();
        let prim_ids: Vec<u32> = bytemuck::pod_collect_to_vec(&data[1]);
        let tris = prim_ids.iter().map(|&i| mesh.triangle(i)).collect();
        t.download = start.elapsed();
        let report = BuildReport {
            setup_time: t.upload + t.codes,
            split_time: t.sort + t.emission + t.boxes,
            reorder_time: t.download,
            fallback_splits: fallback,
            ..BuildReport::default()
        };
        let bvh = crate::verify::verified("LBVH", Bvh { nodes, prim_ids, tris, params, report }, mesh)?;
        Ok((bvh, t))
    }
}
