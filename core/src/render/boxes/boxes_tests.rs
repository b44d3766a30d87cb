use super::*;
use crate::bvh::{AnyBvh, BuildParams};
use crate::mesh::Mesh;
use crate::render::raycast::{render, RenderSettings};
use image::{Rgb, RgbImage};
use std::sync::Arc;

fn camera() -> Camera {
    Camera {
        position: Vec3::new(0.0, 0.0, 5.0),
        look_at: Vec3::ZERO,
        up: Vec3::Y,
        vfov_deg: 90.0,
        width: 200,
        height: 100,
    }
}

fn size() -> Vec2 {
    Vec2::new(200.0, 100.0)
}

/// The twelve triangles of the cube from `lo` to `hi`.
fn cube(lo: Vec3, hi: Vec3) -> Mesh {
    let positions = Aabb::new(lo, hi).corners().to_vec();
    let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
    let triangles = faces.iter().flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]]).collect();
    Mesh { positions, triangles, ..Default::default() }
}

#[test]
fn points_project_like_the_renderer() {
    let p = Projector::new(&camera(), size(), 0.01);
    // The look-at point is the centre; with a 90° vertical fov, y = z·tan(45°) is the top edge.
    assert_eq!(p.project(Vec3::ZERO), Some(Vec2::new(100.0, 50.0)));
    assert!(p.project(Vec3::new(0.0, 5.0, 0.0)).unwrap().y.abs() < 1e-3);
    // And the renderer's ray through that image point heads towards the world point.
    let dir = camera().ray_gen().ray(150.0, 25.0).dir();
    let world = Vec3::new(0.0, 0.0, 5.0) + dir * (5.0 / -dir.z);
    assert!((p.project(world).unwrap() - Vec2::new(150.0, 25.0)).length() < 1e-2);
    assert_eq!(p.project(Vec3::new(0.0, 0.0, 6.0)), None, "behind the eye");
}

/// The root box of a cube at depth 0 is the cube's: 12 segments, whose ends are the image points
/// whose rays the renderer sends through the cube's corners.
#[test]
fn a_cube_s_root_box_projects_to_its_corners() {
    let (lo, hi) = (Vec3::new(-1.0, -0.5, -1.5), Vec3::new(1.5, 1.0, 0.5));
    let bvh = SceneBvh::build_single(Arc::new(cube(lo, hi)), &BuildParams::default(), &Default::default()).unwrap();
    let cam = Camera { position: Vec3::new(3.0, 2.5, 6.0), ..camera() };
    let boxes = boxes_at(&bvh, &BoxPick::at(&bvh, 0));
    assert_eq!(boxes.len(), 1);
    assert_eq!(boxes[0].corners, Aabb::new(lo, hi).corners());
    let segments = box_segments(&boxes, &cam, size(), 1.5, None);
    assert_eq!(segments.len(), 12);
    assert!(segments.iter().all(|s| s.rgb == node_rgb(boxes[0].id) && s.width == 1.5));
    let g = cam.ray_gen();
    for s in &segments {
        for end in [s.a, s.b] {
            let dir = g.ray(end.x, end.y).dir();
            let hit = Aabb::new(lo, hi).corners().iter().any(|&c| (c - cam.position).normalize().dot(dir) > 1.0 - 1e-6);
            assert!(hit, "{end:?} is no corner's image");
        }
    }
    // Each corner is the end of three edges.
    let p = Projector::new(&cam, size(), 0.01);
    for c in Aabb::new(lo, hi).corners() {
        let at = p.project(c).unwrap();
        let ends = segments.iter().flat_map(|s| [s.a, s.b]).filter(|e| (*e - at).length() < 1e-3).count();
        assert_eq!(ends, 3, "{c}");
    }
    assert_eq!(max_depths(&bvh).1, None);
}

#[test]
fn boxes_behind_the_camera_give_no_segments_and_crossing_ones_are_clipped() {
    let behind = [NodeBox::world(3, &Aabb::new(Vec3::new(-1.0, -1.0, 6.0), Vec3::new(1.0, 1.0, 8.0)))];
    assert!(box_segments(&behind, &camera(), size(), 1.0, None).is_empty());
    let p = Projector::new(&camera(), size(), 0.01);
    let (a, b) = p.segment(Vec3::new(1.0, 0.0, 10.0), Vec3::new(1.0, 0.0, 0.0)).expect("part is visible");
    assert!(a.is_finite());
    // x/z = 1/5 with tan(h/2) = 2 (aspect 2, 90° vertical): 100 + 0.2 / 2 * 100 = 110.
    assert!((b.x - 110.0).abs() < 1e-3, "the visible end projects normally: {b:?}");
    let around = Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
    let edges: Vec<_> = p.box_edges(&around.corners()).collect();
    assert!(!edges.is_empty() && edges.len() < 12);
    let two = [NodeBox::world(1, &Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))), NodeBox::world(2, &around)];
    let segments = box_segments(&two, &camera(), size(), 1.0, None);
    assert!(segments.len() > 12 && segments.iter().all(|s| s.a.is_finite() && s.b.is_finite()));
    assert_ne!(node_rgb(1), node_rgb(2));
}

fn drawn_length(s: &[Segment]) -> f32 {
    s.iter().map(|s| (s.b - s.a).length()).sum()
}

