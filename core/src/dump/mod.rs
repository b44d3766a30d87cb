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

mod import;

pub use import::{import, oversized_leaves, untraceable};

mod read;

use crate::bvh::{AnyBvh, Bvh, WideBvh};
use crate::files::FileError;
use crate::geometry::Aabb;
use glam::Vec3;
use serde::{Deserialize, Serialize};
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
    #[error(transparent)]
    File(#[from] FileError),
    /// `plain`: what is wrong in bvhscope's own words, when `why` quotes the file (`without_content`).
    #[error("{path}: not a bvhscope-bvh file: {why}")]
    NotTheFormat { path: String, why: String, plain: Option<&'static str> },
    #[error("{path}: version {found} of the bvhscope-bvh format; this bvhscope reads version {VERSION}")]
    FutureVersion { path: String, found: u32 },
    #[error("{path}: line {line}: {why}")]
    Text { path: String, line: usize, why: String, plain: Option<&'static str> },
    #[error("{path}: {what} more than {} MB, the limit (by default what a BVH dump of this mesh can need; --max-dump-mb sets it)", .limit.div_ceil(1 << 20))]
    TooBig { path: String, what: &'static str, limit: u64 },
}

impl DumpError {
    /// The message without a byte of the file's content: what `grade` reports of a file that is
    /// not a dump (it may be anything a student's archive holds, a link's target included, and the
    /// report goes to the whole class). Where the message quotes the file (a word, a field, a
    /// format's name), its `plain` words stand instead.
    pub fn without_content(&self) -> String {
        match self {
            DumpError::NotTheFormat { path, plain: Some(p), .. } => format!("{path}: not a bvhscope-bvh file: {p}"),
            DumpError::Text { path, line, plain: Some(p), .. } => format!("{path}: line {line}: {p}"),
            other => other.to_string(),
        }
    }
}

/// Bytes a dump of a mesh of `triangles` triangles may take, decompressed: what its largest tree
/// can need written generously (`explain::check::max_references`'s eight references per
/// triangle, two nodes per reference of a few hundred bytes each, as pretty-printed JSON writes
/// them), and 64 MB for small meshes. A dump past it is refused while it is read, so a gzip bomb
/// or a device stops there.
pub fn max_bytes(triangles: usize) -> u64 {
    (64 << 20) + triangles as u64 * 8 * (2 * 400 + 16)
}

/// The forms a dump is written in, by the file's name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DumpFile {
    Json,
    JsonGz,
    Text,
}

impl BvhDump {
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
    pub fn of_any(bvh: &AnyBvh, mesh: &crate::mesh::Mesh, name: Option<String>) -> BvhDump {
        match bvh {
            AnyBvh::Binary(b) => Self::of_bvh(b, mesh, name),
            AnyBvh::Wide(w) => Self::of_wide(w, mesh, name),
            AnyBvh::Wide8(w) => Self::of_wide(w, mesh, name),
        }
    }

    /// The file names a dump can be written to, by what they hold.
    pub const WRITTEN_AS: &'static str = ".json (JSON), .json.gz (gzip-compressed JSON) or .txt (the text form)";

    /// What `path`'s name says the dump is written as, or why it names no dump format.
    pub fn written_as(path: &Path) -> Result<DumpFile, String> {
        let name = path.file_name().map(|n| n.to_string_lossy().to_lowercase()).unwrap_or_default();
        if name.ends_with(".json.gz") {
            Ok(DumpFile::JsonGz)
        } else if name.ends_with(".json") {
            Ok(DumpFile::Json)
        } else if name.ends_with(".txt") {
            Ok(DumpFile::Text)
        } else {
            Err(format!("{}: a dump is written as {}", path.display(), Self::WRITTEN_AS))
        }
    }

    /// Write the dump to `path` in the form its name says (`written_as`), through a temporary file
    /// renamed over `path` when complete.
    pub fn write(&self, path: &Path) -> Result<(), DumpError> {
        use std::io::Write;
        let form = Self::written_as(path).map_err(|why| DumpError::NotTheFormat {
            path: path.display().to_string(),
            why,
            plain: None,
        })?;
        let werr = |source| DumpError::File(FileError::Write { path: path.into(), source });
        crate::files::write_atomically(path, |w| {
            let text = match form {
                DumpFile::Text => self.to_text(),
                DumpFile::Json | DumpFile::JsonGz => serde_json::to_string(self).expect("plain data serialises"),
            };
            match form {
                DumpFile::JsonGz => {
                    let mut gz = flate2::write::GzEncoder::new(w, flate2::Compression::default());
                    gz.write_all(text.as_bytes()).map_err(werr)?;
                    gz.finish().map_err(werr)?;
                }
                _ => w.write_all(text.as_bytes()).map_err(werr)?,
            }
            Ok(())
        })
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
    pub fn of_wide<const W: usize>(w: &WideBvh<W>, mesh: &crate::mesh::Mesh, name: Option<String>) -> BvhDump {
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
