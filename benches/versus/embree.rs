//! Embree 3 (Intel's CPU ray tracing kernels, as the distribution packages them) as a contender,
//! through the dozen calls of its C API the race needs, declared here by hand. Linked only when
//! `build.rs` found `libembree3`; otherwise `all()` is empty and `notice()` says why.
//!
//! What is raced: scenes of the same triangles (one triangle geometry, our vertex and index arrays
//! shared, not copied), build quality medium and high, traced with `rtcIntersect1` (single rays),
//! `rtcIntersect8` (8 consecutive rays: a 2×4 block of a primary tile) and `rtcIntersect1M` with
//! the coherent flag (a ray stream of up to 64 rays: one 8×8 primary tile). A build made on a
//! one-thread rayon pool gets a device with `threads=1`, on the all-thread pool one with as many
//! threads; tracing runs on the caller's thread (Embree starts no threads for it). Memory is what
//! the device allocates for the scene (its BVH and triangle leaves), counted by its memory monitor
//! callback, without our shared arrays.

use crate::contenders::Contender;

#[cfg(not(embree))]
pub fn all() -> Vec<Contender> {
    Vec::new()
}

/// A line for the report when Embree is not in the race.
pub fn notice() -> Option<&'static str> {
    if cfg!(embree) {
        None
    } else {
        Some("Embree 3 not found (Debian: apt-get install libembree-dev, then touch build.rs): raced without it.")
    }
}

#[cfg(embree)]
pub use linked::all;

#[cfg(embree)]
mod linked {
    use super::Contender;
    use crate::contenders::{Built, Family, Tracer};
    use crate::rays::RaySpec;
    use bvhscope::mesh::Mesh;
    use std::ffi::{c_char, c_void, CString};
    use std::sync::atomic::{AtomicIsize, Ordering};
    use std::time::Instant;

    type Device = *mut c_void;
    type Scene = *mut c_void;
    type Geometry = *mut c_void;

    const GEOMETRY_TYPE_TRIANGLE: u32 = 0;
    const BUFFER_TYPE_INDEX: u32 = 0;
    const BUFFER_TYPE_VERTEX: u32 = 1;
    const FORMAT_UINT3: u32 = 0x5003;
    const FORMAT_FLOAT3: u32 = 0x9003;
    const INVALID_ID: u32 = u32::MAX;
    const CONTEXT_INCOHERENT: u32 = 0;
    const CONTEXT_COHERENT: u32 = 1;
    const SCENE_FLAG_ROBUST: u32 = 1 << 2;

    /// `RTCIntersectContext` as `rtcore_config.h` configures it here (one instance level, no
    /// minimum width); `rtcInitIntersectContext` is an inline function, written out in `context`.
    #[repr(C)]
    struct Context {
        flags: u32,
        filter: *const c_void,
        inst_id: [u32; 1],
    }

    fn context(flags: u32) -> Context {
        Context { flags, filter: std::ptr::null(), inst_id: [INVALID_ID] }
    }

    #[repr(C, align(16))]
    #[derive(Clone, Copy)]
    struct Ray1 {
        org: [f32; 3],
        tnear: f32,
        dir: [f32; 3],
        time: f32,
        tfar: f32,
        mask: u32,
        id: u32,
        flags: u32,
    }

    #[repr(C, align(16))]
    #[derive(Clone, Copy)]
    struct Hit1 {
        ng: [f32; 3],
        u: f32,
        v: f32,
        prim_id: u32,
        geom_id: u32,
        inst_id: [u32; 1],
    }

    #[repr(C)]
    #[derive(Clone, Copy)]
    struct RayHit1 {
        ray: Ray1,
        hit: Hit1,
    }

