//! OBJ loading, with errors that name the file and, where known, the line.
//!
//! We read the file ourselves (to tell a missing file from a directory from binary data). Plain
//! files are parsed in parallel (`obj_parallel.rs`, the same models tobj would give); all others go
//! to tobj. tobj reports *what* failed but not *where*; on failure we scan the text once for the
//! first line showing that fault (`obj_lines.rs`), so the user can open the file at the right place.

use super::error::{MeshError, MAX_COORDINATE};
use super::obj_lines::{diagnose, first_bad_face, first_bad_line, line_at, statements, Corner};
use super::obj_parallel::{self, extend_with};
use crate::geometry::triangle::double_area;
use crate::mesh::mesh::{Mesh, MeshGroup};
use crate::parallel::region;
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::borrow::Cow;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// What loading found, for the UI's status line and the CLI's report.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct LoadReport {
    pub path: PathBuf,
    pub vertices: usize,
    pub triangles: usize,
    /// Zero-area triangles left out of the mesh (and so out of the BVH).
    pub degenerate_skipped: usize,
    pub groups: usize,
    pub has_normals: bool,
    pub has_uvs: bool,
    #[serde(skip)]
    pub load_time: Duration,
}

/// Load an OBJ file: polygons are triangulated, groups kept, zero-area triangles skipped.
///
/// The file is read whole (a 2M-triangle OBJ is a quarter of a gigabyte) and parsed in parallel
/// when it is a plain one (`obj_parallel.rs`); otherwise, and to explain any error, by tobj.
pub fn load_obj(path: impl AsRef<Path>) -> Result<(Mesh, LoadReport), MeshError> {
    let path = path.as_ref();
    let start = Instant::now();
    let bytes = read_user_file(path)?;
    let text = decode_text(path, &bytes)?;
    let (mesh, mut report) = parse_obj(path, &text)?;
    report.load_time = start.elapsed();
    Ok((mesh, report))
}

/// The bytes of a file the user named, refusing what is not a regular file: a FIFO, a device
/// (`/dev/zero`, `/dev/urandom`) or a socket would be read forever, or block until another
/// program writes.
pub fn read_user_file(path: &Path) -> Result<Vec<u8>, MeshError> {
    use crate::files::FileError;
    let metadata = crate::files::regular(path)?;
    read_file(path, metadata.len() as usize).map_err(|e| {
        MeshError::File(match e.kind() {
            std::io::ErrorKind::NotFound => FileError::NotFound { path: path.into() },
            _ => FileError::Read { path: path.into(), source: e },
        })
    })
}

/// The file's bytes as text. A UTF-8 byte-order mark (Windows exporters write one) is dropped.
/// Bytes that are not UTF-8 (Latin-1 from older exporters, in comments and object names) are
/// decoded lossily: the names get a replacement character, the geometry, which is ASCII, loads.
/// A NUL byte means binary data, not OBJ text.
pub(crate) fn decode_text<'a>(path: &Path, bytes: &'a [u8]) -> Result<Cow<'a, str>, MeshError> {
    let bytes = bytes.strip_prefix("\u{feff}".as_bytes()).unwrap_or(bytes);
    // Both passes in parallel pieces (issue 37: a big file's load on one thread otherwise).
    if let Some(pos) = obj_parallel::first_byte(bytes, 0) {
        return Err(MeshError::NotText { path: path.into(), line: line_at(bytes, pos) });
    }
    Ok(obj_parallel::utf8(bytes).map_or_else(|| String::from_utf8_lossy(bytes), Cow::Borrowed))
}

/// The whole file. Big files are read in parallel pieces: on this machine faulting in the pages
/// of a fresh buffer costs about as much as the copy, and the threads share that.
/// `len` is the size the file had when looked at; whatever it has grown by since is read too.
fn read_file(path: &Path, len: usize) -> std::io::Result<Vec<u8>> {
    // Pieces small enough that a 160 MB file is read by 16 threads (issue 37), counted parallel.
    const PIECE: usize = 4 << 20;
    let pieces = (len / PIECE).clamp(1, rayon::current_num_threads());
    if len >= 16 * PIECE {
        return crate::parallel::region(|| read_pieces(path, len, pieces));
    }
    read_pieces(path, len, pieces)
}

