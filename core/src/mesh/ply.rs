//! PLY (the Stanford scans' format): a text header naming elements and their properties, then
//! the data in ASCII or binary (little- or big-endian). Vertices give x, y, z of any numeric type
//! (and nx, ny, nz when present; other properties, colours among them, are skipped); faces are
//! lists (`vertex_indices` or `vertex_index`) of any count and index types, fan-triangulated as
//! OBJ's polygons are; `tristrips` (igea, the original Stanford files) are lists with −1 as a
//! restart, unrolled with alternating winding. Triangles are numbered in the file's order: the
//! faces', then the strips', element by element as the header lists them.

use super::assemble::{bad, capacity, fan, finish};
use super::{LoadReport, Mesh, MeshError};
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

/// Where the data is read from: ASCII numbers, or binary of one byte order.
struct Data<'a> {
    encoding: Encoding,
    bytes: &'a [u8],
    at: usize,
}

impl Data<'_> {
    fn value(&mut self, t: Type) -> Option<f64> {
        if self.encoding == Encoding::Ascii {
            let rest = &self.bytes[self.at..];
            let start = rest.iter().position(|b| !b.is_ascii_whitespace())?;
            let len = rest[start..].iter().position(|b| b.is_ascii_whitespace()).unwrap_or(rest.len() - start);
            self.at += start + len;
            return std::str::from_utf8(&rest[start..start + len]).ok()?.parse::<f64>().ok();
        }
        let b = self.bytes.get(self.at..self.at + t.size())?;
        self.at += t.size();
        let little = self.encoding == Encoding::Little;
        macro_rules! read {
            ($ty:ty) => {{
                let a = b.try_into().ok()?;
                (if little { <$ty>::from_le_bytes(a) } else { <$ty>::from_be_bytes(a) }) as f64
            }};
        }
        Some(match t {
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

/// The header: the encoding, the elements, and where the data starts.
fn header(path: &Path, bytes: &[u8]) -> Result<(Encoding, Vec<Element>, usize), MeshError> {
    let end = bytes
        .windows(10)
        .position(|w| w == b"end_header")
        .ok_or_else(|| bad(path, "the header", "no end_header line"))?;
    let data = end + 10 + bytes[end + 10..].iter().position(|&b| b == b'\n').map_or(0, |p| p + 1);
    let text = String::from_utf8_lossy(&bytes[..end]);
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let w: Vec<&str> = line.split_whitespace().collect();
        let at = || format!("header line {}", i + 1);
        match w.first().copied() {
            Some("format") => {
                encoding = Some(match w.get(1).copied() {
                    Some("ascii") => Encoding::Ascii,
                    Some("binary_little_endian") => Encoding::Little,
                    Some("binary_big_endian") => Encoding::Big,
                    other => return Err(bad(path, at(), format!("unknown format {other:?}"))),
                })
            }
            Some("element") => {
                let (Some(name), Some(count)) = (w.get(1), w.get(2).and_then(|c| c.parse::<u64>().ok())) else {
                    return Err(bad(path, at(), "an element needs a name and a count"));
                };
                elements.push(Element { name: name.to_string(), count, properties: Vec::new() });
            }
            Some("property") => {
                let e = elements.last_mut().ok_or_else(|| bad(path, at(), "a property before any element"))?;
                let ty = |k: usize| {
                    w.get(k)
                        .and_then(|t| Type::parse(t))
                        .ok_or_else(|| bad(path, at(), format!("unknown property type {:?}", w.get(k))))
                };
                let p = if w.get(1) == Some(&"list") {
                    let name = w.get(4).ok_or_else(|| bad(path, at(), "a list property needs a name"))?;
                    Property::List(name.to_string(), ty(2)?, ty(3)?)
                } else {
                    let name = w.get(2).ok_or_else(|| bad(path, at(), "a property needs a name"))?;
                    Property::Scalar(name.to_string(), ty(1)?)
                };
                e.properties.push(p);
            }
            Some("comment") | Some("obj_info") | None => {}
            Some(other) => return Err(bad(path, at(), format!("unknown header keyword '{other}'"))),
        }
    }
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
    }
    Ok((encoding, elements, data))
}

pub(crate) fn parse(path: &Path, bytes: &[u8]) -> Result<(Mesh, LoadReport), MeshError> {
    let (encoding, elements, start) = header(path, bytes)?;
    let mut data = Data { encoding, bytes, at: start };
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
            let mut v = [0f64; 6];
            for (k, p) in e.properties.iter().enumerate() {
                let at = || format!("{} {item}", e.name);
                let short =
                    || bad(path, at(), format!("the file ends, or a value is not a number, in property {}", p.name()));
                match p {
                    Property::Scalar(_, t) => {
                        let value = data.value(*t).ok_or_else(short)?;
                        for (slot, idx) in [x, y, z, nx, ny, nz].iter().enumerate() {
                            if *idx == Some(k) {
                                v[slot] = value;
                            }
                        }
                    }
                    Property::List(_, ct, it) => {
                        let n = data.value(*ct).ok_or_else(short)?;
                        if !(0.0..=1e9).contains(&n) || n.fract() != 0.0 {
                            return Err(bad(path, at(), format!("list length {n} of {}", p.name())));
                        }
                        let keep = Some(k) == indices;
                        list.clear();
                        for _ in 0..n as u64 {
                            let value = data.value(*it).ok_or_else(short)?;
                            if keep {
                                list.push(value as i64);
                            }
                        }
                    }
                }
            }
            if is_vertex {
                positions.push(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32));
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
                    return Err(bad(
                        path,
                        format!("{} {item}", e.name),
                        format!("refers to vertex {bad_index}, but only {n} are declared"),
                    ));
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
            }
        }
    }
    if !seen_vertices {
        return Err(bad(path, "the header", "no vertex element"));
    }
    finish(path, positions, normals, triangles)
}
