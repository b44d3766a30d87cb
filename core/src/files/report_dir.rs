//! A report folder: the folder a command writes whole (`grade --out DIR`'s report, `lesson -o
//! DIR`'s handout), described by its kind (`FolderKind`).
//!
//! The folder is written into a fresh folder beside the one named and renamed into place when
//! complete (`ReportDir::publish`): two runs into one folder never mix (each leaves a whole
//! report, the last one wins), no file of an earlier run survives, and a reader never reads a
//! half-written report. An existing folder is accepted only when it is empty or holds nothing but
//! what an earlier report of the kind listed in its list (`FolderKind::list`), unchanged
//! (`manifest::ours`): anything else (a file of the user's, a report file edited since, a link,
//! an older report that wrote no list) is refused by name, before any work and again before the
//! report is put in place, and only the listed files are ever removed. No input may be inside the
//! folder, and no report file may be an input.

use super::{manifest, refuse_inputs, FileError};
use std::path::{Path, PathBuf};

/// What a report folder holds and how it is named in messages; each command that writes one
/// defines its own, as a `const`.
#[derive(Clone, Copy, Debug)]
pub struct FolderKind {
    /// What it is, in words: "grade report", "lesson handout" ("which is not part of a grade
    /// report"). Its last word is what the messages call it ("write the report to another
    /// folder"), its words joined by `-` name its temporary folders (`.grade-report.old-…`).
    pub what: &'static str,
    /// The list of its files written into it (`manifest`): "grade-files.txt".
    pub list: &'static str,
    /// The list's first line: what it is, and the version of its layout ("bvhscope-grade-files 1").
    pub first_line: &'static str,
    /// Its own top-level names: a folder holding one of them but no list is an older report, or
    /// someone's own files named alike. Those not in `folders` are files, none of which may be an
    /// input.
    pub names: &'static [&'static str],
    /// The sub-folders made when it is prepared ("images").
    pub folders: &'static [&'static str],
    /// The option that names the folder, for messages: "--out".
    pub flag: &'static str,
}

impl FolderKind {
    /// What messages call it: the last word of `what` ("report", "handout").
    pub fn noun(&self) -> &'static str {
        self.what.rsplit(' ').next().unwrap_or(self.what)
    }

    /// Its name in temporary folders: `what` with `-` for spaces ("grade-report").
    fn slug(&self) -> String {
        self.what.replace(' ', "-")
    }
}

