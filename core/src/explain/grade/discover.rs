//! What was handed in: one submission per path given, a dump file or a folder holding one dump,
//! named by the file (without its dump extension) or the folder. A single folder given that
//! holds student folders or several dumps is a class (the folder a learning platform hands out):
//! each of its entries is a submission. Nothing is read here but folder listings and the first
//! bytes of candidate files (`BvhDump::sniff`): a folder that holds no dump, or several, is a
//! submission whose row says so.
//!
//! A submission is read only from inside itself: a submission that is a symbolic link, or a link
//! in a student's folder that leads out of it, is refused with a row that says so, never
//! followed, its target never named (a student's archive can carry a link to the teacher's
//! solution, which would otherwise be graded as theirs, or to any file, whose first line would
//! reach the report as an error message).

use crate::dump::{BvhDump, DumpFile};
use std::path::{Path, PathBuf};

/// One student's submission.
#[derive(Clone, Debug, PartialEq)]
pub struct Submission {
    /// Its place among the paths given.
    pub index: usize,
    /// The student, by the file or folder (made unique within the class: `alice (2)`).
    pub name: String,
    /// A file name for its images: the index (unique) and the name in safe characters.
    pub slug: String,
    /// The path as given (or found in the class folder).
    pub path: PathBuf,
    /// The dump to read; `None` when there is none (`problem` says why).
    pub dump: Option<PathBuf>,
    pub problem: Option<String>,
}

/// Why a link is not followed, in the row of its submission.
const LINK: &str = "a submission is read only from inside itself, and links are never followed";

/// A submission per path, in the order given; a single class folder given (`is_class`) is the
/// list of its entries, in name order.
pub fn discover(paths: &[PathBuf]) -> Vec<Submission> {
    let expanded;
    let paths = match paths {
        [one] if is_class(one) => {
            expanded = class_entries(one);
            &expanded[..]
        }
        _ => paths,
    };
    let mut out: Vec<Submission> = Vec::with_capacity(paths.len());
    for (index, path) in paths.iter().enumerate() {
        let (dump, problem) = match (std::fs::symlink_metadata(path), std::fs::metadata(path)) {
            (Err(e), _) if e.kind() == std::io::ErrorKind::NotFound => {
                (None, Some("no such file or folder".to_string()))
            }
            (Err(e), _) => (None, Some(format!("cannot be read: {e}"))),
            // A link, whatever it leads to (a file, a folder, nothing).
            (Ok(m), _) if m.file_type().is_symlink() => (None, Some(format!("is a symbolic link: {LINK}"))),
            (Ok(_), Ok(m)) if m.is_dir() => match dump_in(path) {
                Ok(d) => (Some(d), None),
                Err(why) => (None, Some(why)),
            },
            // A file of any name (the reader says what is wrong with it), a FIFO or a device
            // too: the reader refuses those without opening them.
            (Ok(_), _) => (Some(path.clone()), None),
        };
        let base = student_name(path);
        let taken = |n: &str| out.iter().any(|s| s.name == n);
        let mut name = base.clone();
        let mut k = 2;
        while taken(&name) {
            name = format!("{base} ({k})");
            k += 1;
        }
        let slug = format!("{:03}-{}", index + 1, safe(&name));
        out.push(Submission { index, name, slug, path: path.clone(), dump, problem });
    }
    out
}

/// The visible entries of `dir` (hidden ones left out), sorted; none when it cannot be listed.
fn entries(dir: &Path) -> Vec<PathBuf> {
    let Ok(list) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut v: Vec<PathBuf> = list
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.file_name().is_some_and(|n| !n.to_string_lossy().starts_with('.')))
        .collect();
    v.sort();
    v
}

/// Whether `path` is a file that may be a dump: named as one (`.json`, `.json.gz`, `.txt`), and,
/// for a `.txt` (the name of notes and READMEs too), starting like one.
fn candidate(path: &Path) -> bool {
    match BvhDump::written_as(path) {
        Ok(DumpFile::Text) => BvhDump::sniff(path),
        Ok(DumpFile::Json | DumpFile::JsonGz) => true,
        Err(_) => false,
    }
}

/// Whether the folder `path` (the one path given) is a class rather than one student's folder:
/// it holds a folder, or more than one file that may be a dump (two names of one file are one).
fn is_class(path: &Path) -> bool {
    if !path.is_dir() {
        return false;
    }
    let list = entries(path);
    let folders = list.iter().any(|p| p.is_dir());
    let dumps: Vec<PathBuf> = list.into_iter().filter(|p| p.is_file() && candidate(p)).collect();
    folders || distinct(dumps).len() > 1
}

/// A class folder's submissions: each folder, link and file named as a dump in it.
fn class_entries(dir: &Path) -> Vec<PathBuf> {
    entries(dir)
        .into_iter()
        .filter(|p| {
            let link = std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_symlink());
            link || p.is_dir() || BvhDump::written_as(p).is_ok()
        })
        .collect()
}

