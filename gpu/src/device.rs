//! The GPU device: one adapter found headless (compute only, no surface: a machine without a
//! display, as in ../shared/GPU.md, has one all the same), opened with all of the adapter's own
//! limits, and every failure turned into a `GpuError` instead of wgpu's default panic.
//!
//! Which adapter: the backends `WGPU_BACKEND` names (e.g. `vulkan`, `gl`), else every backend
//! wgpu was built with; of the adapters there that run compute shaders, a discrete GPU before an
//! integrated, virtual or software one (Mesa's lavapipe is `Cpu`), and within a kind Vulkan
//! first (it is what the tests and the benchmarks were checked on).

use std::any::Any;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// What can go wrong on the GPU path. Every message names what to do or what was too large.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter that runs compute shaders was found (backends: {backends}); install a Vulkan driver \
         (Mesa's lavapipe: `apt-get install mesa-vulkan-drivers`) or set WGPU_BACKEND"
    )]
    NoAdapter { backends: String },
    #[error("the GPU adapter {adapter} could not open a device: {reason}")]
    Device { adapter: String, reason: String },
    #[error(
        "{what} needs {bytes} bytes, more than {adapter} allows in one storage buffer ({limit} bytes); \
         use the CPU, or a smaller mesh or frame"
    )]
    TooLarge { what: String, bytes: u64, limit: u64, adapter: String },
    #[error(
        "the tree is {depth} levels deep; the GPU walk's stack of {bytes} bytes per ray for it exceeds {limit} bytes"
    )]
    TooDeep { depth: u32, bytes: u64, limit: u64 },
    #[error("the GPU rejected a command: {0}")]
    Rejected(String),
    #[error("the GPU device was lost ({0}); the CPU result stays in use")]
    Lost(String),
    #[error("reading results back from the GPU failed: {0}")]
    Readback(String),
    #[error("{0}")]
    Input(String),
    /// A tree a GPU builder made that is not sound (`verify`): a bug, never a tree anyone uses.
    #[error(
        "the GPU's {builder} build made a tree that fails the structure check ({why}); this is a bug in bvhscope: please report it with the mesh (the CPU builds the same tree: --device cpu)"
    )]
    Broken { builder: String, why: String },
}

/// Choices for opening the device; `Default` is what the CLI and the app use.
#[derive(Clone, Debug, Default)]
pub struct GpuOptions {
    /// Backends to look on; `None`: `WGPU_BACKEND`, else all.
    pub backends: Option<wgpu::Backends>,
    /// Pretend one storage buffer may hold at most this many bytes (tests of the size checks on
    /// a machine whose real limit is large); the smaller of this and the adapter's applies.
    pub max_buffer_bytes: Option<u64>,
    /// Use the single-precision fallback of the watertight test even where the adapter has
    /// 64-bit floats (tests of the path an adapter without them takes).
    pub no_f64: bool,
}

/// An open GPU device and what it allows. Cheap to share (`Arc` it); every GPU object of this
/// crate (traced trees, builders) is made on one.
pub struct Gpu {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    limits: wgpu::Limits,
    max_buffer: u64,
    f64: bool,
    /// Errors wgpu reports outside any call's result (validation, out of memory), kept here for
    /// the next `check` instead of the default handler's panic.
    errors: Arc<Mutex<Vec<String>>>,
    lost: Arc<Mutex<Option<String>>>,
    /// What was compiled on this device (the kernels), by what it was compiled for: compiling is
    /// slow on a software adapter, and every tree of a format shares them. Typed loosely so the
    /// device knows nothing of what a kernel is.
    compiled: Mutex<HashMap<String, Arc<dyn Any + Send + Sync>>>,
}

impl std::fmt::Debug for Gpu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gpu").field("adapter", &self.name()).field("f64", &self.f64).finish()
    }
}

/// Rank of an adapter: lower is better (discrete first, then Vulkan within a kind).
fn rank(info: &wgpu::AdapterInfo) -> (u8, u8) {
    use wgpu::DeviceType as T;
    let kind = match info.device_type {
        T::DiscreteGpu => 0,
        T::IntegratedGpu => 1,
        T::VirtualGpu => 2,
        T::Cpu => 3,
        T::Other => 4,
    };
    (kind, (info.backend != wgpu::Backend::Vulkan) as u8)
}

/// Storage buffers one of this crate's kernels binds at most (the LBVH's emission pass).
pub(crate) const STORAGE_BUFFERS_NEEDED: u32 = 8;

impl Gpu {
    /// Open the best adapter (see the module docs).
    pub fn new() -> Result<Gpu, GpuError> {
        Self::with_options(&GpuOptions::default())
    }

