//! PLY (the Stanford scans' format): a text header naming elements and their properties, then
//! the data in ASCII or binary (little- or big-endian). Vertices give x, y, z of any numeric type
//! (and nx, ny, nz when present; other properties, colours among them, are skipped); faces are
//! lists (`vertex_indices` or `vertex_index`) of any count and index types, fan-triangulated as
//! OBJ's polygons are; `tristrips` (igea, the original Stanford files) are lists with −1 as a
//! restart, unrolled with alternating winding. Triangles are numbered in the file's order: the
//! faces', then the strips', element by element as the header lists them.

use super::assemble::{bad, capacity, fan, finish, point};
use crate::files::limits;
use crate::mesh::error::MeshError;
use crate::mesh::mesh::Mesh;
use crate::mesh::obj::LoadReport;
use glam::Vec3;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Type {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Type {
    fn parse(s: &str) -> Option<Type> {
        Some(match s {
            "char" | "int8" => Type::I8,
            "uchar" | "uint8" => Type::U8,
            "short" | "int16" => Type::I16,
            "ushort" | "uint16" => Type::U16,
            "int" | "int32" => Type::I32,
            "uint" | "uint32" => Type::U32,
            "float" | "float32" => Type::F32,
            "double" | "float64" => Type::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Type::I8 | Type::U8 => 1,
            Type::I16 | Type::U16 => 2,
            Type::I32 | Type::U32 | Type::F32 => 4,
            Type::F64 => 8,
        }
    }
}

#[derive(Debug)]
enum Property {
    Scalar(String, Type),
    List(String, Type, Type),
}

impl Property {
    fn name(&self) -> &str {
        match self {
            Property::Scalar(n, _) | Property::List(n, _, _) => n,
        }
    }
    /// The fewest bytes it takes in binary (a list of none).
    fn least(&self) -> usize {
        match self {
            Property::Scalar(_, t) | Property::List(_, t, _) => t.size(),
        }
    }
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
}

#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

/// Where the data is read from: ASCII numbers, one item (a vertex, a face) a line, or binary of
/// one byte order.
struct Data<'a> {
    encoding: Encoding,
    bytes: &'a [u8],
    at: usize,
    /// ASCII: the line of the item being read (1 is the file's first) and where it ends.
    line: usize,
    line_end: usize,
}

impl Data<'_> {
    /// Where the item being read is, for messages: its line in ASCII, its byte in binary.
    fn place(&self) -> (&'static str, usize) {
        match self.encoding {
            Encoding::Ascii => ("line", self.line),
            _ => ("byte", self.at),
        }
    }

    /// ASCII: move to the next line that holds something, the item's.
    fn begin_item(&mut self) {
        if self.encoding != Encoding::Ascii {
            return;
        }
        while self.at < self.bytes.len() {
            let rest = &self.bytes[self.at..];
            self.line_end = self.at + rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
            if self.bytes[self.at..self.line_end].iter().any(|b| !b.is_ascii_whitespace()) {
                return;
            }
            self.at = self.line_end + 1;
            self.line += 1;
        }
        self.line_end = self.bytes.len();
    }

    /// ASCII: the item's line must hold nothing more (a value too many would shift every item
    /// after it); then on to the next line.
    fn end_item(&mut self, declared: usize) -> Result<(), String> {
        if self.encoding != Encoding::Ascii {
            return Ok(());
        }
        let rest = &self.bytes[self.at.min(self.line_end)..self.line_end];
        let extra = rest.split(|b| b.is_ascii_whitespace()).filter(|w| !w.is_empty()).count();
        if extra > 0 {
            return Err(format!("{extra} more value(s) on the line than the {declared} the header declares"));
        }
        self.at = self.line_end + 1;
        self.line += 1;
        Ok(())
    }

    fn value(&mut self, t: Type) -> Result<f64, String> {
        if self.encoding == Encoding::Ascii {
            let rest = &self.bytes[self.at.min(self.line_end)..self.line_end];
            let start = rest.iter().position(|b| !b.is_ascii_whitespace()).ok_or("the line ends before it")?;
            let len = rest[start..].iter().position(|b| b.is_ascii_whitespace()).unwrap_or(rest.len() - start);
            self.at += start + len;
            let word = String::from_utf8_lossy(&rest[start..start + len]);
            return word.parse::<f64>().map_err(|_| format!("'{word}' is not a number"));
        }
        let b = self.bytes.get(self.at..self.at + t.size()).ok_or("the file ends before it")?;
        self.at += t.size();
        let little = self.encoding == Encoding::Little;
        macro_rules! read {
            ($ty:ty) => {{
                let a = b.try_into().expect("the type's size");
                (if little { <$ty>::from_le_bytes(a) } else { <$ty>::from_be_bytes(a) }) as f64
            }};
        }
        Ok(match t {
            Type::I8 => b[0] as i8 as f64,
            Type::U8 => b[0] as f64,
            Type::I16 => read!(i16),
            Type::U16 => read!(u16),
            Type::I32 => read!(i32),
            Type::U32 => read!(u32),
            Type::F32 => read!(f32),
            Type::F64 => read!(f64),
        })
    }
}