/// The student a path stands for: a folder's name, or a file's without its dump extension.
fn student_name(path: &Path) -> String {
    // `.` and `..` have no file name: the folder they are.
    let absolute = || std::fs::canonicalize(path).ok();
    let file = path.file_name().map(|n| n.to_string_lossy().into_owned());
    let file = file.or_else(|| absolute()?.file_name().map(|n| n.to_string_lossy().into_owned()));
    let Some(file) = file else { return path.display().to_string() };
    if path.is_dir() {
        return file;
    }
    let lower = file.to_lowercase();
    for ext in [".json.gz", ".json", ".txt", ".gz"] {
        if lower.ends_with(ext) && lower.len() > ext.len() {
            return file[..file.len() - ext.len()].to_string();
        }
    }
    file
}

/// `name` in characters safe in any file system and URL: lowercase letters, digits, `-`, `_`.
fn safe(name: &str) -> String {
    let mut s = String::new();
    for c in name.chars().flat_map(char::to_lowercase) {
        let c = if c.is_ascii_alphanumeric() || c == '_' { c } else { '-' };
        if !(c == '-' && (s.is_empty() || s.ends_with('-'))) {
            s.push(c);
        }
        if s.len() >= 40 {
            break;
        }
    }
    let s = s.trim_end_matches('-').to_string();
    if s.is_empty() {
        "student".into()
    } else {
        s
    }
}

/// The one dump in folder `dir`: its regular files that may be dumps (`candidate`; hidden files
/// left out); of several, the ones that start like dumps (`BvhDump::sniff`), so a `notes.json`
/// beside `bvh.json` is no second dump. A link is followed only when it stays inside `dir`; two
/// names of one file (a link to the dump beside it, a hard link) are one dump. Else why there is
/// no one dump.
fn dump_in(dir: &Path) -> Result<PathBuf, String> {
    std::fs::read_dir(dir).map_err(|e| format!("the folder cannot be listed: {e}"))?;
    let inside = std::fs::canonicalize(dir).map_err(|e| format!("the folder cannot be listed: {e}"))?;
    // With whether each is reached through a link.
    let mut named: Vec<(PathBuf, bool)> = Vec::new();
    let mut links_out: Vec<PathBuf> = Vec::new();
    let mut not_dumps: Vec<PathBuf> = Vec::new();
    for p in entries(dir) {
        if BvhDump::written_as(&p).is_err() {
            continue;
        }
        let link = std::fs::symlink_metadata(&p).is_ok_and(|m| m.file_type().is_symlink());
        let target = if link {
            match std::fs::canonicalize(&p) {
                Ok(t) if t.starts_with(&inside) && t.is_file() => t,
                _ => {
                    links_out.push(p);
                    continue;
                }
            }
        } else {
            p.clone()
        };
        if !target.is_file() {
            continue;
        }
        if candidate(&target) {
            named.push((target, link));
        } else {
            not_dumps.push(p);
        }
    }
    // Two names of one file (a link to the dump beside it, a hard link) are one dump, by the
    // file's own name rather than a link's.
    named.sort_by_key(|(_, link)| *link);
    let mut named = distinct(named.into_iter().map(|(p, _)| p).collect());
    let list = |v: &[PathBuf]| {
        let names: Vec<String> =
            v.iter().take(5).map(|p| p.file_name().unwrap_or_default().to_string_lossy().into_owned()).collect();
        let more = if v.len() > 5 { ", …" } else { "" };
        format!("{}{more}", names.join(", "))
    };
    match named.len() {
        0 => {
            let mut why = format!("the folder holds no dump (a file named {})", BvhDump::WRITTEN_AS);
            if !links_out.is_empty() {
                why += &format!("; {} a symbolic link out of the folder: {LINK}", is_are(&links_out, &list));
            }
            if !not_dumps.is_empty() {
                why += &format!("; {} not start as a dump", does_do(&not_dumps, &list));
            }
            Err(why)
        }
        1 => Ok(named.remove(0)),
        n => {
            let dumps: Vec<PathBuf> = named.iter().filter(|p| BvhDump::sniff(p)).cloned().collect();
            if dumps.len() == 1 {
                return Ok(dumps[0].clone());
            }
            let (count, shown) = if dumps.is_empty() { (n, list(&named)) } else { (dumps.len(), list(&dumps)) };
            Err(format!("the folder holds {count} dumps ({shown}): a submission is one dump"))
        }
    }
}

/// `paths` less those that name a file named before them (`same_file`: links and hard links).
fn distinct(paths: Vec<PathBuf>) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = Vec::with_capacity(paths.len());
    for p in paths {
        if !out.iter().any(|q| same_file::is_same_file(q, &p).unwrap_or(false)) {
            out.push(p);
        }
    }
    out
}

/// "a.json is" / "a.json, b.json are".
fn is_are(v: &[PathBuf], list: &dyn Fn(&[PathBuf]) -> String) -> String {
    format!("{} {}", list(v), if v.len() == 1 { "is" } else { "are each" })
}

/// "notes.txt does" / "a.txt, b.txt do".
fn does_do(v: &[PathBuf], list: &dyn Fn(&[PathBuf]) -> String) -> String {
    format!("{} {}", list(v), if v.len() == 1 { "does" } else { "do" })
}