/// Why a report folder cannot be prepared or put in place.
#[derive(Debug, thiserror::Error)]
pub enum FolderError {
    #[error(transparent)]
    File(#[from] FileError),
    /// The folder named is refused, or the report cannot be put there: `PATH: why`.
    #[error("{}: {message}", .path.display())]
    Output { path: PathBuf, message: String },
}

/// A report folder made ready: written in `work` until `publish` renames it to `root`.
pub struct ReportDir {
    /// Where the report ends up (`--out`).
    root: PathBuf,
    kind: &'static FolderKind,
    /// Where it is written meanwhile: a fresh folder beside `root` (removed if never published).
    work: Option<tempfile::TempDir>,
    /// Every input, with what it is ("the mesh", "alice's dump").
    inputs: Vec<(PathBuf, String)>,
}

impl ReportDir {
    /// Make a fresh folder ready beside `root`, after refusing a `root` that is a file, an
    /// input's folder, a folder holding anything but what an earlier report of the kind listed
    /// (`manifest::ours`), or one holding an input, and report files that are inputs (`inputs`:
    /// path and what it is).
    pub fn prepare(
        root: &Path,
        kind: &'static FolderKind,
        inputs: Vec<(PathBuf, String)>,
    ) -> Result<ReportDir, FolderError> {
        let fail = |message: String| FolderError::Output { path: root.to_path_buf(), message };
        let (noun, flag) = (kind.noun(), kind.flag);
        if root.exists() && !root.is_dir() {
            return Err(fail(format!("is a file: the {noun} is written to a folder ({flag})")));
        }
        if root.is_dir() {
            let same = inputs.iter().find(|(p, _)| p.is_dir() && same_file::is_same_file(p, root).unwrap_or(false));
            if let Some((_, what)) = same {
                return Err(fail(format!("is also {what}: write the {noun} to another folder ({flag})")));
            }
        }
        let mut dir = ReportDir { root: root.to_path_buf(), kind, work: None, inputs };
        for name in kind.names.iter().filter(|n| !kind.folders.contains(n)) {
            let path = dir.root.join(name);
            let inputs: Vec<(&Path, &str)> = dir.inputs.iter().map(|(p, w)| (p.as_path(), w.as_str())).collect();
            refuse_inputs(&path, &inputs)?;
        }
        if root.is_dir() {
            let inside = std::fs::canonicalize(root).map_err(|source| FileError::Read { path: root.into(), source })?;
            let within =
                dir.inputs.iter().find(|(p, _)| std::fs::canonicalize(p).is_ok_and(|p| p.starts_with(&inside)));
            if let Some((_, what)) = within {
                return Err(fail(format!(
                    "holds {what}: a {noun} replaces what it wrote there; write it to another folder ({flag})"
                )));
            }
            manifest::ours(root, kind).map_err(fail)?;
        }
        let parent = match root.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent).map_err(|source| FileError::Write { path: parent.clone(), source })?;
        let name = root.file_name().map_or_else(|| kind.slug(), |n| n.to_string_lossy().into_owned());
        let work = tempfile::Builder::new()
            .prefix(&format!(".{name}.writing-"))
            .tempdir_in(&parent)
            .map_err(|source| FileError::Write { path: root.into(), source })?;
        // A temporary folder is private (0700); the report is as readable as any folder made here.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(work.path(), std::fs::Permissions::from_mode(0o755));
        }
        for folder in kind.folders {
            let path = work.path().join(folder);
            std::fs::create_dir_all(&path).map_err(|source| FileError::Write { path, source })?;
        }
        dir.work = Some(work);
        Ok(dir)
    }

    /// Where the report ends up (the folder named).
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The folder being written.
    fn work(&self) -> &Path {
        self.work.as_ref().map_or(self.root.as_path(), |w| w.path())
    }

    /// The path a report file will have once published (for messages).
    pub fn file(&self, rel: &str) -> PathBuf {
        self.root.join(rel)
    }

    /// The path of `rel` while the report is written, for a file streamed there by its writer
    /// (grade's HTML page): written atomically (`files::write_atomically`) like the others.
    pub fn path_while_written(&self, rel: &str) -> PathBuf {
        self.work().join(rel)
    }

    /// Write an image at `rel` (relative to the folder; its folder one of the kind's `folders`).
    pub fn write_png(&self, rel: &str, img: &image::RgbImage) -> Result<(), FileError> {
        super::write_png(&self.work().join(rel), img)
    }

    /// Write a report file at `rel`.
    pub fn write(&self, rel: &str, bytes: &[u8]) -> Result<(), FileError> {
        super::write_bytes(&self.work().join(rel), bytes)
    }

    /// Read back an image written here (for an HTML page), at most `limit` bytes: this run's,
    /// never an earlier run's.
    pub fn read_image(&self, rel: &str, limit: u64) -> Option<Vec<u8>> {
        let (file, _) = super::open_regular(&self.work().join(rel)).ok()?;
        super::read_limited(file, limit).ok().flatten()
    }

    /// Put the finished report in place: its files listed (`manifest::write`), the folder written
    /// renamed to `root`, an earlier report there moved aside first and, once this one is in
    /// place, emptied of the files its list names and removed. `root` is checked again first:
    /// grading a class takes minutes, and a file put there meanwhile is refused as in `prepare`
    /// (the new report is then left beside it, named). Another run may publish meanwhile: each
    /// rename is of a whole report, so `root` always holds one.
    pub fn publish(&mut self) -> Result<(), FolderError> {
        let Some(work) = self.work.take() else { return Ok(()) };
        let kind = self.kind;
        manifest::write(work.path(), kind)?;
        let fail = |message: String| FolderError::Output { path: self.root.clone(), message };
        let parent = work.path().parent().map(Path::to_path_buf).unwrap_or_else(|| PathBuf::from("."));
        let work = work.keep();
        let mut asides = Vec::new();
        let mut last = None;
        for _ in 0..16 {
            if self.root.is_dir() {
                if let Err(why) = manifest::ours(&self.root, kind) {
                    let _ = self.clear(&asides);
                    return Err(fail(format!("{why} (the new {} is left in {})", kind.noun(), work.display())));
                }
            }
            match std::fs::rename(&work, &self.root) {
                Ok(()) => return self.clear(&asides).map_err(fail),
                Err(e) if self.root.is_dir() => {
                    // An earlier report (checked just above): aside, then removed by its list
                    // once this one is in place.
                    let aside = tempfile::Builder::new()
                        .prefix(&format!(".{}.old-", kind.slug()))
                        .tempdir_in(&parent)
                        .map_err(|e| fail(format!("cannot be put in place: {e}")))?
                        .keep();
                    if std::fs::rename(&self.root, aside.join("report")).is_err() {
                        let _ = std::fs::remove_dir(&aside);
                    } else {
                        asides.push(aside);
                    }
                    last = Some(e);
                }
                Err(e) => {
                    last = Some(e);
                    break;
                }
            }
        }
        let _ = std::fs::remove_dir_all(&work);
        self.restore(&mut asides);
        let _ = self.clear(&asides);
        let e = last.unwrap_or_else(|| std::io::Error::other("another run kept replacing it"));
        Err(fail(format!("cannot be put in place: {e}")))
    }

    /// The report last moved aside put back where it was, when nothing took its place: a
    /// report that cannot be published leaves the earlier one as it found it.
    fn restore(&self, asides: &mut Vec<PathBuf>) {
        if let Some(aside) = asides.pop() {
            if std::fs::rename(aside.join("report"), &self.root).is_ok() {
                let _ = std::fs::remove_dir(&aside);
            } else {
                asides.push(aside);
            }
        }
    }

    /// Remove the earlier reports moved aside, each by its own list (`manifest::remove`): what
    /// it did not list (put there in the instant between the check and the move) is kept, and
    /// named.
    fn clear(&self, asides: &[PathBuf]) -> Result<(), String> {
        for aside in asides {
            manifest::remove(&aside.join("report"), self.kind).map_err(|why| {
                format!(
                    "the {} is in place, but the earlier one moved aside to {} is kept ({why})",
                    self.kind.noun(),
                    aside.display()
                )
            })?;
            let _ = std::fs::remove_dir(aside);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A second kind, as the lesson command's handout: one file and a folder of images.
    const HANDOUT: FolderKind = FolderKind {
        what: "lesson handout",
        list: "handout-files.txt",
        first_line: "bvhscope-handout-files 1",
        names: &["index.html", "steps"],
        folders: &["steps"],
        flag: "-o",
    };

    /// A handout of `steps` (numbers) written into `root` and published.
    fn handout(root: &Path, steps: &[u32]) -> Result<(), FolderError> {
        let mut dir = ReportDir::prepare(root, &HANDOUT, Vec::new())?;
        assert_eq!(dir.file("index.html"), root.join("index.html"));
        dir.write("index.html", b"<html></html>")?;
        for s in steps {
            let rel = format!("steps/step-{s:02}.png");
            dir.write_png(&rel, &image::RgbImage::new(2, 2))?;
            assert!(dir.read_image(&rel, 1 << 20).is_some(), "this run's image is read back");
        }
        dir.publish()
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> =
            std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    }

    #[test]
    fn a_handout_folder_replaces_its_own_files_and_nothing_else() {
        let d = tempfile::tempdir().unwrap();
        let root = d.path().join("handout");
        // A new folder is made, its list written last.
        handout(&root, &[1, 2]).unwrap();
        assert_eq!(names(&root), ["handout-files.txt", "index.html", "steps"]);
        assert_eq!(names(&root.join("steps")), ["step-01.png", "step-02.png"]);
        let list = std::fs::read_to_string(root.join("handout-files.txt")).unwrap();
        assert!(list.starts_with("bvhscope-handout-files 1\nfile\t13\tindex.html\nfolder\tsteps\n"), "{list}");
        // A rerun replaces its own files: no step of the earlier run survives, nothing is left beside.
        handout(&root, &[1]).unwrap();
        assert_eq!(names(&root.join("steps")), ["step-01.png"]);
        assert_eq!(names(d.path()), ["handout"]);

        // A file of the user's is refused by name, and nothing is removed.
        std::fs::write(root.join("steps/notes.txt"), "mine").unwrap();
        let err = handout(&root, &[2]).unwrap_err().to_string();
        assert_eq!(
            err,
            format!(
                "{}: holds steps/notes.txt, which the lesson handout written there did not write: a handout replaces only the files it wrote; move what is yours, or write the handout to another folder (-o)",
                root.display()
            )
        );
        assert_eq!(names(&root.join("steps")), ["notes.txt", "step-01.png"]);
        std::fs::remove_file(root.join("steps/notes.txt")).unwrap();
        // A file of ours edited since is the user's now.
        std::fs::write(root.join("index.html"), "<html>my notes</html>").unwrap();
        let err = handout(&root, &[2]).unwrap_err().to_string();
        assert!(
            err.contains("holds index.html, changed since the lesson handout there wrote it (13 bytes then, 21 now)"),
            "{err}"
        );
        assert_eq!(std::fs::read_to_string(root.join("index.html")).unwrap(), "<html>my notes</html>");
        assert_eq!(names(d.path()), ["handout"], "nothing left beside a refused run");

        // A folder without a list: refused, whether it holds the kind's names or others.
        let mine = d.path().join("site");
        std::fs::create_dir(&mine).unwrap();
        std::fs::write(mine.join("about.txt"), "me").unwrap();
        let err = handout(&mine, &[1]).unwrap_err().to_string();
        assert!(err.contains("holds about.txt, which is not part of a lesson handout"), "{err}");
        std::fs::write(mine.join("index.html"), "<html>my site</html>").unwrap();
        let err = handout(&mine, &[1]).unwrap_err().to_string();
        assert!(err.contains("holds index.html but no handout-files.txt"), "{err}");
        assert_eq!(names(&mine), ["about.txt", "index.html"], "nothing unlisted is removed");
        // A grade report's list is not a handout's.
        std::fs::write(mine.join("handout-files.txt"), "bvhscope-grade-files 1\n").unwrap();
        let err = handout(&mine, &[1]).unwrap_err().to_string();
        assert!(err.contains("holds handout-files.txt, which is not a list of a lesson handout's files"), "{err}");
        assert_eq!(std::fs::read_to_string(mine.join("index.html")).unwrap(), "<html>my site</html>");
    }

    #[test]
    fn a_kind_is_named_by_its_last_word() {
        assert_eq!((HANDOUT.noun(), HANDOUT.slug().as_str()), ("handout", "lesson-handout"));
        let d = tempfile::tempdir().unwrap();
        let file = d.path().join("handout");
        std::fs::write(&file, "x").unwrap();
        let err = ReportDir::prepare(&file, &HANDOUT, Vec::new()).err().unwrap().to_string();
        assert!(err.ends_with("handout: is a file: the handout is written to a folder (-o)"), "{err}");
    }
}
