//! Moving data to and from the GPU: storage buffers made from slices (checked against the
//! adapter's limit before anything is uploaded), uniforms, and read-backs through a mapped
//! staging buffer.

use crate::device::{Gpu, GpuError};
use bytemuck::Pod;

/// Storage buffers are never empty: a binding of zero bytes is invalid, and an empty mesh or ray
/// list still binds its arrays, and a binding must hold one element of its array (80 bytes for a
/// CWBVH node).
const MIN_BYTES: u64 = 256;

fn padded(bytes: u64) -> u64 {
    bytes.max(MIN_BYTES).next_multiple_of(4)
}

impl Gpu {
    /// A storage buffer holding `data` (read and written by kernels, copied from and to), or a
    /// `TooLarge` error naming `what` when one buffer cannot hold it here.
    pub fn upload<T: Pod>(&self, what: &str, data: &[T]) -> Result<wgpu::Buffer, GpuError> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        self.check_size(what, bytes.len() as u64)?;
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        Ok(self.filled(what, bytes, usage))
    }

    /// A buffer of `bytes` (padded), written through the queue: a buffer mapped at creation
    /// panics in wgpu when the device is lost, a queued write reports an error.
    fn filled(&self, what: &str, bytes: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
        let size = padded(bytes.len() as u64);
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(what),
            size,
            usage,
            mapped_at_creation: false,
        });
        if bytes.len() as u64 == size {
            self.queue.write_buffer(&buffer, 0, bytes);
        } else {
            let mut v = bytes.to_vec();
            v.resize(size as usize, 0);
            self.queue.write_buffer(&buffer, 0, &v);
        }
        buffer
    }

    /// A zero-filled storage buffer of `bytes` (kernels write it; it can be read back).
    pub fn storage(&self, what: &str, bytes: u64) -> Result<wgpu::Buffer, GpuError> {
        self.check_size(what, bytes)?;
        Ok(self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(what),
            size: padded(bytes),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }))
    }

    /// A uniform buffer holding `value`.
    pub fn uniform<T: Pod>(&self, what: &str, value: &T) -> wgpu::Buffer {
        self.filled(what, bytemuck::bytes_of(value), wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST)
    }

    /// The first `count` elements of `buffer`, read back (waits for the queue's work).
    pub fn download<T: Pod>(&self, buffer: &wgpu::Buffer, count: usize) -> Result<Vec<T>, GpuError> {
        let bytes = (count * std::mem::size_of::<T>()) as u64;
        let mut out = self.download_bytes(&[(buffer, bytes)])?;
        Ok(bytemuck::pod_collect_to_vec(&out.remove(0)))
    }

    /// `bytes` of `buffer` from `offset` (both multiples of 4), read back.
    pub fn download_at(&self, buffer: &wgpu::Buffer, offset: u64, bytes: u64) -> Result<Vec<u8>, GpuError> {
        Ok(self.read_back(&[(buffer, offset, bytes)])?.remove(0))
    }

    /// Several buffers' first bytes read back through one staging buffer and one submission.
    pub fn download_bytes(&self, parts: &[(&wgpu::Buffer, u64)]) -> Result<Vec<Vec<u8>>, GpuError> {
        let parts: Vec<(&wgpu::Buffer, u64, u64)> = parts.iter().map(|&(b, n)| (b, 0, n)).collect();
        self.read_back(&parts)
    }

    /// (buffer, offset, bytes) parts read back through one staging buffer and one submission.
    fn read_back(&self, parts: &[(&wgpu::Buffer, u64, u64)]) -> Result<Vec<Vec<u8>>, GpuError> {
        let sizes: Vec<u64> = parts.iter().map(|&(_, _, b)| b.next_multiple_of(4)).collect();
        let total: u64 = sizes.iter().sum();
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read-back"),
            size: total.max(4),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        let mut offset = 0;
        for (&(buf, from, _), &size) in parts.iter().zip(&sizes) {
            if size > 0 {
                encoder.copy_buffer_to_buffer(buf, from, &staging, offset, size);
            }
            offset += size;
        }
        self.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.wait()?;
        match rx.recv() {
            Ok(Ok(())) => {}
            Ok(Err(e)) => return Err(GpuError::Readback(e.to_string())),
            Err(_) => return Err(GpuError::Readback("the mapping was never answered".into())),
        }
        let data = slice.get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?;
        let mut out = Vec::with_capacity(parts.len());
        let mut offset = 0usize;
        for (&(_, _, bytes), &size) in parts.iter().zip(&sizes) {
            out.push(data[offset..offset + bytes as usize].to_vec());
            offset += size as usize;
        }
        drop(data);
        staging.unmap();
        Ok(out)
    }
}