fn read_pieces(path: &Path, len: usize, pieces: usize) -> std::io::Result<Vec<u8>> {
    use std::io::{Read, Seek, SeekFrom};
    if pieces == 1 {
        return std::fs::read(path);
    }
    let mut bytes = vec![0u8; len];
    let size = len.div_ceil(pieces);
    bytes.par_chunks_mut(size).enumerate().try_for_each(|(k, piece)| {
        let mut file = std::fs::File::open(path)?;
        file.seek(SeekFrom::Start((k * size) as u64))?;
        file.read_exact(piece)
    })?;
    // The file may have grown since its length was taken; the rest would be missing.
    let mut file = std::fs::File::open(path)?;
    file.seek(SeekFrom::Start(len as u64))?;
    file.read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// Parse OBJ text; `path` is used for the mesh name and in error messages.
pub fn parse_obj(path: impl AsRef<Path>, text: &str) -> Result<(Mesh, LoadReport), MeshError> {
    let path = path.as_ref();
    let text = &*super::obj_lines::lone_cr_as_line_break(text.strip_prefix('\u{feff}').unwrap_or(text));
    let text = &*super::obj_lines::cut_trailing_comments(text);
    let text = &*join_continued_lines(text);
    let (models, by_tobj) = match obj_parallel::models(text) {
        Some(models) => (Ok(models), false),
        None => {
            // (The parallel reader takes only vertices of three coordinates: the rest is here.)
            if let Some((line, message)) = super::obj_lines::first_vertex_with_words(text) {
                return Err(MeshError::Parse { path: path.into(), line: Some(line), message });
            }
            // Vertex colours (`v x y z r g b`) and weights (`v x y z w`) are not needed to show a
            // BVH, and tobj refuses a file that gives colours to some vertices only.
            let plain = positions_only(text);
            (load_models(&mut Cursor::new(plain.as_bytes())).map_err(Problem::Tobj), true)
        }
    };

    let (mesh, report) =
        models.and_then(|models| build_mesh(path, models)).map_err(|problem| explain(path, text, problem))?;
    // Within the limits every reader counts against (the text bounds it already: this names it).
    let limit =
        |what: &str, e: String| MeshError::Parse { path: path.into(), line: None, message: format!("{what}: {e}") };
    crate::files::limits::VERTICES.check(mesh.positions.len() as u64).map_err(|e| limit("the vertices", e))?;
    crate::files::limits::TRIANGLES.check(mesh.triangles.len() as u64).map_err(|e| limit("the triangles", e))?;
    // tobj ignores texture and normal indices when the file declares none (the parallel reader
    // declines such files). They can only be there if the text has a '/'.
    if by_tobj && text.contains('/') {
        check_unchecked_indices(path, text, &report)?;
    }
    Ok((mesh, report))
}

/// The text with each statement continued by a trailing backslash joined into one line (the OBJ
/// format allows it). The line breaks removed are put back after the joined statement, so every
/// line keeps its number in error messages (a joined statement is reported at its first line).
fn join_continued_lines(text: &str) -> Cow<'_, str> {
    let continued = || text.contains("\\\n") || text.contains("\\\r\n");
    if obj_parallel::first_byte(text.as_bytes(), b'\\').is_none() || !continued() {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len());
    let mut pending = 0;
    for line in text.split_inclusive('\n') {
        let body = line.trim_end_matches(['\n', '\r']);
        match body.strip_suffix('\\') {
            Some(head) if line.ends_with('\n') => {
                out.push_str(head);
                out.push(' ');
                pending += 1;
            }
            _ => {
                out.push_str(line);
                for _ in 0..pending {
                    out.push('\n');
                }
                pending = 0;
            }
        }
    }
    Cow::Owned(out)
}

/// The text with every `v` statement cut to its three coordinates (dropping a weight or a
/// colour), line for line.
fn positions_only(text: &str) -> Cow<'_, str> {
    let long = |line: &str| {
        let mut t = line.split('#').next().unwrap_or("").split_whitespace();
        t.next() == Some("v") && t.count() > 3
    };
    if !text.lines().any(long) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        if long(line) {
            let coords: Vec<&str> = line.split_whitespace().skip(1).take(3).collect();
            out.push_str("v ");
            out.push_str(&coords.join(" "));
            out.push('\n');
        } else {
            out.push_str(line);
        }
    }
    Cow::Owned(out)
}

