//! Meshes as people have them on the command line: the same mesh as OBJ, PLY, OFF and STL gives
//! the same statistics; a scene file places a PLY and an STL; a malformed file is one line
//! naming it, exit code 2. (The readers' own tests: `core/src/mesh/formats_tests.rs`.)

mod cli_support;
use cli_support::*;

const TENT_PLY: &str = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n-1 0 -1\n1 0 -1\n0 1 0\n-1 0 1\n1 0 1\n3 0 1 2\n3 2 3 4\n3 0 2 3\n3 1 4 2\n";
const TENT_OFF: &str = "OFF\n5 4 0\n-1 0 -1\n1 0 -1\n0 1 0\n-1 0 1\n1 0 1\n3 0 1 2\n3 2 3 4\n3 0 2 3\n3 1 4 2\n";

/// `stats --format json`, its times (`…_ms`) left out: they differ run to run.
fn stats(path: &str) -> serde_json::Value {
    let out = bvhscope(&["stats", path, "--format", "json", "--size", "64x48"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    fn untimed(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.retain(|k, _| !k.ends_with("_ms"));
                m.values_mut().for_each(untimed);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(untimed),
            _ => {}
        }
    }
    let mut v = serde_json::from_slice(&out.stdout).unwrap();
    untimed(&mut v);
    v
}

#[test]
fn the_same_mesh_in_every_format_gives_the_same_statistics() {
    let obj = tent();
    let ply = tmp("tent.ply");
    let off = tmp("tent.off");
    std::fs::write(&ply, TENT_PLY).unwrap();
    std::fs::write(&off, TENT_OFF).unwrap();
    let want = stats(obj.to_str().unwrap());
    for f in [&ply, &off] {
        let got = stats(f.to_str().unwrap());
        assert_eq!(got["stats"], want["stats"], "{}", f.display());
        assert_eq!(got["rays"], want["rays"], "{}", f.display());
    }
    // A scene file places them, as it places OBJs.
    let scene = tmp("formats-scene.json");
    let text = format!(
        r#"{{"meshes": [{{"file": "{}"}}, {{"file": "{}", "transform": {{"translate": [3, 0, 0]}}}}]}}"#,
        ply.display(),
        off.display()
    );
    std::fs::write(&scene, text).unwrap();
    let out = bvhscope(&["stats", scene.to_str().unwrap(), "--two-level", "--no-rays"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("2 placements of 2 meshes: 8 triangles"));
}

#[test]
fn a_malformed_mesh_is_one_line_naming_the_file_and_the_element() {
    let ply = tmp("broken.ply");
    std::fs::write(&ply, TENT_PLY.replace("3 1 4 2", "3 1 4 9")).unwrap();
    let stl = tmp("broken.stl");
    std::fs::write(&stl, [1u8; 120]).unwrap();
    for (f, needle) in [(&ply, "face 3 (line 18): refers to vertex 9"), (&stl, "neither ASCII STL")] {
        let out = bvhscope(&["render", f.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
        assert!(err.contains(f.to_str().unwrap()) && err.contains(needle), "{err}");
    }
}

/// A glTF whose buffer names a file outside its folder (`/etc/passwd`, `../`) is one line naming
/// the buffer, exit code 2, and nothing is written: the bytes of another file never become
/// triangles, boxes in a dump or numbers in a message.
#[test]
fn a_gltf_naming_a_file_outside_its_folder_is_refused_and_nothing_is_written() {
    let inner = tmp("hostile-gltf").join("scene");
    std::fs::create_dir_all(&inner).unwrap();
    std::fs::write(inner.parent().unwrap().join("secret.bin"), [0u8; 64]).unwrap();
    for (k, uri) in ["/etc/passwd", "../secret.bin", "/proc/self/environ"].into_iter().enumerate() {
        let gltf = inner.join(format!("h{k}.gltf"));
        let json = format!(
            r#"{{"asset": {{"version": "2.0"}}, "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
            "buffers": [{{"uri": "{uri}", "byteLength": 36}}], "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
            "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}}]}}"#
        );
        std::fs::write(&gltf, json).unwrap();
        let dump = inner.join(format!("h{k}.json"));
        let out = bvhscope(&["export-bvh", gltf.to_str().unwrap(), "-o", dump.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{uri}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
        assert!(err.contains("buffer 0: uri") && err.contains(uri), "{err}");
        assert!(!dump.exists(), "{uri}: nothing written");
    }
}
