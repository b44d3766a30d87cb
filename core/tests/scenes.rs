//! Scene files: bvhscope's own format and Moer-lite's scene.json.

#[path = "common/scratch.rs"]
mod scratch;

mod common;

use bvhscope_core::bvh::{AnyBvh, BuildParams, Layout, LinearScan, Strategy};
use bvhscope_core::render::{render, RenderSettings};
use bvhscope_core::scene::{load_any, parse_scene_file, write_scene_file, SceneError};
use bvhscope_core::work::WorkControl;
use glam::Vec3;
use std::path::{Path, PathBuf};

fn temp_dir() -> PathBuf {
    scratch::shared("scenes")
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const TRIANGLE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

#[test]
fn moer_lite_camera_gives_the_handouts_rays() {
    let Some(models) = common::shared_models() else { return };
    let loaded = load_any(models.join("moer-lite-lab1-bvh/scene.json")).unwrap();
    let cam = loaded.camera.expect("the scene's camera");
    assert_eq!((cam.position, cam.look_at, cam.up), (Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, Vec3::Y));
    assert_eq!((cam.vfov_deg, cam.width, cam.height), (45.0, 1200, 800));
    let g = cam.ray_gen();
    // The centre of the film looks straight at lookAt: (0,-1,-5)/√26.
    let centre = g.ray(600.0, 400.0).dir();
    assert!((centre - Vec3::new(0.0, -1.0, -5.0) / 26f32.sqrt()).length() < 1e-6);
    // Moer-lite's PinholeCamera::sampleRay, written out: NDC = pixel / film size, sample = 0.5
    // (pixel centre); x = ((NDC.x-0.5)·W + 0.5) / (W/2) · aspect·tan(fov/2); y likewise, negated;
    // direction (x, y, -1) in the camera frame whose columns are right, up, -forward.
    let (w, h) = (1200.0f32, 800.0f32);
    let half = (45f32.to_radians() * 0.5).tan();
    let forward = (Vec3::ZERO - Vec3::new(0.0, 1.0, 5.0)).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward).normalize();
    for (px, py) in [(0u32, 0u32), (1199, 0), (0, 799), (1199, 799), (300, 650), (777, 123)] {
        let x = ((px as f32 / w - 0.5) * w + 0.5) / (w * 0.5) * (w / h) * half;
        let y = -((py as f32 / h - 0.5) * h + 0.5) / (h * 0.5) * half;
        let expected = (right * x + up * y + forward).normalize();
        let got = g.pixel_ray(px, py).dir();
        assert!((got - expected).length() < 1e-5, "pixel ({px}, {py}): {got} vs {expected}");
    }
    // Top-left, by hand: right = (1,0,0), up = (0, 5, -1)/√26, forward = (0,-1,-5)/√26.
    let tl = g.pixel_ray(0, 0).dir();
    assert!(tl.x < 0.0 && tl.y > 0.0 && tl.z < 0.0, "row 0 is the top, column 0 the left: {tl}");
}

#[test]
fn moer_lite_scene_hit_mask_equals_linear_search() {
    let Some(models) = common::shared_models() else { return };
    let loaded = load_any(models.join("moer-lite-lab1-bvh/scene.json")).unwrap();
    assert!(loaded.warnings.is_empty());
    let cam = loaded.camera.unwrap();
    let settings = RenderSettings::default();
    let mesh = loaded.flat_mesh().unwrap();
    let reference = render(&LinearScan::new(&mesh), &*mesh, &cam, &settings).hit_mask();
    assert!(reference.iter().filter(|&&h| h).count() > 50_000);
    for s in Strategy::ALL {
        let bvh = AnyBvh::build(&mesh, &BuildParams::with_strategy(s));
        assert_eq!(render(&bvh, &*mesh, &cam, &settings).hit_mask(), reference, "{s:?}");
    }
}

