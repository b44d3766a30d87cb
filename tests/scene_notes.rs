//! What the scenes' notes claim about the strategies, checked on their cameras at a smaller size
//! (so a note cannot go stale when the builder changes): the means are per ray that enters the
//! root box, binary layout.

mod common;

use bvhscope::bvh::{AnyBvh, BuildParams, Layout, Strategy};
use bvhscope::render::{render, Camera, RenderSettings};
use bvhscope::scene::load_any;
use std::path::Path;

fn scene(name: &str) -> Option<bvhscope::scene::Scene> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes").join(name);
    match load_any(&path) {
        Ok(l) => Some(l),
        // The scene uses a shared mesh: skipped (with the notice) when the folder is absent.
        Err(e) if common::shared_models().is_none() => {
            let _ = e;
            None
        }
        Err(e) => panic!("{e}"),
    }
}

/// Nodes visited per ray in the root box, and triangle tests, for `strategy` from `camera`.
fn work(l: &bvhscope::scene::Scene, strategy: Strategy, camera: &Camera) -> (f64, f64) {
    let p = BuildParams { strategy, layout: Layout::Binary, ..BuildParams::default() };
    let mesh = l.flat_mesh().unwrap();
    let bvh = AnyBvh::build(&mesh, &p);
    let s = render(&bvh, &*mesh, camera, &RenderSettings { count: true, ..Default::default() }).ray_summary();
    (s.root_mean_nodes_visited, s.root_mean_triangle_tests)
}

fn at(camera: &Camera, width: u32, height: u32) -> Camera {
    Camera { width, height, ..*camera }
}

#[test]
fn in_the_stadium_midpoint_visits_fewer_nodes_than_sah_but_not_from_outside() {
    let Some(l) = scene("teapot-in-stadium.json") else { return };
    let inside = at(l.camera.as_ref().unwrap(), 320, 180);
    let (mid, _) = work(&l, Strategy::Midpoint, &inside);
    let (sah, _) = work(&l, Strategy::SahBinned, &inside);
    let (equal, _) = work(&l, Strategy::EqualCount, &inside);
    assert!(sah > 1.1 * mid, "from inside, SAH {sah:.1} visits more than midpoint {mid:.1}");
    assert!(equal > 1.8 * mid, "equal count {equal:.1} about twice midpoint {mid:.1}");
    let outside = Camera { position: glam::Vec3::new(0.0, 300.0, 400.0), look_at: glam::Vec3::ZERO, ..inside };
    let (mid, _) = work(&l, Strategy::Midpoint, &outside);
    let (sah, _) = work(&l, Strategy::SahBinned, &outside);
    assert!((sah - mid).abs() < 0.1 * mid, "from outside about equal: SAH {sah:.1}, midpoint {mid:.1}");
}

#[test]
fn on_the_floor_sah_visits_half_the_nodes_of_midpoint_in_both_layouts() {
    let l = scene("knot-on-floor.json").expect("a scene of our own assets");
    let camera = at(l.camera.as_ref().unwrap(), 320, 180);
    for layout in [Layout::Binary, Layout::Wide4] {
        let visits = |strategy| {
            let p = BuildParams { strategy, layout, ..BuildParams::default() };
            let mesh = l.flat_mesh().unwrap();
            let bvh = AnyBvh::build(&mesh, &p);
            render(&bvh, &*mesh, &camera, &RenderSettings { count: true, ..Default::default() })
                .ray_summary()
                .root_mean_nodes_visited
        };
        let (mid, sah, equal) = (visits(Strategy::Midpoint), visits(Strategy::SahBinned), visits(Strategy::EqualCount));
        assert!(mid > 1.8 * sah, "{layout:?}: midpoint {mid:.2} against SAH {sah:.2}");
        assert!(equal > mid, "{layout:?}: equal count {equal:.2} worse still than midpoint {mid:.2}");
    }
    let (mid, sah) = (work(&l, Strategy::Midpoint, &camera), work(&l, Strategy::SahBinned, &camera));
    assert!(mid.1 > sah.1, "and more triangle tests: {mid:?} {sah:?}");
}
