//! The frame's tests: passes, samples and counts.

use super::*;
use glam::Vec3;

/// A frame after a pass of `stride`, each traced pixel's sample naming its pixel.
fn traced_frame(w: u32, h: u32, stride: u32, counted: bool) -> Frame {
    let mut f = Frame::new(w, h, counted);
    let (samples, counters) = f.slots_mut();
    for y in (0..h).step_by(stride as usize) {
        for x in (0..w).step_by(stride as usize) {
            let i = (y * w + x) as usize;
            samples[i] = PixelSample { t: x as f32, normal: Vec3::ZERO, prim: y };
            if counted {
                counters[i].nodes_visited = x + 1000 * y;
            }
        }
    }
    f.stride = stride;
    f
}

#[test]
fn a_snapshot_of_a_coarse_pass_shows_what_the_working_frame_shows() {
    for (w, h) in [(37, 23), (16, 8), (1, 1), (9, 17)] {
        for stride in [8, 4, 2, 1] {
            for counted in [false, true] {
                let f = traced_frame(w, h, stride, counted);
                let snap = f.snapshot();
                assert_eq!(snap.counted(), counted);
                assert_eq!(snap.grid_size(), f.grid_size());
                let (cols, rows) = f.grid_size();
                assert_eq!(snap.samples.len(), (cols * rows) as usize, "only the traced pixels are kept");
                for y in 0..h {
                    for x in 0..w {
                        let s = snap.sample(x, y);
                        assert_eq!((s.t as u32, s.prim), (x - x % stride, y - y % stride), "{w}×{h}/{stride}");
                        assert_eq!(s, f.sample(x, y));
                        assert_eq!(snap.counters(x, y), f.counters(x, y));
                    }
                }
                let traced: Vec<_> = f.traced().collect();
                assert_eq!(traced.len(), (cols * rows) as usize);
                assert!(traced.iter().eq(snap.traced().collect::<Vec<_>>().iter()));
                assert_eq!(snap.ray_summary(), f.ray_summary());
                assert_eq!(snap.full_samples().is_some(), stride == 1);
            }
        }
    }
}

#[test]
fn a_frame_on_a_dropped_frames_storage_starts_empty_and_only_its_pool_reuses_it() {
    // Large enough to be kept (over `FramePool::MIN_BYTES` of samples).
    let (w, h) = (701, 499);
    let pool = FramePool::default();
    let mut f = Frame::new_in(&pool, w, h, true);
    let (samples, counters) = f.slots_mut();
    samples.fill(PixelSample { t: 1.0, normal: Vec3::X, prim: 3 });
    counters.fill(RayCounters { nodes_visited: 9, ..RayCounters::ZERO });
    let storage = samples.as_ptr();
    drop(f);
    // Another pool (or none) gets fresh storage: pools are not shared through a global.
    let mut other = Frame::new_in(&FramePool::default(), w, h, true);
    assert_ne!(other.slots_mut().0.as_ptr(), storage);
    for (w, h) in [(w, h), (w - 1, h - 2)] {
        let mut f = Frame::new_in(&pool, w, h, true);
        let n = (w * h) as usize;
        let (samples, counters) = f.slots_mut();
        assert_eq!(samples.as_ptr(), storage, "the pool's kept storage is reused");
        assert_eq!((samples.len(), counters.len()), (n, n));
        assert!(samples.iter().all(|s| *s == PixelSample::MISS));
        assert!(counters.iter().all(|c| *c == RayCounters::ZERO));
        samples.fill(PixelSample { t: 2.0, normal: Vec3::Y, prim: 4 });
    }
}

#[test]
fn frames_without_pixels_give_empty_snapshots_and_images() {
    for (w, h) in [(0, 5), (5, 0), (0, 0)] {
        for stride in [2, 1] {
            let f = traced_frame(w, h, stride, true);
            let snap = f.snapshot();
            assert_eq!(snap.traced().count(), 0);
            let (img, _) = crate::render::view_image(
                &snap,
                crate::render::View::Visits,
                Default::default(),
                Default::default(),
                Default::default(),
            );
            assert_eq!(img.width() * img.height(), 0);
        }
    }
}

