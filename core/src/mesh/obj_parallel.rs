//! A parallel reader for the plain OBJ files big meshes come as, giving exactly the models tobj
//! gives for them; anything it does not know, and every error, goes to tobj, which stays the
//! reference (`obj.rs`).
//!
//! Why it exists: tobj parses on one thread, and for the files of multi-million-triangle meshes that
//! alone takes most of the time we allow for loading and building them (figures: BENCHMARKS.md,
//! "Fifth round", Loading). OBJ lines are independent except for the face indices, which count the
//! vertices declared so far, and the object each face falls in. So the text is cut at line ends
//! into chunks, the chunks are parsed in parallel, and their counts are stitched with prefix sums.
//!
//! "Exactly" means: for a file this reader accepts, [`models`] returns the same `tobj::Model`s as
//! `tobj::load_obj_buf` with our options (`triangulate`, `single_index`, points and lines ignored):
//! the same positions, normals and texture coordinates in the same order (tobj numbers each
//! distinct `v/vt/vn` corner of an object in order of first use), the same indices and names.
//! The tests check that on every shared mesh and on generated files.
//!
//! Accepted: `v x y z`, `vt u v …` and `vn x y z …` (words after the second or third number are
//! ignored, as tobj ignores them), `f` with three or more corners that all have the same form
//! (`v`, `v/vt`, `v//vn` or `v/vt/vn`) and indices inside what was declared before the face, `o`,
//! `g`, `mtllib`, `usemtl <name>`, comments and other statements tobj ignores.
//! Declined, so tobj reads them: everything tobj fails on; vertex colours or weights, `l` lines,
//! points and mixed corner forms; and a few files tobj accepts but treats loosely (an index of 0,
//! a corner of four parts, a face naming a vertex declared after it), where declining is the safe
//! side.

use super::obj_numbering::{Numbering, MISSING, WIDTH};
use crate::parallel::{concat, region};
use rayon::prelude::*;

/// Chunks smaller than this are not worth a task.
const MIN_CHUNK: usize = 1 << 20;

/// tobj's models for `text`, read in parallel, or `None` when the file is not one this reader
/// takes (then tobj must read it).
pub(super) fn models(text: &str) -> Option<Vec<tobj::Model>> {
    models_in_chunks(text, chunk_count(text.len()))
}

fn chunk_count(len: usize) -> usize {
    (len / MIN_CHUNK).clamp(1, 8 * rayon::current_num_threads())
}

/// [`models`] with the text cut into (about) `chunks` pieces; the tests cut small files finely.
fn models_in_chunks(text: &str, chunks: usize) -> Option<Vec<tobj::Model>> {
    let pieces = split_at_lines(text, chunks);
    let mut parsed: Vec<Chunk> = region(|| pieces.par_iter().map(|p| Chunk::parse(p, None)).collect::<Option<_>>())?;

    // Each chunk's indices count from the vertices declared before it.
    let mut prefixes = Vec::with_capacity(parsed.len());
    let mut total = [0usize; 3];
    for c in &parsed {
        prefixes.push(total);
        for (t, n) in total.iter_mut().zip(c.counts()) {
            *t += n;
        }
    }
    if total.iter().any(|&n| n >= MISSING as usize) {
        return None;
    }
    // Relative (negative) indices need that prefix while parsing: read those chunks again.
    let again: Vec<usize> = (0..parsed.len()).filter(|&i| parsed[i].relative).collect();
    let redone: Vec<Chunk> =
        region(|| again.par_iter().map(|&i| Chunk::parse(pieces[i], Some(prefixes[i]))).collect::<Option<_>>())?;
    for (i, c) in again.into_iter().zip(redone) {
        parsed[i] = c;
    }
    // An absolute index may name a vertex of an earlier chunk, but not one declared later.
    let in_range = parsed.iter().zip(&prefixes).all(|(c, p)| (0..3).all(|a| c.beyond[a] <= p[a] as i64));
    let mut forms = parsed.iter().filter_map(|c| c.form);
    let form = forms.next();
    if !in_range || forms.any(|f| Some(f) != form) {
        return None;
    }
    Some(export(Stitched::new(parsed)))
}

/// Bytes per task of the passes over a whole file below.
const PASS_CHUNK: usize = 1 << 20;

/// Where the first `byte` is in `bytes`, looked for in parallel pieces.
pub(super) fn first_byte(bytes: &[u8], byte: u8) -> Option<usize> {
    let piece = region(|| bytes.par_chunks(PASS_CHUNK).position_first(|c| c.contains(&byte)))?;
    let start = piece * PASS_CHUNK;
    bytes[start..].iter().position(|&b| b == byte).map(|i| start + i)
}

