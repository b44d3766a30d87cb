//! The parallel reader against tobj: the same models, on hand-written, shared and generated files.

use super::*;

fn by_tobj(text: &str) -> Vec<tobj::Model> {
    super::super::obj::load_models(&mut std::io::Cursor::new(text.as_bytes())).expect("tobj reads it")
}

/// The same models, field by field (tobj's types do not implement `PartialEq`).
fn assert_same(ours: &[tobj::Model], theirs: &[tobj::Model], what: &str) {
    assert_eq!(ours.len(), theirs.len(), "{what}: model count");
    for (k, (a, b)) in ours.iter().zip(theirs).enumerate() {
        assert_eq!(a.name, b.name, "{what}: model {k} name");
        let (a, b) = (&a.mesh, &b.mesh);
        assert_eq!(a.indices, b.indices, "{what}: model {k} indices");
        // Bit for bit: NaN coordinates are read (our checks reject them later) and must match too.
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.positions), bits(&b.positions), "{what}: model {k} positions");
        assert_eq!(bits(&a.normals), bits(&b.normals), "{what}: model {k} normals");
        assert_eq!(bits(&a.texcoords), bits(&b.texcoords), "{what}: model {k} texcoords");
        assert!(a.vertex_color.is_empty() && b.vertex_color.is_empty(), "{what}: model {k} colours");
        assert_eq!(a.face_arities, b.face_arities, "{what}: model {k} arities");
    }
}

/// Read `text` cut into 1, 2, 3, 7 and 64 chunks; each must give tobj's models.
fn check(text: &str) {
    let theirs = by_tobj(text);
    for chunks in [1, 2, 3, 7, 64] {
        let ours = models_in_chunks(text, chunks).unwrap_or_else(|| panic!("declined in {chunks} chunks:\n{text}"));
        assert_same(&ours, &theirs, &format!("{chunks} chunks"));
    }
}

#[test]
fn shared_vertices_seams_and_objects_match_tobj() {
    // Two objects sharing positions; a seam (vertex 2 with two uvs); a quad and a pentagon.
    let text = "# a comment\nmtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0.5 0\n\
                vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1 0\nvn 0 0 1\r\nvn 0 0 -1 extra\n\
                o first\nusemtl red\nf 1/1/1 2/2/1 3/3/1 4/4/1\nf 2/1/1 5/2/1 3/3/1\ns off\n\
                g   second  \nf 1/1/2 2/2/2 5/3/2 3/1/2 4/4/2\no\nf 3/3/1 4/4/1 5/1/1\n";
    check(text);
}

#[test]
fn every_corner_form_and_relative_indices_match_tobj() {
    let head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nvn 1 0 0\n";
    for faces in [
        "f 1 2 3\nf 2 4 3\n",
        "f 1/1 2/2 3/3\nf 2/2 4/1 3/3\n",
        "f 1//1 2//1 3//2\nf 2//1 4//2 3//2\n",
        "f 1/1/1 2/2/1 3/3/2\nf -3/-2/-1 -1/-3/-1 -2/-1/-2\n",
        "f -4 -3 -2\nv 5 5 5\nf -1 -2 -3\n",
    ] {
        check(&format!("{head}{faces}"));
    }
}

#[test]
fn a_model_without_faces_is_kept_as_tobj_keeps_it() {
    check("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no trailing\n");
    check("o only\nv 0 0 0\n");
    check("");
}

#[test]
fn what_tobj_must_read_is_declined() {
    for text in [
        "v 0 0 0 1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",                   // a weight
        "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",               // a colour
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nf 1 2 3\n",              // a line
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",                       // a point or line face
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2 3\n",           // mixed forms
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",                     // out of range
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1 1 1\nf 4 2 3 0\n", // index 0
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n",               // no texture coordinates
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",                  // relative, too far back
        "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n",                     // not a number
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n",               // four parts
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl\nf 1 2 3\n",             // a material without a name
    ] {
        for chunks in [1, 3, 64] {
            assert!(models_in_chunks(text, chunks).is_none(), "accepted in {chunks} chunks:\n{text}");
        }
    }
}

#[test]
fn a_later_chunk_may_name_vertices_of_an_earlier_one_but_not_of_a_later_one() {
    let early = "v 0 0 0\nv 1 0 0\nv 0 1 0\n# padding\n# padding\nf 1 2 3\n";
    check(early);
    let late = "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
    for chunks in [1, 2, 4] {
        assert!(models_in_chunks(late, chunks).is_none(), "{chunks} chunks");
    }
}

#[test]
fn unicode_spaces_and_names_match_tobj() {
    // U+00A0 and the vertical tab separate words for tobj; the name keeps its accents.
    check("v\u{a0}0 0 0\nv 1\u{b}0 0\nv 0 1 0\no tête\nf 1 2 3\n");
}

