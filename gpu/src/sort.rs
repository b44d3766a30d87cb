//! A stable GPU radix sort of (key, value) pairs of u32 (shaders/radix_sort.wgsl): four bits a
//! pass, least significant first, so pairs of equal keys keep their order, as the LBVH needs
//! (equal Morton codes stay in triangle order).

use crate::device::{Gpu, GpuError};
use crate::kernel::{Bind, Kernel};
use crate::scan::Scan;
use std::sync::Arc;

/// Pairs per tile (one workgroup).
const TILE: u32 = 4096;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct SortParams {
    pub(crate) n: u32,
    pub(crate) shift: u32,
    pub(crate) tiles: u32,
    pub(crate) pad: u32,
}

pub(crate) struct RadixSort {
    histogram: Arc<Kernel>,
    scatter: Arc<Kernel>,
    scan: Scan,
}

/// The buffers a sort of `n` pairs needs besides its keys and values (and their twins).
pub(crate) struct SortScratch {
    offsets: wgpu::Buffer,
    scan: wgpu::Buffer,
}

impl RadixSort {
    pub(crate) fn new(gpu: &Gpu) -> Result<RadixSort, GpuError> {
        let src = crate::shaders::source("radix_sort.wgsl");
        let binds = [Bind::Uniform, Bind::Read, Bind::Read, Bind::ReadWrite, Bind::ReadWrite, Bind::ReadWrite];
        let k = |entry: &'static str| {
            gpu.compiled(format!("sort {entry}"), || Kernel::new(gpu, entry, src, entry, &binds, &[]))
        };
        Ok(RadixSort { histogram: k("histogram")?, scatter: k("scatter")?, scan: Scan::new(gpu)? })
    }

    fn counters(n: u32) -> u32 {
        16 * n.div_ceil(TILE).max(1) + 1
    }

    /// The (name, bytes) of the scratch buffers for `n` pairs, for checking limits first.
    pub(crate) fn scratch_sizes(n: u32) -> [(&'static str, u64); 2] {
        let c = Self::counters(n);
        [("the sort's digit counts", c as u64 * 4), ("the sort's scan sums", Scan::scratch_bytes(c))]
    }

    pub(crate) fn scratch(gpu: &Gpu, n: u32) -> Result<SortScratch, GpuError> {
        let [(a, ab), (b, bb)] = Self::scratch_sizes(n);
        Ok(SortScratch { offsets: gpu.storage(a, ab)?, scan: gpu.storage(b, bb)? })
    }

    /// Record the sort of the first `n` pairs of (`keys`, `vals`) by the low `bits` bits of the
    /// keys (rounded up to whole passes of four); `tmp_keys` and `tmp_vals` hold as many. The
    /// sorted pairs end in `keys` and `vals`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        n: u32,
        bits: u32,
        keys: &wgpu::Buffer,
        vals: &wgpu::Buffer,
        tmp_keys: &wgpu::Buffer,
        tmp_vals: &wgpu::Buffer,
        scratch: &SortScratch,
    ) {
        let tiles = n.div_ceil(TILE).max(1);
        let grid = gpu.grid(tiles, 1);
        let passes = bits.div_ceil(4);
        for pass in 0..passes {
            let (ki, vi, ko, vo) =
                if pass % 2 == 0 { (keys, vals, tmp_keys, tmp_vals) } else { (tmp_keys, tmp_vals, keys, vals) };
            let p = gpu.uniform("sort parameters", &SortParams { n, shift: 4 * pass, tiles, pad: 0 });
            let bind = self.histogram.bind(gpu, &[&p, ki, vi, &scratch.offsets, ko, vo]);
            self.histogram.dispatch(encoder, &bind, grid);
            self.scan.record(gpu, encoder, &scratch.offsets, Self::counters(n), &scratch.scan);
            let bind = self.scatter.bind(gpu, &[&p, ki, vi, &scratch.offsets, ko, vo]);
            self.scatter.dispatch(encoder, &bind, grid);
        }
        if passes % 2 == 1 {
            encoder.copy_buffer_to_buffer(tmp_keys, 0, keys, 0, n as u64 * 4);
            encoder.copy_buffer_to_buffer(tmp_vals, 0, vals, 0, n as u64 * 4);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the standard library's stable sort, over sizes around the tile and block sizes,
    /// with few distinct keys (long runs of equal keys, whose order must be kept).
    #[test]
    fn sorts_pairs_stably_as_the_standard_library_does() {
        let Some(gpu) = crate::device::gpu_for_tests() else { return };
        let sort = RadixSort::new(&gpu).unwrap();
        let scan = Scan::new(&gpu).unwrap();
        let mut rng = bvhscope_core::random::Rng::new(99);
        let mut next = || (rng.next_u64() >> 32) as u32;
        for (n, range, bits) in [
            (1u32, 16u32, 4u32),
            (300, 7, 8),
            (4096, 1 << 30, 30),
            (4097, 50, 30),
            (70_001, 1 << 20, 30),
            (20_000, 3, 5),
        ] {
            let keys: Vec<u32> = (0..n).map(|_| next() % range).collect();
            let vals: Vec<u32> = (0..n).collect();
            let (k, v) = (gpu.upload("k", &keys).unwrap(), gpu.upload("v", &vals).unwrap());
            let (tk, tv) = (gpu.storage("tk", n as u64 * 4).unwrap(), gpu.storage("tv", n as u64 * 4).unwrap());
            let scratch = RadixSort::scratch(&gpu, n).unwrap();
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            sort.record(&gpu, &mut enc, n, bits, &k, &v, &tk, &tv, &scratch);
            gpu.queue.submit([enc.finish()]);
            let (gk, gv) = (gpu.download::<u32>(&k, n as usize).unwrap(), gpu.download::<u32>(&v, n as usize).unwrap());
            let mut want: Vec<(u32, u32)> = keys.iter().copied().zip(vals).collect();
            want.sort_by_key(|p| p.0);
            assert!(gk.iter().copied().eq(want.iter().map(|p| p.0)), "{n} keys sorted");
            assert!(gv.iter().copied().eq(want.iter().map(|p| p.1)), "{n}: equal keys keep their order");
        }
        // The scan on its own, with the total at the end.
        let data: Vec<u32> = (0..10_000).map(|i| i % 7).chain([0]).collect();
        let buf = gpu.upload("scan", &data).unwrap();
        let scratch = gpu.storage("sums", Scan::scratch_bytes(10_001)).unwrap();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        scan.record(&gpu, &mut enc, &buf, 10_001, &scratch);
        gpu.queue.submit([enc.finish()]);
        let got = gpu.download::<u32>(&buf, 10_001).unwrap();
        let want: Vec<u32> = data
            .iter()
            .scan(0, |s, &x| {
                let r = *s;
                *s += x;
                Some(r)
            })
            .collect();
        assert_eq!(got, want);
    }
}
