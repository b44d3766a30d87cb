//! Files a user's file names (a glTF's buffers): read only from the file's own folder or below,
//! after links are resolved. A reference is a relative URI: no scheme (`file:`, `http:`), no
//! absolute path, nothing that climbs out (`../`), no link that leads out, and what it names must
//! be a regular file (no device, no FIFO, nothing under `/proc` since that is out of the folder).
//! So a crafted file cannot turn `/etc/passwd` or `/proc/self/environ` into triangles, boxes in a
//! dump or numbers in an error message.

use std::path::{Component, Path, PathBuf};

/// Why a reference is refused, in words that follow the reference itself (`'../x.bin' climbs
/// out of …`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("'{reference}' {why}")]
pub struct Refused {
    pub reference: String,
    pub why: String,
}

/// The file that `reference` (a relative URI, percent-encoded) names beside `file`, when it lies
/// at or below `file`'s folder once links are resolved and is a regular file.
pub fn beside(file: &Path, reference: &str) -> Result<PathBuf, Refused> {
    let refuse = |why: String| Refused { reference: reference.to_string(), why };
    let decoded = percent_encoding::percent_decode_str(reference)
        .decode_utf8()
        .map_err(|_| refuse("is not UTF-8 once its %-escapes are decoded".into()))?;
    let scheme = decoded
        .split_once(':')
        .map(|(s, _)| s)
        .filter(|s| s.len() > 1 && s.chars().all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c)));
    if let Some(s) = scheme {
        return Err(refuse(format!("is a '{s}:' URI; only files beside this one (or data: URIs) are read")));
    }
    if decoded.contains('\0') {
        return Err(refuse("holds a NUL character".into()));
    }
    let relative = Path::new(&*decoded);
    let outside = "lies outside this file's folder: only files in it or below it are read";
    if relative.has_root() || relative.components().any(|c| matches!(c, Component::Prefix(_))) {
        return Err(refuse(format!("is an absolute path; it {outside}")));
    }
    if relative.components().any(|c| c == Component::ParentDir) {
        return Err(refuse(format!("climbs out with '..'; it {outside}")));
    }
    let folder = match file.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let target = folder.join(relative);
    let (Ok(root), resolved) = (std::fs::canonicalize(folder), std::fs::canonicalize(&target)) else {
        return Err(refuse("cannot be looked up: this file's folder cannot be read".into()));
    };
    let resolved = match resolved {
        Ok(r) => r,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(refuse("names no file".into())),
        Err(e) => return Err(refuse(format!("cannot be looked up: {e}"))),
    };
    if !resolved.starts_with(&root) {
        return Err(refuse(format!("is a link to {}; it {outside}", resolved.display())));
    }
    match std::fs::metadata(&resolved) {
        Ok(m) if m.is_file() => Ok(resolved),
        Ok(m) if m.is_dir() => Err(refuse("is a folder, not a file".into())),
        Ok(_) => Err(refuse("is not a regular file (a device, FIFO or socket)".into())),
        Err(e) => Err(refuse(format!("cannot be looked up: {e}"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_files_at_or_below_the_folder_are_named() {
        let d = crate::scratch::shared("beside");
        let inner = d.join("scene");
        std::fs::create_dir_all(inner.join("sub")).unwrap();
        std::fs::write(inner.join("sub/data 1.bin"), b"x").unwrap();
        std::fs::write(d.join("secret.bin"), b"s").unwrap();
        let file = inner.join("s.gltf");
        assert_eq!(beside(&file, "sub/data%201.bin").unwrap(), inner.join("sub/data 1.bin").canonicalize().unwrap());
        assert!(beside(&file, "./sub/data 1.bin").is_ok());
        let why = |r: &str| beside(&file, r).unwrap_err().to_string();
        assert!(why("../secret.bin").contains("climbs out"), "{}", why("../secret.bin"));
        assert!(why("sub/%2E%2E/../secret.bin").contains("climbs out"));
        assert!(why("/etc/passwd").contains("absolute path"));
        assert!(why("%2Fetc%2Fpasswd").contains("absolute path"));
        assert!(why("file:///etc/passwd").contains("'file:' URI"));
        assert!(why("missing.bin").contains("names no file"));
        assert!(why("sub").contains("folder"));
        #[cfg(unix)]
        {
            let link = inner.join("out.bin");
            let _ = std::fs::remove_file(&link);
            std::os::unix::fs::symlink(d.join("secret.bin"), &link).unwrap();
            assert!(why("out.bin").contains("is a link to"), "{}", why("out.bin"));
            let dev = inner.join("zero.bin");
            let _ = std::fs::remove_file(&dev);
            std::os::unix::fs::symlink("/dev/zero", &dev).unwrap();
            assert!(why("zero.bin").contains("outside"), "{}", why("zero.bin"));
        }
    }
}