/// The header: the encoding, the elements, where the data starts and the data's first line. It
/// ends at the line that is `end_header` (a comment that mentions it does not end it).
fn header(path: &Path, bytes: &[u8]) -> Result<(Encoding, Vec<Element>, usize, usize), MeshError> {
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut at = 0;
    let mut number = 0;
    let data = loop {
        let Some(len) = bytes[at..].iter().position(|&b| b == b'\n') else {
            return Err(bad(path, "the header", "no end_header line"));
        };
        let line = String::from_utf8_lossy(&bytes[at..at + len]);
        at += len + 1;
        number += 1;
        let w: Vec<&str> = line.split_whitespace().collect();
        let here = || format!("header line {number}");
        match w.first().copied() {
            _ if number == 1 => {}
            Some("end_header") => break at,
            Some("format") => {
                encoding = Some(match w.get(1).copied() {
                    Some("ascii") => Encoding::Ascii,
                    Some("binary_little_endian") => Encoding::Little,
                    Some("binary_big_endian") => Encoding::Big,
                    other => return Err(bad(path, here(), format!("unknown format {other:?}"))),
                })
            }
            Some("element") => {
                let (Some(name), Some(count)) = (w.get(1), w.get(2).and_then(|c| c.parse::<u64>().ok())) else {
                    return Err(bad(path, here(), "an element needs a name and a count"));
                };
                elements.push(Element { name: name.to_string(), count, properties: Vec::new() });
            }
            Some("property") => {
                let e = elements.last_mut().ok_or_else(|| bad(path, here(), "a property before any element"))?;
                let ty = |k: usize| {
                    w.get(k)
                        .and_then(|t| Type::parse(t))
                        .ok_or_else(|| bad(path, here(), format!("unknown property type {:?}", w.get(k))))
                };
                let p = if w.get(1) == Some(&"list") {
                    let name = w.get(4).ok_or_else(|| bad(path, here(), "a list property needs a name"))?;
                    Property::List(name.to_string(), ty(2)?, ty(3)?)
                } else {
                    let name = w.get(2).ok_or_else(|| bad(path, here(), "a property needs a name"))?;
                    Property::Scalar(name.to_string(), ty(1)?)
                };
                e.properties.push(p);
            }
            Some("comment") | Some("obj_info") | None => {}
            Some(other) => return Err(bad(path, here(), format!("unknown header keyword '{other}'"))),
        }
    };
    let encoding = encoding.ok_or_else(|| bad(path, "the header", "no format line"))?;
    // No count may claim more than the file could hold: each item takes at least its least bytes
    // in binary, two in ASCII (a digit and a space).
    let mut room = (bytes.len() - data) as u64;
    for e in &elements {
        let least = match encoding {
            Encoding::Ascii => 2 * e.properties.len().max(1) as u64,
            _ => e.properties.iter().map(|p| p.least() as u64).sum::<u64>().max(1),
        };
        if e.count.saturating_mul(least) > room {
            return Err(bad(
                path,
                format!("element {}", e.name),
                format!("claims {} items, more than the {} bytes of data left could hold", e.count, room),
            ));
        }
        room -= e.count * least;
        let limit = match e.name.as_str() {
            "vertex" => Some(limits::VERTICES),
            "face" | "tristrips" => Some(limits::TRIANGLES),
            _ => None,
        };
        if let Some(limit) = limit {
            limit.check(e.count).map_err(|m| bad(path, format!("element {}", e.name), m))?;
        }
    }
    Ok((encoding, elements, data, number + 1))
}

