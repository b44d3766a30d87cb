//! One compute kernel: a WGSL module compiled for one entry point with its pipeline-overridable
//! constants, an explicit bind group layout (so a binding a variant leaves unused still binds),
//! and its dispatch; a builder's kernels as one set (`KernelSet`). Compilation errors come back as
//! `GpuError::Rejected` with naga's message.

use crate::device::{Gpu, GpuError};
use std::sync::Arc;

/// A module's source: the prelude every module starts with (`shaders/prelude.wgsl`: `Tri`), then
/// `parts` in order.
pub(crate) fn module(parts: &[&str]) -> String {
    let prelude = crate::shaders::source("prelude.wgsl");
    std::iter::once(prelude).chain(parts.iter().copied()).collect::<Vec<_>>().join("\n")
}

/// How a kernel sees one binding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Bind {
    Uniform,
    Read,
    ReadWrite,
}

pub(crate) struct Kernel {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    label: String,
}

impl Kernel {
    /// `binds[i]` is binding `i` of group 0.
    pub(crate) fn new(
        gpu: &Gpu,
        label: &str,
        source: &str,
        entry: &str,
        binds: &[Bind],
        constants: &[(&str, f64)],
    ) -> Result<Kernel, GpuError> {
        let numbered: Vec<(u32, Bind)> = binds.iter().enumerate().map(|(i, &b)| (i as u32, b)).collect();
        Self::with_bindings(gpu, label, source, entry, &numbered, constants)
    }

    /// A kernel whose entry point uses the bindings `binds` (number, kind) of a module that
    /// declares more (a module of several kernels, each binding what it uses: a layout of all of
    /// them could pass the adapter's storage-buffer count).
    pub(crate) fn with_bindings(
        gpu: &Gpu,
        label: &str,
        source: &str,
        entry: &str,
        binds: &[(u32, Bind)],
        constants: &[(&str, f64)],
    ) -> Result<Kernel, GpuError> {
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let entries: Vec<wgpu::BindGroupLayoutEntry> = binds
            .iter()
            .map(|&(i, b)| wgpu::BindGroupLayoutEntry {
                binding: i,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: match b {
                        Bind::Uniform => wgpu::BufferBindingType::Uniform,
                        Bind::Read => wgpu::BufferBindingType::Storage { read_only: true },
                        Bind::ReadWrite => wgpu::BufferBindingType::Storage { read_only: false },
                    },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            })
            .collect();
        let layout = gpu
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries });
        let pipeline_layout = gpu.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = gpu.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions { constants, zero_initialize_workgroup_memory: true },
            cache: None,
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError::Rejected(format!("kernel {label}: {e}")));
        }
        Ok(Kernel { pipeline, layout, label: label.to_string() })
    }

    /// A bind group of `buffers` (binding i = `buffers[i]`, whole buffers).
    pub(crate) fn bind(&self, gpu: &Gpu, buffers: &[&wgpu::Buffer]) -> wgpu::BindGroup {
        let numbered: Vec<(u32, &wgpu::Buffer)> = buffers.iter().enumerate().map(|(i, &b)| (i as u32, b)).collect();
        self.bind_numbered(gpu, &numbered)
    }

    /// A bind group of (binding, buffer) pairs, whole buffers.
    pub(crate) fn bind_numbered(&self, gpu: &Gpu, buffers: &[(u32, &wgpu::Buffer)]) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry> = buffers
            .iter()
            .map(|&(i, b)| wgpu::BindGroupEntry { binding: i, resource: b.as_entire_binding() })
            .collect();
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(&self.label),
            layout: &self.layout,
            entries: &entries,
        })
    }

    /// Record one dispatch of `groups` workgroups (x, y) into `encoder`.
    pub(crate) fn dispatch(&self, encoder: &mut wgpu::CommandEncoder, bind: &wgpu::BindGroup, groups: (u32, u32)) {
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(&self.label), timestamp_writes: None });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind, &[]);
        pass.dispatch_workgroups(groups.0, groups.1, 1);
    }
}

/// A builder's kernels: one module's entry points, each with the bindings it uses (binding 0 the
/// uniform parameters, 1..=`read_only` read-only storage, the rest read-write), compiled once per
/// device, and recorded into an encoder by name.
pub(crate) struct KernelSet {
    table: &'static [(&'static str, &'static [u32])],
    kernels: Vec<Arc<Kernel>>,
}

impl KernelSet {
    /// Compile every entry of `table` from `source`; `name` keys the device's cache.
    pub(crate) fn new(
        gpu: &Gpu,
        name: &str,
        source: &str,
        table: &'static [(&'static str, &'static [u32])],
        read_only: u32,
    ) -> Result<KernelSet, GpuError> {
        let mut kernels = Vec::with_capacity(table.len());
        for &(entry, binds) in table {
            let binds: Vec<(u32, Bind)> = binds
                .iter()
                .map(|&b| {
                    let kind = match b {
                        0 => Bind::Uniform,
                        b if b <= read_only => Bind::Read,
                        _ => Bind::ReadWrite,
                    };
                    (b, kind)
                })
                .collect();
            kernels.push(gpu.compiled(format!("{name} {entry}"), || {
                Kernel::with_bindings(gpu, entry, source, entry, &binds, &[])
            })?);
        }
        Ok(KernelSet { table, kernels })
    }

    /// Record `entry` over `threads` invocations (64 a group), binding each of its bindings `b`
    /// to `buffer(b)`.
    pub(crate) fn record<'a>(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        entry: &str,
        buffer: impl Fn(u32) -> &'a wgpu::Buffer,
        threads: u32,
    ) {
        let k = self.table.iter().position(|(e, _)| *e == entry).expect("an entry of the set's table");
        let entries: Vec<(u32, &wgpu::Buffer)> = self.table[k].1.iter().map(|&b| (b, buffer(b))).collect();
        let kernel = &self.kernels[k];
        kernel.dispatch(encoder, &kernel.bind_numbered(gpu, &entries), gpu.grid(threads, 64));
    }
}