#[test]
fn root_box_means_count_only_the_rays_that_visited_a_node() {
    let mut f = Frame::new(4, 1, true);
    let (samples, counters) = f.slots_mut();
    // Two rays miss the root box (one box test, no node), one enters and misses, one hits.
    counters[0] = RayCounters { box_tests: 1, ..RayCounters::ZERO };
    counters[1] = RayCounters { box_tests: 1, ..RayCounters::ZERO };
    counters[2] =
        RayCounters { nodes_visited: 3, box_tests: 5, leaves_visited: 1, triangle_tests: 2, ..RayCounters::ZERO };
    counters[3] =
        RayCounters { nodes_visited: 9, box_tests: 17, leaves_visited: 2, triangle_tests: 6, ..RayCounters::ZERO };
    samples[3] = PixelSample { t: 1.0, normal: Vec3::Y, prim: 0 };
    f.stride = 1;
    let s = f.ray_summary();
    assert_eq!((s.rays, s.hits, s.root_rays), (4, 1, 2));
    assert_eq!(s.mean_nodes_visited, 3.0);
    assert_eq!(s.root_mean_nodes_visited, 6.0);
    assert_eq!(s.root_mean_box_tests, 11.0);
    assert_eq!(s.root_mean_triangle_tests, 4.0);
    assert_eq!(s.mean_triangle_tests, 2.0);
    assert_eq!(s.root_fraction(), 0.5);
}

#[test]
fn an_untraced_frame_has_no_samples_to_show() {
    let f = Frame::new(5, 3, true);
    assert_eq!(f.traced().count(), 0);
    assert_eq!(f.ray_summary().rays, 0);
    assert!(f.full_samples().is_none());
    assert!(!Frame::new(5, 3, false).counted());
}

/// Hits and counts traced outside the renderer (as the GPU path returns them) make the frame the
/// renderer makes: the same samples, normals included, and the same counts CSV.
#[test]
fn a_frame_from_hits_and_counts_is_the_rendered_frame() {
    use crate::bvh::{Accelerator, BuildParams, Bvh, TraceOptions};
    use crate::render::camera::Camera;
    use crate::render::raycast::{render, RenderSettings};
    let mesh = crate::mesh::generate::torus_knot(2, 3, 0.3, 64, 8);
    let bvh = Bvh::build(&mesh, &BuildParams::default());
    let camera = Camera::framing_from(&mesh.bounds(), 29, 17, Vec3::new(0.3, 0.5, 1.0), 45.0);
    let rendered = render(&bvh, &mesh, &camera, &RenderSettings { count: true, ..Default::default() });
    let gen = camera.ray_gen();
    let (mut hits, mut counters) = (Vec::new(), Vec::new());
    for y in 0..camera.height {
        for x in 0..camera.width {
            let mut c = RayCounters::ZERO;
            hits.push(bvh.closest_hit(&mut gen.pixel_ray(x, y), TraceOptions::default(), &mut c));
            counters.push(c);
        }
    }
    assert!(hits.iter().any(|h| h.is_some()) && hits.iter().any(|h| h.is_none()));
    let made = Frame::from_hits(&mesh, &camera, &hits, &counters).unwrap();
    assert!(made.is_complete() && made.counted());
    assert_eq!(made.full_samples(), rendered.full_samples());
    assert_eq!(made.counts_csv(), rendered.counts_csv());
    let plain = Frame::from_hits(&mesh, &camera, &hits, &[]).unwrap();
    assert!(!plain.counted() && plain.full_samples() == rendered.full_samples());

    // Wrong lengths and triangles the mesh lacks are errors naming them, not panics.
    let short = Frame::from_hits(&mesh, &camera, &hits[1..], &counters).unwrap_err();
    assert!(short.to_string().contains("hits: 492 given for a 29x17 frame of 493 pixels"), "{short}");
    let e = Frame::from_hits(&mesh, &camera, &hits, &counters[..3]).unwrap_err();
    assert!(e.to_string().starts_with("counters: 3 given"), "{e}");
    let mut bad = hits.clone();
    let i = bad.iter().position(|h| h.is_some()).unwrap();
    bad[i].as_mut().unwrap().prim = 1 << 30;
    let e = Frame::from_hits(&mesh, &camera, &bad, &counters).unwrap_err();
    assert!(e.to_string().contains(&format!("hit triangle {}, but the mesh has", 1 << 30)), "{e}");
    let wrong_camera = Camera { vfov_deg: 0.0, ..camera };
    assert!(Frame::from_hits(&mesh, &camera, &hits, &counters).is_ok());
    assert!(matches!(Frame::from_hits(&mesh, &wrong_camera, &hits, &counters), Err(FromHitsError::Camera(_))));
}