#[test]
fn our_scene_file_round_trips_and_places_meshes() {
    let dir = temp_dir();
    write(&dir, "tri.obj", TRIANGLE_OBJ);
    let text = r#"{
        "camera": { "position": [0, 0, 5], "look_at": [0, 0, 0], "vertical_fov": 30, "size": [64, 48] },
        "meshes": [
            { "file": "tri.obj" },
            { "file": "tri.obj", "transform": { "translate": [10, 0, 0], "rotate": { "axis": [0, 0, 1], "degrees": 90 }, "scale": 2 } }
        ],
        "bvh": { "strategy": "midpoint", "layout": "binary", "max_leaf_size": 2 }
    }"#;
    let path = write(&dir, "two.json", text);
    let loaded = load_any(&path).unwrap();
    assert_eq!(loaded.placed_triangles(), 2, "one OBJ placed twice");
    let flat = loaded.flat_mesh().unwrap();
    assert_eq!(flat.groups.len(), 2);
    // Second placement: scale 2, rotate 90° about z, then translate: (1,0,0) → (0,2,0) → (10,2,0).
    let moved = flat.triangle(1);
    assert!((moved[1] - Vec3::new(10.0, 2.0, 0.0)).length() < 1e-5, "{moved:?}");
    let build = loaded.build.unwrap();
    assert_eq!((build.strategy, build.max_leaf_size), (Strategy::Midpoint, 2));
    let cam = loaded.camera.unwrap();
    assert_eq!((cam.width, cam.height, cam.vfov_deg), (64, 48, 30.0));

    // Written back, it reads the same.
    let meshes = loaded.desc.as_ref().unwrap().meshes.clone();
    let again = parse_scene_file(&path, &write_scene_file(&cam, &meshes, &build)).unwrap();
    assert_eq!(again.camera, Some(cam));
    assert_eq!(again.build, Some(build));
    for (a, b) in again.meshes.iter().zip(&meshes) {
        assert_eq!(a.file, b.file);
        assert!(a.transform.abs_diff_eq(b.transform, 1e-5));
    }
}

