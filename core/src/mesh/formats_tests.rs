//! The mesh readers (`formats.rs`, `ply.rs`, `off.rs`, `stl.rs`) on files written here: the same
//! mesh in every format gives the same triangles, the same tree and the same image; every variant
//! each format has; malformed files give one message naming the file and the element.

use super::*;
use crate::mesh::error::MeshError;
use crate::mesh::generate;
use crate::mesh::obj::write_obj;
use glam::Vec3;
use std::path::PathBuf;

fn dir() -> PathBuf {
    crate::scratch::shared("formats")
}

fn write(name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn mesh() -> Mesh {
    generate::torus(1.0, 0.35, 12, 8)
}

fn ply(m: &Mesh, encoding: &str) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat {encoding} 1.0\ncomment written by bvhscope's tests\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        m.positions.len(),
        m.triangles.len()
    )
    .into_bytes();
    let big = encoding == "binary_big_endian";
    let f = |x: f32| if big { x.to_be_bytes() } else { x.to_le_bytes() };
    let i = |x: u32| if big { x.to_be_bytes() } else { x.to_le_bytes() };
    for p in &m.positions {
        if encoding == "ascii" {
            out.extend(format!("{} {} {} 200\n", p.x, p.y, p.z).bytes());
        } else {
            for c in p.to_array() {
                out.extend(f(c));
            }
            out.push(200);
        }
    }
    for t in &m.triangles {
        if encoding == "ascii" {
            out.extend(format!("3 {} {} {}\n", t[0], t[1], t[2]).bytes());
        } else {
            out.push(3);
            for c in t {
                out.extend(i(*c));
            }
        }
    }
    out
}

fn off(m: &Mesh) -> Vec<u8> {
    let mut s = format!("COFF # with colours\n{} {} 0\n", m.positions.len(), m.triangles.len());
    for p in &m.positions {
        s += &format!("{} {} {} 255 0 0\n", p.x, p.y, p.z);
    }
    for t in &m.triangles {
        s += &format!("3 {} {} {} 0.5 0.5 0.5\n", t[0], t[1], t[2]);
    }
    s.into_bytes()
}

fn stl_binary(m: &Mesh, header: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8; 80];
    out[..header.len()].copy_from_slice(header);
    out.extend((m.triangles.len() as u32).to_le_bytes());
    for t in &m.triangles {
        out.extend([0u8; 12]);
        for &c in t {
            for x in m.positions[c as usize].to_array() {
                out.extend(x.to_le_bytes());
            }
        }
        out.extend([0u8; 2]);
    }
    out
}

fn stl_ascii(m: &Mesh) -> Vec<u8> {
    let mut s = String::from("solid torus\n");
    for t in &m.triangles {
        s += "  facet normal 0 0 0\n    outer loop\n";
        for &c in t {
            let p = m.positions[c as usize];
            s += &format!("      vertex {} {} {}\n", p.x, p.y, p.z);
        }
        s += "    endloop\n  endfacet\n";
    }
    s += "endsolid torus\n";
    s.into_bytes()
}

/// Each triangle's corners, in the mesh's order.
fn corners(m: &Mesh) -> Vec<[Vec3; 3]> {
    m.triangles.iter().map(|t| t.map(|i| m.positions[i as usize])).collect()
}

#[test]
fn one_mesh_in_every_format_gives_the_same_triangles_tree_and_image() {
    let m = mesh();
    let mut obj = Vec::new();
    write_obj(&m, &mut obj).unwrap();
    let files = [
        write("torus.obj", &obj),
        write("torus-ascii.ply", &ply(&m, "ascii")),
        write("torus-le.ply", &ply(&m, "binary_little_endian")),
        write("torus-be.ply", &ply(&m, "binary_big_endian")),
        write("torus.off", &off(&m)),
        write("torus-ascii.stl", &stl_ascii(&m)),
        // A binary STL whose header starts with "solid", as many do: told by its size.
        write("torus-binary.stl", &stl_binary(&m, b"solid but binary")),
    ];
    let (reference, _) = load_mesh(&files[0]).unwrap();
    let p = crate::bvh::BuildParams::default();
    let tree = |m: &Mesh| crate::bvh::AnyBvh::build(m, &p);
    let camera = crate::render::Camera::framing(&reference.bounds(), 48, 32);
    let settings = crate::render::RenderSettings { count: true, ..Default::default() };
    let image = |m: &Mesh| crate::render::render(&tree(m), m, &camera, &settings).counts_csv().unwrap();
    let want = (corners(&reference), tree(&reference).binary_tree(&reference).nodes.len(), image(&reference));
    for f in &files[1..] {
        let (got, report) = load_mesh(f).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(corners(&got), want.0, "{}: the same triangles in the same order", f.display());
        assert_eq!(tree(&got).binary_tree(&got).nodes.len(), want.1, "{}", f.display());
        assert_eq!(image(&got), want.2, "{}: the same image, pixel for pixel", f.display());
        assert_eq!(report.triangles, m.triangles.len());
    }
}

