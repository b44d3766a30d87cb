//! The device: found and named, or a clear error; buffers round-trip; sizes checked before upload.

mod common;

use bvhscope_gpu::{Gpu, GpuError, GpuOptions};

#[test]
fn no_backend_is_a_clear_error_not_a_panic() {
    let e =
        Gpu::with_options(&GpuOptions { backends: Some(wgpu::Backends::empty()), ..Default::default() }).unwrap_err();
    assert!(matches!(e, GpuError::NoAdapter { .. }));
    assert!(e.to_string().contains("mesa-vulkan-drivers"), "{e}");
}

#[test]
fn the_adapter_is_named_and_buffers_round_trip() {
    let Some(gpu) = common::gpu() else { return };
    let name = gpu.name();
    assert!(!gpu.info().name.is_empty() && name.contains(&gpu.info().name), "{name}");
    assert!(gpu.max_buffer_bytes() >= 1 << 20);
    let data: Vec<u32> = (0..1000).map(|i| i * 3 + 1).collect();
    let buf = gpu.upload("round trip", &data).unwrap();
    assert_eq!(gpu.download::<u32>(&buf, 1000).unwrap(), data);
    let empty = gpu.upload::<u32>("empty", &[]).unwrap();
    assert!(gpu.download::<u32>(&empty, 0).unwrap().is_empty());
}

#[test]
fn a_forced_small_limit_refuses_uploads_before_they_happen() {
    let Some(_) = common::gpu() else { return };
    let gpu = Gpu::with_options(&GpuOptions { max_buffer_bytes: Some(4096), ..Default::default() }).unwrap();
    assert_eq!(gpu.max_buffer_bytes(), 4096);
    assert!(gpu.upload("fits", &[0u32; 1024]).is_ok());
    let e = gpu.upload("too many numbers", &[0u32; 1025]).unwrap_err();
    assert_eq!(
        e,
        GpuError::TooLarge {
            what: "too many numbers".into(),
            bytes: 4100,
            limit: 4096,
            adapter: gpu.info().name.clone()
        }
    );
}
