//! The list of a report's files (`grade-files.txt`): every file and folder `grade` wrote, each
//! file with its size, written last into the report before it is put in place. A later `grade
//! --out` into the same folder replaces only what the list names, unchanged: a folder holding
//! anything else (a file of the user's, a file edited since, a symbolic link, a report of a
//! bvhscope that wrote no list) is refused, named, and left as it is.
//!
//! ```text
//! bvhscope-grade-files 1
//! file→1234→grade.csv
//! folder→images
//! file→5678→images/001-ana-visits.png
//! ```
//!
//! Fields are separated by tabs (→ above), paths are relative with `/`, the path last (the
//! report's names hold no tab nor newline). Nothing is removed by the list's word alone: what is
//! removed is what a walk of the folder finds, each entry checked against the list.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The list's name in the report folder.
pub const MANIFEST_FILE: &str = "grade-files.txt";
/// Its first line: what it is, and the version of its layout.
const FIRST_LINE: &str = "bvhscope-grade-files 1";
/// The largest list read: a class of a thousand lists about 100 kB.
const MAX_BYTES: u64 = 16 << 20;
/// The report's own names (`report.rs`'s, which imports this file): a folder holding one of
/// them but no list is an older report, or someone's own files named alike.
const REPORT_NAMES: [&str; 4] = ["grade.csv", "grade.json", "grade.html", "images"];

/// An entry found in a folder, links not followed.
struct Entry {
    /// Relative to the folder, with `/` (for the list and for messages).
    rel: String,
    path: PathBuf,
    kind: Kind,
}

#[derive(PartialEq)]
enum Kind {
    File(u64),
    Folder,
    /// A symbolic link (never the report's: it writes none).
    Link,
    /// Anything else: a FIFO, a socket, a device.
    Other,
}

/// Every entry below `root`, depth first in name order (a folder before what it holds), links
/// not followed.
fn walk(root: &Path) -> std::io::Result<Vec<Entry>> {
    let mut out = Vec::new();
    walk_into(root, "", &mut out)?;
    Ok(out)
}

fn walk_into(dir: &Path, prefix: &str, out: &mut Vec<Entry>) -> std::io::Result<()> {
    let mut list: Vec<std::fs::DirEntry> = std::fs::read_dir(dir)?.collect::<Result<_, _>>()?;
    list.sort_by_key(|e| e.file_name());
    for e in list {
        let rel = format!("{prefix}{}", e.file_name().to_string_lossy());
        let t = e.file_type()?;
        let kind = if t.is_symlink() {
            Kind::Link
        } else if t.is_dir() {
            Kind::Folder
        } else if t.is_file() {
            Kind::File(e.metadata()?.len())
        } else {
            Kind::Other
        };
        let folder = kind == Kind::Folder;
        out.push(Entry { rel: rel.clone(), path: e.path(), kind });
        if folder {
            walk_into(&e.path(), &format!("{rel}/"), out)?;
        }
    }
    Ok(())
}

/// Write the list of everything in `work` (the report just written, all of it ours) into it.
pub fn write(work: &Path) -> Result<(), crate::files::FileError> {
    let read = |source| crate::files::FileError::Read { path: work.into(), source };
    let mut text = format!("{FIRST_LINE}\n");
    for e in walk(work).map_err(read)? {
        match e.kind {
            Kind::File(bytes) => text += &format!("file\t{bytes}\t{}\n", e.rel),
            Kind::Folder => text += &format!("folder\t{}\n", e.rel),
            // The report writes neither; were one there, it would be left out, hence not ours.
            Kind::Link | Kind::Other => {}
        }
    }
    crate::files::write_bytes(&work.join(MANIFEST_FILE), text.as_bytes())
}