/// Texture and normal indices tobj did not check (it ignores them when none are declared).
fn check_unchecked_indices(path: &Path, text: &str, report: &LoadReport) -> Result<(), MeshError> {
    for (missing, which) in [(!report.has_uvs, Corner::TexCoord), (!report.has_normals, Corner::Normal)] {
        if missing {
            if let Some((line, message)) = first_bad_face(text, Some(which)) {
                return Err(MeshError::IndexOutOfRange { path: path.into(), line: Some(line), message });
            }
        }
    }
    Ok(())
}

/// What went wrong before the text was looked at for line numbers.
enum Problem {
    Tobj(tobj::LoadError),
    /// (what, OBJ keyword, values per line)
    NonFinite(&'static str, &'static str, usize),
    TooLarge,
    NoTriangles {
        degenerate: usize,
    },
}

/// Turn a problem into an error naming the file and, where it can be found, the line.
fn explain(path: &Path, text: &str, problem: Problem) -> MeshError {
    if let Some(pos) = text.bytes().position(|b| b == 0) {
        return MeshError::NotText { path: path.into(), line: line_at(text.as_bytes(), pos) };
    }
    match problem {
        Problem::Tobj(e) => diagnose(path, text, e),
        Problem::NonFinite(what, keyword, min) => {
            MeshError::NonFinite { path: path.into(), line: first_bad_line(text, keyword, min), what }
        }
        // Faces of one or two corners (lines and points written as `f`) make no triangle: when
        // they are all there is, say which line instead of just "no triangles".
        Problem::NoTriangles { degenerate } => match first_bad_face(text, None).filter(|_| degenerate == 0) {
            Some((line, message)) => MeshError::Parse { path: path.into(), line: Some(line), message },
            None => MeshError::NoTriangles { path: path.into(), degenerate },
        },
        Problem::TooLarge => {
            let line = statements(text).find_map(|(n, k, args)| {
                let big = args.iter().take(3).any(|a| a.parse::<f32>().is_ok_and(|x| x.abs() > MAX_COORDINATE));
                (k == "v" && big).then_some(n)
            });
            MeshError::TooLarge { path: path.into(), line }
        }
    }
}

/// tobj with our options: the reference the parallel reader is tested against.
pub(super) fn load_models(reader: &mut impl std::io::BufRead) -> Result<Vec<tobj::Model>, tobj::LoadError> {
    let options = tobj::LoadOptions { triangulate: true, single_index: true, ignore_points: true, ignore_lines: true };
    // Materials are not needed to show a BVH; a missing .mtl must not fail the load.
    tobj::load_obj_buf(reader, &options, |_| Err(tobj::LoadError::OpenFileFailed)).map(|(models, _)| models)
}

