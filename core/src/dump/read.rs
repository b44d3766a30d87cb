//! Reading a dump: JSON, gzip-compressed JSON or the text form, bounded by size, into the
//! dump's types (`BvhDump::read`); what makes a file look like one (`BvhDump::sniff`).

use super::{BvhDump, DumpError, DumpNode, FORMAT, VERSION};
use crate::files::FileError;
use serde::Deserialize;
use std::io::Read;
use std::path::Path;

/// `without_content`'s words for a format that is not this one.
const OTHER_FORMAT: &str = "its \"format\" names another format";

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

    /// Read straight into the dump's types, never into a `serde_json::Value` (a tree of maps
    /// took some fifteen times the file's size: 300 MB for a 21 MB dump); the text is gone over
    /// three times instead, keeping nothing the first two: is it JSON, what format and version
    /// does it say, then the dump. A key given twice, at any depth, is an error naming it, as in
    /// scene files and rubrics (`json::check`).
    fn from_json(text: &str, name: &str) -> Result<BvhDump, DumpError> {
        let not = |why: String| DumpError::NotTheFormat { path: name.into(), why, plain: None };
        // A message that quotes the file (serde's name a field or a value from it).
        let quotes =
            |why: String, plain: &'static str| DumpError::NotTheFormat { path: name.into(), why, plain: Some(plain) };
        // JSON with no key given twice in any object (`json::check`: a repeated key is named).
        let top = crate::json::check(text).map_err(|e| match e.is_data() {
            true => quotes(e.to_string(), "a key given twice"),
            false => not(format!("broken JSON: {e}")),
        })?;
        if top != crate::json::Kind::Object {
            let kind = top.name();
            return Err(not(format!("the JSON is {kind}, not an object with \"format\": \"{FORMAT}\"")));
        }
        // The format and version first, so a future version is named as such, not as broken JSON.
        #[derive(Deserialize)]
        struct Head {
            format: Option<String>,
            version: Option<serde_json::Value>,
        }
        let head: Head = serde_json::from_str(text)
            .map_err(|e| quotes(e.to_string(), "\"format\" or \"version\" is not of the right type, or given twice"))?;
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
        serde_json::from_str::<BvhDump>(text).map_err(|e| {
            quotes(e.to_string(), "its fields are not a dump's (one missing, unknown, repeated or of the wrong type)")
        })
    }

    fn from_text(text: &str, name: &str) -> Result<BvhDump, DumpError> {
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
                "node" => dump.nodes.push(text_node(&rest, n, name)?),
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
}

/// One `node` line of the text form: its words after `node`, line `n` of the file `name`.
fn text_node(rest: &[&str], n: usize, name: &str) -> Result<DumpNode, DumpError> {
    let err = |why: String| DumpError::Text { path: name.into(), line: n, why, plain: None };
    // A message that quotes the line.
    let quotes =
        |why: String, plain: &'static str| DumpError::Text { path: name.into(), line: n, why, plain: Some(plain) };
    let num = |s: &str| {
        s.parse::<f32>().map_err(|_| quotes(format!("'{s}' is not a number"), "a word where a number must be"))
    };
    let int = |s: &str| {
        s.parse::<u32>()
            .map_err(|_| quotes(format!("'{s}' is not a whole number"), "a word where a whole number must be"))
    };
    if rest.len() < 8 {
        return Err(err("a node is 'node MIN(3) MAX(3) children C..' or '... leaf FIRST COUNT'".into()));
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
        "leaf" => return Err(err(format!("'leaf' takes FIRST COUNT: two numbers, not {}", rest.len() - 7))),
        "children" => {
            let mut kids = Vec::new();
            let mut k = 7;
            while k < rest.len() && rest[k] != "axis" {
                kids.push(int(rest[k])?);
                k += 1;
            }
            if k < rest.len() {
                let a = rest.get(k + 1).ok_or_else(|| err("'axis' without a value".into()))?;
                let axis = a.parse::<u8>().ok().filter(|&a| a <= 2);
                node.axis = Some(axis.ok_or_else(|| {
                    quotes(format!("axis '{a}' is not 0, 1 or 2 (x, y, z)"), "an axis that is not 0, 1 or 2 (x, y, z)")
                })?);
                if let Some(extra) = rest.get(k + 2) {
                    return Err(quotes(
                        format!("'{extra}' after the axis: a node line ends with it"),
                        "words after the axis: a node line ends with it",
                    ));
                }
            }
            node.children = Some(kids);
        }
        other => {
            return Err(quotes(
                format!("'{other}': expected 'children' or 'leaf FIRST COUNT'"),
                "a word where 'children' or 'leaf FIRST COUNT' must be",
            ))
        }
    }
    Ok(node)
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

#[cfg(test)]
mod tests {
    use super::*;

    const NODE: &str = r#"{"min": [0, 0, 0], "max": [1, 1, 1], "first": 0, "count": 1}"#;

    /// A key given twice is an error naming it, at the top, in a node and in an object the dump's
    /// types skip (an unknown key's), as scene files and rubrics refuse it (a reader that kept the last value would check another tree than the
    /// student sees).
    #[test]
    fn a_key_given_twice_is_an_error_naming_it() {
        let read = |text: &str| BvhDump::from_json(text, "d.json");
        let ok = format!(r#"{{"format": "bvhscope-bvh", "version": 1, "primitives": [0], "nodes": [{NODE}]}}"#);
        assert_eq!(read(&ok).unwrap().nodes.len(), 1);
        for (text, key) in [
            (format!(r#"{{"format": "bvhscope-bvh", "version": 1, "primitives": [0], "primitives": [1], "nodes": [{NODE}]}}"#), "primitives"),
            (format!(r#"{{"format": "bvhscope-bvh", "format": "bvhscope-bvh", "version": 1, "primitives": [0], "nodes": [{NODE}]}}"#), "format"),
            (r#"{"format": "bvhscope-bvh", "version": 1, "primitives": [0], "nodes": [{"min": [0, 0, 0], "max": [1, 1, 1], "max": [2, 2, 2], "first": 0, "count": 1}]}"#.to_string(), "max"),
            (format!(r#"{{"format": "bvhscope-bvh", "version": 1, "notes": {{"by": "a", "by": "b"}}, "primitives": [0], "nodes": [{NODE}]}}"#), "by"),
        ] {
            let e = read(&text).unwrap_err();
            let said = e.to_string();
            let named = format!("d.json: not a bvhscope-bvh file: the key \"{key}\" is given twice");
            assert!(said.starts_with(&named), "{said}");
            // Without the file's words (grade's report), the key is not quoted.
            assert_eq!(e.without_content(), "d.json: not a bvhscope-bvh file: a key given twice");
        }
    }
}
