//! PLOC on the GPU (Meister & Bittner, "Parallel Locally-Ordered Clustering for Bounding Volume
//! Hierarchy Construction", TVCG 2018), with core's `bvh::ploc` rules, so that it clusters exactly
//! as core does and the tree is core's PLOC tree node for node: the Morton order of the LBVH build
//! (`GpuLbvh::morton_order`), then rounds of nearest-neighbour search, merging of mutual pairs and
//! compaction on the GPU (shaders/ploc.wgsl), then, on the host, core's bottom-up choice of leaves
//! under the SAH and its layout (O(n), after the clustered tree is read back).

use crate::device::{Gpu, GpuError};
use crate::kernel::KernelSet;
use crate::lbvh::{morton_sizes, GpuBuildTimings, GpuLbvh, MAX_TRIANGLES};
use crate::scan::Scan;
use bvhscope_core::bvh::params::{MAX_LEAF_SIZE, PLOC_RADIUS, TRAVERSAL_COST};
use bvhscope_core::bvh::{BuildParams, BuildReport, Bvh, BvhNode, Strategy};
use bvhscope_core::geometry::Aabb;
use bvhscope_core::mesh::Mesh;
use glam::Vec3;
use std::time::Instant;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct PParams {
    pub(crate) count: u32,
    pub(crate) radius: u32,
    pub(crate) n: u32,
    pub(crate) never: u32,
}

const LEAF: u32 = u32::MAX;

/// Each kernel and the bindings it uses (shaders/ploc.wgsl numbers them).
const KERNELS: [(&str, &[u32]); 5] = [
    ("init", &[0, 1, 2, 3, 4, 9]),
    ("nearest_neighbours", &[0, 3, 5]),
    ("mutual", &[0, 5, 10]),
    ("keep_flags", &[0, 5, 6]),
    ("compact", &[0, 3, 4, 5, 6, 7, 8, 9, 10]),
];

/// The PLOC module: the builders' boxes, then its kernels.
pub(crate) fn source() -> String {
    crate::kernel::module(&[crate::shaders::source("boxes.wgsl"), crate::shaders::source("ploc.wgsl")])
}

/// The buffers of a PLOC build over `n` triangles (besides the Morton order's).
fn buffer_sizes(n: u64) -> Vec<(&'static str, u64)> {
    vec![
        ("PLOC's cluster boxes", 24 * n),
        ("PLOC's second cluster boxes", 24 * n),
        ("PLOC's clusters", 4 * n),
        ("PLOC's second clusters", 4 * n),
        ("PLOC's nearest neighbours", 4 * n),
        ("PLOC's places", 4 * (n + 1)),
        ("PLOC's nodes", 32 * (2 * n.max(1) - 1)),
        ("PLOC's scan sums", Scan::scratch_bytes(n as u32 + 1)),
    ]
}

/// The PLOC builder's kernels on one device (and the LBVH's, for the Morton order).
pub struct GpuPloc {
    lbvh: GpuLbvh,
    kernels: KernelSet,
    scan: Scan,
}

/// A node of the clustered tree as read back: its box and children (LEAF: a primitive's slot).
struct ClusterNode {
    bounds: Aabb,
    left: u32,
    right: u32,
}

