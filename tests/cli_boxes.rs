//! `render --boxes DEPTH`: the BVH's node boxes at a depth drawn into the PNG, by the code that
//! draws the app's overlay. The root box of a cube lands on the pixels along its projected edges
//! (worked out here from the camera, independently of the projection in the core), nothing else
//! changes, and the same command writes the same bytes.

mod cli_support;

use cli_support::{bvhscope, tent, tmp};
use glam::{Vec2, Vec3};
use image::RgbImage;

const EYE: Vec3 = Vec3::new(2.6, 2.1, 4.3);
const FOV: f32 = 45.0;
const W: u32 = 160;
const H: u32 = 120;

fn cube() -> std::path::PathBuf {
    let p = tmp("boxes-cube.obj");
    let mut obj = String::new();
    for k in 0..8 {
        let c = |bit: u32| if k & bit == 0 { -1.0 } else { 1.0 };
        obj += &format!("v {} {} {}\n", c(1), c(2) * 0.5, c(4) * 0.75);
    }
    for f in [[1, 2, 4, 3], [5, 7, 8, 6], [1, 5, 6, 2], [3, 4, 8, 7], [1, 3, 7, 5], [2, 6, 8, 4]] {
        obj += &format!("f {} {} {}\nf {} {} {}\n", f[0], f[1], f[2], f[0], f[2], f[3]);
    }
    std::fs::write(&p, obj).unwrap();
    p
}

/// `render` of the cube with `extra` words; the PNG.
fn render(mesh: &std::path::Path, name: &str, extra: &[&str]) -> (RgbImage, Vec<u8>) {
    let out = tmp(name);
    let camera = format!("{},{},{}:0,0,0", EYE.x, EYE.y, EYE.z);
    let size = format!("{W}x{H}");
    let mut args =
        vec!["render", mesh.to_str().unwrap(), "--camera", &camera, "--size", &size, "-o", out.to_str().unwrap()];
    args.extend(extra);
    let run = bvhscope(&args);
    assert!(run.status.success(), "{args:?}: {}", String::from_utf8_lossy(&run.stderr));
    let bytes = std::fs::read(&out).unwrap();
    (image::load_from_memory(&bytes).unwrap().to_rgb8(), bytes)
}

/// The cube's corners on the image: a pinhole camera at EYE looking at the origin, Y up.
fn corners() -> Vec<Vec2> {
    let forward = (-EYE).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let tan_v = (FOV.to_radians() * 0.5).tan();
    let tan_h = tan_v * W as f32 / H as f32;
    (0..8)
        .map(|k| {
            let c = |bit: u32, s: f32| if k & bit == 0 { -s } else { s };
            let d = Vec3::new(c(1, 1.0), c(2, 0.5), c(4, 0.75)) - EYE;
            let (x, y, z) = (d.dot(right), d.dot(up), d.dot(forward));
            Vec2::new(W as f32 * 0.5 * (1.0 + x / z / tan_h), H as f32 * 0.5 * (1.0 - y / z / tan_v))
        })
        .collect()
}

fn distance_to_segment(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let d = b - a;
    let t = ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    (a + d * t).distance(p)
}

