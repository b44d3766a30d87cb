//! Files written to break the readers (issue 58): each is one error naming the element, line or
//! value, never a panic, a silent misreading or a read outside the file's folder.

use super::*;
use base64::Engine;
use std::path::PathBuf;

fn dir() -> PathBuf {
    crate::scratch::shared("hostile")
}

fn write(name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir().join(name);
    if let Some(parent) = p.parent() {
        std::fs::create_dir_all(parent).unwrap();
    }
    std::fs::write(&p, bytes).unwrap();
    p
}

/// The error loading `name` (any mesh format) gives; a panic fails the test.
fn refused(name: &str, bytes: &[u8]) -> String {
    match load_mesh(write(name, bytes)) {
        Err(e) => e.to_string(),
        Ok((m, _)) => panic!("{name} loaded ({} triangles)", m.triangles.len()),
    }
}

fn gltf_refused(name: &str, json: &str) -> String {
    match crate::mesh::load_gltf(&write(name, json.as_bytes())) {
        Err(e) => e.to_string(),
        Ok(g) => panic!("{name} loaded ({} placements)", g.placements.len()),
    }
}

fn b64(bytes: &[u8]) -> String {
    format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(bytes))
}

/// A quad's four positions then its six indices as `index_bytes` (already encoded): a glTF with
/// one mesh, its index accessor of `component` type, `extra` added to the document's end.
fn quad(index_bytes: &[u8], component: u32, nodes: &str, extra_accessors: &str) -> String {
    let mut bin = Vec::new();
    for p in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in p {
            bin.extend(c.to_le_bytes());
        }
    }
    bin.extend(index_bytes);
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": {nodes},
        "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
        "buffers": [{{"uri": "{}", "byteLength": {}}}],
        "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": {}}}],
        "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
                      {{"bufferView": 1, "componentType": {component}, "count": 6, "type": "SCALAR"}}{extra_accessors}]}}"#,
        b64(&bin),
        bin.len(),
        index_bytes.len()
    )
}

fn u16s(v: &[u16]) -> Vec<u8> {
    v.iter().flat_map(|i| i.to_le_bytes()).collect()
}

#[test]
fn an_off_face_of_the_largest_count_is_refused_not_a_panic() {
    let e = refused("huge-face.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n18446744073709551615 0 1 2\n");
    assert!(e.contains("line 6: face 0") && e.contains("declares 18446744073709551615 vertices"), "{e}");
}