/// core's `ploc::layout`: leaves where a subtree of at most `max_leaf` primitives is cheaper
/// as one, then the nodes depth first, each node's children a pair; the primitive order of the
/// leaves. Merged nodes come after their children (`compact` numbers them round by round).
fn layout(nodes: &[ClusterNode], root: u32, params: &BuildParams) -> (Vec<BvhNode>, Vec<u32>) {
    let ci = params.cost.intersection as f64;
    let mut count = vec![0u32; nodes.len()];
    let mut cost = vec![0f64; nodes.len()];
    let mut leaf = vec![false; nodes.len()];
    for (k, c) in nodes.iter().enumerate() {
        let area = c.bounds.area() as f64;
        if c.left == LEAF {
            (count[k], cost[k], leaf[k]) = (1, ci * area, true);
            continue;
        }
        let (l, r) = (c.left as usize, c.right as usize);
        count[k] = count[l] + count[r];
        (cost[k], leaf[k]) = params.cost.leaf_or_split(area, count[k], cost[l] + cost[r], params.max_leaf_size);
    }
    let mut out = vec![BvhNode::leaf(Aabb::EMPTY, 0, 0)];
    let mut order: Vec<u32> = Vec::with_capacity(count[root as usize] as usize);
    let mut stack = vec![(root, 0usize)];
    let mut under = Vec::new();
    while let Some((k, slot)) = stack.pop() {
        let c = &nodes[k as usize];
        if leaf[k as usize] {
            let first = order.len() as u32;
            under.clear();
            under.push(k);
            while let Some(u) = under.pop() {
                let cu = &nodes[u as usize];
                if cu.left == LEAF {
                    order.push(cu.right);
                } else {
                    under.extend([cu.right, cu.left]);
                }
            }
            out[slot] = BvhNode::leaf(c.bounds, first, count[k as usize] as u16);
            continue;
        }
        let left = out.len();
        out.extend([BvhNode::leaf(Aabb::EMPTY, 0, 0); 2]);
        // The widest axis: clusters are not split on a plane (core's PLOC names the same).
        out[slot] = BvhNode::interior(c.bounds, left as u32, c.bounds.widest_axis() as u8);
        stack.push((c.right, left + 1));
        stack.push((c.left, left));
    }
    (out, order)
}

impl GpuPloc {
    pub fn new(gpu: &Gpu) -> Result<GpuPloc, GpuError> {
        let kernels = KernelSet::new(gpu, "ploc", &source(), &KERNELS, 2)?;
        Ok(GpuPloc { lbvh: GpuLbvh::new(gpu)?, kernels, scan: Scan::new(gpu)? })
    }

    /// Refuse a mesh whose build would pass one storage buffer's limit, naming the buffer.
    pub fn check_size(gpu: &Gpu, triangles: usize) -> Result<(), GpuError> {
        if triangles > MAX_TRIANGLES {
            return Err(GpuError::Input(format!(
                "the GPU PLOC takes at most {MAX_TRIANGLES} triangles ({triangles} given)"
            )));
        }
        let n = triangles as u64;
        morton_sizes(n)
            .iter()
            .map(|&(_, w, b)| (w, b))
            .chain(buffer_sizes(n))
            .try_for_each(|(w, b)| gpu.check_size(w, b))
    }

    fn record(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, entry: &str, bufs: &[&wgpu::Buffer], threads: u32) {
        self.kernels.record(gpu, enc, entry, |b| bufs[b as usize], threads);
    }