#[test]
fn the_root_box_is_drawn_along_its_projected_edges_and_nowhere_else() {
    let mesh = cube();
    let (plain, plain_bytes) = render(&mesh, "plain.png", &[]);
    let (boxed, boxed_bytes) = render(&mesh, "boxed.png", &["--boxes", "0"]);
    let (_, again) = render(&mesh, "boxed-again.png", &["--boxes", "0"]);
    assert_eq!(boxed_bytes, again, "the same bytes every run");
    assert_ne!(plain_bytes, boxed_bytes);
    let (_, plain_again) = render(&mesh, "plain-again.png", &[]);
    assert_eq!(plain_bytes, plain_again, "without --boxes, the image as it was");

    let c = corners();
    let edges: Vec<(Vec2, Vec2)> = (0..8usize)
        .flat_map(|i| [1usize, 2, 4].into_iter().filter(move |b| i & b == 0).map(move |b| (i, i | b)))
        .map(|(i, j)| (c[i], c[j]))
        .collect();
    assert_eq!(edges.len(), 12);
    let colour = bvhscope::render::boxes::node_rgb(0);
    let mut on_edges = 0;
    for (x, y, px) in boxed.enumerate_pixels() {
        let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
        let d = edges.iter().map(|&(a, b)| distance_to_segment(centre, a, b)).fold(f32::INFINITY, f32::min);
        if d >= 1.3 {
            assert_eq!(px, plain.get_pixel(x, y), "({x}, {y}) is {d} px from every edge: unchanged");
        } else if d <= 0.2 {
            assert_eq!(px.0, colour, "({x}, {y}) lies on an edge: the root box's colour");
            on_edges += 1;
        }
    }
    assert!(on_edges > 100, "{on_edges} pixels on the edges");
    // At each corner (where three edges meet), the box's colour, at least half covering the image.
    for p in c {
        assert!(p.x >= 0.0 && p.y >= 0.0 && p.x < W as f32 && p.y < H as f32, "{p} on the image");
        let (x, y) = (p.x as u32, p.y as u32);
        let (got, was) = (boxed.get_pixel(x, y).0, plain.get_pixel(x, y).0);
        for k in 0..3 {
            let (g, w, b) = (got[k] as i32, was[k] as i32, colour[k] as i32);
            assert!((g - b).abs() * 2 <= (w - b).abs() + 2, "corner ({x}, {y}): {got:?} over {was:?}, box {colour:?}");
        }
    }
}

/// Over a heatmap the boxes are on the image, the legend below it as it was.
#[test]
fn the_legend_is_left_alone() {
    let mesh = tent();
    let (plain, _) = render(&mesh, "tent-plain.png", &["--view", "visits"]);
    let (boxed, _) = render(&mesh, "tent-boxed.png", &["--view", "visits", "--boxes", "0"]);
    assert!(plain.height() > H && plain.dimensions() == boxed.dimensions(), "a legend below the image");
    assert!((H..plain.height()).all(|y| (0..plain.width()).all(|x| plain.get_pixel(x, y) == boxed.get_pixel(x, y))));
    assert!((0..H).any(|y| (0..W).any(|x| plain.get_pixel(x, y) != boxed.get_pixel(x, y))));
}

/// With --against, each build's boxes on its side of the split; the split's line left white.
#[test]
fn against_draws_each_build_s_boxes_on_its_side() {
    let mesh = cube();
    let pair = ["--view", "visits", "--against", "midpoint", "--pair-view", "halves"];
    let (plain, _) = render(&mesh, "pair-plain.png", &pair);
    let (boxed, _) = render(&mesh, "pair-boxed.png", &[&pair[..], &["--boxes", "0"]].concat());
    let x0 = W / 2;
    assert!((0..H).all(|y| boxed.get_pixel(x0 - 1, y).0 == [255; 3] && boxed.get_pixel(x0, y).0 == [255; 3]));
    for side in [0..x0 - 1, x0 + 1..W] {
        assert!(side.clone().any(|x| (0..H).any(|y| plain.get_pixel(x, y) != boxed.get_pixel(x, y))), "{side:?}");
    }
}

#[test]
fn a_depth_the_tree_does_not_have_is_refused_in_one_line() {
    let mesh = cube();
    let out = bvhscope(&[
        "render",
        mesh.to_str().unwrap(),
        "--size",
        "32x24",
        "--boxes",
        "40",
        "-o",
        tmp("deep.png").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("--boxes 40") && err.contains("deepest level"), "{err}");
    assert!(!tmp("deep.png").exists());
    let out = bvhscope(&["render", mesh.to_str().unwrap(), "--boxes", "-1"]);
    assert_eq!(out.status.code(), Some(2));
}
