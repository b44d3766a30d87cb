//! The renderer's passes: each pixel once, packets equal to single rays, counts after the image, the
//! same frame on any thread count, cancellation.

use super::*;
use crate::bvh::{BuildParams, Bvh};
use crate::mesh::Mesh;
use glam::Vec3;

fn quad_scene() -> (Mesh, Camera) {
    let mesh = Mesh::from_triangles(
        "quad",
        vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    );
    let cam = Camera {
        position: Vec3::new(0.0, 0.0, 3.0),
        look_at: Vec3::ZERO,
        up: Vec3::Y,
        vfov_deg: 60.0,
        width: 37,
        height: 23,
    };
    (mesh, cam)
}

#[test]
fn progressive_passes_trace_each_pixel_once_and_match_a_single_pass() {
    let (mesh, cam) = quad_scene();
    let bvh = Bvh::build(&mesh, &BuildParams::default());
    let settings = RenderSettings { count: true, progressive: true, ..Default::default() };
    let mut strides = Vec::new();
    let mut total = 0;
    let control = WorkControl::new();
    let frame = render_progressive(&bvh, &mesh, &cam, &settings, &FramePool::default(), &control, |f, p| {
        strides.push(f.stride());
        total += p.rays;
    })
    .unwrap();
    assert_eq!(strides, PASS_STRIDES);
    assert_eq!(total, 37 * 23, "every pixel traced exactly once over all passes");
    assert_eq!(control.done(), 37 * 23);
    let single = render(&bvh, &mesh, &cam, &settings);
    assert_eq!(frame.full_samples(), single.full_samples());
    assert!(frame.counted() && single.counted());
    assert!(frame.traced().eq(single.traced()), "the same counters too");
    let samples = frame.full_samples().unwrap();
    assert!(samples.iter().any(|s| s.is_hit()) && samples.iter().any(|s| !s.is_hit()));
    assert!(frame.traced().all(|(_, c)| c.box_tests >= 1), "counters recorded");
}

#[test]
fn the_plain_view_traced_in_packets_shows_what_single_rays_show() {
    let mesh = crate::mesh::generate::torus_knot(2, 3, 0.3, 128, 12);
    // Odd sizes: packets at the frame's right and bottom edges have inactive lanes.
    let cam = Camera::framing_from(&mesh.bounds(), 45, 29, Vec3::new(0.3, 0.5, 1.0), 45.0);
    for layout in crate::bvh::Layout::ALL {
        let bvh = crate::bvh::AnyBvh::build(&mesh, &BuildParams { layout, ..Default::default() });
        assert!(bvh.traces_packets(), "{layout:?}");
        let mut total = 0;
        let control = WorkControl::new();
        let plain = RenderSettings { progressive: true, ..Default::default() };
        let frame =
            render_progressive(&bvh, &mesh, &cam, &plain, &FramePool::default(), &control, |_, p| total += p.rays)
                .unwrap();
        assert_eq!(total, 45 * 29, "{layout:?}: every pixel traced once");
        assert_eq!(control.done(), 45 * 29);
        let one_pass = render(&bvh, &mesh, &cam, &plain);
        assert_eq!(frame.full_samples(), one_pass.full_samples(), "{layout:?}: passes = one pass");
        assert!(!frame.counted());
        let counted = render(&bvh, &mesh, &cam, &RenderSettings { count: true, ..Default::default() });
        let samples = frame.full_samples().unwrap();
        let hits = samples.iter().filter(|s| s.is_hit()).count();
        assert!(hits > 100 && hits < 45 * 29, "{layout:?}: {hits} hits");
        for (i, (p, c)) in samples.iter().zip(counted.full_samples().unwrap()).enumerate() {
            assert_eq!(p.t.to_bits(), c.t.to_bits(), "{layout:?}: pixel {i}");
            assert!(counted.counters(i as u32 % 45, i as u32 / 45).box_tests >= 1, "{layout:?}: pixel {i}");
        }
    }
}

