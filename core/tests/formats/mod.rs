//! Valid files of every mesh format and variant the readers take, written here from one small mesh
//! (so the tests know how many triangles each must give): PLY in ASCII and both byte orders, with
//! the header shapes Blender and MeshLab write, and triangle strips; OFF, COFF, NOFF and 4OFF;
//! STL in ASCII, binary, and binary whose header starts with "solid"; glTF with a data URI, a
//! buffer file beside it, a GLB, sparse storage and instancing.

use bvhscope_core::mesh::Mesh;

/// A file to read: its name, its bytes, files it names (beside it), and what it must give.
pub struct Sample {
    pub name: String,
    pub bytes: Vec<u8>,
    pub beside: Vec<(String, Vec<u8>)>,
    pub triangles: usize,
    /// glTF: how many placements its nodes make.
    pub placements: usize,
}

fn sample(name: &str, bytes: Vec<u8>, triangles: usize) -> Sample {
    Sample { name: name.into(), bytes, beside: Vec::new(), triangles, placements: 0 }
}

#[derive(Clone, Copy)]
enum Enc {
    Ascii,
    Little,
    Big,
}

fn put(out: &mut Vec<u8>, enc: Enc, v: f64, ty: &str) {
    macro_rules! bytes {
        ($x:expr) => {
            match enc {
                Enc::Little => out.extend($x.to_le_bytes()),
                _ => out.extend($x.to_be_bytes()),
            }
        };
    }
    match (enc, ty) {
        (Enc::Ascii, _) => out.extend(format!("{v} ").as_bytes()),
        (_, "uchar") => out.push(v as u8),
        (_, "ushort") => bytes!(v as u16),
        (_, "int") => bytes!(v as i32),
        (_, "uint") => bytes!(v as u32),
        (_, "float") => bytes!(v as f32),
        (_, "double") => bytes!(v),
        _ => unreachable!("a type the writer uses"),
    }
}

/// PLY of `shape`: "plain", "blender" (normals, texture coordinates, colours, uint indices),
/// "meshlab" (per-corner texture coordinates after the indices), "strips" (a `tristrips` element).
fn ply(m: &Mesh, enc: Enc, shape: &str) -> Sample {
    let format = match enc {
        Enc::Ascii => "ascii",
        Enc::Little => "binary_little_endian",
        Enc::Big => "binary_big_endian",
    };
    let (nv, nt) = (m.positions.len(), m.triangles.len());
    let mut h = format!("ply\nformat {format} 1.0\n");
    let vertex: Vec<(&str, &str)> = match shape {
        "blender" => {
            h += "comment Created in Blender version 4.2.0\n";
            vec![
                ("float", "x"),
                ("float", "y"),
                ("float", "z"),
                ("float", "nx"),
                ("float", "ny"),
                ("float", "nz"),
                ("float", "s"),
                ("float", "t"),
                ("uchar", "red"),
                ("uchar", "green"),
                ("uchar", "blue"),
                ("uchar", "alpha"),
            ]
        }
        "meshlab" => {
            h += "comment VCGLIB generated\n";
            vec![
                ("double", "x"),
                ("double", "y"),
                ("double", "z"),
                ("uchar", "red"),
                ("uchar", "green"),
                ("uchar", "blue"),
                ("uchar", "alpha"),
            ]
        }
        _ => vec![("float", "x"), ("float", "y"), ("float", "z")],
    };
    h += &format!("element vertex {nv}\n");
    for (ty, name) in &vertex {
        h += &format!("property {ty} {name}\n");
    }
    let (element, index_ty) = match shape {
        "strips" => ("tristrips", "int"),
        "blender" => ("face", "uint"),
        _ => ("face", "int"),
    };
    h += &format!(
        "element {element} {}\nproperty list uchar {index_ty} vertex_indices\n",
        if shape == "strips" { 1 } else { nt }
    );
    if shape == "meshlab" {
        h += "property list uchar float texcoord\n";
    }
    h += "end_header\n";
    let mut out = h.into_bytes();
    let newline = |out: &mut Vec<u8>| {
        if let Enc::Ascii = enc {
            out.push(b'\n');
        }
    };
    for (i, p) in m.positions.iter().enumerate() {
        for (ty, name) in &vertex {
            let v = match *name {
                "x" => p.x as f64,
                "y" => p.y as f64,
                "z" => p.z as f64,
                "nx" | "ny" => 0.0,
                "nz" => 1.0,
                "s" | "t" => 0.5,
                _ => (i % 256) as f64,
            };
            put(&mut out, enc, v, ty);
        }
        newline(&mut out);
    }
    if shape == "strips" {
        // Each triangle a strip of its own, -1 between: the reader unrolls them as the file's.
        let list: Vec<f64> = m.triangles.iter().flat_map(|t| [t[0] as f64, t[1] as f64, t[2] as f64, -1.0]).collect();
        put(&mut out, enc, list.len() as f64, if let Enc::Ascii = enc { "int" } else { "uchar" });
        // A list longer than 255 does not fit a uchar count: strips are written in ASCII only.
        for v in list {
            put(&mut out, enc, v, index_ty);
        }
        newline(&mut out);
    } else {
        for t in &m.triangles {
            put(&mut out, enc, 3.0, "uchar");
            for &i in t {
                put(&mut out, enc, i as f64, index_ty);
            }
            if shape == "meshlab" {
                put(&mut out, enc, 6.0, "uchar");
                for k in 0..6 {
                    put(&mut out, enc, k as f64 / 6.0, "float");
                }
            }
            newline(&mut out);
        }
    }
    sample(&format!("{shape}-{format}.ply"), out, nt)
}