/// What a list says: each file's size (`None` for a folder), by relative path.
fn read_list(root: &Path) -> Result<Option<HashMap<String, Option<u64>>>, String> {
    let path = root.join(MANIFEST_FILE);
    match std::fs::symlink_metadata(&path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("holds {MANIFEST_FILE}, which cannot be read: {e}")),
        Ok(m) if !m.is_file() => return Err(not_list()),
        Ok(_) => {}
    }
    let (file, _) = crate::files::open_regular(&path).map_err(|e| format!("holds {MANIFEST_FILE}: {e}"))?;
    let bytes = crate::files::read_limited(file, MAX_BYTES)
        .map_err(|e| format!("holds {MANIFEST_FILE}, which cannot be read: {e}"))?
        .ok_or_else(not_list)?;
    let text = String::from_utf8(bytes).map_err(|_| not_list())?;
    let mut lines = text.lines();
    if lines.next() != Some(FIRST_LINE) {
        return Err(not_list());
    }
    let mut listed = HashMap::new();
    for line in lines {
        let mut f = line.splitn(3, '\t');
        match (f.next(), f.next(), f.next()) {
            (Some("file"), Some(bytes), Some(rel)) => {
                listed.insert(rel.to_string(), Some(bytes.parse::<u64>().map_err(|_| not_list())?));
            }
            (Some("folder"), Some(rel), None) => {
                listed.insert(rel.to_string(), None);
            }
            _ => return Err(not_list()),
        }
    }
    Ok(Some(listed))
}

fn not_list() -> String {
    format!("holds {MANIFEST_FILE}, which is not a list of a grade report's files: {REFUSED}")
}

/// What a refusal tells the user to do.
const REFUSED: &str =
    "a report replaces only the files it wrote; move what is yours, or write the report to another folder (--out)";

/// Whether the folder `root` holds only what a report listed (or nothing): every entry below it
/// the list itself or a listed file of the listed size, or a listed folder. `Ok`: what to remove
/// to empty it, deepest first, each with whether it is a folder; `Err`: the first entry that is
/// not the report's, in words.
pub fn ours(root: &Path) -> Result<Vec<(PathBuf, bool)>, String> {
    let entries = walk(root).map_err(|e| format!("cannot be read: {e}"))?;
    if entries.is_empty() {
        return Ok(Vec::new());
    }
    let Some(listed) = read_list(root)? else {
        let older = entries.iter().find(|e| REPORT_NAMES.contains(&e.rel.as_str()));
        return Err(match older {
            Some(e) => format!(
                "holds {} but no {MANIFEST_FILE}: it is not a report this bvhscope wrote (an older bvhscope's report did not list its files: remove that one by hand); {REFUSED}",
                e.rel
            ),
            None => format!("holds {}, which is not part of a grade report: {REFUSED}", entries[0].rel),
        });
    };
    // A folder not listed is named only when nothing in it is: "images/thesis/chapter1.tex"
    // says more than "images/thesis".
    let mut folder = None;
    for e in &entries {
        let why = match (&e.kind, listed.get(&e.rel)) {
            (Kind::File(_), _) if e.rel == MANIFEST_FILE => continue,
            (Kind::Link, _) => ", a symbolic link,",
            (Kind::File(now), Some(Some(then))) if now == then => continue,
            (Kind::File(now), Some(Some(then))) => {
                return Err(format!(
                    "holds {}, changed since the grade report there wrote it ({then} bytes then, {now} now): {REFUSED}",
                    e.rel
                ))
            }
            (Kind::Folder, Some(None)) => continue,
            _ => "",
        };
        let message = format!("holds {}{why}, which the grade report written there did not write: {REFUSED}", e.rel);
        if e.kind != Kind::Folder {
            return Err(message);
        }
        folder.get_or_insert(message);
    }
    if let Some(message) = folder {
        return Err(message);
    }
    Ok(entries.into_iter().rev().map(|e| (e.path, e.kind == Kind::Folder)).collect())
}

/// Remove the report in `root` and `root` itself, only when it holds nothing but what its list
/// names (`ours`): each file by name, each folder only once empty, so nothing else is removed
/// even if it appears meanwhile. `Err`: what was left, in words.
pub fn remove(root: &Path) -> Result<(), String> {
    for (path, folder) in ours(root)? {
        let gone = if folder { std::fs::remove_dir(&path) } else { std::fs::remove_file(&path) };
        gone.map_err(|e| format!("{}: cannot be removed: {e}", path.display()))?;
    }
    std::fs::remove_dir(root).map_err(|e| format!("{}: cannot be removed: {e}", root.display()))
}
