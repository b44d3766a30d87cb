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

use crate::bvh::{AnyBvh, Bvh, WideBvh};
use crate::files::FileError;
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

/// `without_content`'s words for a format that is not this one.
const OTHER_FORMAT: &str = "its \"format\" names another format";

/// The forms a dump is written in, by the file's name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DumpFile {
    Json,
    JsonGz,
    Text,
}

impl BvhDump {
    /// Whether `path` looks like a dump rather than a mesh or a scene (what a file dropped on the
    /// app is taken for): gzip, or the format's name in its first kilobytes. Only regular files
    /// are opened (a FIFO would block).
    pub fn sniff(path: &Path) -> bool {
        let Ok((file, _)) = crate::files::open_regular(path) else { return false };
        let mut head = Vec::new();
        if file.take(4096).read_to_end(&mut head).is_err() {
            return false;
        }
        head.starts_with(&[0x1f, 0x8b]) || head.windows(FORMAT.len()).any(|w| w == FORMAT.as_bytes())
    }

    /// Read a dump: JSON, gzip-compressed JSON (`.gz`, one member or several), or the text form
    /// (anything whose first word is `bvhscope-bvh`). At most `limit` bytes are read, counted
    /// after decompression (`max_bytes`).
    pub fn read(path: &Path, limit: u64) -> Result<BvhDump, DumpError> {
        let name = path.display().to_string();
        let io = |source| DumpError::File(FileError::Read { path: path.into(), source });
        let too_big = |what| DumpError::TooBig { path: name.clone(), what, limit };
        let (mut file, _) = crate::files::open_regular(path)?;
        let mut magic = [0u8; 2];
        let n = file.read(&mut magic).map_err(io)?;
        let head = std::io::Cursor::new(magic[..n].to_vec());
        let bytes = if magic[..n] == [0x1f, 0x8b] {
            // Every member of a multi-member gzip file, and bytes after the last member are an
            // error (MultiGzDecoder reads them as a broken member), not silently ignored.
            let gz = flate2::read::MultiGzDecoder::new(head.chain(file));
            crate::files::read_limited(gz, limit)
                .map_err(|e| DumpError::NotTheFormat {
                    path: name.clone(),
                    why: format!("broken gzip data: {e}"),
                    plain: None,
                })?
                .ok_or_else(|| too_big("decompresses to"))?
        } else {
            crate::files::read_limited(head.chain(file), limit).map_err(io)?.ok_or_else(|| too_big("is"))?
        };
        let text = decode(&bytes).ok_or_else(|| DumpError::NotTheFormat {
            path: name.clone(),
            why: "not text (a NUL byte: binary data, nor gzip)".into(),
            plain: None,
        })?;
        let start = text.trim_start();
        let dump = if start.starts_with('{') || start.starts_with('[') || start.starts_with("null") {
            Self::from_json(start, &name)?
        } else {
            Self::from_text(&text, &name)?
        };
        if dump.format != FORMAT {
            return Err(DumpError::NotTheFormat {
                path: name,
                why: format!("its format is \"{}\"", dump.format),
                plain: Some(OTHER_FORMAT),
            });
        }
        if dump.version != VERSION {
            return Err(DumpError::FutureVersion { path: name, found: dump.version });
        }
        Ok(dump)
    }

    fn from_json(text: &str, name: &str) -> Result<BvhDump, DumpError> {
        let not = |why: String| DumpError::NotTheFormat { path: name.into(), why, plain: None };
        // A message that quotes the file (serde's name a field or a value from it).
        let quotes =
            |why: String, plain: &'static str| DumpError::NotTheFormat { path: name.into(), why, plain: Some(plain) };
        // The format and version first, so a future version is named as such, not as broken JSON.
        #[derive(Deserialize)]
        struct Head {
            format: Option<String>,
            version: Option<serde_json::Value>,
        }
        let value: serde_json::Value = serde_json::from_str(text).map_err(|e| not(format!("broken JSON: {e}")))?;
        if !value.is_object() {
            let kind = match &value {
                serde_json::Value::Null => "null",
                serde_json::Value::Array(_) => "an array",
                serde_json::Value::String(_) => "a string",
                serde_json::Value::Number(_) => "a number",
                _ => "a boolean",
            };
            return Err(not(format!("the JSON is {kind}, not an object with \"format\": \"{FORMAT}\"")));
        }
        let head = Head::deserialize(&value)
            .map_err(|e| quotes(e.to_string(), "\"format\" or \"version\" is not of the right type"))?;
        match head.format.as_deref() {
            Some(FORMAT) => {}
            Some(f) => return Err(quotes(format!("its format is \"{f}\""), OTHER_FORMAT)),
            None => return Err(not("no \"format\" field".into())),
        }
        match head.version.as_ref().map(|v| v.as_u64()) {
            None => return Err(not(format!("no \"version\" field (this bvhscope reads version {VERSION})"))),
            Some(Some(v)) if v != VERSION as u64 => {
                return Err(DumpError::FutureVersion { path: name.into(), found: v.min(u32::MAX as u64) as u32 })
            }
            Some(Some(_)) => {}
            Some(None) => return Err(not("\"version\" is not a whole number".into())),
        }
        BvhDump::deserialize(value).map_err(|e| {
            quotes(e.to_string(), "its fields are not a dump's (one missing, unknown, repeated or of the wrong type)")
        })
    }

