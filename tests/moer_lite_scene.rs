//! The Moer-lite lab's BVH scene, rendered with every strategy and both traversal orders, gives
//! the same hit mask and normal image as the linear scan.

mod common;

use bvhscope::bvh::{AnyBvh, BuildParams, Layout, LinearScan, Strategy, TraceOptions, TraversalOrder};
use bvhscope::render::{render, view_image, Camera, ColorMap, HeatRange, RenderSettings, View};
use glam::Vec3;

#[test]
fn moer_lite_scene_matches_linear_for_every_strategy() {
    let Some(mesh) = common::shared_mesh("moer-lite-lab1-bvh/models/Monkey.obj") else {
        return;
    };
    // The scene.json camera: position (0,1,5), lookAt origin, up +y, verticalFov 45, film 1200x800.
    let camera = Camera {
        position: Vec3::new(0.0, 1.0, 5.0),
        look_at: Vec3::ZERO,
        up: Vec3::Y,
        vfov_deg: 45.0,
        width: 1200,
        height: 800,
    };
    let settings = RenderSettings::default();
    let reference = render(&LinearScan::new(&mesh), &mesh, &camera, &settings);
    let ref_mask = reference.hit_mask();
    let hits = ref_mask.iter().filter(|&&h| h).count();
    assert!(hits > 50_000, "the monkey covers a good part of the frame ({hits} pixels)");
    let (ref_img, _) = view_image(&reference, View::Normals, ColorMap::Viridis, HeatRange::Auto, Default::default());

    for (strategy, layout) in Strategy::ALL.into_iter().flat_map(|s| Layout::ALL.map(|l| (s, l))) {
        let bvh = AnyBvh::build(&mesh, &BuildParams { layout, ..BuildParams::with_strategy(strategy) });
        // The wide layout always visits the nearest child first; one order is enough there.
        let orders: &[TraversalOrder] =
            if layout == Layout::Binary { &TraversalOrder::ALL } else { &[TraversalOrder::EntryDistance] };
        for &order in orders {
            let s = RenderSettings { trace: TraceOptions { order, ..settings.trace }, ..settings };
            let frame = render(&bvh, &mesh, &camera, &s);
            assert_eq!(frame.hit_mask(), ref_mask, "{strategy:?} {layout:?} {order:?}: hit mask differs");
            let (img, _) = view_image(&frame, View::Normals, ColorMap::Viridis, HeatRange::Auto, Default::default());
            // Identical except where two triangles tie at a shared edge, where the interpolated
            // normals agree up to rounding.
            let off = img
                .pixels()
                .zip(ref_img.pixels())
                .filter(|(a, b)| a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > 1))
                .count();
            assert_eq!(off, 0, "{strategy:?} {layout:?} {order:?}: {off} normal pixels differ");
            let same_t = frame
                .full_samples()
                .unwrap()
                .iter()
                .zip(reference.full_samples().unwrap())
                .all(|(a, b)| a.t == b.t || (a.t - b.t).abs() <= 1e-5 * b.t);
            assert!(same_t, "{strategy:?} {layout:?} {order:?}: depths differ");
        }
    }
}
