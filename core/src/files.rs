//! Files the user names, read and written safely, for every reader and writer of the project:
//!
//! - only regular files are read: a FIFO would block until another program writes, a device
//!   (`/dev/zero`, `/dev/urandom`) would be read forever;
//! - what is read can be bounded while it streams in (`read_limited`), so a gzip bomb stops at
//!   the bound instead of filling memory;
//! - an output is written to a temporary file beside it and renamed over it only when complete
//!   (`write_atomically`): a full disk or an error leaves the old file as it was, never a
//!   truncated one;
//! - an output that is one of the inputs is refused before anything is written (`refuse_inputs`):
//!   `export-bvh m.obj -o m.obj` must not replace the mesh;
//! - a file named by a user's file (a glTF's buffer) is read only from that file's folder or below
//!   (`beside`), and no more of it than the naming file declares (`read_declared`);
//! - one set of limits (`limits`) that every reader counts against;
//! - a folder a command writes whole (`ReportDir`, of a `FolderKind`: grade's report, a lesson's
//!   handout) is written beside it and renamed into place, replacing only the files its list says
//!   an earlier run wrote (`manifest`).

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

mod beside;
pub mod limits;
mod manifest;
mod report_dir;
pub use beside::{beside, Refused};
pub use report_dir::{FolderError, FolderKind, ReportDir};

/// Why a file the user named cannot be read or written.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    #[error("{}: no such file", .path.display())]
    NotFound { path: PathBuf },
    #[error("{}: is a directory, not a file", .path.display())]
    IsDirectory { path: PathBuf },
    #[error("{}: is {what}, not a regular file", .path.display())]
    NotRegular { path: PathBuf, what: &'static str },
    #[error("{}: cannot read: {source}", .path.display())]
    Read { path: PathBuf, source: std::io::Error },
    #[error("{}: cannot write: {source}", .path.display())]
    Write { path: PathBuf, source: std::io::Error },
    #[error("{}: is also {what} of this command: refusing to overwrite it (name another output file)", .path.display())]
    OutputIsInput { path: PathBuf, what: String },
    #[error("{}: {what} is written here, and its name must end in {}", .path.display(), extensions_text(.extensions))]
    WrongName { path: PathBuf, what: &'static str, extensions: &'static [&'static str] },
    #[error("{}: holds {len} bytes, fewer than the {declared} declared for it", .path.display())]
    Short { path: PathBuf, len: u64, declared: u64 },
    #[error("{}: is read-only: refusing to replace it (as a shell's > would; make it writable, or name another file)", .path.display())]
    ReadOnly { path: PathBuf },
}

fn extensions_text(e: &[&str]) -> String {
    let dotted: Vec<String> = e.iter().map(|e| format!(".{e}")).collect();
    match dotted.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => dotted.join(""),
    }
}

/// What an output holds, and the names that say so: a file is what its name says.
#[derive(Clone, Copy, Debug)]
pub struct OutputKind {
    pub what: &'static str,
    pub extensions: &'static [&'static str],
}

pub const PNG: OutputKind = OutputKind { what: "a PNG image", extensions: &["png"] };
pub const CSV: OutputKind = OutputKind { what: "CSV", extensions: &["csv"] };
pub const JSON: OutputKind = OutputKind { what: "JSON", extensions: &["json"] };

impl OutputKind {
    /// `Ok` when `path`'s name ends in one of the kind's extensions (any case); checked before
    /// anything is computed or opened.
    pub fn check(&self, path: &Path) -> Result<(), FileError> {
        let name = path.file_name().map(|n| n.to_string_lossy().to_lowercase()).unwrap_or_default();
        if self.extensions.iter().any(|e| name.ends_with(&format!(".{e}"))) {
            Ok(())
        } else {
            Err(FileError::WrongName { path: path.into(), what: self.what, extensions: self.extensions })
        }
    }
}

/// A path's file name as messages and titles show it (the whole path where it has none).
pub fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into_owned())
}

/// An image written as PNG to `path` (named `.png`: `PNG.check`), atomically.
pub fn write_png(path: &Path, img: &image::RgbImage) -> Result<(), FileError> {
    PNG.check(path)?;
    let mut bytes = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png)
        .map_err(|e| FileError::Write { path: path.into(), source: std::io::Error::other(e.to_string()) })?;
    write_bytes(path, &bytes)
}

