//! OFF (Object File Format, as geometry-processing courses and libigl use it): a header keyword
//! (`OFF`, or a variant with prefixes: `C` colours, `N` normals, `ST` texture coordinates, `4`
//! four coordinates; the counts may follow on the same line), then the vertex, face and edge
//! counts, the vertices (x y z and what the prefixes add), and the faces (n i₀ … iₙ₋₁, colour
//! values after them ignored). `#` starts a comment. Faces are fan-triangulated as OBJ's are.
//! A `4OFF` vertex is homogeneous (x y z w): the point is (x/w, y/w, z/w).

use super::assemble::{bad, capacity, coordinate, fan, finish};
use crate::files::limits;
use crate::mesh::error::MeshError;
use crate::mesh::mesh::Mesh;
use crate::mesh::obj::LoadReport;
use glam::Vec3;
use std::path::Path;

/// The header keyword, if `bytes` start with one (after blank lines and comments).
fn keyword(text: &str) -> Option<&str> {
    let first = text.lines().map(|l| l.split('#').next().unwrap_or("").trim()).find(|l| !l.is_empty())?;
    let word = first.split_whitespace().next()?;
    let rest = word.strip_suffix("OFF")?;
    let mut r = rest;
    for prefix in ["ST", "C", "N", "4", "n"] {
        r = r.strip_prefix(prefix).unwrap_or(r);
    }
    r.is_empty().then_some(word)
}

/// Whether the file starts as an OFF does.
pub(crate) fn has_header(bytes: &[u8]) -> bool {
    keyword(&String::from_utf8_lossy(&bytes[..bytes.len().min(256)])).is_some()
}

pub(crate) fn parse(path: &Path, bytes: &[u8]) -> Result<(Mesh, LoadReport), MeshError> {
    if bytes.contains(&0) {
        return Err(bad(path, "the file", "binary data (the binary OFF form is not read; write it as text)"));
    }
    let text = String::from_utf8_lossy(bytes);
    let word = keyword(&text).ok_or_else(|| bad(path, "line 1", "no OFF header (OFF, COFF, NOFF, STOFF …)"))?;
    let (normals, four) = (word.contains('N'), word.contains('4'));
    // The lines that hold something, with their numbers, comments cut off.
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.split('#').next().unwrap_or("").split_whitespace().collect::<Vec<&str>>()))
        .filter(|(_, w)| !w.is_empty());
    let (_, header) = lines.next().expect("the keyword's line");
    let counts = match header.len() {
        1 => lines.next().ok_or_else(|| bad(path, "the header", "no vertex, face and edge counts"))?,
        _ => (1, header[1..].to_vec()),
    };
    let count = |k: usize, what: &str| -> Result<u64, MeshError> {
        let t = counts.1.get(k).copied().unwrap_or(if k == 2 { "0" } else { "" });
        t.parse::<u64>().map_err(|_| bad(path, format!("line {}", counts.0), format!("{what} '{t}' is not a count")))
    };
    let (nv, nf) = (count(0, "the vertex count")?, count(1, "the face count")?);
    let at_counts = format!("line {}", counts.0);
    limits::VERTICES.check(nv).map_err(|e| bad(path, &at_counts, e))?;
    // A face is at least one triangle (fewer corners give none, and take bytes of the file).
    limits::TRIANGLES.check(nf).map_err(|e| bad(path, &at_counts, e))?;
    let mut positions = Vec::with_capacity(capacity(nv, bytes.len(), 6));
    let mut vertex_normals = Vec::new();
    let number = |line: usize, what: &str, t: &str| -> Result<f64, MeshError> {
        t.parse::<f64>().map_err(|_| bad(path, format!("line {line}"), format!("{what}: '{t}' is not a number")))
    };
    for v in 0..nv {
        let (line, w) = lines
            .next()
            .ok_or_else(|| bad(path, format!("vertex {v}"), format!("the file ends before it ({nv} declared)")))?;
        let need = if normals { 6 } else { 3 } + usize::from(four);
        if w.len() < need {
            return Err(bad(path, format!("line {line}"), format!("vertex {v} has {} numbers, not {need}", w.len())));
        }
        let what = format!("vertex {v}");
        let x = |k: usize| number(line, &what, w[k]);
        let scale = if four { x(3)? } else { 1.0 };
        if scale == 0.0 {
            return Err(bad(path, format!("line {line}"), format!("{what}: w is 0, a point at infinity")));
        }
        let at = |e: String| bad(path, format!("line {line}"), format!("{what}: {e}"));
        let mut p = [0f32; 3];
        for (k, c) in p.iter_mut().enumerate() {
            *c = coordinate(x(k)? / scale).map_err(at)?;
        }
        positions.push(Vec3::from_array(p));
        if normals {
            let o = 3 + usize::from(four);
            vertex_normals.push(Vec3::new(x(o)? as f32, x(o + 1)? as f32, x(o + 2)? as f32));
        }
    }
    let mut triangles = Vec::with_capacity(capacity(nf, bytes.len(), 8));
    let mut polygon = Vec::new();
    for f in 0..nf {
        let (line, w) = lines
            .next()
            .ok_or_else(|| bad(path, format!("face {f}"), format!("the file ends before it ({nf} declared)")))?;
        let at = format!("line {line}: face {f}");
        let n: usize = w[0].parse().map_err(|_| bad(path, &at, format!("'{}' is not a vertex count", w[0])))?;
        if n >= w.len() {
            return Err(bad(path, &at, format!("declares {n} vertices but lists {}", w.len() - 1)));
        }
        polygon.clear();
        // Colour values after the indices are skipped.
        for t in &w[1..=n] {
            let i: u32 = t.parse().map_err(|_| bad(path, &at, format!("vertex index '{t}' is not an index")))?;
            if i as u64 >= nv {
                return Err(bad(path, &at, format!("refers to vertex {i}, but only {nv} are declared")));
            }
            polygon.push(i);
        }
        fan(&polygon, &mut triangles);
    }
    finish(path, positions, vertex_normals, triangles)
}