    pub fn with_options(opts: &GpuOptions) -> Result<Gpu, GpuError> {
        let backends = opts.backends.or_else(wgpu::Backends::from_env).unwrap_or(wgpu::Backends::all());
        let desc = wgpu::InstanceDescriptor { backends, ..wgpu::InstanceDescriptor::new_without_display_handle() };
        let instance = wgpu::Instance::new(desc);
        let adapters = pollster::block_on(instance.enumerate_adapters(backends));
        let usable = adapters.into_iter().filter(|a| {
            let caps = a.get_downlevel_capabilities();
            caps.flags.contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
                && a.limits().max_storage_buffers_per_shader_stage >= STORAGE_BUFFERS_NEEDED
        });
        let adapter = usable
            .min_by_key(|a| rank(&a.get_info()))
            .ok_or(GpuError::NoAdapter { backends: format!("{backends:?}") })?;
        let info = adapter.get_info();
        let limits = adapter.limits();
        let f64 = adapter.features().contains(wgpu::Features::SHADER_F64) && !opts.no_f64;
        let features = if f64 { wgpu::Features::SHADER_F64 } else { wgpu::Features::empty() };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("bvhscope-gpu"),
            required_features: features,
            required_limits: limits.clone(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| GpuError::Device { adapter: info.name.clone(), reason: e.to_string() })?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            sink.lock().unwrap_or_else(|p| p.into_inner()).push(e.to_string());
        }));
        let lost = Arc::new(Mutex::new(None));
        let lost_sink = lost.clone();
        device.set_device_lost_callback(move |reason, msg| {
            *lost_sink.lock().unwrap_or_else(|p| p.into_inner()) = Some(format!("{reason:?}: {msg}"));
        });
        let binding = limits.max_storage_buffer_binding_size as u64;
        let max_buffer = binding.min(limits.max_buffer_size).min(opts.max_buffer_bytes.unwrap_or(u64::MAX));
        Ok(Gpu { device, queue, info, limits, max_buffer, f64, errors, lost, compiled: Mutex::new(HashMap::new()) })
    }

    /// The adapter's name, its backend and driver, e.g. "NVIDIA H200 (Vulkan, NVIDIA 580.159)":
    /// what every benchmark prints.
    pub fn name(&self) -> String {
        let i = &self.info;
        let driver =
            [i.driver.as_str(), i.driver_info.as_str()].iter().filter(|s| !s.is_empty()).cloned().collect::<Vec<_>>();
        format!(
            "{} ({:?}, {:?}{}{})",
            i.name,
            i.backend,
            i.device_type,
            if driver.is_empty() { "" } else { ", " },
            driver.join(" ")
        )
    }

    pub fn info(&self) -> &wgpu::AdapterInfo {
        &self.info
    }

    /// Whether this is a software adapter (lavapipe, llvmpipe): right for correctness, never for timing.
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    pub fn limits(&self) -> &wgpu::Limits {
        &self.limits
    }

    /// Whether the watertight test's double-precision fallback runs in doubles (`SHADER_F64`),
    /// as on the CPU; else in the single-precision form of `shaders/triangle.wgsl`.
    pub fn has_f64(&self) -> bool {
        self.f64
    }

    /// The most bytes one storage buffer may hold here (the smaller of the binding and buffer
    /// limits, and of a limit forced by `GpuOptions`).
    pub fn max_buffer_bytes(&self) -> u64 {
        self.max_buffer
    }

    /// Refuse `bytes` for `what` before anything is uploaded when one storage buffer cannot hold it.
    pub fn check_size(&self, what: &str, bytes: u64) -> Result<(), GpuError> {
        if bytes > self.max_buffer {
            return Err(GpuError::TooLarge {
                what: what.to_string(),
                bytes,
                limit: self.max_buffer,
                adapter: self.info.name.clone(),
            });
        }
        Ok(())
    }

    /// The first error wgpu reported since the last check, or the device's loss.
    pub fn check(&self) -> Result<(), GpuError> {
        if let Some(l) = self.lost.lock().unwrap_or_else(|p| p.into_inner()).clone() {
            return Err(GpuError::Lost(l));
        }
        let mut errors = self.errors.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(e) = errors.first().cloned() {
            errors.clear();
            return Err(GpuError::Rejected(e));
        }
        Ok(())
    }

    /// Block until the queue's work is done, then `check`.
    pub fn wait(&self) -> Result<(), GpuError> {
        self.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| GpuError::Lost(e.to_string()))?;
        self.check()
    }

    /// Give the device up now (as the driver does when it loses it): every later call on this
    /// `Gpu` fails with an error, and the caller keeps its CPU results. For shutting down early,
    /// and for testing that a lost device never takes the program down.
    pub fn destroy(&self) {
        self.device.destroy();
    }

    /// What was compiled for `key` (a kernel), made by `make` the first time.
    pub(crate) fn compiled<T: Any + Send + Sync>(
        &self,
        key: String,
        make: impl FnOnce() -> Result<T, GpuError>,
    ) -> Result<Arc<T>, GpuError> {
        let found = self.compiled.lock().unwrap_or_else(|p| p.into_inner()).get(&key).cloned();
        if let Some(k) = found.and_then(|k| k.downcast::<T>().ok()) {
            return Ok(k);
        }
        let k = Arc::new(make()?);
        self.compiled.lock().unwrap_or_else(|p| p.into_inner()).insert(key, k.clone());
        Ok(k)
    }

    /// Workgroups for `n` threads of `size` each, as a dispatch grid within the adapter's
    /// per-dimension limit (x first, then rows of y); kernels rebuild the linear index from it.
    pub(crate) fn grid(&self, n: u32, size: u32) -> (u32, u32) {
        let groups = n.div_ceil(size).max(1);
        let max = self.limits.max_compute_workgroups_per_dimension.max(1);
        if groups <= max {
            (groups, 1)
        } else {
            (max, groups.div_ceil(max))
        }
    }
}

/// Open the GPU for a test: `None` with a printed notice where no adapter is found, except under
/// `CI=true`, where CI must find lavapipe and a missing adapter fails the test.
pub fn gpu_for_tests() -> Option<Gpu> {
    match Gpu::new() {
        Ok(g) => Some(g),
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true") => panic!("CI=true needs a GPU adapter: {e}"),
        Err(e) => {
            // Written to stderr directly: libtest captures `eprintln!` of passing tests.
            use std::io::Write;
            let _ = writeln!(std::io::stderr(), "notice: {e}; skipping GPU tests");
            None
        }
    }
}