    /// `RTCRayHit8`: ray then hit, each field 8 lanes wide.
    #[repr(C, align(32))]
    struct RayHit8 {
        org: [[f32; 8]; 3],
        tnear: [f32; 8],
        dir: [[f32; 8]; 3],
        time: [f32; 8],
        tfar: [f32; 8],
        mask: [u32; 8],
        id: [u32; 8],
        flags: [u32; 8],
        ng: [[f32; 8]; 3],
        u: [f32; 8],
        v: [f32; 8],
        prim_id: [u32; 8],
        geom_id: [u32; 8],
        inst_id: [u32; 8],
    }

    /// `rtcIntersect8`'s lane mask, aligned as it reads it.
    #[repr(C, align(32))]
    struct Valid([i32; 8]);

    type MemoryMonitor = extern "C" fn(user: *mut c_void, bytes: isize, post: bool) -> bool;

    #[link(name = "embree3")]
    extern "C" {
        fn rtcNewDevice(config: *const c_char) -> Device;
        fn rtcReleaseDevice(device: Device);
        fn rtcGetDeviceError(device: Device) -> u32;
        fn rtcSetDeviceMemoryMonitorFunction(device: Device, f: MemoryMonitor, user: *mut c_void);
        fn rtcNewScene(device: Device) -> Scene;
        fn rtcReleaseScene(scene: Scene);
        fn rtcSetSceneBuildQuality(scene: Scene, quality: u32);
        fn rtcSetSceneFlags(scene: Scene, flags: u32);
        fn rtcNewGeometry(device: Device, kind: u32) -> Geometry;
        fn rtcSetGeometryBuildQuality(geometry: Geometry, quality: u32);
        fn rtcSetSharedGeometryBuffer(
            geometry: Geometry,
            kind: u32,
            slot: u32,
            format: u32,
            ptr: *const c_void,
            offset: usize,
            stride: usize,
            count: usize,
        );
        fn rtcCommitGeometry(geometry: Geometry);
        fn rtcAttachGeometry(scene: Scene, geometry: Geometry) -> u32;
        fn rtcReleaseGeometry(geometry: Geometry);
        fn rtcCommitScene(scene: Scene);
        fn rtcIntersect1(scene: Scene, context: *mut Context, rayhit: *mut RayHit1);
        fn rtcIntersect8(valid: *const i32, scene: Scene, context: *mut Context, rayhit: *mut RayHit8);
        fn rtcIntersect1M(scene: Scene, context: *mut Context, rayhit: *mut RayHit1, m: u32, stride: usize);
    }

    /// Bytes the device holds now, kept up to date by its memory monitor.
    extern "C" fn monitor(user: *mut c_void, bytes: isize, _post: bool) -> bool {
        // SAFETY: `user` is the `AtomicIsize` boxed in `EmbreeScene`, alive as long as the device.
        unsafe { &*(user as *const AtomicIsize) }.fetch_add(bytes, Ordering::Relaxed);
        true
    }

    #[derive(Clone, Copy, PartialEq, Eq)]
    pub enum Quality {
        Medium = 1,
        High = 2,
    }

    #[derive(Clone, Copy, PartialEq, Eq)]
    enum Trace {
        Single,
        Packet8,
        Stream,
    }

    /// A committed scene with the arrays it shares; released on drop.
    struct EmbreeScene {
        device: Device,
        scene: Scene,
        trace: Trace,
        _vertices: Vec<[f32; 4]>,
        _indices: Vec<[u32; 3]>,
        _bytes: Box<AtomicIsize>,
    }

    // SAFETY: a committed Embree scene may be traced from any number of threads at once (Embree's
    // documentation of rtcIntersect*); nothing here mutates it after the commit.
    unsafe impl Send for EmbreeScene {}
    unsafe impl Sync for EmbreeScene {}

    impl Drop for EmbreeScene {
        fn drop(&mut self) {
            // SAFETY: both handles were made by `build` and are released once.
            unsafe {
                rtcReleaseScene(self.scene);
                rtcReleaseDevice(self.device);
            }
        }
    }

