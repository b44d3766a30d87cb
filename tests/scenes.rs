//! Scene files: bvhscope's own format and Moer-lite's scene.json.

mod common;

use bvhscope::bvh::{AnyBvh, BuildParams, LinearScan, SplitStrategy};
use bvhscope::render::{render, RenderSettings};
use bvhscope::scene::{load_any, parse_scene_file, write_scene_file, SceneError};
use glam::Vec3;
use std::path::{Path, PathBuf};

fn temp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("bvhscope-scenes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
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
    let reference = render(&LinearScan::new(&loaded.mesh), &loaded.mesh, &cam, &settings).hit_mask();
    assert!(reference.iter().filter(|&&h| h).count() > 50_000);
    for s in SplitStrategy::ALL {
        let bvh = AnyBvh::build(&loaded.mesh, &BuildParams::with_strategy(s));
        assert_eq!(render(&bvh, &loaded.mesh, &cam, &settings).hit_mask(), reference, "{s:?}");
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
    assert_eq!(loaded.mesh.triangle_count(), 2, "one OBJ placed twice");
    assert_eq!(loaded.mesh.groups.len(), 2);
    // Second placement: scale 2, rotate 90° about z, then translate: (1,0,0) → (0,2,0) → (10,2,0).
    let moved = loaded.mesh.triangle(1);
    assert!((moved[1] - Vec3::new(10.0, 2.0, 0.0)).length() < 1e-5, "{moved:?}");
    let build = loaded.build.unwrap();
    assert_eq!((build.strategy, build.max_leaf_size), (SplitStrategy::Midpoint, 2));
    let cam = loaded.camera.unwrap();
    assert_eq!((cam.width, cam.height, cam.vfov_deg), (64, 48, 30.0));

    // Written back, it reads the same.
    let meshes = loaded.scene.as_ref().unwrap().meshes.clone();
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
    assert_eq!(loaded.mesh.triangle_count(), 1);
    assert_eq!(loaded.warnings.len(), 1);
    assert!(loaded.warnings[0].contains("scene.shapes[0] (sphere)"), "{:?}", loaded.warnings);
}