/// Every OBJ among the shared meshes, read whole and in many pieces, gives tobj's models.
/// Absent folder: skipped with a notice, except under CI=true, where it is promised.
#[test]
fn shared_meshes_match_tobj() {
    // The core crate sits in core/ of the checkout; the shared folder is beside the checkout.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/models");
    if !dir.is_dir() {
        assert!(std::env::var("CI").map_or(true, |v| v != "true"), "CI=true but {} is missing", dir.display());
        use std::io::Write;
        let _ = writeln!(std::io::stderr(), "notice: {} not found; skipping", dir.display());
        return;
    }
    let mut files = vec![];
    let mut dirs = vec![dir];
    while let Some(d) = dirs.pop() {
        for entry in std::fs::read_dir(d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj")) {
                files.push(path);
            }
        }
    }
    assert!(files.len() >= 7, "the shared meshes: {files:?}");
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        let theirs = by_tobj(&text);
        for chunks in [1, 5, 64] {
            let ours = models_in_chunks(&text, chunks).unwrap_or_else(|| panic!("{} declined", path.display()));
            assert_same(&ours, &theirs, &format!("{} in {chunks} chunks", path.display()));
        }
    }
}

use proptest::prelude::*;

/// A random plain OBJ file: vertices, texture coordinates and normals interleaved with faces
/// of 3–6 corners of one form, absolute (sometimes `+n`) or relative indices, objects (sometimes
/// after leading whitespace), comments, materials, blank lines and CRLF line ends; numbers in
/// plain or exponent form, now and then NaN or infinite; words separated by spaces, tabs,
/// vertical tabs or no-break spaces; extra words after `vt` and `vn`; corners like `1/` and `1//`.
fn obj_text() -> impl Strategy<Value = String> {
    let line = prop_oneof![
        4 => (0u8..3, any::<[i16; 4]>()).prop_map(|(a, x)| (a, x.to_vec())),
        3 => (3u8..4, proptest::collection::vec(any::<i16>(), 3..7)),
        1 => (4u8..8, any::<[i16; 4]>()).prop_map(|(a, x)| (a, x.to_vec())),
    ];
    (any::<(bool, bool)>(), any::<bool>(), proptest::collection::vec(line, 1..60)).prop_map(
        |((uv, normal), crlf, lines)| {
            let mut counts = [0i64; 3];
            let mut out = String::new();
            for (kind, x) in lines {
                let sep = ["\t", "\u{b}", "\u{a0}", "  "].get(x[0].rem_euclid(16) as usize).unwrap_or(&" ");
                let num = |k: usize| match x[k].rem_euclid(61) {
                    0 => "nan".to_owned(),
                    1 => "-inf".to_owned(),
                    2..=9 => format!("{:e}", x[k] as f32 / 8.0),
                    _ => format!("{}", x[k] as f32 / 64.0),
                };
                let extra = if x.len() == 4 && x[3] % 5 == 0 { format!("{sep}{}", num(3)) } else { String::new() };
                match kind {
                    0 => out += &format!("v{sep}{}{sep}{}{sep}{}", num(0), num(1), num(2)),
                    1 => out += &format!("vt{sep}{}{sep}{}{extra}", num(0), num(1)),
                    2 => out += &format!("vn{sep}{}{sep}{}{sep}{}{extra}", num(0), num(1), num(2)),
                    3 => {
                        let needed = [true, uv, normal];
                        if (0..3).any(|a| needed[a] && counts[a] == 0) {
                            continue;
                        }
                        out += "f";
                        for (c, &r) in x.iter().enumerate() {
                            let index = |a: usize| {
                                let i = (r as i64 + 7 * a as i64).rem_euclid(counts[a]);
                                // Every third corner counts back from the last declared.
                                match (c + a) % 3 {
                                    2 => format!("{}", i - counts[a]),
                                    1 if r % 2 == 0 => format!("+{}", i + 1),
                                    _ => format!("{}", i + 1),
                                }
                            };
                            let tail = ["", "/", "//"][r.rem_euclid(3) as usize];
                            out += &match (uv, normal) {
                                (false, false) => format!(" {}{tail}", index(0)),
                                (true, false) => format!(" {}/{}", index(0), index(1)),
                                (false, true) => format!(" {}//{}", index(0), index(2)),
                                (true, true) => format!(" {}/{}/{}", index(0), index(1), index(2)),
                            };
                        }
                    }
                    4 => out += &format!("{}o part{}", if x[1] % 4 == 0 { " " } else { "" }, x[0] % 4),
                    5 => out += &format!("g  group {} ", x[0] % 3),
                    6 => out += &format!("usemtl m{}\n# note {}", x[0], x[1]),
                    _ => out += "",
                }
                if kind < 3 {
                    counts[kind as usize] += 1;
                }
                out += if crlf { "\r\n" } else { "\n" };
            }
            out
        },
    )
}

proptest! {
    #[test]
    fn generated_files_match_tobj(text in obj_text()) {
        check(&text);
    }
}