#[test]
fn malformed_scene_files_name_the_field() {
    let dir = temp_dir();
    write(&dir, "tri.obj", TRIANGLE_OBJ);
    let moer_camera = r#""camera": {"type": "pinhole", "transform": {"position": [0,1,5], "lookAt": [0,0,0], "up": [0,1,0]}, "verticalFov": 45, "film": {"size": [10, 10]}}"#;
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "unknown shape type",
            format!(r#"{{{moer_camera}, "scene": {{"shapes": [{{"type": "teapot"}}]}}}}"#),
            "scene.shapes[0].type",
        ),
        ("missing OBJ", r#"{"meshes": [{"file": "missing.obj"}]}"#.into(), "meshes[0].file"),
        (
            "bad transform",
            r#"{"meshes": [{"file": "tri.obj", "transform": {"scale": 0}}]}"#.into(),
            "meshes[0].transform.scale",
        ),
        (
            "bad rotation",
            r#"{"meshes": [{"file": "tri.obj", "transform": {"rotate": {"axis": [0,0,0], "degrees": 5}}}]}"#.into(),
            "meshes[0].transform.rotate.axis",
        ),
        (
            "singular matrix",
            r#"{"meshes": [{"file": "tri.obj", "transform": {"matrix": [[0,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}}]}"#
                .into(),
            "meshes[0].transform.matrix",
        ),
        ("wrong type", r#"{"meshes": [{"file": 7}]}"#.into(), "meshes[0].file"),
        (
            "wrong type in camera",
            r#"{"camera": {"position": "here", "look_at": [0,0,0], "size": [4,4]}, "meshes": []}"#.into(),
            "camera.position",
        ),
        (
            "wrong moer-lite transform",
            format!(
                r#"{{{moer_camera}, "scene": {{"shapes": [{{"type": "triangle", "file": "tri.obj", "transform": {{"rotate": {{"axis": [0,1,0]}}}}}}]}}}}"#
            ),
            "scene.shapes[0].transform.rotate.radian",
        ),
        ("unknown field", r#"{"meshes": [], "lights": []}"#.into(), "lights"),
        ("bad strategy", r#"{"meshes": [{"file": "tri.obj"}], "bvh": {"strategy": "fast"}}"#.into(), "bvh.strategy"),
    ];
    for (what, text, field) in cases {
        let path = write(&dir, "bad.json", &text);
        let e = load_any(&path).expect_err(what);
        let msg = e.to_string();
        assert!(matches!(e, SceneError::Field { .. }), "{what}: {msg}");
        assert!(msg.starts_with(&path.display().to_string()), "{what}: names the file: {msg}");
        assert!(msg.contains(&format!(": {field}:")), "{what}: names the field {field}: {msg}");
    }
    let path = write(&dir, "broken.json", "{\n \"meshes\": [,]\n}");
    assert!(matches!(load_any(&path), Err(SceneError::Json { line: 2, .. })));
}

#[test]
fn analytic_shapes_are_listed_in_a_warning_and_the_rest_loads() {
    let dir = temp_dir();
    write(&dir, "tri.obj", TRIANGLE_OBJ);
    let text = r#"{"camera": {"transform": {"position": [0,0,5], "lookAt": [0,0,0], "up": [0,1,0]}, "verticalFov": 45, "film": {"size": [8, 8]}},
        "scene": {"shapes": [{"type": "sphere", "center": [0,0,0], "radius": 1}, {"type": "triangle", "file": "tri.obj"}]}}"#;
    let loaded = load_any(write(&dir, "mixed.json", text)).unwrap();
    assert_eq!(loaded.placed_triangles(), 1);
    assert_eq!(loaded.warnings.len(), 1);
    assert!(loaded.warnings[0].contains("scene.shapes[0] (sphere)"), "{:?}", loaded.warnings);
}

#[test]
fn a_scene_of_many_placements_costs_memory_per_placement_and_flattens_only_within_the_budget() {
    use bvhscope_core::bvh::SceneBuild;
    use bvhscope_core::scene::{SceneError, MAX_FLAT_TRIANGLES};
    let dir = temp_dir();
    // 21,000 placements of 1,000 triangles: 21M placed triangles, past the one-level budget.
    let n = 21_000;
    let scene = load_any(common::many_placements(&dir, n)).unwrap();
    assert_eq!(scene.placed_triangles(), 21_000_000);
    assert!(scene.placed_triangles() > MAX_FLAT_TRIANGLES);
    assert_eq!(scene.report.triangles, 21_000_000, "the report counts placed triangles");
    // The box of every placed vertex, without flattening: 145 × 145 grid, 3 apart, torus radius 1.3.
    let b = scene.bounds();
    assert!((b.min.x + 1.3).abs() < 0.02 && (b.max.x - (144.0 * 3.0 + 1.3)).abs() < 0.02, "{b:?}");
    assert!((b.max.z - (144.0 * 3.0 + 1.3)).abs() < 0.02 && (b.max.y - 0.3).abs() < 0.02, "{b:?}");

    // One level is refused before anything is allocated, in one sentence naming the file.
    let e = scene.flat_mesh().expect_err("past the budget");
    assert!(matches!(e, SceneError::TooLargeToFlatten { triangles: 21_000_000, .. }), "{e}");
    let text = e.to_string();
    assert!(text.contains("many-21000.json") && text.contains("two levels"), "{text}");
    let one = SceneBuild { bvh: BuildParams::default(), top: None };
    assert!(scene.build(&one, &WorkControl::new()).is_err());

    // Two levels: one torus BVH, and per placement a transform pair, a box and an id.
    let top = BuildParams { max_leaf_size: 1, layout: Layout::Binary, ..BuildParams::default() };
    let two = scene.build(&SceneBuild { bvh: BuildParams::default(), top: Some(top) }, &WorkControl::new()).unwrap();
    let t = two.two_level().unwrap();
    let mesh_bvh = bvhscope_core::bvh::TreeView::memory_bytes(&t.bottom[0]);
    let per_placement = (two.memory_bytes() - mesh_bvh) as f64 / n as f64;
    assert!(per_placement < 400.0, "{per_placement:.0} bytes per placement");
    // The scene holds its one mesh and no flattened copy.
    match &scene.geometry {
        bvhscope_core::scene::Geometry::Placed { instances, flat, .. } => {
            assert_eq!(instances.meshes.len(), 1);
            assert!(flat.get().is_none(), "nothing was flattened");
        }
        other => panic!("a scene file's geometry is its placements: {other:?}"),
    }
    // It traces and shades: the ray down onto the first torus's ring hits it.
    let mut ray = bvhscope_core::geometry::Ray::new(Vec3::new(1.0, 5.0, 0.0), -Vec3::Y);
    let hit = bvhscope_core::bvh::Accelerator::closest_hit(
        &two,
        &mut ray,
        Default::default(),
        &mut bvhscope_core::bvh::NoStats,
    )
    .expect("hits the torus");
    assert!((hit.t - 4.7).abs() < 0.01, "t = {}", hit.t);
    let n = bvhscope_core::mesh::Surface::shading_normal(&two, &ray, hit.prim, hit.triangle_hit());
    assert!(n.y > 0.9, "the top of the ring faces up: {n}");
}
