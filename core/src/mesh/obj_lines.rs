//! Finding the line behind an OBJ loading failure: tobj says *what* is wrong, these scans of the
//! text say *where*, so the user can open the file at the right place.

use super::error::MeshError;
use std::path::{Path, PathBuf};

/// 1-based line number of byte offset `pos`.
pub(super) fn line_at(bytes: &[u8], pos: usize) -> usize {
    bytes[..pos.min(bytes.len())].iter().filter(|&&b| b == b'\n').count() + 1
}

/// Lines of the file as (1-based number, keyword, rest of the tokens); comments dropped.
pub(super) fn statements(text: &str) -> impl Iterator<Item = (usize, &str, Vec<&str>)> {
    text.lines().enumerate().filter_map(|(i, line)| {
        let line = line.split('#').next().unwrap_or("");
        let mut tokens = line.split_whitespace();
        let keyword = tokens.next()?;
        Some((i + 1, keyword, tokens.collect()))
    })
}

/// First `keyword` line with fewer than `min` values, or whose first values fail `ok`.
fn first_line_where(text: &str, keyword: &str, min: usize, ok: impl Fn(&str) -> bool) -> Option<usize> {
    statements(text).find_map(|(n, k, args)| {
        let bad = args.len() < min || !args.iter().take(3).all(|a| ok(a));
        (k == keyword && bad).then_some(n)
    })
}

/// First `keyword` line whose first `min` values are missing, unparsable or not finite.
pub(super) fn first_bad_line(text: &str, keyword: &str, min: usize) -> Option<usize> {
    first_line_where(text, keyword, min, |a| a.parse::<f32>().is_ok_and(f32::is_finite))
}

/// First `keyword` line with a value that does not parse (or too few values).
fn first_unparsable_line(text: &str, keyword: &str, min: usize) -> Option<usize> {
    first_line_where(text, keyword, min, |a| a.parse::<f32>().is_ok())
}

/// Which attribute of a face corner (`v/vt/vn`) a check is about.
#[derive(Clone, Copy)]
pub(super) enum Corner {
    Position = 0,
    TexCoord = 1,
    Normal = 2,
}

/// First face line with a malformed corner, or an index of `which` outside what was declared
/// before it (OBJ indices are 1-based; negative ones count back from the last declared).
pub(super) fn first_bad_face(text: &str, which: Option<Corner>) -> Option<(usize, String)> {
    let mut counts = [0i64; 3];
    for (n, k, args) in statements(text) {
        match k {
            "v" => counts[0] += 1,
            "vt" => counts[1] += 1,
            "vn" => counts[2] += 1,
            "f" => {
                if which.is_none() && args.len() < 3 {
                    return Some((n, format!("a face needs at least 3 corners, this one has {}", args.len())));
                }
                for corner in &args {
                    if which.is_none() && corner.split('/').count() > 3 {
                        return Some((n, format!("face corner '{corner}' has more than three indices")));
                    }
                    for (slot, part) in corner.split('/').enumerate().take(3) {
                        if part.is_empty() && slot > 0 {
                            continue;
                        }
                        let Ok(idx) = part.parse::<i64>() else {
                            if which.is_none() {
                                return Some((n, format!("face corner '{corner}' is not a number")));
                            }
                            continue;
                        };
                        let Some(which) = which else { continue };
                        if slot != which as usize {
                            continue;
                        }
                        let count = counts[slot];
                        let resolved = if idx < 0 { count + idx + 1 } else { idx };
                        if idx == 0 || resolved < 1 || resolved > count {
                            let what = ["vertex", "texture coordinate", "normal"][slot];
                            return Some((
                                n,
                                format!("face refers to {what} {idx}, but only {count} are declared before this line"),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}

/// Turn tobj's error into ours, with the line found by scanning the text.
pub(super) fn diagnose(path: &Path, text: &str, e: tobj::LoadError) -> MeshError {
    use tobj::LoadError as L;
    let path: PathBuf = path.into();
    let parse = |line: Option<usize>, message: &str| MeshError::Parse {
        path: path.clone(),
        line,
        message: message.to_string(),
    };
    match e {
        L::PositionParseError => {
            parse(first_unparsable_line(text, "v", 3), "cannot read a vertex position (expected 3 numbers)")
        }
        L::NormalParseError => {
            parse(first_unparsable_line(text, "vn", 3), "cannot read a vertex normal (expected 3 numbers)")
        }
        L::TexcoordParseError => parse(first_unparsable_line(text, "vt", 1), "cannot read a texture coordinate"),
        L::FaceParseError | L::InvalidPolygon => match first_bad_face(text, None) {
            Some((line, msg)) => parse(Some(line), &msg),
            None => parse(None, &format!("invalid face ({e})")),
        },
        L::FaceVertexOutOfBounds | L::FaceTexCoordOutOfBounds | L::FaceNormalOutOfBounds => {
            let which = match e {
                L::FaceVertexOutOfBounds => Corner::Position,
                L::FaceTexCoordOutOfBounds => Corner::TexCoord,
                _ => Corner::Normal,
            };
            let (line, message) = match first_bad_face(text, Some(which)) {
                Some((line, msg)) => (Some(line), msg),
                None => (None, e.to_string()),
            };
            MeshError::IndexOutOfRange { path, line, message }
        }
        other => parse(None, &format!("not a valid OBJ file ({other})")),
    }
}