/// The bytes as text, when they are UTF-8, checked in parallel pieces: each piece ends before an
/// ASCII byte (never inside a character), so the text is UTF-8 exactly when every piece is.
/// `None`: not UTF-8 (the caller decodes it lossily, on one thread, as before).
pub(super) fn utf8(bytes: &[u8]) -> Option<&str> {
    let mut cuts = vec![0];
    while let Some(&last) = cuts.last() {
        let at = (last + PASS_CHUNK).min(bytes.len());
        let cut = bytes[at..].iter().position(|&b| b < 0x80).map_or(bytes.len(), |i| at + i);
        cuts.push(cut);
        if cut == bytes.len() {
            break;
        }
    }
    let valid = region(|| cuts.par_windows(2).all(|w| std::str::from_utf8(&bytes[w[0]..w[1]]).is_ok()));
    // SAFETY: every piece is UTF-8 and each ends where a character starts (an ASCII byte, or
    // the end), so their concatenation, all of `bytes`, is UTF-8.
    valid.then(|| unsafe { std::str::from_utf8_unchecked(bytes) })
}

/// Items from this many on are converted in parallel (a big model's positions and triangles;
/// a file of many small objects must not pay the pool for each).
const PARALLEL_ITEMS: usize = 1 << 14;

/// `to` extended with `f` of each of `from`, in order (in parallel for many).
pub(super) fn extend_with<T: Sync, U: Send>(to: &mut Vec<U>, from: &[T], f: impl Fn(&T) -> U + Sync + Send) {
    if from.len() >= PARALLEL_ITEMS {
        region(|| to.par_extend(from.par_iter().map(f)));
    } else {
        to.extend(from.iter().map(f));
    }
}

/// Cut `text` after line ends into about `chunks` pieces of similar size.
fn split_at_lines(text: &str, chunks: usize) -> Vec<&str> {
    let bytes = text.as_bytes();
    let mut pieces = Vec::with_capacity(chunks);
    let mut start = 0;
    for k in 1..chunks {
        let target = (text.len() * k / chunks).max(start);
        let Some(nl) = bytes[target..].iter().position(|&b| b == b'\n') else { break };
        let end = target + nl + 1;
        if end > start {
            pieces.push(&text[start..end]);
            start = end;
        }
    }
    pieces.push(&text[start..]);
    pieces
}

/// Which attributes the face corners name (every corner of the file must be alike).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
struct Form {
    uv: bool,
    normal: bool,
}

/// What one chunk of lines holds.
#[derive(Default)]
struct Chunk {
    /// Positions (3 floats each), texture coordinates (2), normals (3), as declared.
    attrs: [Vec<f32>; 3],
    /// Corners of the triangles, fanned from each face's first corner as tobj does:
    /// indices of position, texture coordinate and normal, file-wide.
    corners: Vec<[u32; 3]>,
    form: Option<Form>,
    /// A negative index was met; its meaning needs the counts of the chunks before.
    relative: bool,
    /// Per attribute, the most an absolute index reaches past what this chunk had declared
    /// by its line; the chunks before must have declared at least that many.
    beyond: [i64; 3],
    /// `o` and `g` statements: (triangles of this chunk before it, the object's name).
    objects: Vec<(usize, String)>,
}

impl Chunk {
    /// Parse one piece; `prefix` is the count of each attribute declared before it, when known.
    fn parse(text: &str, prefix: Option<[usize; 3]>) -> Option<Chunk> {
        let mut chunk = Chunk::default();
        let prefix = prefix.map(|p| p.map(|n| n as i64));
        // Vertical tab is whitespace to tobj's `split_whitespace` but not to the faster ASCII
        // split; non-ASCII text may hold other Unicode spaces.
        let ascii = text.bytes().all(|b| b < 0x80 && b != 0x0b);
        for line in text.lines() {
            let ok = if ascii {
                chunk.line(line, line.split_ascii_whitespace(), prefix)
            } else {
                chunk.line(line, line.split_whitespace(), prefix)
            };
            if !ok {
                return None;
            }
        }
        Some(chunk)
    }

    fn counts(&self) -> [usize; 3] {
        [0, 1, 2].map(|a| self.attrs[a].len() / WIDTH[a])
    }