    fn from_text(text: &str, name: &str) -> Result<BvhDump, DumpError> {
        let err = |line: usize, why: String| DumpError::Text { path: name.into(), line, why, plain: None };
        // A message that quotes the line.
        let quotes = |line: usize, why: String, plain: &'static str| DumpError::Text {
            path: name.into(),
            line,
            why,
            plain: Some(plain),
        };
        let mut dump =
            BvhDump { format: String::new(), version: 0, mesh: None, primitives: Vec::new(), nodes: Vec::new() };
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            let n = i + 1;
            let mut words = line.split_whitespace();
            let Some(head) = words.next() else { continue };
            let rest: Vec<&str> = words.collect();
            let num = |s: &str| {
                s.parse::<f32>()
                    .map_err(|_| quotes(n, format!("'{s}' is not a number"), "a word where a number must be"))
            };
            let int = |s: &str| {
                s.parse::<u32>().map_err(|_| {
                    quotes(n, format!("'{s}' is not a whole number"), "a word where a whole number must be")
                })
            };
            match head {
                FORMAT if dump.format.is_empty() => {
                    dump.format = FORMAT.into();
                    dump.version = int(rest.first().copied().unwrap_or("?"))?;
                    if dump.version != VERSION {
                        return Err(DumpError::FutureVersion { path: name.into(), found: dump.version });
                    }
                    if let Some(extra) = rest.get(1) {
                        return Err(quotes(
                            n,
                            format!("'{extra}' after 'bvhscope-bvh 1': the first line holds nothing else"),
                            "words after 'bvhscope-bvh 1': the first line holds nothing else",
                        ));
                    }
                }
                _ if dump.format.is_empty() => {
                    return Err(DumpError::NotTheFormat {
                        path: name.into(),
                        why: "the first line is not 'bvhscope-bvh 1' (nor is the file JSON)".into(),
                        plain: None,
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
                        "leaf" => {
                            return Err(err(
                                n,
                                format!("'leaf' takes FIRST COUNT: two numbers, not {}", rest.len() - 7),
                            ))
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
                                let axis = a.parse::<u8>().ok().filter(|&a| a <= 2);
                                node.axis = Some(axis.ok_or_else(|| {
                                    quotes(
                                        n,
                                        format!("axis '{a}' is not 0, 1 or 2 (x, y, z)"),
                                        "an axis that is not 0, 1 or 2 (x, y, z)",
                                    )
                                })?);
                                if let Some(extra) = rest.get(k + 2) {
                                    return Err(quotes(
                                        n,
                                        format!("'{extra}' after the axis: a node line ends with it"),
                                        "words after the axis: a node line ends with it",
                                    ));
                                }
                            }
                            node.children = Some(kids);
                        }
                        other => {
                            return Err(quotes(
                                n,
                                format!("'{other}': expected 'children' or 'leaf FIRST COUNT'"),
                                "a word where 'children' or 'leaf FIRST COUNT' must be",
                            ))
                        }
                    }
                    dump.nodes.push(node);
                }
                other => {
                    return Err(quotes(
                        n,
                        format!("'{other}' is not mesh, primitives or node"),
                        "a line that is not mesh, primitives or node",
                    ))
                }
            }
        }
        if dump.format.is_empty() {
            return Err(DumpError::NotTheFormat { path: name.into(), why: "the file is empty".into(), plain: None });
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

/// A dump's bytes as text: a UTF-8 byte-order mark dropped, bytes that are not UTF-8 decoded as
/// Latin-1 (as meshes and scenes are: an exporter's comment or mesh name may be written so; the
/// numbers and words of the format are ASCII). `None` for binary data (a NUL byte).
fn decode(bytes: &[u8]) -> Option<std::borrow::Cow<'_, str>> {
    let bytes = bytes.strip_prefix("\u{feff}".as_bytes()).unwrap_or(bytes);
    if bytes.contains(&0) {
        return None;
    }
    Some(match std::str::from_utf8(bytes) {
        Ok(s) => std::borrow::Cow::Borrowed(s),
        Err(_) => std::borrow::Cow::Owned(bytes.iter().map(|&b| b as char).collect()),
    })
}
