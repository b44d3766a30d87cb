//! The list of a report folder's files (`grade-files.txt`, `handout-files.txt`: the kind's
//! `FolderKind::list`): every file and folder the command wrote, each file with its size, written
//! last into the folder before it is put in place. A later run into the same folder replaces only
//! what the list names, unchanged: a folder holding anything else (a file of the user's, a file
//! edited since, a symbolic link, a report of a bvhscope that wrote no list) is refused, named,
//! and left as it is.
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

use super::FolderKind;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The largest list read: a class of a thousand lists about 100 kB.
const MAX_BYTES: u64 = 16 << 20;

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

/// Write the list of everything in `work` (the folder just written, all of it ours) into it.
pub(super) fn write(work: &Path, kind: &FolderKind) -> Result<(), super::FileError> {
    let read = |source| super::FileError::Read { path: work.into(), source };
    let mut text = format!("{}\n", kind.first_line);
    for e in walk(work).map_err(read)? {
        match e.kind {
            Kind::File(bytes) => text += &format!("file\t{bytes}\t{}\n", e.rel),
            Kind::Folder => text += &format!("folder\t{}\n", e.rel),
            // The report writes neither; were one there, it would be left out, hence not ours.
            Kind::Link | Kind::Other => {}
        }
    }
    super::write_bytes(&work.join(kind.list), text.as_bytes())
}

/// What a list says: each file's size (`None` for a folder), by relative path.
fn read_list(root: &Path, kind: &FolderKind) -> Result<Option<HashMap<String, Option<u64>>>, String> {
    let list = kind.list;
    let path = root.join(list);
    match std::fs::symlink_metadata(&path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("holds {list}, which cannot be read: {e}")),
        Ok(m) if !m.is_file() => return Err(not_list(kind)),
        Ok(_) => {}
    }
    let (file, _) = super::open_regular(&path).map_err(|e| format!("holds {list}: {e}"))?;
    let bytes = super::read_limited(file, MAX_BYTES)
        .map_err(|e| format!("holds {list}, which cannot be read: {e}"))?
        .ok_or_else(|| not_list(kind))?;
    let text = String::from_utf8(bytes).map_err(|_| not_list(kind))?;
    let mut lines = text.lines();
    if lines.next() != Some(kind.first_line) {
        return Err(not_list(kind));
    }
    let mut listed = HashMap::new();
    for line in lines {
        let mut f = line.splitn(3, '\t');
        match (f.next(), f.next(), f.next()) {
            (Some("file"), Some(bytes), Some(rel)) => {
                listed.insert(rel.to_string(), Some(bytes.parse::<u64>().map_err(|_| not_list(kind))?));
            }
            (Some("folder"), Some(rel), None) => {
                listed.insert(rel.to_string(), None);
            }
            _ => return Err(not_list(kind)),
        }
    }
    Ok(Some(listed))
}

fn not_list(kind: &FolderKind) -> String {
    format!("holds {}, which is not a list of a {}'s files: {}", kind.list, kind.what, refused(kind))
}

/// What a refusal tells the user to do.
fn refused(kind: &FolderKind) -> String {
    let noun = kind.noun();
    format!(
        "a {noun} replaces only the files it wrote; move what is yours, or write the {noun} to another folder ({})",
        kind.flag
    )
}

/// Whether the folder `root` holds only what a report listed (or nothing): every entry below it
/// the list itself or a listed file of the listed size, or a listed folder. `Ok`: what to remove
/// to empty it, deepest first, each with whether it is a folder; `Err`: the first entry that is
/// not the report's, in words.
pub(super) fn ours(root: &Path, kind: &FolderKind) -> Result<Vec<(PathBuf, bool)>, String> {
    let entries = walk(root).map_err(|e| format!("cannot be read: {e}"))?;
    if entries.is_empty() {
        return Ok(Vec::new());
    }
    let (what, list, noun) = (kind.what, kind.list, kind.noun());
    let Some(listed) = read_list(root, kind)? else {
        // A folder holding one of the kind's own names but no list is an older report, or
        // someone's own files named alike.
        let older = entries.iter().find(|e| kind.names.contains(&e.rel.as_str()));
        return Err(match older {
            Some(e) => format!(
                "holds {} but no {list}: it is not a {noun} this bvhscope wrote (someone's own file named alike, or an older bvhscope's {noun}, which listed none: move it or remove it by hand); {}",
                e.rel,
                refused(kind)
            ),
            None => format!("holds {}, which is not part of a {what}: {}", entries[0].rel, refused(kind)),
        });
    };
    // A folder not listed is named only when nothing in it is: "images/thesis/chapter1.tex"
    // says more than "images/thesis".
    let mut folder = None;
    for e in &entries {
        let why = match (&e.kind, listed.get(&e.rel)) {
            (Kind::File(_), _) if e.rel == list => continue,
            (Kind::Link, _) => ", a symbolic link,",
            (Kind::File(now), Some(Some(then))) if now == then => continue,
            (Kind::File(now), Some(Some(then))) => {
                return Err(format!(
                    "holds {}, changed since the {what} there wrote it ({then} bytes then, {now} now): {}",
                    e.rel,
                    refused(kind)
                ))
            }
            (Kind::Folder, Some(None)) => continue,
            _ => "",
        };
        let message = format!("holds {}{why}, which the {what} written there did not write: {}", e.rel, refused(kind));
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
pub(super) fn remove(root: &Path, kind: &FolderKind) -> Result<(), String> {
    for (path, folder) in ours(root, kind)? {
        let gone = if folder { std::fs::remove_dir(&path) } else { std::fs::remove_file(&path) };
        gone.map_err(|e| format!("{}: cannot be removed: {e}", path.display()))?;
    }
    std::fs::remove_dir(root).map_err(|e| format!("{}: cannot be removed: {e}", root.display()))
}