    fn ray1(r: &RaySpec) -> RayHit1 {
        RayHit1 {
            ray: Ray1 {
                org: r.origin.to_array(),
                tnear: 0.0,
                dir: r.dir.to_array(),
                time: 0.0,
                tfar: f32::INFINITY,
                mask: u32::MAX,
                id: 0,
                flags: 0,
            },
            hit: Hit1 { ng: [0.0; 3], u: 0.0, v: 0.0, prim_id: INVALID_ID, geom_id: INVALID_ID, inst_id: [INVALID_ID] },
        }
    }

    impl EmbreeScene {
        fn build(mesh: &Mesh, quality: Quality, trace: Trace) -> (EmbreeScene, std::time::Duration) {
            let threads = rayon::current_num_threads();
            // BENCH_EMBREE_ISA=avx2 (or sse4.2, avx512): the kernels Embree would pick on another CPU.
            let isa = std::env::var("BENCH_EMBREE_ISA").ok().filter(|i| !i.is_empty());
            let isa = isa.map(|i| format!(",isa={i}")).unwrap_or_default();
            let config = CString::new(format!("threads={threads},set_affinity=0{isa}")).expect("no NUL");
            // Embree reads 16 bytes at the last vertex: four floats per vertex, stride 16.
            let vertices: Vec<[f32; 4]> = mesh.positions.iter().map(|p| [p.x, p.y, p.z, 0.0]).collect();
            let indices = mesh.triangles.clone();
            let bytes = Box::new(AtomicIsize::new(0));
            // SAFETY: the calls follow Embree's API: handles from rtcNew*, shared buffers that
            // outlive the scene (moved into it), the monitor's pointer boxed in it too.
            unsafe {
                let device = rtcNewDevice(config.as_ptr());
                assert!(!device.is_null(), "rtcNewDevice failed");
                rtcSetDeviceMemoryMonitorFunction(device, monitor, &*bytes as *const AtomicIsize as *mut c_void);
                let scene = rtcNewScene(device);
                rtcSetSceneBuildQuality(scene, quality as u32);
                // BENCH_EMBREE_ROBUST=1: Embree's robust mode (avoids its optimisations that can
                // miss rays through edges and vertices), as bvhscope always is.
                if std::env::var("BENCH_EMBREE_ROBUST").is_ok_and(|v| v == "1") {
                    rtcSetSceneFlags(scene, SCENE_FLAG_ROBUST);
                }
                let geometry = rtcNewGeometry(device, GEOMETRY_TYPE_TRIANGLE);
                rtcSetGeometryBuildQuality(geometry, quality as u32);
                rtcSetSharedGeometryBuffer(
                    geometry,
                    BUFFER_TYPE_VERTEX,
                    0,
                    FORMAT_FLOAT3,
                    vertices.as_ptr().cast(),
                    0,
                    16,
                    vertices.len(),
                );
                rtcSetSharedGeometryBuffer(
                    geometry,
                    BUFFER_TYPE_INDEX,
                    0,
                    FORMAT_UINT3,
                    indices.as_ptr().cast(),
                    0,
                    12,
                    indices.len(),
                );
                rtcCommitGeometry(geometry);
                rtcAttachGeometry(scene, geometry);
                rtcReleaseGeometry(geometry);
                // What the device holds before the build: the scene and geometry objects.
                bytes.store(0, Ordering::Relaxed);
                let start = Instant::now();
                rtcCommitScene(scene);
                let took = start.elapsed();
                // Owned first, so a failed build releases the scene and device on its way out.
                let built = EmbreeScene { device, scene, trace, _vertices: vertices, _indices: indices, _bytes: bytes };
                assert_eq!(rtcGetDeviceError(device), 0, "Embree reported an error building the scene");
                (built, took)
            }
        }

        fn bytes(&self) -> isize {
            self._bytes.load(Ordering::Relaxed)
        }
    }

    impl Tracer for EmbreeScene {
        fn trace(&self, r: &RaySpec) -> bool {
            let mut rh = ray1(r);
            let mut ctx = context(CONTEXT_INCOHERENT);
            // SAFETY: a committed scene, a valid context and ray.
            unsafe { rtcIntersect1(self.scene, &mut ctx, &mut rh) };
            rh.hit.geom_id != INVALID_ID
        }