/// tobj's models as one mesh: groups kept, zero-area triangles left out and counted.
fn build_mesh(path: &Path, models: Vec<tobj::Model>) -> Result<(Mesh, LoadReport), Problem> {
    let mut mesh = Mesh { name: mesh_name(path), ..Default::default() };
    let has_normals = models.iter().any(|m| !m.mesh.normals.is_empty());
    let has_uvs = models.iter().any(|m| !m.mesh.texcoords.is_empty());
    let mut degenerate = 0usize;
    let mut file_base = 0u32;
    for model in &models {
        let m = &model.mesh;
        let base = mesh.positions.len() as u32;
        let nverts = m.positions.len() / 3;
        extend_with(&mut mesh.positions, m.positions.as_chunks::<3>().0, |p| Vec3::from_array(*p));
        if has_normals {
            if m.normals.len() == m.positions.len() {
                extend_with(&mut mesh.normals, m.normals.as_chunks::<3>().0, |n| Vec3::from_array(*n));
            } else {
                // A part without normals: zero normals make `fill_intersection` use the plane's.
                mesh.normals.extend(std::iter::repeat_n(Vec3::ZERO, nverts));
            }
        }
        if has_uvs {
            if m.texcoords.len() / 2 == nverts {
                extend_with(&mut mesh.uvs, m.texcoords.as_chunks::<2>().0, |t| Vec2::from_array(*t));
            } else {
                mesh.uvs.extend(std::iter::repeat_n(Vec2::ZERO, nverts));
            }
        }
        let first = mesh.triangles.len() as u32;
        // In parallel, in order, for big parts: a 2M-triangle mesh spends a tenth of its load here
        // otherwise. Small ones stay on this thread: handing work to the pool costs tens of
        // microseconds, which a file of 50,000 small objects would pay 50,000 times.
        let positions = &mesh.positions;
        let corners = |f: &[u32]| [f[0] + base, f[1] + base, f[2] + base];
        let keep = |tri: &[u32; 3]| {
            let verts = tri.map(|i| positions[i as usize]);
            !(verts.iter().all(|v| v.is_finite()) && double_area(&verts) == 0.0)
        };
        // Each kept triangle with its number in the file (zero-area ones counted, as dumps do).
        let numbered = |(i, f): (usize, &[u32])| (file_base + i as u32, corners(f));
        let kept: Vec<(u32, [u32; 3])> = if m.indices.len() >= 3 << 14 {
            region(|| m.indices.par_chunks_exact(3).enumerate().map(numbered).filter(|(_, t)| keep(t)).collect())
        } else {
            m.indices.chunks_exact(3).enumerate().map(numbered).filter(|(_, t)| keep(t)).collect()
        };
        file_base += (m.indices.len() / 3) as u32;
        degenerate += m.indices.len() / 3 - kept.len();
        extend_with(&mut mesh.triangles, &kept, |&(_, t)| t);
        extend_with(&mut mesh.file_numbers, &kept, |&(f, _)| f);
        let last = mesh.triangles.len() as u32;
        if last > first {
            mesh.groups.push(MeshGroup { name: model.name.clone(), triangles: first..last });
        }
    }

    if region(|| mesh.positions.par_iter().any(|p| !p.is_finite())) {
        return Err(Problem::NonFinite("a vertex position", "v", 3));
    }
    if region(|| mesh.positions.par_iter().any(|p| p.abs().max_element() > MAX_COORDINATE)) {
        return Err(Problem::TooLarge);
    }
    if region(|| mesh.normals.par_iter().any(|n| !n.is_finite())) {
        return Err(Problem::NonFinite("a vertex normal", "vn", 3));
    }
    if region(|| mesh.uvs.par_iter().any(|t| !t.is_finite())) {
        return Err(Problem::NonFinite("a texture coordinate", "vt", 1));
    }
    if mesh.triangles.is_empty() {
        return Err(Problem::NoTriangles { degenerate });
    }
    mesh.file_triangles = file_base as usize;
    let report = LoadReport {
        path: path.into(),
        vertices: mesh.positions.len(),
        triangles: mesh.triangles.len(),
        degenerate_skipped: degenerate,
        groups: mesh.groups.len(),
        has_normals,
        has_uvs,
        load_time: Duration::ZERO,
    };
    Ok((mesh, report))
}

/// Write a mesh as OBJ text: one `o` per group, positions, normals and uvs when present.
pub fn write_obj(mesh: &Mesh, out: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(out, "# {} — written by bvhscope", mesh.name)?;
    for p in &mesh.positions {
        writeln!(out, "v {} {} {}", p.x, p.y, p.z)?;
    }
    for t in &mesh.uvs {
        writeln!(out, "vt {} {}", t.x, t.y)?;
    }
    for n in &mesh.normals {
        writeln!(out, "vn {} {} {}", n.x, n.y, n.z)?;
    }
    let corner = |i: u32| {
        let i = i + 1;
        match (mesh.uvs.is_empty(), mesh.normals.is_empty()) {
            (true, true) => format!("{i}"),
            (false, true) => format!("{i}/{i}"),
            (true, false) => format!("{i}//{i}"),
            (false, false) => format!("{i}/{i}/{i}"),
        }
    };
    let groups = if mesh.groups.is_empty() {
        vec![super::MeshGroup { name: mesh.name.clone(), triangles: 0..mesh.triangles.len() as u32 }]
    } else {
        mesh.groups.clone()
    };
    for g in &groups {
        writeln!(out, "o {}", g.name.replace(char::is_whitespace, "_"))?;
        for t in &mesh.triangles[g.triangles.start as usize..g.triangles.end as usize] {
            writeln!(out, "f {} {} {}", corner(t[0]), corner(t[1]), corner(t[2]))?;
        }
    }
    Ok(())
}

