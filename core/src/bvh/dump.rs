//! The `bvhscope-bvh` format: a BVH written by another program (a student's renderer) or by
//! bvhscope itself, to be checked, drawn and compared. Version 1 (the README documents it):
//!
//! - JSON: `{"format": "bvhscope-bvh", "version": 1, "mesh": "monkey.obj", "primitives": [..],
//!   "nodes": [{"min": [x,y,z], "max": [x,y,z], "children": [a, b], "axis": 0} |
//!   {"min": .., "max": .., "first": f, "count": n}]}`; node 0 is the root, nodes in any order,
//!   2 to 8 children, a leaf holds `primitives[first .. first + count]`, a primitive is a triangle
//!   index of the mesh (faces in file order, fan-triangulated, degenerate ones included);
//! - the same gzip-compressed (`.json.gz`);
//! - a plain text form a C++ program prints without a JSON library, one line per item:
//!   `bvhscope-bvh 1`, optionally `mesh FILE`, `primitives P0 P1 ...` (any number of such
//!   lines, concatenated), then one line per node in index order:
//!   `node MINX MINY MINZ MAXX MAXY MAXZ children C1 C2 [C3 C4] [axis A]` or
//!   `node MINX MINY MINZ MAXX MAXY MAXZ leaf FIRST COUNT`; `#` starts a comment.

use super::Bvh;
use crate::geometry::Aabb;
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::io::Read;
use std::path::Path;

pub const FORMAT: &str = "bvhscope-bvh";
pub const VERSION: u32 = 1;

/// One node as written: interior (`children`) or leaf (`first`, `count`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DumpNode {
    pub min: [f32; 3],
    pub max: [f32; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub children: Option<Vec<u32>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<u8>,
}