/// The app's normal and depth views: the image from uncounted passes first, then the same
/// frame counted, as the counted render makes it; where packets are not traced (secondary
/// rays), counted passes straight away.
#[test]
fn counts_after_the_image_give_the_counted_frame_as_a_last_pass() {
    let mesh = crate::mesh::generate::torus_knot(2, 3, 0.3, 128, 12);
    let cam = Camera::framing_from(&mesh.bounds(), 45, 29, Vec3::new(0.3, 0.5, 1.0), 45.0);
    let bvh =
        crate::bvh::AnyBvh::build(&mesh, &BuildParams { layout: crate::bvh::Layout::Wide8, ..Default::default() });
    let settings = RenderSettings { count: true, progressive: true, ..Default::default() };
    let mut passes = Vec::new();
    let control = WorkControl::new();
    render_passes_counts_after(&bvh, &mesh, &cam, &settings, &FramePool::default(), &control, |f, p| {
        passes.push((f, p))
    })
    .unwrap();
    let shape: Vec<_> = passes.iter().map(|(f, p)| (p.stride, f.counted(), p.counts_follow, p.counts_only)).collect();
    let image = |stride| (stride, false, stride == 1, false);
    assert_eq!(shape, [image(8), image(4), image(2), image(1), (1, true, false, true)]);
    assert_eq!(control.done(), 45 * 29, "progress starts again for the counted pass");
    let counted = render(&bvh, &mesh, &cam, &settings);
    let (image, last) = (&passes[3].0, &passes[4].0);
    assert_eq!(image.full_samples(), last.full_samples(), "the counted pass draws the same image");
    assert_eq!(last.full_samples(), counted.full_samples());
    assert!(last.traced().eq(counted.traced()), "and counts what the counted render counts");
    assert_eq!(passes[4].1.rays, 45 * 29);

    // Without counters asked for: the uncounted passes only.
    let plain = RenderSettings { count: false, ..settings };
    let mut n = 0;
    render_passes_counts_after(&bvh, &mesh, &cam, &plain, &FramePool::default(), &control, |f, p| {
        assert!(!f.counted() && !p.counts_only && !p.counts_follow);
        n += 1;
    })
    .unwrap();
    assert_eq!(n, PASS_STRIDES.len());
    // The linear scan traces no packets: counted passes straight away.
    let scan = crate::bvh::LinearScan::new(&mesh);
    let mut counted_passes = Vec::new();
    render_passes_counts_after(&scan, &mesh, &cam, &settings, &FramePool::default(), &control, |f, p| {
        counted_passes.push((f.counted(), p.counts_only || p.counts_follow))
    })
    .unwrap();
    assert_eq!(counted_passes, vec![(true, false); PASS_STRIDES.len()]);
}

/// The pieces are shared among however many threads there are: the frame, its images and
/// the heatmap's legend are the same on one thread and on three, counted and in packets.
#[test]
fn a_frame_is_the_same_on_one_thread_and_on_three() {
    use crate::render::colormap::ColorMap;
    use crate::render::legend::draw_legend;
    use crate::render::views::{view_image, HeatRange, View};
    let mesh = crate::mesh::generate::torus_knot(2, 3, 0.3, 128, 12);
    // Wider than a piece, with partial pieces and bands at the right and bottom edges.
    let cam = Camera::framing_from(&mesh.bounds(), 301, 45, Vec3::new(0.3, 0.5, 1.0), 45.0);
    let bvh = crate::bvh::AnyBvh::build(&mesh, &BuildParams::default());
    let cost = BuildParams::default().cost;
    let on = |threads: usize, settings: RenderSettings, view: View| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut passes = Vec::new();
            let f =
                render_progressive(&bvh, &mesh, &cam, &settings, &FramePool::default(), &WorkControl::new(), |f, _| {
                    passes.push(view_image(f, view, ColorMap::Viridis, HeatRange::Auto, cost).0)
                })
                .unwrap();
            assert_eq!(f.hit_count(), f.traced().filter(|(s, _)| s.is_hit()).count());
            let (img, legend) = view_image(&f, view, ColorMap::Viridis, HeatRange::Auto, cost);
            let img = legend.as_ref().map_or(img.clone(), |l| draw_legend(&img, l));
            (f.full_samples().unwrap().to_vec(), f.traced().map(|(_, c)| c).collect::<Vec<_>>(), passes, img, legend)
        })
    };
    for progressive in [false, true] {
        for (count, view) in [(true, View::Visits), (true, View::Cost), (false, View::Normals), (false, View::Depth)] {
            let settings = RenderSettings { count, progressive, ..Default::default() };
            let one = on(1, settings, view);
            assert!(one.0.iter().any(|s| s.is_hit()), "{view:?}");
            assert!(on(3, settings, view) == one, "{view:?}, progressive {progressive}");
        }
    }
}

#[test]
fn cancel_stops_the_render() {
    let (mesh, cam) = quad_scene();
    let bvh = Bvh::build(&mesh, &BuildParams::default());
    let control = WorkControl::new();
    let settings = RenderSettings { progressive: true, ..Default::default() };
    let mut passes = 0;
    let r = render_progressive(&bvh, &mesh, &cam, &settings, &FramePool::default(), &control, |_, _| {
        passes += 1;
        control.cancel();
    });
    assert_eq!(r.unwrap_err(), Cancelled);
    assert_eq!(passes, 1);
}