/// OFF of a `keyword` (OFF, COFF, NOFF, 4OFF), the counts on the keyword's line or the next.
fn off(m: &Mesh, keyword: &str, counts_inline: bool) -> Sample {
    let (nv, nt) = (m.positions.len(), m.triangles.len());
    let mut s = format!("# written by the fuzzer\n{keyword}");
    s += &if counts_inline { format!(" {nv} {nt} 0\n") } else { format!("\n{nv} {nt} 0\n") };
    for p in &m.positions {
        match keyword {
            "4OFF" => s += &format!("{} {} {} 2\n", 2.0 * p.x, 2.0 * p.y, 2.0 * p.z),
            "NOFF" => s += &format!("{} {} {} 0 0 1\n", p.x, p.y, p.z),
            "COFF" => s += &format!("{} {} {} 255 128 0 255\n", p.x, p.y, p.z),
            _ => s += &format!("{} {} {}\n", p.x, p.y, p.z),
        }
    }
    for t in &m.triangles {
        s += &format!("3 {} {} {} # a face\n", t[0], t[1], t[2]);
    }
    sample(&format!("{keyword}-{counts_inline}.off"), s.into_bytes(), nt)
}

fn stl(m: &Mesh, kind: &str) -> Sample {
    let nt = m.triangles.len();
    if kind == "ascii" {
        let mut s = String::from("solid fuzz\n");
        for t in &m.triangles {
            s += "  facet normal 0 0 1\n    outer loop\n";
            for &i in t {
                let p = m.positions[i as usize];
                s += &format!("      vertex {} {} {}\n", p.x, p.y, p.z);
            }
            s += "    endloop\n  endfacet\n";
        }
        s += "endsolid fuzz\n";
        return sample("ascii.stl", s.into_bytes(), nt);
    }
    let mut out = vec![b' '; 80];
    if kind == "solid" {
        out[..14].copy_from_slice(b"solid exported");
    }
    out.extend((nt as u32).to_le_bytes());
    for t in &m.triangles {
        for v in [0f32, 0.0, 1.0] {
            out.extend(v.to_le_bytes());
        }
        for &i in t {
            for c in m.positions[i as usize].to_array() {
                out.extend(c.to_le_bytes());
            }
        }
        out.extend([0, 0]);
    }
    sample(&format!("{kind}.stl"), out, nt)
}