#[test]
fn ply_faces_of_any_size_and_types_and_tristrips_with_restarts() {
    // A quad (fan: 0 1 2, 0 2 3) as ushort indices, a strip 0 1 2 3 -1 1 2 3 with int counts.
    let text = "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar ushort vertex_index\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n8 0 1 2 3 -1 1 2 3\n";
    let (m, r) = load_mesh(write("strips.ply", text.as_bytes())).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 2], [2, 1, 3], [1, 2, 3]]);
    assert!(r.has_normals && m.normals.len() == 4);
}

#[test]
fn off_variants_counts_on_the_header_line_and_polygons() {
    let text = "NOFF 4 1 0\n# a square with normals\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n";
    let (m, _) = load_mesh(write("square.off", text.as_bytes())).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(m.normals.len(), 4);
}

fn error(name: &str, bytes: &[u8]) -> String {
    let p = write(name, bytes);
    let e: MeshError = load_mesh(&p).unwrap_err();
    let text = e.to_string();
    assert!(text.starts_with(&p.display().to_string()), "names the file: {text}");
    text
}

#[test]
fn malformed_files_name_the_file_the_element_and_the_problem() {
    // A header that claims four billion faces allocates nothing: the file could not hold them.
    let mut huge = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 4000000000\nproperty list uchar int vertex_indices\nend_header\n".to_vec();
    huge.extend([0u8; 36 + 13]);
    let t = error("huge.ply", &huge);
    assert!(t.contains("element face") && t.contains("claims 4000000000"), "{t}");
    let t = error("range.ply", b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
    assert!(t.contains("face 0") && t.contains("vertex 7"), "{t}");
    let mut cut = ply(&mesh(), "binary_little_endian");
    cut.truncate(cut.len() - 5);
    let t = error("cut.ply", &cut);
    assert!(t.contains("face") && t.contains("ends"), "{t}");
    let mut cut = stl_binary(&mesh(), b"solid but binary");
    cut.truncate(cut.len() - 50);
    let t = error("cut.stl", &cut);
    assert!(t.contains("holds binary data, so it is not ASCII STL") && t.contains("cut short?"), "{t}");
    let t = error("nothing.stl", &[7u8; 200]);
    assert!(t.contains("neither ASCII STL") && t.contains("binary STL"), "{t}");
    let t = error("short.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n");
    assert!(t.contains("face 0") && t.contains("declares 3 vertices but lists 2"), "{t}");
    let t = error(
        "facet.stl",
        b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n",
    );
    assert!(t.contains("a facet of 2 vertices"), "{t}");
    let t = error("nan.off", b"OFF\n3 1 0\n0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n");
    assert!(t.contains("line 4: vertex 1: coordinate NaN is not a finite number"), "{t}");
}

#[test]
fn fuzzed_bytes_never_panic() {
    use crate::random::Rng;
    let base = [ply(&mesh(), "binary_little_endian"), ply(&mesh(), "ascii"), off(&mesh()), stl_binary(&mesh(), b"")];
    let mut rng = Rng::new(7);
    for (k, b) in base.iter().enumerate() {
        for round in 0..60 {
            let mut bytes = b.clone();
            for _ in 0..1 + round % 5 {
                let at = rng.below(bytes.len() as u64) as usize;
                bytes[at] = rng.below(256) as u8;
            }
            if round % 7 == 0 {
                bytes.truncate(rng.below(bytes.len() as u64) as usize);
            }
            let ext = ["ply", "ply", "off", "stl"][k];
            let _ = load_mesh(write(&format!("fuzz.{ext}"), &bytes));
        }
    }
}