impl DumpNode {
    pub fn bounds(&self) -> Aabb {
        Aabb::new(Vec3::from(self.min), Vec3::from(self.max))
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BvhDump {
    pub format: String,
    pub version: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<String>,
    pub primitives: Vec<u32>,
    pub nodes: Vec<DumpNode>,
}

/// Why a dump cannot be read (the checker's exit code 2).
#[derive(Debug, thiserror::Error)]
pub enum DumpError {
    #[error("{path}: cannot read: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: not a bvhscope-bvh file: {why}")]
    NotTheFormat { path: String, why: String },
    #[error("{path}: version {found} of the bvhscope-bvh format; this bvhscope reads version {VERSION}")]
    FutureVersion { path: String, found: u32 },
    #[error("{path}: line {line}: {why}")]
    Text { path: String, line: usize, why: String },
}

impl BvhDump {
    /// Whether `path` looks like a dump rather than a mesh or a scene (what a file dropped on the
    /// app is taken for): gzip, or the format's name in its first kilobytes.
    pub fn sniff(path: &Path) -> bool {
        let mut head = [0u8; 4096];
        let Ok(n) = std::fs::File::open(path).and_then(|mut f| f.read(&mut head)) else { return false };
        let head = &head[..n];
        head.starts_with(&[0x1f, 0x8b]) || head.windows(FORMAT.len()).any(|w| w == FORMAT.as_bytes())
    }

    /// Read a dump: JSON, gzip-compressed JSON (`.gz`), or the text form (anything whose first
    /// word is `bvhscope-bvh`).
    pub fn read(path: &Path) -> Result<BvhDump, DumpError> {
        let name = path.display().to_string();
        let io = |source| DumpError::Io { path: name.clone(), source };
        let mut bytes = std::fs::read(path).map_err(io)?;
        if bytes.starts_with(&[0x1f, 0x8b]) {
            let mut out = Vec::new();
            flate2::read::GzDecoder::new(&bytes[..]).read_to_end(&mut out).map_err(io)?;
            bytes = out;
        }
        let text = String::from_utf8(bytes)
            .map_err(|_| DumpError::NotTheFormat { path: name.clone(), why: "not text (nor gzip)".into() })?;
        let dump = if text.trim_start().starts_with('{') {
            Self::from_json(&text, &name)?
        } else {
            Self::from_text(&text, &name)?
        };
        if dump.format != FORMAT {
            return Err(DumpError::NotTheFormat { path: name, why: format!("its format is \"{}\"", dump.format) });
        }
        if dump.version != VERSION {
            return Err(DumpError::FutureVersion { path: name, found: dump.version });
        }
        Ok(dump)
    }

    fn from_json(text: &str, name: &str) -> Result<BvhDump, DumpError> {
        // The format and version first, so a future version is named as such, not as broken JSON.
        #[derive(Deserialize)]
        struct Head {
            format: Option<String>,
            version: Option<u32>,
        }
        let head: Head = serde_json::from_str(text)
            .map_err(|e| DumpError::NotTheFormat { path: name.into(), why: format!("broken JSON: {e}") })?;
        match (head.format.as_deref(), head.version) {
            (Some(FORMAT), Some(v)) if v != VERSION => {
                return Err(DumpError::FutureVersion { path: name.into(), found: v })
            }
            (Some(FORMAT), Some(_)) => {}
            (f, _) => {
                let why = f.map_or("no \"format\" field".to_string(), |f| format!("its format is \"{f}\""));
                return Err(DumpError::NotTheFormat { path: name.into(), why });
            }
        }
        serde_json::from_str(text).map_err(|e| DumpError::NotTheFormat { path: name.into(), why: e.to_string() })
    }

    fn from_text(text: &str, name: &str) -> Result<BvhDump, DumpError> {
        let err = |line: usize, why: String| DumpError::Text { path: name.into(), line, why };
        let mut dump =
            BvhDump { format: String::new(), version: 0, mesh: None, primitives: Vec::new(), nodes: Vec::new() };
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            let n = i + 1;
            let mut words = line.split_whitespace();
            let Some(head) = words.next() else { continue };
            let rest: Vec<&str> = words.collect();
            let num = |s: &str| s.parse::<f32>().map_err(|_| err(n, format!("'{s}' is not a number")));
            let int = |s: &str| s.parse::<u32>().map_err(|_| err(n, format!("'{s}' is not a whole number")));
            match head {
                FORMAT if dump.format.is_empty() => {
                    dump.format = FORMAT.into();
                    dump.version = int(rest.first().copied().unwrap_or("?"))?;
                    if dump.version != VERSION {
                        return Err(DumpError::FutureVersion { path: name.into(), found: dump.version });
                    }
                }
                _ if dump.format.is_empty() => {
                    return Err(DumpError::NotTheFormat {
                        path: name.into(),
                        why: "the first line is not 'bvhscope-bvh 1' (nor is the file JSON)".into(),
                    })
                }
                "mesh" => dump.mesh = Some(rest.join(" ")),
                "primitives" => {
                    for w in rest {
                        dump.primitives.push(int(w)?);
                    }
                }
                "node" => {
                    if rest.len() < 8 {
                        return Err(err(
                            n,
                            "a node is 'node MIN(3) MAX(3) children C..' or '... leaf FIRST COUNT'".into(),
                        ));
                    }
                    let f: Vec<f32> = rest[..6].iter().map(|w| num(w)).collect::<Result<_, _>>()?;
                    let mut node = DumpNode {
                        min: [f[0], f[1], f[2]],
                        max: [f[3], f[4], f[5]],
                        children: None,
                        first: None,
                        count: None,
                        axis: None,
                    };
                    match rest[6] {
                        "leaf" if rest.len() == 9 => {
                            node.first = Some(int(rest[7])?);
                            node.count = Some(int(rest[8])?);
                        }
                        "children" => {
                            let mut kids = Vec::new();
                            let mut k = 7;
                            while k < rest.len() && rest[k] != "axis" {
                                kids.push(int(rest[k])?);
                                k += 1;
                            }
                            if k < rest.len() {
                                let a = rest.get(k + 1).ok_or_else(|| err(n, "'axis' without a value".into()))?;
                                node.axis = Some(int(a)? as u8);
                            }
                            node.children = Some(kids);
                        }
                        other => return Err(err(n, format!("'{other}': expected 'children' or 'leaf FIRST COUNT'"))),
                    }
                    dump.nodes.push(node);
                }
                other => return Err(err(n, format!("'{other}' is not mesh, primitives or node"))),
            }
        }
        if dump.format.is_empty() {
            return Err(DumpError::NotTheFormat { path: name.into(), why: "the file is empty".into() });
        }
        Ok(dump)
    }

    /// The text form.
    pub fn to_text(&self) -> String {
        use std::fmt::Write;
        let mut o = format!("{FORMAT} {VERSION}\n");
        if let Some(m) = &self.mesh {
            let _ = writeln!(o, "mesh {m}");
        }
        for chunk in self.primitives.chunks(32) {
            let words: Vec<String> = chunk.iter().map(|p| p.to_string()).collect();
            let _ = writeln!(o, "primitives {}", words.join(" "));
        }
        for n in &self.nodes {
            let (a, b) = (n.min, n.max);
            let _ = write!(o, "node {} {} {} {} {} {}", a[0], a[1], a[2], b[0], b[1], b[2]);
            match (&n.children, n.first, n.count) {
                (Some(kids), _, _) => {
                    let words: Vec<String> = kids.iter().map(|k| k.to_string()).collect();
                    let _ = write!(o, " children {}", words.join(" "));
                    if let Some(axis) = n.axis {
                        let _ = write!(o, " axis {axis}");
                    }
                }
                (None, f, c) => {
                    let _ = write!(o, " leaf {} {}", f.unwrap_or(0), c.unwrap_or(0));
                }
            }
            o.push('\n');
        }
        o
    }

    /// A tree of bvhscope's in any layout (`of_bvh`, `of_wide`).
    pub fn of_any(bvh: &super::AnyBvh, mesh: &crate::mesh::Mesh, name: Option<String>) -> BvhDump {
        match bvh {
            super::AnyBvh::Binary(b) => Self::of_bvh(b, mesh, name),
            super::AnyBvh::Wide(w) => Self::of_wide(w, mesh, name),
            super::AnyBvh::Wide8(w) => Self::of_wide(w, mesh, name),
        }
    }

    /// Write the dump to `path`: the text form when its name ends in `.txt`, else JSON.
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        let text = if path.extension().is_some_and(|e| e == "txt") {
            self.to_text()
        } else {
            serde_json::to_string(self).expect("plain data serialises")
        };
        std::fs::write(path, text)
    }