    /// Build core's PLOC tree of `mesh` with `params` (its leaf size, SAH costs and radius).
    /// Timings: `emission` is the clustering rounds on the GPU, `boxes` the leaves and layout on
    /// the host, `download` the read-back of the clustered tree and the triangles' gathering.
    pub fn build(&self, gpu: &Gpu, mesh: &Mesh, params: &BuildParams) -> Result<(Bvh, GpuBuildTimings), GpuError> {
        let mut params = BuildParams {
            strategy: Strategy::Ploc,
            max_leaf_size: MAX_LEAF_SIZE.clamp(params.max_leaf_size),
            ploc_radius: PLOC_RADIUS.clamp(params.ploc_radius),
            ..*params
        };
        params.cost.traversal = TRAVERSAL_COST.clamp(params.cost.traversal);
        let n = mesh.triangle_count();
        let mut t = GpuBuildTimings::default();
        if n == 0 {
            let nodes = vec![BvhNode::leaf(Aabb::EMPTY, 0, 0)];
            return Ok((Bvh { nodes, prim_ids: vec![], tris: vec![], params, report: BuildReport::default() }, t));
        }
        Self::check_size(gpu, n)?;
        let morton = self.lbvh.morton_order(gpu, mesh, params.max_leaf_size, &mut t)?;
        let start = Instant::now();
        let sizes = buffer_sizes(n as u64);
        let made: Vec<wgpu::Buffer> = sizes.iter().map(|&(w, b)| gpu.storage(w, b)).collect::<Result<_, _>>()?;
        let p = gpu.uniform(
            "PLOC parameters",
            &PParams { count: n as u32, radius: params.ploc_radius, n: n as u32, never: 0 },
        );
        let stats = gpu.upload("PLOC's counters", &[0u32, n as u32])?;
        let tris = morton[1].as_ref().expect("made by morton_order");
        let vals = morton[3].as_ref().expect("made by morton_order");
        // Bindings 0..=10; rounds alternate which box and cluster buffers are read and written.
        let bufs = |flip: bool| -> Vec<&wgpu::Buffer> {
            let (bi, bo, ci, co) = if flip { (1, 0, 3, 2) } else { (0, 1, 2, 3) };
            vec![&p, tris, vals, &made[bi], &made[ci], &made[4], &made[5], &made[bo], &made[co], &made[6], &stats]
        };
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.record(gpu, &mut enc, "init", &bufs(false), n as u32);
        gpu.queue.submit([enc.finish()]);
        let (mut count, mut flip) = (n as u32, false);
        let mut rounds = 0;
        while count > 1 {
            rounds += 1;
            let pp = PParams { count, radius: params.ploc_radius, n: n as u32, never: 0 };
            gpu.queue.write_buffer(&p, 0, bytemuck::bytes_of(&pp));
            gpu.queue.write_buffer(&stats, 0, bytemuck::bytes_of(&0u32));
            let b = bufs(flip);
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            self.record(gpu, &mut enc, "nearest_neighbours", &b, count);
            self.record(gpu, &mut enc, "mutual", &b, count);
            gpu.queue.submit([enc.finish()]);
            let r = gpu.download_bytes(&[(&stats, 4), (&made[4], 4)])?;
            if r[0] == [0; 4] {
                // core's rule for a round without a mutual pair (equal areas): the first cluster
                // and its nearest are made mutual.
                let j = u32::from_le_bytes(r[1][..4].try_into().expect("4 bytes"));
                gpu.queue.write_buffer(&made[4], j as u64 * 4, bytemuck::bytes_of(&0u32));
            }
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            self.record(gpu, &mut enc, "keep_flags", &b, count + 1);
            self.scan.record(gpu, &mut enc, &made[5], count + 1, &made[7]);
            self.record(gpu, &mut enc, "compact", &b, count);
            gpu.queue.submit([enc.finish()]);
            let next = gpu.download_at(&made[5], 4 * count as u64, 4)?;
            count = u32::from_le_bytes(next[..4].try_into().expect("4 bytes"));
            flip = !flip;
        }
        t.emission = start.elapsed();
        t.rounds = rounds;

        let start = Instant::now();
        let node_count = 2 * n as u64 - 1;
        let root_buf = if flip { &made[3] } else { &made[2] };
        let data = gpu.download_bytes(&[(&made[6], 32 * node_count), (vals, 4 * n as u64), (root_buf, 4)])?;
        let words: Vec<[u32; 8]> = bytemuck::pod_collect_to_vec(&data[0]);
        let sorted: Vec<u32> = bytemuck::pod_collect_to_vec(&data[1]);
        let root = u32::from_le_bytes(data[2][..4].try_into().expect("4 bytes"));
        let nodes: Vec<ClusterNode> = words
            .iter()
            .map(|w| {
                let f = |i: usize| f32::from_bits(w[i]);
                ClusterNode {
                    bounds: Aabb::new(Vec3::new(f(0), f(1), f(2)), Vec3::new(f(3), f(4), f(5))),
                    left: w[6],
                    right: w[7],
                }
            })
            .collect();
        t.download = start.elapsed();
        let start = Instant::now();
        let (bvh_nodes, order) = layout(&nodes, root, &params);
        let prim_ids: Vec<u32> = order.iter().map(|&slot| sorted[slot as usize]).collect();
        let tris = prim_ids.iter().map(|&i| mesh.triangle(i)).collect();
        t.boxes = start.elapsed();
        let report = BuildReport {
            setup_time: t.upload + t.codes,
            split_time: t.sort + t.emission + t.boxes,
            reorder_time: t.download,
            ..BuildReport::default()
        };
        let bvh = crate::verify::verified("PLOC", Bvh { nodes: bvh_nodes, prim_ids, tris, params, report }, mesh)?;
        Ok((bvh, t))
    }
}