        fn trace_chunk(&self, rays: &[RaySpec]) -> usize {
            match self.trace {
                Trace::Single => rays.iter().filter(|r| self.trace(r)).count(),
                Trace::Packet8 => rays.chunks(8).map(|c| self.packet8(c)).sum(),
                Trace::Stream => {
                    let mut stream: Vec<RayHit1> = Vec::with_capacity(64);
                    let mut hits = 0;
                    for c in rays.chunks(64) {
                        stream.clear();
                        stream.extend(c.iter().map(ray1));
                        let mut ctx = context(CONTEXT_COHERENT);
                        // SAFETY: `stream` holds `len` contiguous RTCRayHit records.
                        unsafe {
                            rtcIntersect1M(
                                self.scene,
                                &mut ctx,
                                stream.as_mut_ptr(),
                                stream.len() as u32,
                                std::mem::size_of::<RayHit1>(),
                            )
                        };
                        hits += stream.iter().filter(|h| h.hit.geom_id != INVALID_ID).count();
                    }
                    hits
                }
            }
        }
    }

    impl EmbreeScene {
        /// Up to 8 rays in one `rtcIntersect8` call (missing lanes invalid).
        fn packet8(&self, rays: &[RaySpec]) -> usize {
            // SAFETY: all-zero is a valid value of this plain-data struct.
            let mut p: RayHit8 = unsafe { std::mem::zeroed() };
            // Unused lanes get an empty interval too: a fallback path of Embree's that ignores
            // `valid` treats a ray as active when tnear <= tfar.
            p.tnear = [f32::INFINITY; 8];
            p.tfar = [f32::NEG_INFINITY; 8];
            // rtcIntersect8 reads the mask as one 32-byte vector.
            let mut valid = Valid([0; 8]);
            for (k, r) in rays.iter().enumerate() {
                valid.0[k] = -1;
                p.tnear[k] = 0.0;
                for a in 0..3 {
                    p.org[a][k] = r.origin[a];
                    p.dir[a][k] = r.dir[a];
                }
                p.tfar[k] = f32::INFINITY;
                p.mask[k] = u32::MAX;
                p.geom_id[k] = INVALID_ID;
                p.prim_id[k] = INVALID_ID;
                p.inst_id[k] = INVALID_ID;
            }
            let mut ctx = context(CONTEXT_COHERENT);
            // SAFETY: a committed scene, a 32-byte aligned packet, `valid` 8 lanes.
            unsafe { rtcIntersect8(valid.0.as_ptr(), self.scene, &mut ctx, &mut p) };
            (0..rays.len()).filter(|&k| p.geom_id[k] != INVALID_ID).count()
        }
    }

    fn contender(quality: Quality, trace: Trace) -> Contender {
        let q = if quality == Quality::Medium { "medium" } else { "high" };
        let how = match trace {
            Trace::Single => "rtcIntersect1",
            Trace::Packet8 => "rtcIntersect8",
            Trace::Stream => "stream of 64",
        };
        Contender {
            name: format!("embree {q} ({how})"),
            family: if trace == Trace::Single { Family::Embree } else { Family::EmbreePackets },
            slow_build: false,
            build: Box::new(move |mesh| {
                let (scene, took) = EmbreeScene::build(mesh, quality, trace);
                let bytes = scene.bytes() as f64 / mesh.triangle_count().max(1) as f64;
                (Built { tracer: Box::new(scene), sah_cost: None, bytes_per_tri: Some(bytes) }, took)
            }),
        }
    }

    /// Embree's rows: both qualities with single rays; the medium scene with packets and streams.
    pub fn all() -> Vec<Contender> {
        vec![
            contender(Quality::Medium, Trace::Single),
            contender(Quality::High, Trace::Single),
            contender(Quality::Medium, Trace::Packet8),
            contender(Quality::Medium, Trace::Stream),
        ]
    }
}
