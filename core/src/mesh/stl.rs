//! STL, as CAD and 3D printing write it: binary (an 80-byte header, a little-endian triangle
//! count, 50 bytes a triangle: its normal, three corners, two attribute bytes) or ASCII (`solid`,
//! then `facet normal … outer loop vertex … ×3 endloop endfacet`, `endsolid`). Which one is told
//! by the content: a binary file is exactly as long as its count says, whatever its header's
//! first word (many binary files start with "solid" too). STL stores each triangle's corners
//! apart: the mesh has three vertices a triangle, the file's triangles in its order.

use super::assemble::{bad, capacity, coordinate, finish};
use crate::files::limits;
use crate::mesh::error::MeshError;
use crate::mesh::mesh::Mesh;
use crate::mesh::obj::LoadReport;
use glam::Vec3;
use std::path::Path;

/// Whether `bytes` are a binary STL: 84 bytes of header and count, then the count's 50-byte records.
pub(crate) fn is_binary(bytes: &[u8]) -> bool {
    bytes.len() >= 84 && {
        let n = u32::from_le_bytes(bytes[80..84].try_into().expect("four bytes")) as u64;
        bytes.len() as u64 == 84 + 50 * n
    }
}

pub(crate) fn parse(path: &Path, bytes: &[u8]) -> Result<(Mesh, LoadReport), MeshError> {
    if is_binary(bytes) {
        return binary(path, bytes);
    }
    let solid = bytes.trim_ascii_start().starts_with(b"solid");
    if bytes.contains(&0) || !solid {
        let n = if bytes.len() >= 84 {
            u32::from_le_bytes(bytes[80..84].try_into().expect("four bytes")) as u64
        } else {
            0
        };
        // Binary data that does not add up, or text that is not STL's: say which it looked like.
        let why = if solid { "it holds binary data, so it is not ASCII STL" } else { "it does not start with 'solid'" };
        return Err(bad(
            path,
            "the file",
            format!(
                "neither ASCII STL ({why}) nor binary STL ({} bytes, where a binary STL of the {n} triangles its header counts has {}: cut short?)",
                bytes.len(),
                84 + 50 * n
            ),
        ));
    }
    ascii(path, &String::from_utf8_lossy(bytes))
}

fn binary(path: &Path, bytes: &[u8]) -> Result<(Mesh, LoadReport), MeshError> {
    let records = &bytes[84..];
    limits::TRIANGLES.check(records.len() as u64 / 50).map_err(|e| bad(path, "the header", e))?;
    let mut positions = Vec::with_capacity(records.len() / 50 * 3);
    let f = |b: &[u8], k: usize| f32::from_le_bytes(b[4 * k..4 * k + 4].try_into().expect("four bytes"));
    for (t, r) in records.chunks_exact(50).enumerate() {
        for c in 0..3 {
            let k = 3 + 3 * c;
            let mut p = [0f32; 3];
            for (j, x) in p.iter_mut().enumerate() {
                *x = coordinate(f(r, k + j) as f64).map_err(|e| {
                    bad(path, format!("triangle {t} (at byte {})", 84 + 50 * t), format!("corner {c}: {e}"))
                })?;
            }
            positions.push(Vec3::from_array(p));
        }
    }
    let triangles = (0..positions.len() as u32 / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    finish(path, positions, Vec::new(), triangles)
}

fn ascii(path: &Path, text: &str) -> Result<(Mesh, LoadReport), MeshError> {
    let mut positions = Vec::with_capacity(capacity(u64::MAX, text.len(), 40));
    let mut in_facet = 0usize;
    for (i, line) in text.lines().enumerate() {
        let mut w = line.split_whitespace();
        match w.next() {
            Some("vertex") => {
                let mut xyz = [0f32; 3];
                for (k, x) in xyz.iter_mut().enumerate() {
                    let t = w.next().unwrap_or("");
                    let at = format!("line {}", i + 1);
                    let value: f64 = t
                        .parse()
                        .map_err(|_| bad(path, &at, format!("vertex coordinate {k} '{t}' is not a number")))?;
                    *x = coordinate(value).map_err(|e| bad(path, &at, e))?;
                }
                positions.push(Vec3::from_array(xyz));
                in_facet += 1;
                if in_facet > 3 {
                    return Err(bad(path, format!("line {}", i + 1), "a facet of more than 3 vertices"));
                }
            }
            Some("endfacet") => {
                if in_facet != 3 {
                    return Err(bad(path, format!("line {}", i + 1), format!("a facet of {in_facet} vertices, not 3")));
                }
                in_facet = 0;
            }
            _ => {}
        }
    }
    if in_facet != 0 || positions.len() % 3 != 0 {
        return Err(bad(path, "the file", "ends inside a facet"));
    }
    let triangles = (0..positions.len() as u32 / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    finish(path, positions, Vec::new(), triangles)
}