pub(crate) fn parse(path: &Path, bytes: &[u8]) -> Result<(Mesh, LoadReport), MeshError> {
    let (encoding, elements, start, line) = header(path, bytes)?;
    let mut data = Data { encoding, bytes, at: start, line, line_end: start };
    let (mut positions, mut normals, mut triangles) = (Vec::new(), Vec::new(), Vec::new());
    let mut list: Vec<i64> = Vec::new();
    let mut seen_vertices = false;
    for e in &elements {
        let find = |n: &str| e.properties.iter().position(|p| p.name() == n);
        let (x, y, z) = (find("x"), find("y"), find("z"));
        let (nx, ny, nz) = (find("nx"), find("ny"), find("nz"));
        let indices = find("vertex_indices").or_else(|| find("vertex_index"));
        let is_vertex = e.name == "vertex";
        if is_vertex {
            if x.is_none() || y.is_none() || z.is_none() {
                return Err(bad(path, "element vertex", "has no x, y and z properties"));
            }
            positions.reserve(capacity(e.count, bytes.len(), 3));
            seen_vertices = true;
        }
        let with_normals = is_vertex && nx.is_some() && ny.is_some() && nz.is_some();
        for item in 0..e.count {
            data.begin_item();
            let place = data.place();
            let at = || format!("{} {item} ({} {})", e.name, place.0, place.1);
            let mut v = [0f64; 6];
            let mut values = 0;
            for (k, p) in e.properties.iter().enumerate() {
                let fail = |why: String| bad(path, at(), format!("property {}: {why}", p.name()));
                match p {
                    Property::Scalar(_, t) => {
                        let value = data.value(*t).map_err(fail)?;
                        values += 1;
                        for (slot, idx) in [x, y, z, nx, ny, nz].iter().enumerate() {
                            if *idx == Some(k) {
                                v[slot] = value;
                            }
                        }
                    }
                    Property::List(_, ct, it) => {
                        let n = data.value(*ct).map_err(fail)?;
                        if !(0.0..=1e9).contains(&n) || n.fract() != 0.0 {
                            return Err(fail(format!("list length {n}")));
                        }
                        values += 1 + n as usize;
                        // Only the index list is kept: a list after it (MeshLab's per-corner
                        // texture coordinates) is read past, not over it.
                        let keep = Some(k) == indices;
                        if keep {
                            list.clear();
                        }
                        for _ in 0..n as u64 {
                            let value = data.value(*it).map_err(fail)?;
                            if keep {
                                if !value.is_finite() || value.fract() != 0.0 {
                                    return Err(fail(format!("vertex index {value} is not a whole number")));
                                }
                                list.push(value as i64);
                            }
                        }
                    }
                }
            }
            data.end_item(values).map_err(|why| bad(path, at(), why))?;
            if is_vertex {
                positions.push(point([v[0], v[1], v[2]]).map_err(|why| bad(path, at(), why))?);
                if with_normals {
                    normals.push(Vec3::new(v[3] as f32, v[4] as f32, v[5] as f32));
                }
            } else if indices.is_some() && (e.name == "face" || e.name == "tristrips") {
                if !seen_vertices {
                    return Err(bad(path, format!("element {}", e.name), "comes before the vertices it refers to"));
                }
                let n = positions.len() as i64;
                let restart = e.name == "tristrips";
                if let Some(&bad_index) = list.iter().find(|&&i| i >= n || (i < 0 && !(restart && i == -1))) {
                    return Err(bad(path, at(), format!("refers to vertex {bad_index}, but only {n} are declared")));
                }
                if restart {
                    for strip in list.split(|&i| i == -1) {
                        for k in 2..strip.len() {
                            let (a, b, c) = (strip[k - 2] as u32, strip[k - 1] as u32, strip[k] as u32);
                            triangles.push(if k % 2 == 0 { [a, b, c] } else { [b, a, c] });
                        }
                    }
                } else {
                    let polygon: Vec<u32> = list.iter().map(|&i| i as u32).collect();
                    fan(&polygon, &mut triangles);
                }
                limits::TRIANGLES.check(triangles.len() as u64).map_err(|why| bad(path, at(), why))?;
            }
        }
    }
    if !seen_vertices {
        return Err(bad(path, "the header", "no vertex element"));
    }
    finish(path, positions, normals, triangles)
}
