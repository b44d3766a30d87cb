//! Every mesh reader under hostile input, in process (issue 58): valid files of every format and
//! variant (`formats/mod.rs`) load with their triangle count, then each is mutated — bytes flipped,
//! cut short, bytes inserted, numbers in its header made huge, negative, fractional or NaN, and
//! for glTF node DAGs, hostile URIs, wrong component types, short strides and inflated counts —
//! and every case must answer within its time, never panic, hold at its peak no more than a fixed
//! multiple of the file's bytes (a counting allocator measures the reading thread), and when it
//! refuses, say where: a line, element or byte.
//!
//! `FUZZ_CASES=N` runs N mutations of each valid file instead of the default (CI keeps it short;
//! the README gives a long run's command and count).

#[path = "common/scratch.rs"]
mod scratch;

mod formats;

use bvhscope_core::mesh::{generate, is_gltf, load_gltf, load_mesh};
use bvhscope_core::random::Rng;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The system allocator, counting the bytes live on each thread and their peak.
struct Counting;

thread_local! {
    static LIVE: Cell<isize> = const { Cell::new(0) };
    static PEAK: Cell<isize> = const { Cell::new(0) };
}

fn count(delta: isize) {
    let _ = LIVE.try_with(|live| {
        let now = live.get() + delta;
        live.set(now);
        let _ = PEAK.try_with(|peak| peak.set(peak.get().max(now)));
    });
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            count(layout.size() as isize);
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            count(layout.size() as isize);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        count(-(layout.size() as isize));
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            count(new_size as isize - layout.size() as isize);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The most a read may hold at its peak: this many times the bytes of the file and the files it
/// names, and `SLACK` for any file (the glTF document's own structures, a message).
const PER_BYTE: usize = 64;
const SLACK: usize = 4 << 20;

fn cases(default: usize) -> usize {
    std::env::var("FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn dir(sub: &str) -> PathBuf {
    let d = scratch::shared("fuzz-formats").join(sub);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// What reading `path` gave: triangles and placements, or the error's words.
type Outcome = Result<(usize, usize), String>;

fn read(path: &Path) -> Outcome {
    if is_gltf(path) {
        let g = load_gltf(path).map_err(|e| e.to_string())?;
        Ok((g.meshes.iter().map(|m| m.triangles.len()).sum(), g.placements.len()))
    } else {
        let (m, _) = load_mesh(path).map_err(|e| e.to_string())?;
        Ok((m.triangles.len(), 0))
    }
}

/// Read `path` on a thread of its own: a panic or taking over 20 s fails; returns what it gave
/// and its peak of live bytes.
fn bounded(path: &Path) -> (Outcome, usize) {
    let (tx, rx) = std::sync::mpsc::channel();
    let p = path.to_path_buf();
    std::thread::spawn(move || {
        LIVE.with(|l| l.set(0));
        PEAK.with(|p| p.set(0));
        let got = std::panic::catch_unwind(|| read(&p));
        let peak = PEAK.with(|p| p.get()).max(0) as usize;
        let _ = tx.send(got.map(|g| (g, peak)));
    });
    match rx.recv_timeout(Duration::from_secs(20)) {
        Ok(Ok(v)) => v,
        Ok(Err(_)) => panic!("{}: the reader panicked", path.display()),
        Err(_) => panic!("{}: the reader took longer than 20 s", path.display()),
    }
}

/// Words that say where in a file a refusal is: every error must have one.
const PLACES: [&str; 20] = [
    "line",
    "vertex",
    "face",
    "triangle",
    "element",
    "header",
    "byte",
    "buffer",
    "accessor",
    "node",
    "mesh",
    "primitive",
    "the file",
    "the document",
    "GLB",
    "scene",
    "coordinate",
    "not a text file",
    "no triangles",
    "tristrips",
];

/// Write `bytes` (and the files it names) as `name` in a fresh folder, read it, check the bounds.
fn check(case: &str, name: &str, bytes: &[u8], beside: &[(String, Vec<u8>)]) -> Outcome {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let d = dir(&format!("case-{}", NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)));
    let path = d.join(name);
    std::fs::write(&path, bytes).unwrap();
    let mut size = bytes.len();
    for (n, b) in beside {
        std::fs::write(d.join(n), b).unwrap();
        size += b.len();
    }
    let (got, peak) = bounded(&path);
    assert!(
        peak <= PER_BYTE * size + SLACK,
        "{case}: {name} held {peak} bytes at its peak, from {size} bytes of files"
    );
    if let Err(e) = &got {
        assert!(e.starts_with(&path.display().to_string()), "{case}: the error names the file: {e}");
        assert!(!e.contains("\n"), "{case}: one line: {e}");
        assert!(PLACES.iter().any(|w| e.contains(w)), "{case}: the error says where: {e}");
    }
    let _ = std::fs::remove_dir_all(&d);
    got
}

#[test]
fn every_valid_sample_loads_with_its_triangles() {
    let m = generate::torus(1.0, 0.35, 6, 4);
    for s in formats::all(&m) {
        let got = check(&format!("valid-{}", s.name), &s.name, &s.bytes, &s.beside);
        assert_eq!(got, Ok((s.triangles, s.placements)), "{}", s.name);
    }
}

/// Numbers a header edit writes in place of one of the file's.
const NUMBERS: [&str; 9] =
    ["18446744073709551615", "4294967295", "2147483648", "-1", "0", "1.9", "nan", "1e39", "99999999"];

/// One mutation of `bytes`, and its name.
fn mutate(bytes: &[u8], rng: &mut Rng, gltf: bool) -> (Vec<u8>, String) {
    let mut b = bytes.to_vec();
    let at = |rng: &mut Rng, len: usize| rng.below(len.max(1) as u64) as usize;
    let kind = rng.below(if gltf { 7 } else { 5 });
    match kind {
        0 => {
            let n = 1 + rng.below(8);
            for _ in 0..n {
                let i = at(rng, b.len());
                if i < b.len() {
                    b[i] = rng.below(256) as u8;
                }
            }
            (b, format!("{n} bytes flipped"))
        }
        1 => {
            let i = at(rng, b.len());
            b.truncate(i);
            (b, format!("cut at {i}"))
        }
        2 => {
            let i = at(rng, b.len());
            let extra: Vec<u8> = (0..1 + rng.below(16)).map(|_| rng.below(256) as u8).collect();
            b.splice(i..i, extra);
            (b, format!("bytes inserted at {i}"))
        }
        3 | 4 => {
            // A number in the text (a header's count, a vertex's coordinate, a JSON field) replaced.
            let text_end = b.len().min(if kind == 3 { 1024 } else { b.len() });
            let digits: Vec<usize> = (0..text_end)
                .filter(|&i| b[i].is_ascii_digit() && (i == 0 || !b[i - 1].is_ascii_alphanumeric()))
                .collect();
            if digits.is_empty() {
                return (b, "no number to edit".into());
            }
            let s = digits[at(rng, digits.len())];
            let e = s + b[s..].iter().take_while(|c| c.is_ascii_digit() || **c == b'.').count();
            let n = NUMBERS[at(rng, NUMBERS.len())];
            b.splice(s..e, n.bytes());
            (b, format!("number at {s} made {n}"))
        }
        _ => {
            // glTF: an edit of its JSON a hostile file would make.
            const EDITS: [(&str, &str); 10] = [
                (r#""children": [1, 2]"#, r#""children": [1, 1, 2, 2]"#),
                (r#""nodes": [0]"#, r#""nodes": [0, 0, 0]"#),
                (r#""mesh": 0, "translation""#, r#""children": [0], "mesh": 0, "translation""#),
                ("fuzz%20data.bin", "../../../../../../etc/passwd"),
                ("fuzz%20data.bin", "/proc/self/environ"),
                (r#""componentType": 5123, "count""#, r#""componentType": 5126, "count""#),
                (r#""componentType": 5123, "count""#, r#""componentType": 5122, "count""#),
                (r#""byteOffset": 0, "byteLength""#, r#""byteOffset": 0, "byteStride": 4, "byteLength""#),
                (r#""count": 1,"#, r#""count": 0,"#),
                (r#""type": "SCALAR"}"#, r#""type": "SCALAR", "count": 4294967295}"#),
            ];
            let (from, to) = EDITS[at(rng, EDITS.len())];
            let text = String::from_utf8_lossy(&b).replacen(from, to, 1);
            (text.into_bytes(), format!("'{from}' made '{to}'"))
        }
    }
}

#[test]
fn mutated_samples_are_read_or_refused_in_bounds() {
    let m = generate::torus(1.0, 0.35, 6, 4);
    let n = cases(60);
    for (k, s) in formats::all(&m).into_iter().enumerate() {
        let gltf = s.name.ends_with(".gltf");
        for i in 0..n {
            let mut rng = Rng::at(58, (k * 1_000_000 + i) as u64);
            let (bytes, what) = mutate(&s.bytes, &mut rng, gltf);
            // A GLB's JSON edited in place would no longer match its chunk's length: its JSON is
            // mutated as a .gltf's is only through the byte-level kinds.
            let _ = check(&format!("{}-{i} ({what})", s.name), &s.name, &bytes, &s.beside);
        }
    }
}

#[test]
fn a_glb_with_chunk_lengths_past_its_end_or_below_its_header_is_refused() {
    let m = generate::torus(1.0, 0.35, 6, 4);
    let glb = formats::all(&m).into_iter().find(|s| s.name.ends_with(".glb")).unwrap();
    for (at, value) in [(8usize, 0u32), (8, 11), (8, u32::MAX), (12, u32::MAX), (12, 0), (4, 1)] {
        let mut b = glb.bytes.clone();
        b[at..at + 4].copy_from_slice(&value.to_le_bytes());
        let got = check(&format!("glb-{at}-{value}"), "edited.glb", &b, &[]);
        assert!(got.is_err(), "a GLB with {value} at byte {at} loaded");
    }
}