    /// One line, split into words as tobj splits it. `false`: leave this file to tobj.
    fn line<'a>(&mut self, line: &'a str, mut words: impl Iterator<Item = &'a str>, prefix: Option<[i64; 3]>) -> bool {
        match words.next() {
            // Exactly three coordinates: a fourth (weight) or three more (colour) go to tobj.
            Some("v") => floats(&mut words, &mut self.attrs[0], 3) && words.next().is_none(),
            // tobj reads two texture coordinates and three normal components, ignoring the rest.
            Some("vt") => floats(&mut words, &mut self.attrs[1], 2),
            Some("vn") => floats(&mut words, &mut self.attrs[2], 3),
            Some("f") => self.face(words, prefix),
            Some("l") => false,
            Some("o" | "g") => {
                // tobj names the object by the line after its first character, trimmed.
                let first = line.chars().next().map_or(0, char::len_utf8);
                let name = line[first..].trim();
                let name = if name.is_empty() { "unnamed_object" } else { name };
                self.objects.push((self.corners.len() / 3, name.to_owned()));
                true
            }
            // Materials are not read (`load_models` fails every .mtl), so `usemtl` never starts a
            // new model; tobj only rejects one without a name (as split at its first space).
            Some("usemtl") => !line.split_once(' ').unwrap_or_default().1.trim().is_empty(),
            // Comments, `mtllib`, `s` and whatever else tobj ignores.
            _ => true,
        }
    }

    /// A face, fanned into triangles from its first corner.
    fn face<'a>(&mut self, words: impl Iterator<Item = &'a str>, prefix: Option<[i64; 3]>) -> bool {
        let counts = self.counts().map(|n| n as i64);
        let mut n = 0;
        let (mut first, mut last) = ([0; 3], [0; 3]);
        for word in words {
            let Some((corner, form)) = self.corner(word, counts, prefix) else { return false };
            if *self.form.get_or_insert(form) != form {
                return false;
            }
            if n >= 2 {
                self.corners.extend([first, last, corner]);
            }
            if n == 0 {
                first = corner;
            }
            last = corner;
            n += 1;
        }
        n >= 3
    }

    /// One `v`, `v/vt`, `v//vn` or `v/vt/vn` corner, its indices made file-wide and 0-based.
    fn corner(&mut self, word: &str, counts: [i64; 3], prefix: Option<[i64; 3]>) -> Option<([u32; 3], Form)> {
        let mut index = [MISSING; 3];
        for (a, part) in word.split('/').enumerate() {
            if a >= 3 {
                return None;
            }
            if part.is_empty() {
                continue;
            }
            let x: i64 = part.parse::<isize>().ok()? as i64;
            let i = if x > 0 {
                self.beyond[a] = self.beyond[a].max(x - counts[a]);
                x - 1
            } else if x < 0 {
                // Counts back from the last declared: needs the chunks before.
                self.relative = true;
                let i = prefix.map_or(0, |p| p[a]) + counts[a] + x;
                if i < 0 && prefix.is_some() {
                    return None;
                }
                i.max(0)
            } else {
                return None;
            };
            index[a] = u32::try_from(i).ok().filter(|&i| i != MISSING)?;
        }
        (index[0] != MISSING).then_some((index, Form { uv: index[1] != MISSING, normal: index[2] != MISSING }))
    }
}

/// Parse the next `n` words as floats, as tobj does (Rust's own float syntax).
fn floats<'a>(words: &mut impl Iterator<Item = &'a str>, out: &mut Vec<f32>, n: usize) -> bool {
    for _ in 0..n {
        match words.next().map(str::parse::<f32>) {
            Some(Ok(x)) => out.push(x),
            _ => return false,
        }
    }
    true
}

/// All chunks as one file.
struct Stitched {
    attrs: [Vec<f32>; 3],
    corners: Vec<[u32; 3]>,
    objects: Vec<(usize, String)>,
}

impl Stitched {
    /// The chunks' lists one after the other, copied in parallel (a serial copy of a big file's
    /// attributes and corners was a tenth of its load on many threads).
    fn new(chunks: Vec<Chunk>) -> Stitched {
        let (mut attrs, mut corners, mut objects) = (<[Vec<Vec<f32>>; 3]>::default(), Vec::new(), Vec::new());
        let mut before = 0;
        for c in chunks {
            objects.extend(c.objects.into_iter().map(|(t, name)| (before + t, name)));
            before += c.corners.len() / 3;
            for (to, from) in attrs.iter_mut().zip(c.attrs) {
                to.push(from);
            }
            corners.push(c.corners);
        }
        Stitched { attrs: attrs.map(|a| concat(a, 0)), corners: concat(corners, 0), objects }
    }
}

/// Models as tobj makes them: an `o` or `g` after faces ends the current model; the last model
/// is always emitted, even with no faces.
fn export(all: Stitched) -> Vec<tobj::Model> {
    let mut numbering = Numbering::new(all.attrs[0].len() / 3);
    let mut models = Vec::with_capacity(all.objects.len() + 1);
    let (mut name, mut start) = ("unnamed_object".to_owned(), 0);
    for (at, next) in all.objects {
        if at > start {
            models.push(tobj::Model::new(numbering.mesh(&all.attrs, &all.corners[3 * start..3 * at]), name));
            start = at;
        }
        name = next;
    }
    models.push(tobj::Model::new(numbering.mesh(&all.attrs, &all.corners[3 * start..]), name));
    models
}

#[cfg(test)]
mod obj_parallel_tests;
