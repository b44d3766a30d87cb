//! The ready-made scenes in `scenes/` and the generated meshes in `assets/` they use. Every scene
//! file in the folder is checked (a new one is covered without touching this file): it loads,
//! builds with every strategy in both layouts, and a small render from its camera hits the same
//! pixels as the linear scan, and as the two-level BVH over its placements. The committed assets must be exactly what the generators write, and
//! a scene whose mesh is missing must say which field and where to get the mesh.

mod common;
#[path = "../core/tests/common/scratch.rs"]
mod scratch;

use bvhscope::bvh::{AnyBvh, BuildParams, Layout, LinearScan, SceneBuild, Strategy};
use bvhscope::mesh::{generate, write_obj};
use bvhscope::render::{render, Camera, RenderSettings};
use bvhscope::scene::{describe, load_any, SceneError};
use bvhscope::work::WorkControl;
use std::path::{Component, Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Every `.json` in `scenes/`, sorted.
fn scene_files() -> Vec<PathBuf> {
    let dir = root().join("scenes");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| entry.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no scene files in {}", dir.display());
    files
}

fn name(path: &Path) -> String {
    path.file_name().unwrap().to_string_lossy().into_owned()
}

/// `a/b/../c` → `a/c` without asking the file system (the file may not exist).
fn lexical(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.components().next_back(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}

/// Whether a scene's mesh is one of the shared test meshes (`../shared/models/`, not shipped).
fn is_shared(file: &Path) -> bool {
    lexical(file).starts_with(lexical(&root().join("../shared/models")))
}

/// The camera at about 96×64 pixels (its aspect kept), with fewer pixels for big meshes so the
/// linear scan stays near 10^9 triangle tests.
fn small_camera(camera: &Camera, triangles: usize) -> Camera {
    let aspect = camera.width as f64 / camera.height as f64;
    let pixels = (96.0 * 64.0f64).min(1e9 / triangles as f64).max(24.0 * 16.0);
    let height = (pixels / aspect).sqrt().round().max(1.0);
    let width = (height * aspect).round().max(1.0);
    Camera { width: width as u32, height: height as u32, ..*camera }
}

#[test]
fn every_scene_has_a_note_a_camera_and_reachable_meshes() {
    let readme = std::fs::read_to_string(root().join("scenes/README.md")).expect("scenes/README.md");
    for path in scene_files() {
        let n = name(&path);
        let desc = describe(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(desc.note.as_deref().is_some_and(|t| t.len() > 20), "{n}: a note on what the scene teaches");
        assert!(desc.camera.is_some(), "{n}: a camera that frames the scene");
        assert!(readme.contains(&format!("`{n}`")), "{n}: listed in scenes/README.md");
        for (i, m) in desc.meshes.iter().enumerate() {
            if is_shared(&m.file) {
                let hint = m.if_missing.as_deref().unwrap_or_default();
                assert!(hint.contains("../shared/models"), "{n}: meshes[{i}] is a shared mesh; if_missing says where");
            } else {
                assert!(lexical(&m.file).starts_with(root()), "{n}: meshes[{i}] is outside the repository");
                assert!(m.file.is_file(), "{n}: meshes[{i}]: {} is missing", m.file.display());
            }
        }
    }
}

#[test]
fn every_scene_builds_everywhere_and_hits_what_the_linear_scan_hits() {
    for path in scene_files() {
        let n = name(&path);
        let desc = describe(&path).unwrap_or_else(|e| panic!("{e}"));
        if desc.meshes.iter().any(|m| is_shared(&m.file)) && common::shared_models().is_none() {
            eprintln!("notice: skipping {n}: it needs the shared test meshes");
            continue;
        }
        let loaded = load_any(&path).unwrap_or_else(|e| panic!("{e}"));
        let flat = loaded.flat_mesh().unwrap_or_else(|e| panic!("{e}"));
        let mesh = &*flat;
        assert!(loaded.warnings.is_empty(), "{n}: {:?}", loaded.warnings);
        assert_eq!(loaded.desc.as_ref().and_then(|s| s.note.as_ref()), desc.note.as_ref(), "{n}: the note");
        let camera = small_camera(&loaded.camera.expect("a camera"), mesh.triangle_count());
        let settings = RenderSettings::default();
        let reference = render(&LinearScan::new(mesh), mesh, &camera, &settings).hit_mask();
        let hits = reference.iter().filter(|&&h| h).count();
        assert!(hits * 20 >= reference.len(), "{n}: the camera sees the scene ({hits} of {} pixels)", reference.len());
        let base = loaded.build.unwrap_or_default();
        for strategy in Strategy::ALL {
            for layout in Layout::ALL {
                let bvh = AnyBvh::build(mesh, &BuildParams { strategy, layout, ..base });
                common::check_any(&bvh, mesh);
                let mask = render(&bvh, mesh, &camera, &settings).hit_mask();
                let differ = mask.iter().zip(&reference).filter(|(a, b)| a != b).count();
                assert_eq!(differ, 0, "{n}, {strategy:?} {layout:?}: {differ} pixels differ from the linear scan");
            }
            // Two levels (this strategy on both), shading through the placements without the
            // flattened mesh, against the flattened scene's single BVH.
            assert!(loaded.instances().is_some(), "a scene gives its placements");
            let p = BuildParams { strategy, ..base };
            let two = loaded.build(&SceneBuild { bvh: p, top: Some(p) }, &WorkControl::new()).unwrap();
            let (a, b) =
                (render(&two, &two, &camera, &settings), render(&AnyBvh::build(mesh, &p), mesh, &camera, &settings));
            let differ = common::hit_differences(&a, &b, |x, y| {
                assert!((x.t - y.t).abs() <= 1e-4 * y.t, "{n}, {strategy:?}: two levels t {} vs one {}", x.t, y.t);
                if x.prim == y.prim {
                    let (nx, ny) = (x.normal, y.normal);
                    assert!(nx.dot(ny) > 0.999, "{n}, {strategy:?}: triangle {} shaded {nx} vs {ny}", x.prim);
                }
            });
            // Rotated placements round differently in object space: allow a grazing ray in 1000.
            assert!(
                differ * 1000 <= a.full_samples().unwrap().len(),
                "{n}, {strategy:?}: {differ} pixels differ between two levels and one"
            );
        }
    }
}

#[test]
fn committed_assets_are_what_the_generators_write() {
    let dir = root().join("assets");
    let assets = generate::assets();
    for (file, mesh) in &assets {
        let path = dir.join(file);
        let mut expected = Vec::new();
        write_obj(mesh, &mut expected).unwrap();
        let committed = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(committed.len() < 1 << 20, "{file} is over 1 MB");
        if committed != expected {
            let (a, b) = (String::from_utf8_lossy(&committed), String::from_utf8_lossy(&expected));
            // The first line that differs (or the first one past the shorter text).
            let line = a.lines().zip(b.lines()).position(|(x, y)| x != y);
            let line = line.unwrap_or(a.lines().count().min(b.lines().count()));
            let only_rounding = same_but_last_digits(&a, &b);
            let message = format!(
                "assets/{file} differs from what mesh::generate::assets() writes, from line {} \
                 (file: {:?}, generated: {:?}). Run `cargo run --example make_assets` and commit the result.",
                line + 1,
                a.lines().nth(line),
                b.lines().nth(line)
            );
            // The assets are written on Linux (glibc), where CI runs. Another libm may round a sine
            // or cosine differently in the last place; that is not the generator drifting.
            if only_rounding && !cfg!(all(target_os = "linux", target_env = "gnu")) {
                eprintln!("notice: {message} The numbers differ only in the last place (this platform's sin/cos).");
            } else {
                panic!("{message}");
            }
        }
    }
    // No stray OBJ in assets/ that no generator writes.
    for entry in std::fs::read_dir(&dir).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "obj") {
            let n = name(&p);
            assert!(assets.iter().any(|(f, _)| *f == n), "assets/{n} is not written by mesh::generate::assets()");
        }
    }
}

/// Same lines and words, numbers equal within 2 units in the last place of an f32.
fn same_but_last_digits(a: &str, b: &str) -> bool {
    a.lines().count() == b.lines().count()
        && a.lines().zip(b.lines()).all(|(x, y)| {
            let (x, y): (Vec<&str>, Vec<&str>) = (x.split(' ').collect(), y.split(' ').collect());
            x.len() == y.len()
                && x.iter().zip(&y).all(|(s, t)| match (s.parse::<f32>(), t.parse::<f32>()) {
                    (Ok(p), Ok(q)) => p == q || (p.signum() == q.signum() && p.to_bits().abs_diff(q.to_bits()) <= 2),
                    _ => s == t,
                })
        })
}

#[test]
fn a_missing_mesh_names_the_field_and_gives_the_hint() {
    let dir = scratch::shared("shipped");
    // Two levels down, so a scene's `../../shared/models/…` points at a folder that is not there.
    let scenes = dir.join("a/b");
    std::fs::create_dir_all(&scenes).unwrap();
    std::fs::write(scenes.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let text = r#"{"meshes": [{"file": "tri.obj"}, {"file": "gone/missing.obj", "if_missing": "get it from the course page"}]}"#;
    let path = scenes.join("missing.json");
    std::fs::write(&path, text).unwrap();
    let e = load_any(&path).expect_err("the mesh is missing");
    let msg = e.to_string();
    assert!(matches!(e, SceneError::Field { ref field, .. } if field == "meshes[1].file"), "{msg}");
    assert!(msg.contains(": meshes[1].file: ") && msg.contains("missing.obj"), "{msg}");
    assert!(msg.contains("get it from the course page"), "{msg}");

    // Each shipped scene's shared meshes: moved where `../shared/models` does not exist, the scene
    // fails on its first shared mesh with that mesh's hint. (Its own meshes are pointed back at
    // the repository.)
    for scene in scene_files() {
        let desc = describe(&scene).unwrap();
        let Some(first) = desc.meshes.iter().position(|m| is_shared(&m.file)) else { continue };
        let mut json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&scene).unwrap()).unwrap();
        for (m, d) in json["meshes"].as_array_mut().unwrap().iter_mut().zip(&desc.meshes) {
            if !is_shared(&d.file) {
                m["file"] = serde_json::Value::from(d.file.to_string_lossy().into_owned());
            }
        }
        let moved = scenes.join(name(&scene));
        std::fs::write(&moved, json.to_string()).unwrap();
        let msg = load_any(&moved).expect_err("the shared mesh is not found from there").to_string();
        let hint = desc.meshes[first].if_missing.as_deref().unwrap();
        assert!(msg.contains(&format!(": meshes[{first}].file: ")), "{}: {msg}", name(&scene));
        assert!(msg.contains(hint), "{}: the hint: {msg}", name(&scene));
    }
    let _ = std::fs::remove_dir_all(&dir);
}