/// glTF over the mesh's positions and u16 indices; `how`: "data" (a data URI), "file" (a buffer
/// beside it), "glb"; `sparse`: one position replaced by sparse storage (by itself: the same
/// mesh); `instanced`: the mesh placed by two nodes under a parent.
fn gltf(m: &Mesh, how: &str, sparse: bool, instanced: bool) -> Sample {
    use base64::Engine;
    let mut bin: Vec<u8> = m.positions.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
    let pos_len = bin.len();
    bin.extend(m.triangles.iter().flatten().flat_map(|&i| (i as u16).to_le_bytes()));
    let idx_len = bin.len() - pos_len;
    bin.extend(1u16.to_le_bytes()); // the sparse index: position 1
    bin.extend(m.positions[1].to_array().iter().flat_map(|c| c.to_le_bytes())); // its value
    let (lo, hi) = (m.bounds().min, m.bounds().max);
    let sparse_json = if sparse {
        r#", "sparse": {"count": 1, "indices": {"bufferView": 2, "componentType": 5123}, "values": {"bufferView": 3}}"#
    } else {
        ""
    };
    let (nodes, roots, placements) = if instanced {
        (
            r#"[{"children": [1, 2], "scale": [2, 2, 2]}, {"mesh": 0, "translation": [3, 0, 0]}, {"mesh": 0, "rotation": [0, 0.7071068, 0, 0.7071068]}]"#,
            "[0]",
            2,
        )
    } else {
        (r#"[{"mesh": 0}]"#, "[0]", 1)
    };
    let uri = match how {
        "data" => format!(
            r#""uri": "data:application/octet-stream;base64,{}", "#,
            base64::engine::general_purpose::STANDARD.encode(&bin)
        ),
        "file" => r#""uri": "fuzz%20data.bin", "#.to_string(),
        _ => String::new(),
    };
    let json = format!(
        r#"{{"asset": {{"version": "2.0", "generator": "bvhscope fuzzer"}}, "scene": 0, "scenes": [{{"nodes": {roots}}}], "nodes": {nodes},
  "meshes": [{{"name": "shape", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
  "buffers": [{{{uri}"byteLength": {}}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": {pos_len}}}, {{"buffer": 0, "byteOffset": {pos_len}, "byteLength": {idx_len}}},
                  {{"buffer": 0, "byteOffset": {}, "byteLength": 2}}, {{"buffer": 0, "byteOffset": {}, "byteLength": 12}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": {}, "type": "VEC3", "min": [{}, {}, {}], "max": [{}, {}, {}]{sparse_json}}},
                {{"bufferView": 1, "componentType": 5123, "count": {}, "type": "SCALAR"}}]}}"#,
        bin.len(),
        pos_len + idx_len,
        pos_len + idx_len + 2,
        m.positions.len(),
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z,
        3 * m.triangles.len()
    );
    let name = format!("{how}-{sparse}-{instanced}");
    let mut s = if how == "glb" {
        sample(&format!("{name}.glb"), glb(&json, &bin), m.triangles.len())
    } else {
        sample(&format!("{name}.gltf"), json.into_bytes(), m.triangles.len())
    };
    if how == "file" {
        s.beside.push(("fuzz data.bin".into(), bin));
    }
    s.placements = placements;
    s
}

pub fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    j.resize(j.len().next_multiple_of(4), b' ');
    let mut b = bin.to_vec();
    b.resize(b.len().next_multiple_of(4), 0);
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

/// Every valid sample, of every format and variant.
pub fn all(m: &Mesh) -> Vec<Sample> {
    let mut out = Vec::new();
    for enc in [Enc::Ascii, Enc::Little, Enc::Big] {
        for shape in ["plain", "blender", "meshlab"] {
            out.push(ply(m, enc, shape));
        }
    }
    out.push(ply(m, Enc::Ascii, "strips"));
    for keyword in ["OFF", "COFF", "NOFF", "4OFF"] {
        out.push(off(m, keyword, keyword == "COFF"));
    }
    for kind in ["ascii", "binary", "solid"] {
        out.push(stl(m, kind));
    }
    for how in ["data", "file", "glb"] {
        out.push(gltf(m, how, how == "glb", how != "data"));
    }
    out.push(gltf(m, "data", true, true));
    out
}
