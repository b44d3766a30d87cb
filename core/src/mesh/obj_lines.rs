//! Finding the line behind an OBJ loading failure: tobj says *what* is wrong, these scans of the
//! text say *where*, so the user can open the file at the right place.

use super::error::MeshError;
use std::borrow::Cow;
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
                        let what = ["vertex", "texture coordinate", "normal"][slot];
                        if idx == 0 {
                            return Some((
                                n,
                                format!("face refers to {what} 0: OBJ indices start at 1 (or count back from -1)"),
                            ));
                        }
                        if resolved < 1 || resolved > count {
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

/// The text with every lone carriage return (old Mac line ends, or a file whose line ends were
/// mixed up) made a line break, as CR LF and LF are: otherwise `v 0 0 0\rv 9 9 9` reads as one
/// vertex and every face after it points one vertex off. CR LF is left as it is.
pub(super) fn lone_cr_as_line_break(text: &str) -> std::borrow::Cow<'_, str> {
    use rayon::prelude::*;
    let b = text.as_bytes();
    let lone = |i: usize| b[i] == b'\r' && b.get(i + 1) != Some(&b'\n');
    // (In parallel pieces: a big file is scanned before anything else is read.)
    if !(0..b.len()).into_par_iter().with_min_len(1 << 16).any(lone) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        if c == '\r' && chars.peek() != Some(&'\n') {
            out.push('\n');
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

/// The first `v` statement with words after its coordinates that are not numbers (`v 0 0 0
/// garbage`), or more than a position, a weight and a colour: (line, why). Exporters write a
/// weight (`v x y z w`) or a colour (`v x y z r g b`, MeshLab, ZBrush), which are numbers and
/// are accepted (and not read); anything else is an error naming the line, not a vertex that
/// silently drops what followed it.
pub(super) fn first_vertex_with_words(text: &str) -> Option<(usize, String)> {
    statements(text).find_map(|(n, k, args)| {
        if k != "v" || args.len() <= 3 {
            return None;
        }
        if let Some(w) = args.iter().skip(3).find(|a| a.parse::<f32>().is_err()) {
            return Some((n, format!("'{w}' after the vertex's coordinates: a vertex is x y z, optionally followed by a weight w or a colour r g b")));
        }
        (args.len() > 7).then(|| (n, format!("a vertex of {} numbers: a vertex is x y z, optionally followed by a weight w or a colour r g b", args.len())))
    })
}

/// The text with comments that follow a statement on its line cut off (`v 0 1 0 # apex`), as
/// the OBJ format's `#` starts a comment wherever it is; tobj reads them as part of the
/// statement ("color parse error"). Lines keep their numbers. Borrowed when no line has one.
pub(super) fn cut_trailing_comments(text: &str) -> Cow<'_, str> {
    let trailing = text.match_indices('#').any(|(at, _)| {
        let start = text[..at].rfind('\n').map_or(0, |n| n + 1);
        !text[start..at].trim().is_empty()
    });
    if !trailing {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        match line.find('#') {
            Some(at) => {
                out.push_str(&line[..at]);
                if line.ends_with('\n') {
                    out.push('\n');
                }
            }
            None => out.push_str(line),
        }
    }
    Cow::Owned(out)
}