#[test]
fn gltf_indices_of_floats_bytes_or_shorts_and_a_short_stride_are_refused_naming_the_accessor() {
    let floats: Vec<u8> = [0f32, 1.0, 2.0, 0.0, 2.0, 3.0].iter().flat_map(|f| f.to_le_bytes()).collect();
    let e = gltf_refused("float-indices.gltf", &quad(&floats, 5126, r#"[{"mesh": 0}]"#, ""));
    assert!(e.contains("the indices (accessor 1)") && e.contains("SCALAR of unsigned"), "{e}");
    for component in [5120, 5122] {
        let e =
            gltf_refused("signed-indices.gltf", &quad(&u16s(&[0, 1, 2, 0, 2, 3]), component, r#"[{"mesh": 0}]"#, ""));
        assert!(e.contains("accessor 1"), "{e}");
    }
    // The positions' view read with a stride of 4 bytes, where an element takes 12.
    let json = quad(&u16s(&[0, 1, 2, 0, 2, 3]), 5123, r#"[{"mesh": 0}]"#, "")
        .replace(r#""byteOffset": 0, "byteLength": 48}"#, r#""byteOffset": 0, "byteLength": 48, "byteStride": 4}"#);
    let e = gltf_refused("short-stride.gltf", &json);
    assert!(e.contains("POSITION (accessor 0)") && e.contains("byteStride of 4"), "{e}");
    // The good quad loads (the cases above differ from it only where they say).
    let ok = quad(&u16s(&[0, 1, 2, 0, 2, 3]), 5123, r#"[{"mesh": 0}]"#, "");
    assert_eq!(crate::mesh::load_gltf(&write("good-quad.gltf", ok.as_bytes())).unwrap().meshes[0].triangles.len(), 2);
}

#[test]
fn a_gltf_node_graph_that_is_not_a_forest_is_refused_naming_the_node() {
    let idx = u16s(&[0, 1, 2, 0, 2, 3]);
    let twice = quad(&idx, 5123, r#"[{"children": [1, 1]}, {"mesh": 0}]"#, "");
    assert!(gltf_refused("twice.gltf", &twice).contains("node 0: names node 1 twice among its children"));
    let two_parents =
        quad(&idx, 5123, r#"[{"children": [1, 2]}, {"children": [3]}, {"children": [3]}, {"mesh": 0}]"#, "");
    let e = gltf_refused("two-parents.gltf", &two_parents);
    assert!(e.contains("node 3: has two parents, node 1 and node 2"), "{e}");
    // Twenty levels of two children each naming one node would place the mesh a million times.
    let nodes: Vec<String> = (0..20).map(|i| format!(r#"{{"children": [{0}, {0}]}}"#, i + 1)).collect();
    let doubling = quad(&idx, 5123, &format!(r#"[{}, {{"mesh": 0}}]"#, nodes.join(", ")), "");
    assert!(gltf_refused("doubling.gltf", &doubling).contains("twice among its children"));
    let root_twice = quad(&idx, 5123, r#"[{"mesh": 0}]"#, "").replace(r#""nodes": [0]}"#, r#""nodes": [0, 0]}"#);
    assert!(gltf_refused("root-twice.gltf", &root_twice).contains("node 0: is named twice among scene 0's nodes"));
    let root_child = quad(&idx, 5123, r#"[{"children": [0], "mesh": 0}]"#, "");
    assert!(gltf_refused("root-child.gltf", &root_child).contains("node 0: is a root of scene 0 and a child of node 0"));
}

#[test]
fn placements_past_the_limit_and_data_named_again_and_again_are_refused() {
    let idx = u16s(&[0, 1, 2, 0, 2, 3]);
    let n = crate::files::limits::PLACEMENTS.max + 1;
    let nodes = vec![r#"{"mesh": 0}"#; n as usize].join(",");
    let roots: Vec<String> = (0..n).map(|i| i.to_string()).collect();
    let json = quad(&idx, 5123, &format!("[{nodes}]"), "")
        .replace(r#""scenes": [{"nodes": [0]}]"#, &format!(r#""scenes": [{{"nodes": [{}]}}]"#, roots.join(",")));
    let e = gltf_refused("many.gltf", &json);
    assert!(e.contains("250001 placements, more than the 250000"), "{e}");
    // One index accessor of 60,000 triangles named by 500 primitives.
    let big: Vec<u8> = (0..180_000u32).flat_map(|i| ((i % 4) as u16).to_le_bytes()).collect();
    let primitives = vec![r#"{"attributes": {"POSITION": 0}, "indices": 1}"#; 500].join(",");
    let json = quad(&big, 5123, r#"[{"mesh": 0}]"#, "").replace(r#""count": 6"#, r#""count": 180000"#).replace(
        r#"{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}"#,
        &format!(r#"{{"primitives": [{primitives}]}}"#),
    );
    let e = gltf_refused("reused.gltf", &json);
    assert!(e.contains("named again and again"), "{e}");
}

#[test]
fn gltf_buffers_are_read_only_beside_the_file_and_no_further_than_declared() {
    let mut bin = Vec::new();
    for p in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in p {
            bin.extend(c.to_le_bytes());
        }
    }
    let doc = |uri: &str, len: usize| {
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
            "buffers": [{{"uri": "{uri}", "byteLength": {len}}}], "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
            "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}}]}}"#
        )
    };
    write("outside.bin", &bin);
    // Longer than declared: the rest is not read (and is no error).
    let mut longer = bin.clone();
    longer.extend([7u8; 1000]);
    write("inner/tri.bin", &longer);
    let g = crate::mesh::load_gltf(&write("inner/ok.gltf", doc("tri.bin", 36).as_bytes())).unwrap();
    assert_eq!(g.meshes[0].triangles.len(), 1);
    let outside = dir().join("outside.bin").display().to_string();
    for (uri, why) in [
        ("../outside.bin", "climbs out"),
        (outside.as_str(), "absolute path"),
        ("/proc/self/environ", "absolute path"),
        ("/etc/passwd", "absolute path"),
        ("file:///etc/passwd", "'file:' URI"),
    ] {
        let e = gltf_refused("inner/hostile.gltf", &doc(uri, 36));
        assert!(e.contains("buffer 0: uri") && e.contains(why), "{uri}: {e}");
    }
    let e = gltf_refused("inner/short.gltf", &doc("tri.bin", 5000));
    assert!(e.contains("buffer 0: holds 1036 bytes, its declared length is 5000"), "{e}");
}

#[test]
fn gltf_sparse_storage_and_node_matrices_are_checked() {
    let idx = u16s(&[0, 1, 2, 0, 2, 3]);
    // Sparse storage of the indices over the index view itself: one replaced index.
    let sparse = |count: u32, index: u16| {
        quad(&[idx.clone(), index.to_le_bytes().to_vec(), 3u16.to_le_bytes().to_vec()].concat(), 5123, r#"[{"mesh": 0}]"#, "")
            .replace(r#""byteOffset": 48, "byteLength": 16}"#, r#""byteOffset": 48, "byteLength": 12}, {"buffer": 0, "byteOffset": 60, "byteLength": 2}, {"buffer": 0, "byteOffset": 62, "byteLength": 2}"#)
            .replace(r#""count": 6, "type": "SCALAR"}"#, &format!(r#""count": 6, "type": "SCALAR", "sparse": {{"count": {count}, "indices": {{"bufferView": 2, "componentType": 5123}}, "values": {{"bufferView": 3}}}}}}"#))
    };
    let g = crate::mesh::load_gltf(&write("sparse-ok.gltf", sparse(1, 5).as_bytes())).unwrap();
    assert_eq!(g.meshes[0].triangles, vec![[0, 1, 2], [0, 2, 3]]);
    let g = crate::mesh::load_gltf(&write("sparse-set.gltf", sparse(1, 4).as_bytes())).unwrap();
    assert_eq!(g.meshes[0].triangles, vec![[0, 1, 2]], "the second triangle, made [0, 3, 3], has no area");
    let e = gltf_refused("sparse-past.gltf", &sparse(1, 6));
    assert!(e.contains("sparse index 6 (entry 0), past the accessor's 6 elements"), "{e}");
    let e = gltf_refused("sparse-none.gltf", &sparse(0, 1));
    assert!(e.contains("a sparse count of 0"), "{e}");
    let projective = quad(&idx, 5123, r#"[{"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0.5, 0,0,0,1]}]"#, "");
    assert!(gltf_refused("projective.gltf", &projective).contains("node 0: a projective matrix"));
}

#[test]
fn a_gltf_nan_position_is_named_by_its_element() {
    let idx = u16s(&[0, 1, 2, 0, 2, 3]);
    let mut json = quad(&idx, 5123, r#"[{"mesh": 0}]"#, "");
    let mut bin: Vec<u8> = Vec::new();
    for p in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, f32::NAN, 0.0], [0.0, 1.0, 0.0]] {
        for c in p {
            bin.extend(c.to_le_bytes());
        }
    }
    bin.extend(&idx);
    let start = json.find("data:").unwrap();
    let end = start + json[start..].find('"').unwrap();
    json.replace_range(start..end, &b64(&bin));
    let e = gltf_refused("nan.gltf", &json);
    assert!(e.contains("POSITION element 2: coordinate NaN is not a finite number"), "{e}");
}

const PLY_HEAD: &str =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n";
const PLY_VERTICES: &str = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n";

#[test]
fn a_ply_list_after_the_indices_and_end_header_in_a_comment_are_read() {
    let meshlab = format!(
        "{}element face 2\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\nend_header\n{PLY_VERTICES}3 0 1 2 6 0 0 1 0 1 1\n3 0 2 3 6 0 0 1 1 0 1\n",
        PLY_HEAD.replace("ply\n", "ply\ncomment written by hand, before the end_header line\n")
    );
    let (m, _) = load_mesh(write("meshlab.ply", meshlab.as_bytes())).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
}

#[test]
fn ply_indices_that_are_not_whole_and_a_value_too_many_are_refused_naming_the_line() {
    let face = |f: &str, ty: &str| {
        format!("{PLY_HEAD}element face 1\nproperty list uchar {ty} vertex_indices\nend_header\n{PLY_VERTICES}{f}\n")
    };
    let e = refused("fraction.ply", face("3 0 1.9 2", "float").as_bytes());
    assert!(e.contains("face 0 (line 14)") && e.contains("vertex index 1.9 is not a whole number"), "{e}");
    let e = refused("nan-index.ply", face("3 0 nan 2", "float").as_bytes());
    assert!(e.contains("vertex index NaN is not a whole number"), "{e}");
    // Binary: a float index of 1.5.
    let mut bin = PLY_HEAD.replace("ascii", "binary_little_endian").into_bytes();
    bin.extend(b"element face 1\nproperty list uchar float vertex_indices\nend_header\n");
    for v in [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend(v.to_le_bytes());
    }
    bin.push(3);
    for i in [0f32, 1.5, 2.0] {
        bin.extend(i.to_le_bytes());
    }
    assert!(refused("fraction-bin.ply", &bin).contains("vertex index 1.5 is not a whole number"));
    let shifted = format!("{PLY_HEAD}element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 7\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n");
    let e = refused("shifted.ply", shifted.as_bytes());
    assert!(e.contains("vertex 0 (line 10)") && e.contains("1 more value(s) on the line than the 3"), "{e}");
}

#[test]
fn a_non_finite_or_too_large_coordinate_is_named_in_every_format() {
    let nan_ply = format!("{}end_header\n0 0 0\n1 nan 0\n1 1 0\n0 1 0\n", PLY_HEAD);
    let e = refused("nan.ply", nan_ply.as_bytes());
    assert!(e.contains("vertex 1 (line 9)") && e.contains("coordinate NaN is not a finite number"), "{e}");
    let e = refused("big.off", b"OFF\n3 1 0\n0 0 0\n1e39 0 0\n0 1 0\n3 0 1 2\n");
    assert!(e.contains("line 4: vertex 1: coordinate 1e39 exceeds"), "{e}");
    let e = refused("inf.stl", b"solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex inf 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n");
    assert!(e.contains("line 5: coordinate inf is not a finite number"), "{e}");
    let mut stl = vec![0u8; 80];
    stl.extend(1u32.to_le_bytes());
    for v in [0f32, 0.0, 1.0, 0.0, 0.0, 0.0, f32::INFINITY, 0.0, 0.0, 0.0, 1.0, 0.0] {
        stl.extend(v.to_le_bytes());
    }
    stl.extend([0, 0]);
    let e = refused("inf-bin.stl", &stl);
    assert!(e.contains("triangle 0 (at byte 84): corner 1: coordinate inf"), "{e}");
}

#[test]
fn a_4off_vertex_is_divided_by_its_w() {
    let (m, _) = load_mesh(write("w.off", b"4OFF\n3 1 0\n2 0 0 2\n0 4 0 2\n0 0 0 1\n3 0 1 2\n")).unwrap();
    assert_eq!(m.positions, vec![glam::Vec3::X, 2.0 * glam::Vec3::Y, glam::Vec3::ZERO]);
    assert!(
        refused("w0.off", b"4OFF\n3 1 0\n2 0 0 0\n0 4 0 2\n0 0 0 1\n3 0 1 2\n").contains("line 3: vertex 0: w is 0")
    );
}

#[test]
fn obj_comments_after_a_statement_are_comments() {
    let (m, _) = load_mesh(write("comments.obj", b"v 0 0 0 # origin\nv 1 0 0\nv 0 1 0 # apex\nf 1 2 3 # c\n")).unwrap();
    assert_eq!(m.triangles.len(), 1);
    assert_eq!(m.positions[2], glam::Vec3::Y);
}

/// What exporters write and the checks must not refuse: positions and normals interleaved in one
/// view (a byteStride of 24, the normals' accessor at offset 12), unsigned-byte indices, and two
/// primitives sharing one POSITION accessor (read once, numbered primitive by primitive).
#[test]
fn interleaved_attributes_byte_indices_and_shared_positions_load() {
    let mut bin = Vec::new();
    for p in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in p.into_iter().chain([0.0, 0.0, 1.0]) {
            bin.extend(c.to_le_bytes());
        }
    }
    bin.extend([0u8, 1, 2, 0, 2, 3]);
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
        "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1}}, "indices": 2}},
                                    {{"attributes": {{"POSITION": 0, "NORMAL": 1}}, "indices": 3}}]}}],
        "buffers": [{{"uri": "{}", "byteLength": {}}}],
        "bufferViews": [{{"buffer": 0, "byteLength": 96, "byteStride": 24}}, {{"buffer": 0, "byteOffset": 96, "byteLength": 6}}],
        "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
                      {{"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 4, "type": "VEC3"}},
                      {{"bufferView": 1, "componentType": 5121, "count": 3, "type": "SCALAR"}},
                      {{"bufferView": 1, "byteOffset": 3, "componentType": 5121, "count": 3, "type": "SCALAR"}}]}}"#,
        b64(&bin),
        bin.len()
    );
    let g = crate::mesh::load_gltf(&write("interleaved.gltf", json.as_bytes())).unwrap();
    let m = &g.meshes[0];
    assert_eq!(m.positions.len(), 4, "the shared positions read once");
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(m.normals, vec![glam::Vec3::Z; 4]);
}
