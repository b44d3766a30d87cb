//! The glTF reader on files written here: one mesh placed by three nodes opens as three
//! placements of one mesh (the hierarchy's transforms composed); a GLB of the torus gives the
//! OBJ's triangles, tree and image; a `.gltf` with its buffer beside it, 16-bit indices, an
//! unindexed primitive and a skipped one of points; a buffer shorter than it says is one
//! message naming it.

use super::*;
use crate::mesh::generate;
use base64::Engine;

fn write(name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let d = crate::scratch::shared("gltf");
    let p = d.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// The mesh's positions (f32) then its indices (u32), and the glTF JSON over them, the buffer
/// given by `uri` (None: the GLB's binary chunk); `nodes` as JSON.
fn document(m: &Mesh, uri: Option<&str>, nodes: &str, scene: &str) -> (String, Vec<u8>) {
    let mut bin = Vec::new();
    for p in &m.positions {
        for c in p.to_array() {
            bin.extend(c.to_le_bytes());
        }
    }
    let pos_len = bin.len();
    for t in &m.triangles {
        for i in t {
            bin.extend(i.to_le_bytes());
        }
    }
    let (lo, hi) = (m.bounds().min, m.bounds().max);
    let uri = uri.map_or(String::new(), |u| format!(r#""uri": "{u}", "#));
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": {scene}}}], "nodes": {nodes},
        "meshes": [{{"name": "shape", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
        "buffers": [{{{uri}"byteLength": {}}}],
        "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": {pos_len}}}, {{"buffer": 0, "byteOffset": {pos_len}, "byteLength": {}}}],
        "accessors": [{{"bufferView": 0, "componentType": 5126, "count": {}, "type": "VEC3", "min": [{}, {}, {}], "max": [{}, {}, {}]}},
                      {{"bufferView": 1, "componentType": 5125, "count": {}, "type": "SCALAR"}}]}}"#,
        bin.len(),
        bin.len() - pos_len,
        m.positions.len(),
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z,
        m.triangles.len() * 3
    );
    (json, bin)
}

fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + j.len() + 8 + b.len()) as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(j);
    out.extend((b.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(b);
    out
}

#[test]
fn one_mesh_used_by_three_nodes_opens_as_three_placements_of_one_mesh() {
    let m = generate::torus(1.0, 0.35, 8, 6);
    // A parent scaled by 2 with two children moved along x; a third node at the root.
    let nodes = r#"[{"scale": [2, 2, 2], "children": [1, 2]}, {"mesh": 0, "translation": [3, 0, 0]},
                    {"mesh": 0, "translation": [-3, 0, 0]}, {"mesh": 0}]"#;
    let (json, bin) = document(&m, Some(""), nodes, "[0, 3]");
    let uri =
        format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bin));
    let json = json.replace(r#""uri": "", "#, &format!(r#""uri": "{uri}", "#));
    let path = write("three.gltf", json.as_bytes());
    let scene = crate::scene::Scene::open(&path).unwrap();
    let inst = scene.instances().expect("a scene of placements");
    assert_eq!((inst.meshes.len(), inst.placements.len()), (1, 3));
    let moved: Vec<glam::Vec3> = inst.placements.iter().map(|(_, t)| t.transform_point3(glam::Vec3::ZERO)).collect();
    for want in [glam::Vec3::new(6.0, 0.0, 0.0), glam::Vec3::new(-6.0, 0.0, 0.0), glam::Vec3::ZERO] {
        assert!(moved.iter().any(|p| (*p - want).length() < 1e-5), "{want} in {moved:?}");
    }
    assert_eq!(scene.report.triangles, 3 * m.triangles.len());
}

#[test]
fn a_glb_gives_the_objs_triangles() {
    let m = generate::torus(1.0, 0.35, 12, 8);
    let (json, bin) = document(&m, None, r#"[{"mesh": 0}]"#, "[0]");
    let path = write("torus.glb", &glb(&json, &bin));
    let g = load_gltf(&path).unwrap();
    assert_eq!(g.meshes.len(), 1);
    assert_eq!(g.meshes[0].positions, m.positions);
    assert_eq!(g.meshes[0].triangles, m.triangles);
}

#[test]
fn a_short_buffer_is_one_message_naming_it() {
    let m = generate::torus(1.0, 0.35, 8, 6);
    let (json, bin) = document(&m, None, r#"[{"mesh": 0}]"#, "[0]");
    let path = write("short.glb", &glb(&json, &bin[..bin.len() / 2]));
    let e = match load_gltf(&path) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("a short buffer loaded"),
    };
    assert!(e.starts_with(&path.display().to_string()) && e.contains("buffer 0"), "{e}");
}

#[test]
fn a_glb_opens_with_the_objs_triangles_tree_and_image() {
    let m = generate::torus(1.0, 0.35, 12, 8);
    let mut obj = Vec::new();
    crate::mesh::write_obj(&m, &mut obj).unwrap();
    let (reference, _) = crate::mesh::load_mesh(write("torus-ref.obj", &obj)).unwrap();
    let (json, bin) = document(&m, None, r#"[{"mesh": 0}]"#, "[0]");
    let scene = crate::scene::Scene::open(write("torus-scene.glb", &glb(&json, &bin))).unwrap();
    let flat = scene.flat_mesh().unwrap();
    let corners = |m: &Mesh| m.triangles.iter().map(|t| t.map(|i| m.positions[i as usize])).collect::<Vec<_>>();
    assert_eq!(corners(&flat), corners(&reference));
    let p = crate::bvh::BuildParams::default();
    let camera = crate::render::Camera::framing(&reference.bounds(), 48, 32);
    let settings = crate::render::RenderSettings { count: true, ..Default::default() };
    let look = |m: &Mesh| {
        let bvh = crate::bvh::AnyBvh::build(m, &p);
        let nodes = bvh.binary_tree(m).nodes.len();
        (nodes, crate::render::render(&bvh, m, &camera, &settings).counts_csv().unwrap())
    };
    assert_eq!(look(&flat), look(&reference), "the same tree and the same image");
}

/// A `.gltf` whose buffer is a file beside it (its name with a space, %20 in the URI), u16
/// indices, a second primitive without indices, a third of points (skipped, with a warning).
#[test]
fn a_gltf_with_its_buffer_beside_it_short_indices_an_unindexed_primitive_and_points() {
    let mut bin = Vec::new();
    for p in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in p {
            bin.extend(c.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend(i.to_le_bytes());
    }
    write("quad data.bin", &bin);
    let json = r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}, {"attributes": {"POSITION": 2}},
                                   {"attributes": {"POSITION": 0}, "mode": 0}]}],
        "buffers": [{"uri": "quad%20data.bin", "byteLength": 60}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
                      {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]}"#;
    let g = load_gltf(&write("quad.gltf", json.as_bytes())).unwrap();
    assert_eq!(g.meshes.len(), 1);
    assert_eq!(g.meshes[0].triangles, vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]]);
    assert_eq!(g.warnings.len(), 1, "{:?}", g.warnings);
    assert!(g.warnings[0].contains("primitive 2") && g.warnings[0].contains("Points"), "{:?}", g.warnings);
}
