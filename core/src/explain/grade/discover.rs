//! What was handed in: one submission per path given, a dump file or a folder holding one dump,
//! named by the file (without its dump extension) or the folder. Nothing is read here but folder
//! listings: a folder that holds no dump, or several, is a submission whose row says so.

use crate::dump::BvhDump;
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
    /// The path as given.
    pub path: PathBuf,
    /// The dump to read; `None` when there is none (`problem` says why).
    pub dump: Option<PathBuf>,
    pub problem: Option<String>,
}

/// A submission per path, in the order given.
pub fn discover(paths: &[PathBuf]) -> Vec<Submission> {
    let mut out: Vec<Submission> = Vec::with_capacity(paths.len());
    for (index, path) in paths.iter().enumerate() {
        let (dump, problem) = match std::fs::metadata(path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => (None, Some("no such file or folder".to_string())),
            Err(e) => (None, Some(format!("cannot be read: {e}"))),
            Ok(m) if m.is_dir() => match dump_in(path) {
                Ok(d) => (Some(d), None),
                Err(why) => (None, Some(why)),
            },
            // A file of any name (the reader says what is wrong with it), a FIFO or a device
            // too: the reader refuses those without opening them.
            Ok(_) => (Some(path.clone()), None),
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

/// The one dump in folder `dir`: its regular files named as dumps are (`.json`, `.json.gz`,
/// `.txt`; hidden files left out); of several, the ones that look like dumps (`BvhDump::sniff`),
/// so a `notes.txt` beside `bvh.txt` is no second dump. Else why there is no one dump.
fn dump_in(dir: &Path) -> Result<PathBuf, String> {
    let entries = std::fs::read_dir(dir).map_err(|e| format!("the folder cannot be listed: {e}"))?;
    let mut named: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| {
            let hidden = p.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.'));
            !hidden && p.is_file() && BvhDump::written_as(p).is_ok()
        })
        .collect();
    named.sort();
    let list = |v: &[PathBuf]| {
        let names: Vec<String> =
            v.iter().take(5).map(|p| p.file_name().unwrap_or_default().to_string_lossy().into_owned()).collect();
        let more = if v.len() > 5 { ", …" } else { "" };
        format!("{}{more}", names.join(", "))
    };
    match named.len() {
        0 => Err(format!("the folder holds no dump (a file named {})", BvhDump::WRITTEN_AS)),
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
