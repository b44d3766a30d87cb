//! Every kind of bad mesh file gives its own error naming the file, never a panic.

#[path = "../core/tests/common/scratch.rs"]
mod scratch;

use bvhscope::files::FileError;
use bvhscope::mesh::{load_obj, MeshError};
use std::path::PathBuf;

fn temp_file(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = scratch::shared("bad-input");
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn load_err(path: &PathBuf) -> MeshError {
    let e = load_obj(path).expect_err("bad input must fail");
    let msg = e.to_string();
    assert!(msg.starts_with(&path.display().to_string()), "message names the file: {msg}");
    assert!(!msg.contains('\n'), "one line: {msg}");
    e
}

#[test]
fn missing_file() {
    let p = std::env::temp_dir().join("bvhscope-definitely-missing.obj");
    assert!(matches!(load_err(&p), MeshError::File(FileError::NotFound { .. })));
}

#[test]
fn directory() {
    let p = std::env::temp_dir();
    assert!(matches!(load_err(&p), MeshError::File(FileError::IsDirectory { .. })));
}

#[test]
fn binary_file() {
    // A PNG's header: its first NUL byte comes after two line feeds, on line 3.
    let p = temp_file("binary.obj", &[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a, 0, 0, 0, 13, 0xff, 0xfe]);
    let e = load_err(&p);
    assert!(matches!(e, MeshError::NotText { line: 3, .. }), "{e:?}");
    let p = temp_file("nul.obj", b"v 0 0 0\nv 1 0 0\n# caf\0\nf 1 2 3\n");
    assert!(matches!(load_err(&p), MeshError::NotText { line: 3, .. }));
}

#[test]
fn no_triangles() {
    let p = temp_file("empty.obj", b"");
    assert!(matches!(load_err(&p), MeshError::NoTriangles { .. }));
    let p = temp_file("points.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\nl 1 2\n");
    assert!(matches!(load_err(&p), MeshError::NoTriangles { .. }));
}

#[test]
fn index_out_of_range() {
    let p = temp_file("oob.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    let e = load_err(&p);
    assert!(matches!(e, MeshError::IndexOutOfRange { line: Some(4), .. }), "{e}");
    let p = temp_file("oob-normal.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n");
    let e = load_err(&p);
    assert!(matches!(e, MeshError::IndexOutOfRange { line: Some(5), .. }), "{e}");
    assert!(e.to_string().contains("normal 2"), "{e}");
    // tobj ignores texture/normal indices when the file declares none; we do not.
    for (name, text, line) in [
        ("undeclared-vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1 2/2/2 3/3/3\n", 4),
        ("zero-normal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1//0 2 3\n", 5),
        ("negative-vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/-5 2 3\n", 4),
    ] {
        let p = temp_file(name, text.as_bytes());
        let e = load_err(&p);
        assert!(matches!(e, MeshError::IndexOutOfRange { line: Some(l), .. } if l == line), "{name}: {e}");
    }
}

#[test]
fn coordinates_too_large_to_trace() {
    let p = temp_file("huge.obj", b"v 0 0 0\nv 1e13 0 0\nv 0 1 0\nf 1 2 3\n");
    let e = load_err(&p);
    assert!(matches!(e, MeshError::TooLarge { line: Some(2), .. }), "{e}");
    let p = temp_file("large-ok.obj", b"v 0 0 0\nv 1e9 0 0\nv 0 1e9 0\nf 1 2 3\n");
    assert!(load_obj(&p).is_ok());
}

#[test]
fn nan_and_infinite_coordinates() {
    let p = temp_file("nan.obj", b"v 0 0 0\nv 1 NaN 0\nv 0 1 0\nf 1 2 3\n");
    assert!(matches!(load_err(&p), MeshError::NonFinite { line: Some(2), .. }));
    let p = temp_file("inf.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 -inf\nf 1 2 3\n");
    assert!(matches!(load_err(&p), MeshError::NonFinite { line: Some(3), .. }));
    let p = temp_file("nan-normal.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 nan 1\nf 1//1 2//1 3//1\n");
    assert!(matches!(load_err(&p), MeshError::NonFinite { line: Some(4), what: "a vertex normal", .. }));
}

#[test]
fn garbage_text() {
    let p = temp_file("garbage.obj", b"v 0 0 0\nv one two three\nf 1 2 3\n");
    let e = load_err(&p);
    assert!(matches!(e, MeshError::Parse { line: Some(2), .. }), "{e}");
    let p = temp_file("face.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n");
    let e = load_err(&p);
    assert!(
        matches!(e, MeshError::Parse { line: Some(4), .. } | MeshError::IndexOutOfRange { line: Some(4), .. }),
        "{e}"
    );
}

// Inputs that real files bring.

#[test]
fn a_byte_order_mark_is_skipped() {
    // Windows exporters start the file with one; it used to swallow the first vertex.
    let p = temp_file("bom.obj", b"\xef\xbb\xbfv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let (mesh, report) = load_obj(&p).expect("loads");
    assert_eq!((report.vertices, report.triangles), (3, 1));
    assert_eq!(mesh.positions[0], glam::Vec3::ZERO);
}

#[test]
fn latin1_names_and_comments_are_decoded_and_the_geometry_loads() {
    let p = temp_file(
        "latin1.obj",
        b"# caf\xe9 cr\xe9\xe9 par un vieil exporteur\no t\xeate\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let (mesh, report) = load_obj(&p).expect("loads");
    assert_eq!(report.triangles, 1);
    assert_eq!(mesh.groups[0].name, "t\u{fffd}te", "the name decoded lossily");
}

#[cfg(unix)]
#[test]
fn a_fifo_or_a_device_is_refused_at_once() {
    for dev in ["/dev/zero", "/dev/urandom", "/dev/null"] {
        let e = load_err(&PathBuf::from(dev));
        assert!(matches!(e, MeshError::File(FileError::NotRegular { .. })), "{dev}: {e}");
        assert!(e.to_string().contains("character device"), "{e}");
    }
    let fifo = scratch::shared("fifo").join("never-written.obj");
    let _ = std::fs::remove_file(&fifo);
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().expect("mkfifo runs");
    assert!(made.success());
    // Nobody writes to it: reading it would block for ever. The check must not open it.
    let e = load_err(&fifo);
    assert!(e.to_string().contains("a FIFO (named pipe), not a regular file"), "{e}");
    std::fs::rename(&fifo, fifo.with_extension("json")).unwrap();
    let e = bvhscope::scene::load_any(fifo.with_extension("json")).expect_err("a FIFO scene file");
    assert!(e.to_string().contains("FIFO"), "{e}");
    let _ = std::fs::remove_file(fifo.with_extension("json"));
}

#[test]
fn a_statement_continued_with_a_backslash_is_joined_and_lines_keep_their_numbers() {
    let p = temp_file("continued.obj", b"v 0 0 0\nv 1 \\\n0 0\nv 0 1 0\nf 1 2 \\\r\n 3\nv 0 0 nan\nf 1 2 4\n");
    let e = load_err(&p);
    assert!(matches!(e, MeshError::NonFinite { line: Some(7), .. }), "line 7 is still line 7: {e}");
    let p = temp_file("continued-ok.obj", b"v 0 0 0\nv 1 \\\n0 0\nv 0 1 0\nf 1 2 \\\n 3\n");
    let (mesh, report) = load_obj(&p).expect("loads");
    assert_eq!((report.vertices, report.triangles), (3, 1));
    assert_eq!(mesh.positions[1], glam::Vec3::X);
}

#[test]
fn vertices_with_weights_or_colours_mixed_with_plain_ones_load() {
    // tobj refused this ("face vertex color index out of bounds"); colours are not needed here.
    let p = temp_file("mixed-v.obj", b"v 0 0 0\nv 1 0 0 1.0\nv 0 1 0 0.5 0.5 0.5\nv 1 1 0\nf 1 2 3\nf 2 4 3\n");
    let (mesh, report) = load_obj(&p).expect("loads");
    assert_eq!((report.vertices, report.triangles), (4, 2));
    assert_eq!(mesh.positions[2], glam::Vec3::Y);
}

#[test]
fn faces_of_fewer_than_three_corners_are_named_by_line() {
    let p = temp_file("short-faces.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 3\n");
    let e = load_err(&p);
    assert!(matches!(e, MeshError::Parse { line: Some(4), .. }), "{e}");
    assert!(e.to_string().contains("at least 3 corners, this one has 2"), "{e}");
}
