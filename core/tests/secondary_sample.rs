//! `compare`'s sample of a frame's secondary rays costs the memory of the rays it keeps, not of the
//! frame's (issue 58: the bunny at 2048×1536 with 256 ao rays per pixel took 6.6 GB, listing over
//! a hundred million rays to keep a quarter million). A test binary of its own: it counts every
//! allocation of the process (its global allocator), which no other test's threads should touch.

use bvhscope_core::bvh::{AnyBvh, BuildParams};
use bvhscope_core::geometry::Ray;
use bvhscope_core::mesh::generate;
use bvhscope_core::render::{render, Camera, RayKind, RenderSettings, SecondaryRays, SecondarySpec};
use glam::Vec3;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

/// The system allocator, keeping the bytes allocated now and the most since `reset`.
struct Counting;

static NOW: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(by: usize) {
    let now = NOW.fetch_add(by, Relaxed) + by;
    PEAK.fetch_max(now, Relaxed);
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        NOW.fetch_sub(layout.size(), Relaxed);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            NOW.fetch_sub(layout.size(), Relaxed);
            grew(new_size);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The most bytes allocated at once while `f` ran, over what was allocated before it.
fn peak_of<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let before = NOW.load(Relaxed);
    PEAK.store(before, Relaxed);
    let out = f();
    (out, PEAK.load(Relaxed) - before)
}

#[test]
fn a_sample_of_a_frames_secondary_rays_costs_the_memory_of_the_sample() {
    // A 256×192 frame whose every pixel hit (a camera looking down at a wide floor), 256 ao rays
    // each: 12.6 million rays, over half a gigabyte listed. `compare` keeps a quarter million.
    let mesh = generate::floor(1000.0);
    let mut camera = Camera::framing(&mesh.bounds(), 256, 192);
    (camera.position, camera.look_at, camera.up) = (Vec3::new(0.0, 10.0, 0.0), Vec3::ZERO, Vec3::Z);
    let pixels = (camera.width * camera.height) as usize;
    let tree = AnyBvh::build(&mesh, &BuildParams::default());
    let frame = render(&tree, &mesh, &camera, &RenderSettings::default());
    assert_eq!(frame.hit_count(), pixels, "every camera ray hits the floor");
    let keep = 1 << 18;
    for kind in [RayKind::Ao, RayKind::Bounce, RayKind::Shadow] {
        let spec = SecondarySpec { kind, samples: 256, ..SecondarySpec::default() };
        let sec = SecondaryRays::new(spec, &mesh.bounds(), &camera);
        let (kept, peak) = peak_of(|| sec.frame_rays(&frame, &camera, keep));
        let total = pixels as u64 * spec.rays_per_hit() as u64;
        assert_eq!(kept.of, total, "{kind:?}");
        assert_eq!(kept.rays.len() as u64, total.min(keep as u64), "{kind:?}");
        // The kept rays, and a little more (the test harness's threads may allocate meanwhile).
        let bound = keep * std::mem::size_of::<Ray>() + (1 << 20);
        assert!(peak <= bound, "{kind:?}: {peak} bytes at most at once for {} rays kept of {total}", kept.rays.len());
    }
}