#[test]
fn the_depth_test_drops_what_lies_behind_the_surface() {
    // A wall at z = 0 facing the camera (at z = 5), and boxes in front of it, behind it, across it.
    let wall = cube(Vec3::new(-9.0, -9.0, -0.01), Vec3::new(9.0, 9.0, 0.0));
    let cam = camera();
    let frame = render(&AnyBvh::build(&wall, &BuildParams::default()), &wall, &cam, &RenderSettings::default());
    let b = |id: usize, z0: f32, z1: f32| {
        [NodeBox::world(id, &Aabb::new(Vec3::new(-1.0, -1.0, z0), Vec3::new(1.0, 1.0, z1)))]
    };
    let all = |b: &[NodeBox]| drawn_length(&box_segments(b, &cam, size(), 1.0, None));
    let shown = |b: &[NodeBox]| drawn_length(&box_segments(b, &cam, size(), 1.0, Some(&frame)));
    let (front, behind, across) = (b(1, 1.0, 2.0), b(2, -3.0, -2.0), b(3, -1.0, 1.0));
    assert!((shown(&front) - all(&front)).abs() < 0.01 * all(&front), "a box in front is drawn whole");
    assert_eq!(shown(&behind), 0.0, "a box behind the wall is hidden");
    let (a, s) = (all(&across), shown(&across));
    assert!(s > 0.3 * a && s < 0.8 * a, "part of a box through the wall: {s} of {a}");
}

/// Two levels, as the app shows them by default: each placement of the mesh's BVH at the depth
/// (in its colour), and the top level's boxes at depth 1 in white, twice as wide.
#[test]
fn two_level_boxes_take_the_app_s_defaults() {
    use glam::Affine3A;
    let mesh = Arc::new(cube(Vec3::ZERO, Vec3::ONE));
    let placements: Vec<(u32, Affine3A)> =
        (0..4).map(|k| (0, Affine3A::from_translation(Vec3::new(3.0 * k as f32, 0.0, 0.0)))).collect();
    let p = BuildParams::default();
    let bvh = SceneBvh::build_two_level(vec![mesh], &placements, &p, &p, &Default::default()).unwrap();
    let (bottom_max, top_max) = max_depths(&bvh);
    assert!(top_max.unwrap() >= 1 && bottom_max >= 1);
    let pick = BoxPick::at(&bvh, 0);
    assert_eq!(pick, BoxPick { depth: 0, top_depth: Some(DEFAULT_TOP_DEPTH), bottom: true, leaves_above: false });
    let boxes = boxes_at(&bvh, &pick);
    let (top, bottom): (Vec<&NodeBox>, Vec<&NodeBox>) = boxes.iter().partition(|b| b.top);
    assert_eq!(bottom.len(), 4, "the mesh's root box at each placement");
    assert!(bottom.iter().any(|b| b.corners[0] == Vec3::new(9.0, 0.0, 0.0)));
    assert!(!top.is_empty());
    let cam = Camera { position: Vec3::new(4.5, 2.0, 12.0), look_at: Vec3::new(4.5, 0.5, 0.0), ..camera() };
    let segments = box_segments(&boxes, &cam, size(), 1.0, None);
    assert!(segments.iter().any(|s| s.rgb == TOP_RGB && s.width == 2.0));
    assert!(segments.iter().any(|s| s.rgb != TOP_RGB && s.width == 1.0));
}

const GREY: Rgb<u8> = Rgb([40, 40, 40]);

#[test]
fn a_segment_is_drawn_along_its_line_and_nowhere_else() {
    let mut img = RgbImage::from_pixel(24, 12, GREY);
    let s = Segment { a: Vec2::new(3.0, 5.5), b: Vec2::new(20.0, 5.5), rgb: [250, 10, 20], width: 1.5 };
    draw_segments(&mut img, &[s], 0..24, 0..12);
    for (x, y, px) in img.enumerate_pixels() {
        let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
        let d = Vec2::new(cx.clamp(3.0, 20.0) - cx, 5.5 - cy).length();
        if d <= 0.25 {
            assert_eq!(px.0, s.rgb, "({x}, {y}) on the line");
        } else if d >= 1.25 {
            assert_eq!(*px, GREY, "({x}, {y}) off the line");
        }
    }
    // The same bytes again; nothing outside the area asked for; far-off ends are clipped.
    let mut again = RgbImage::from_pixel(24, 12, GREY);
    draw_segments(&mut again, &[s], 0..24, 0..12);
    assert_eq!(img, again);
    let mut left = RgbImage::from_pixel(24, 12, GREY);
    draw_segments(&mut left, &[s], 0..10, 0..12);
    assert!(left.enumerate_pixels().all(|(x, y, p)| if x < 10 { p == img.get_pixel(x, y) } else { *p == GREY }));
    let mut far = RgbImage::from_pixel(24, 12, GREY);
    let diagonal = Segment { a: Vec2::new(-1e7, -1e7), b: Vec2::new(1e7, 1e7), ..s };
    draw_segments(&mut far, &[diagonal], 0..24, 0..12);
    assert_eq!(far.get_pixel(6, 6).0, s.rgb, "on the diagonal");
    assert_eq!(*far.get_pixel(20, 2), GREY);
}