    /// A binary tree of bvhscope's over `mesh`, as a dump (its leaf order is the primitives'
    /// order, each triangle by its number in the file: `Mesh::file_number`).
    pub fn of_bvh(bvh: &Bvh, mesh: &crate::mesh::Mesh, name: Option<String>) -> BvhDump {
        let nodes = bvh
            .nodes
            .iter()
            .map(|n| {
                let b = n.bounds();
                let (min, max) = (glam::Vec3::from(b.min).to_array(), glam::Vec3::from(b.max).to_array());
                if n.is_leaf() {
                    DumpNode { min, max, children: None, first: Some(n.index), count: Some(n.count as u32), axis: None }
                } else {
                    let kids = vec![n.index, n.index + 1];
                    DumpNode { min, max, children: Some(kids), first: None, count: None, axis: Some(n.axis) }
                }
            })
            .collect();
        let primitives = bvh.prim_ids.iter().map(|&p| mesh.file_number(p)).collect();
        BvhDump { format: FORMAT.into(), version: VERSION, mesh: name, primitives, nodes }
    }

    /// A 4- or 8-wide tree of bvhscope's over `mesh`, as a dump: wide node i is dump node i (its
    /// box is its slot's in its parent, the root's the tree's), and each leaf slot a dump leaf after them.
    pub fn of_wide<const W: usize>(w: &super::WideBvh<W>, mesh: &crate::mesh::Mesh, name: Option<String>) -> BvhDump {
        let arr = |v: glam::Vec3A| glam::Vec3::from(v).to_array();
        let mut boxes = vec![w.root_bounds; w.nodes.len()];
        let mut leaves = Vec::new();
        let mut kids: Vec<Vec<u32>> = vec![Vec::new(); w.nodes.len()];
        for (i, n) in w.nodes.iter().enumerate() {
            for s in n.slots() {
                let b = n.boxes.bounds(s);
                if n.count[s] == 0 {
                    boxes[n.child[s] as usize] = b;
                    kids[i].push(n.child[s]);
                } else {
                    kids[i].push((w.nodes.len() + leaves.len()) as u32);
                    leaves.push(DumpNode {
                        min: arr(b.min),
                        max: arr(b.max),
                        children: None,
                        first: Some(n.child[s]),
                        count: Some(n.count[s] as u32),
                        axis: None,
                    });
                }
            }
        }
        let primitives: Vec<u32> = w.prim_ids.iter().map(|&p| mesh.file_number(p)).collect();
        // A tree of one leaf (a mesh of a few triangles): that leaf is the root.
        if w.nodes.len() == 1 && leaves.len() == 1 {
            return BvhDump { format: FORMAT.into(), version: VERSION, mesh: name, primitives, nodes: leaves };
        }
        let mut nodes: Vec<DumpNode> = (0..w.nodes.len())
            .map(|i| DumpNode {
                min: arr(boxes[i].min),
                max: arr(boxes[i].max),
                children: Some(kids[i].clone()),
                first: None,
                count: None,
                axis: None,
            })
            .collect();
        nodes.extend(leaves);
        BvhDump { format: FORMAT.into(), version: VERSION, mesh: name, primitives, nodes }
    }
}