/// What a file that is neither a regular file nor a directory is, in words.
fn special_file_kind(kind: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if kind.is_char_device() {
            return "a character device";
        }
        if kind.is_block_device() {
            return "a block device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    let _ = kind;
    "a special file"
}

/// The metadata of `path` when it is a regular file the user may read.
pub fn regular(path: &Path) -> Result<std::fs::Metadata, FileError> {
    let metadata = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => FileError::NotFound { path: path.into() },
        _ => FileError::Read { path: path.into(), source: e },
    })?;
    let kind = metadata.file_type();
    if kind.is_dir() {
        return Err(FileError::IsDirectory { path: path.into() });
    }
    if !kind.is_file() {
        return Err(FileError::NotRegular { path: path.into(), what: special_file_kind(&kind) });
    }
    Ok(metadata)
}

/// `path` opened for reading, when it is a regular file (checked before opening: opening a FIFO
/// blocks).
pub fn open_regular(path: &Path) -> Result<(std::fs::File, u64), FileError> {
    let len = regular(path)?.len();
    let file = std::fs::File::open(path).map_err(|source| FileError::Read { path: path.into(), source })?;
    Ok((file, len))
}

/// Everything `reader` gives, or `Ok(None)` as soon as it has given more than `limit` bytes
/// (nothing past `limit + 1` bytes is read or kept).
pub fn read_limited(reader: impl Read, limit: u64) -> std::io::Result<Option<Vec<u8>>> {
    let mut out = Vec::new();
    reader.take(limit.saturating_add(1)).read_to_end(&mut out)?;
    Ok((out.len() as u64 <= limit).then_some(out))
}

/// The first `declared` bytes of the regular file `path`: a file shorter than that is an error,
/// and nothing past `declared` is read, however large the file is.
pub fn read_declared(path: &Path, declared: u64) -> Result<Vec<u8>, FileError> {
    let (file, len) = open_regular(path)?;
    if len < declared {
        return Err(FileError::Short { path: path.into(), len, declared });
    }
    let mut out = Vec::with_capacity(declared as usize);
    file.take(declared).read_to_end(&mut out).map_err(|source| FileError::Read { path: path.into(), source })?;
    if (out.len() as u64) < declared {
        return Err(FileError::Short { path: path.into(), len: out.len() as u64, declared });
    }
    Ok(out)
}

/// Write `path` through `write` into a temporary file in the same folder, renamed over `path`
/// once everything is written and flushed: readers of `path` see the old file or the new one,
/// never a part. On any error the temporary file is removed and `path` is untouched.
pub fn write_atomically<E>(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<&mut std::fs::File>) -> Result<(), E>,
) -> Result<(), E>
where
    E: From<FileError>,
{
    let err = |source| E::from(FileError::Write { path: path.into(), source });
    // A file there that may not be written is refused, as a shell's `>` refuses it: the rename
    // below would replace it whatever its mode. Read-only (no write bit for anyone) is refused
    // even for root, who may write anything: someone marked it so. Otherwise opening it for
    // writing, without truncating, asks the system, and changes nothing.
    if let Some(m) = std::fs::metadata(path).ok().filter(|m| m.is_file()) {
        let denied = || {
            std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .is_err_and(|e| e.kind() == std::io::ErrorKind::PermissionDenied)
        };
        if m.permissions().readonly() || denied() {
            return Err(E::from(FileError::ReadOnly { path: path.into() }));
        }
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path.file_name().map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    let mut builder = tempfile::Builder::new();
    let prefix = format!(".{name}.");
    builder.prefix(&prefix).suffix(".tmp");
    // Made as any new file is (0666 less the umask), not tempfile's private 0600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut tmp = builder.tempfile_in(dir).map_err(err)?;
    {
        let mut w = std::io::BufWriter::new(tmp.as_file_mut());
        write(&mut w)?;
        w.flush().map_err(err)?;
    }
    tmp.as_file().sync_all().map_err(err)?;
    // A file written over keeps its permissions.
    if let Ok(m) = std::fs::metadata(path) {
        let _ = std::fs::set_permissions(tmp.path(), m.permissions());
    }
    tmp.persist(path).map_err(|e| err(e.error))?;
    Ok(())
}

/// `bytes` written to `path` atomically (`write_atomically`).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    write_atomically(path, |w| w.write_all(bytes).map_err(|source| FileError::Write { path: path.into(), source }))
}

/// Refuse to write `output` when it is the same file as one of `inputs` (by the file itself, so
/// `./m.obj`, a symbolic link to it and a hard link all count), each input named with what it is
/// ("the mesh", "the BVH dump"). Outputs that do not exist yet are no input.
pub fn refuse_inputs(output: &Path, inputs: &[(&Path, &str)]) -> Result<(), FileError> {
    if !output.exists() {
        return Ok(());
    }
    for (input, what) in inputs {
        if same_file::is_same_file(output, input).unwrap_or(false) {
            return Err(FileError::OutputIsInput { path: output.into(), what: what.to_string() });
        }
    }
    Ok(())
}