fn mesh_name(path: &Path) -> String {
    path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| path.display().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quads_are_triangulated_and_groups_kept() {
        let text = "o first\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\ng second\nv 0 0 1\nf 1 2 5\n";
        let (mesh, report) = parse_obj("quad.obj", text).unwrap();
        assert_eq!(mesh.triangles.len(), 3);
        assert_eq!(report.triangles, 3);
        let names: Vec<_> = mesh.groups.iter().map(|g| g.name.as_str()).collect();
        assert_eq!(names, ["first", "second"]);
        assert_eq!(mesh.groups[0].triangles, 0..2);
        assert!(!report.has_normals && !report.has_uvs);
    }

    #[test]
    fn normals_and_uvs_are_kept() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\n";
        let (mesh, report) = parse_obj("t.obj", text).unwrap();
        assert!(report.has_normals && report.has_uvs);
        assert_eq!(mesh.normals.len(), mesh.positions.len());
        assert_eq!(mesh.uvs.len(), mesh.positions.len());
        assert!(mesh.normals.iter().all(|&n| n == Vec3::Z));
    }

    #[test]
    fn degenerate_triangles_are_skipped_and_counted() {
        let text = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\nf 1 1 4\n";
        let (mesh, report) = parse_obj("d.obj", text).unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 3]]);
        assert_eq!(report.degenerate_skipped, 2);
    }

    fn err(text: &str) -> MeshError {
        parse_obj("bad.obj", text).expect_err("must fail")
    }

    #[test]
    fn nan_position_names_the_line() {
        let e = err("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
        assert!(matches!(e, MeshError::NonFinite { line: Some(3), .. }), "{e}");
        assert_eq!(e.to_string(), "bad.obj: line 3: a vertex position has a NaN or infinite coordinate");
        let e = err("v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n");
        assert_eq!(e.line(), Some(2));
    }

    #[test]
    fn index_out_of_range_names_the_line() {
        let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n");
        assert!(matches!(e, MeshError::IndexOutOfRange { line: Some(5), .. }), "{e}");
        assert!(e.to_string().contains("vertex 9"), "{e}");
        let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n");
        assert!(matches!(e, MeshError::IndexOutOfRange { line: Some(4), .. }), "{e}");
    }

    #[test]
    fn texture_and_normal_indices_are_checked_even_when_none_are_declared() {
        for (text, line) in [
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1 2/2/2 3/3/3\n", 4),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1//0 2 3\n", 5),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/-5 2 3\n", 4),
        ] {
            let e = err(text);
            assert!(matches!(e, MeshError::IndexOutOfRange { line: Some(l), .. } if l == line), "{text:?}: {e}");
        }
        let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n");
        assert_eq!(e.line(), Some(4), "{e}");
    }

    #[test]
    fn unparsable_position_names_the_line() {
        let e = err("v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n");
        assert!(matches!(e, MeshError::Parse { line: Some(2), .. }), "{e}");
    }

    #[test]
    fn no_triangles_is_an_error() {
        assert!(matches!(err("v 0 0 0\nv 1 0 0\n"), MeshError::NoTriangles { degenerate: 0, .. }));
        assert!(matches!(err(""), MeshError::NoTriangles { .. }));
        let e = err("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
        assert!(matches!(e, MeshError::NoTriangles { degenerate: 1, .. }), "{e}");
    }

    #[test]
    fn written_obj_reads_back_the_same_mesh() {
        let mut m = crate::mesh::generate::torus(2.0, 0.5, 12, 6);
        m.name = "ring".into();
        let mut text = Vec::new();
        write_obj(&m, &mut text).unwrap();
        let (back, report) = parse_obj("ring.obj", std::str::from_utf8(&text).unwrap()).unwrap();
        assert_eq!(report.triangles, m.triangles.len());
        assert!(report.has_normals && report.has_uvs);
        for i in 0..m.triangle_count() as u32 {
            let (a, b) = (m.triangle(i), back.triangle(i));
            assert!(a.iter().zip(&b).all(|(p, q)| (*p - *q).length() < 1e-5), "triangle {i}");
        }
        assert_eq!(back.groups[0].name, "torus");
    }

    #[test]
    fn nul_byte_is_not_text() {
        let e = err("v 0 0 0\n\0\0\0");
        assert!(matches!(e, MeshError::NotText { line: 2, .. }), "{e}");
    }
}