/// Where `path` will be written: its folder made canonical (links and `.`/`..` resolved) and its
/// name, so `same.csv` and `./same.csv`, or `d/x.png` and `d/../d/x.png`, are one place though
/// the file does not exist yet. `None` when the folder does not exist (nothing can be written).
fn target(path: &Path) -> Option<PathBuf> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Some(std::fs::canonicalize(dir).ok()?.join(path.file_name()?))
}

/// Refuse two outputs of one command that are the same file: the same name, the same place by
/// its canonical folder and name (`target`), or the same existing file.
pub fn refuse_same_outputs(outputs: &[(&Path, &str)]) -> Result<(), FileError> {
    for (i, (a, what_a)) in outputs.iter().enumerate() {
        for (b, what_b) in &outputs[i + 1..] {
            let same = a == b
                || target(a).is_some_and(|t| Some(t) == target(b))
                || same_file::is_same_file(a, b).unwrap_or(false);
            if same {
                return Err(FileError::OutputIsInput { path: a.into(), what: format!("{what_b} (and {what_a})") });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir() -> PathBuf {
        crate::scratch::shared("files")
    }

    #[test]
    fn an_atomic_write_leaves_the_old_file_when_it_fails_and_replaces_it_when_done() {
        let p = dir().join("out.txt");
        std::fs::write(&p, "old").unwrap();
        let failed: Result<(), FileError> = write_atomically(&p, |w| {
            w.write_all(b"half of the new").unwrap();
            Err(FileError::Write { path: p.clone(), source: std::io::Error::other("disk full") })
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "old");
        write_bytes(&p, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "new");
        let left: Vec<_> = std::fs::read_dir(dir())
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(left.is_empty(), "no temporary file is left behind");
    }

    #[test]
    fn an_output_that_is_an_input_is_refused_by_the_file_not_the_name() {
        let d = dir();
        let mesh = d.join("m.obj");
        std::fs::write(&mesh, "v 0 0 0").unwrap();
        let other = d.join("fresh.json");
        assert!(refuse_inputs(&other, &[(&mesh, "the mesh")]).is_ok());
        let dotted = d.join(".").join("m.obj");
        let e = refuse_inputs(&dotted, &[(&mesh, "the mesh")]).unwrap_err().to_string();
        assert!(e.contains("the mesh") && e.contains("refusing"), "{e}");
        #[cfg(unix)]
        {
            let link = d.join("link.obj");
            let _ = std::fs::remove_file(&link);
            std::os::unix::fs::symlink(&mesh, &link).unwrap();
            assert!(refuse_inputs(&link, &[(&mesh, "the mesh")]).is_err());
        }
        assert!(refuse_same_outputs(&[(&other, "the image"), (&other, "the counts")]).is_err());
    }

    #[test]
    fn an_output_is_named_for_what_it_holds() {
        assert!(PNG.check(Path::new("a/b.PNG")).is_ok());
        let e = PNG.check(Path::new("old.jpg")).unwrap_err().to_string();
        assert_eq!(e, "old.jpg: a PNG image is written here, and its name must end in .png");
        let both = OutputKind { what: "x", extensions: &["json", "json.gz", "txt"] };
        assert!(both.check(Path::new("t.json.gz")).is_ok());
        assert!(both.check(Path::new("t.gz")).unwrap_err().to_string().ends_with(".json, .json.gz or .txt"));
        // A refused name leaves the file that was there.
        let p = dir().join("old.jpg");
        std::fs::write(&p, "jpeg bytes").unwrap();
        assert!(write_png(&p, &image::RgbImage::new(2, 2)).is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"jpeg bytes");
    }

    #[test]
    fn reads_stop_at_their_limit_and_special_files_are_refused() {
        assert_eq!(read_limited(&b"12345"[..], 5).unwrap(), Some(b"12345".to_vec()));
        assert_eq!(read_limited(std::io::repeat(0), 1000).unwrap(), None);
        #[cfg(unix)]
        {
            let e = open_regular(Path::new("/dev/zero")).unwrap_err().to_string();
            assert!(e.contains("character device"), "{e}");
        }
        assert!(open_regular(&dir()).unwrap_err().to_string().contains("directory"));
    }

    #[test]
    fn a_declared_read_takes_no_more_than_declared_and_refuses_less() {
        let p = dir().join("declared.bin");
        std::fs::write(&p, b"0123456789").unwrap();
        assert_eq!(read_declared(&p, 4).unwrap(), b"0123");
        let e = read_declared(&p, 11).unwrap_err().to_string();
        assert!(e.ends_with("holds 10 bytes, fewer than the 11 declared for it"), "{e}");
    }
}
