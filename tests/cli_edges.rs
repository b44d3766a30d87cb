//! The last edges (issue 47): one ray's walk listed in memory that does not grow with it, two
//! outputs that are one file under two spellings, output that cannot be written, OBJ line ends
//! and words after a vertex, a scene of too many placements, a read-only target, and `check`'s
//! rays aimed at every triangle.

mod cli_support;

use cli_support::{bvhscope, tmp};
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The bytes live on the heap now and at most since `PEAK` was last reset.
struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            let now = LIVE.fetch_add(l.size(), Ordering::Relaxed) + l.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        LIVE.fetch_sub(l.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// The tests that measure the heap run one at a time (the others here allocate little).
static MEASURING: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn s(p: &std::path::Path) -> String {
    p.to_str().unwrap().to_string()
}

/// Bytes of the output kept for reading back.
const HEAD: usize = 8 << 20;

/// A sink that counts what is written and keeps the first bytes.
struct Sink {
    bytes: usize,
    head: Vec<u8>,
}

impl std::io::Write for Sink {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        self.bytes += b.len();
        if self.head.len() < HEAD {
            self.head.extend_from_slice(&b[..b.len().min(HEAD - self.head.len())]);
        }
        Ok(b.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// The 100,000-deep chain (a correct tree: every box the mesh's), its mesh and its dump.
fn chain() -> (PathBuf, PathBuf) {
    let n = 100_000usize;
    let side = ((n + 1) as f64).sqrt() as usize + 1;
    let mut obj = String::new();
    for k in 0..=n {
        let (x, y) = (k % side, k / side);
        obj += &format!("v {x} {y} 0\nv {}.9 {y} 0\nv {x} {}.9 0\n", x, y);
    }
    for k in 0..=n {
        obj += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
    }
    let mesh = tmp("chain100k.obj");
    std::fs::write(&mesh, obj).unwrap();
    let b = format!("\"min\": [0, 0, 0], \"max\": [{}, {}, 0]", side + 1, side + 1);
    let mut nodes = Vec::with_capacity(2 * n + 1);
    for k in 0..n {
        nodes.push(format!("{{{b}, \"children\": [{}, {}]}}", 2 * k + 1, 2 * k + 2));
        nodes.push(format!("{{{b}, \"first\": {k}, \"count\": 1}}"));
    }
    nodes.push(format!("{{{b}, \"first\": {n}, \"count\": 1}}"));
    let prims: Vec<String> = (0..=n).map(|k| k.to_string()).collect();
    let dump = tmp("chain100k.json");
    std::fs::write(
        &dump,
        format!(
            "{{\"format\": \"bvhscope-bvh\", \"version\": 1, \"primitives\": [{}], \"nodes\": [{}]}}",
            prims.join(","),
            nodes.join(",")
        ),
    )
    .unwrap();
    (mesh, dump)
}

/// `trace --format json` of a ray down the 100,000-deep chain: 800,000 steps listed as the walk
/// goes, the heap never past 300 MB (it took 6.4 GB when the walk was kept), the JSON whole; with
/// `--max-steps` the listing stops there, the hit and counts are the whole walk's, and it says so.
#[test]
fn a_walk_of_any_length_is_listed_in_bounded_memory() {
    let _one = MEASURING.lock().unwrap_or_else(|p| p.into_inner());
    let (mesh, dump) = chain();
    let run = |extra: &[&str]| {
        let mut words = vec!["bvhscope", "trace"];
        let (m, d) = (s(&mesh), s(&dump));
        words.extend([m.as_str(), "--bvh", d.as_str(), "--ray", "0.45,0.2,5:0,0,-1", "--format", "json"]);
        words.extend(extra);
        let cli = bvhscope::cli::Cli::from_words(&words).unwrap();
        let Some(bvhscope::cli::Command::Trace(args)) = cli.command else { panic!("trace") };
        let mut sink = Sink { bytes: 0, head: Vec::new() };
        let before = LIVE.load(Ordering::Relaxed);
        PEAK.store(before, Ordering::Relaxed);
        bvhscope::cli::trace::write(&args, &mut sink).unwrap();
        (sink, PEAK.load(Ordering::Relaxed) - before)
    };
    let (all, peak) = run(&[]);
    assert!(all.bytes > 50 << 20, "800,000 steps written: {} bytes", all.bytes);
    assert!(peak < 300 << 20, "the heap grew by {} MB", peak >> 20);
    let (cut, _) = run(&["--max-steps", "1000"]);
    let v: serde_json::Value = serde_json::from_slice(&cut.head).expect("the JSON is whole");
    assert_eq!(v["steps"].as_array().unwrap().len(), 1000);
    assert!(v["steps_left_out"].as_u64().unwrap() > 500_000, "{}", v["steps_left_out"]);
    assert_eq!(v["counts"]["nodes_visited"], 200_001, "the whole walk's counts");
    assert_eq!(v["hit"]["triangle"], 0, "the whole walk's hit: the first strip");
    assert!(v["note"].as_str().unwrap().starts_with("the first 1000 steps are listed (--max-steps)"), "{}", v["note"]);
}

/// Two outputs of one command that are one file under two spellings are refused before anything
/// is written, as the same name always was.
#[test]
fn two_outputs_that_are_one_file_are_refused() {
    let dir = tmp("same-out");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("d")).unwrap();
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let (a, b) = (s(&dir.join("same.csv")), s(&dir.join("d/../same.csv")));
    let png = s(&dir.join("x.png"));
    let r = bvhscope(&[
        "render",
        torus,
        "--view",
        "visits",
        "--against",
        "midpoint",
        "--size",
        "16x16",
        "--counts",
        &a,
        "--difference",
        &b,
        "-o",
        &png,
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(err.contains("refusing to overwrite it"), "{err}");
    assert!(!dir.join("same.csv").exists() && !dir.join("x.png").exists(), "nothing written");
}

/// Output that cannot be written (`> /dev/full`) is one line on stderr and exit 2, never exit 0
/// over an answer nobody got.
#[cfg(target_os = "linux")]
#[test]
fn a_failed_write_to_stdout_is_an_error() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let dump = tmp("full-check.json");
    assert!(bvhscope(&["export-bvh", torus, "-o", &s(&dump)]).status.success());
    for args in [
        vec!["check", torus, "--bvh", dump.to_str().unwrap(), "--format", "json", "--rays", "10", "--no-compare"],
        vec!["stats", torus, "--no-rays"],
        vec!["inspect", torus, "--node", "1"],
        vec!["trace", torus, "--pixel", "3,3", "--size", "8x8"],
    ] {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let r = std::process::Command::new(env!("CARGO_BIN_EXE_bvhscope")).args(&args).stdout(full).output().unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("cannot write to standard output"), "{args:?}: {err}");
    }
}

/// CR, LF and CR LF all end a line of an OBJ; words after a vertex's coordinates that are not a
/// weight or a colour are an error naming the line; a colour is read past.
#[test]
fn obj_line_ends_and_words_after_a_vertex() {
    use bvhscope::mesh::parse_obj;
    let p = std::path::Path::new("m.obj");
    let lf = "v 0 0 0\nv 9 9 9\nv 0 9 0\nf 1 2 3\n";
    for text in [
        lf.to_string(),
        lf.replace('\n', "\r"),
        lf.replace('\n', "\r\n"),
        "v 0 0 0\rv 9 9 9\r\nv 0 9 0\nf 1 2 3".into(),
    ] {
        let (m, _) = parse_obj(p, &text).unwrap();
        assert_eq!(m.triangle(0)[1], glam::Vec3::splat(9.0), "{text:?}");
        assert_eq!(m.positions.len(), 3);
    }
    let e = parse_obj(p, "v 0 0 0\nv 1 0 0 garbage here\nv 0 1 0\nf 1 2 3\n").unwrap_err().to_string();
    assert!(e.starts_with("m.obj: line 2: 'garbage' after the vertex's coordinates"), "{e}");
    let (m, _) = parse_obj(p, "v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 0 1 0 0.5\nf 1 2 3\n").unwrap();
    assert_eq!(m.triangle_count(), 1, "a colour and a weight are numbers, read past");
}

/// A scene file of more placements than a scene file may hold is refused, in one line naming
/// the file, before a JSON value is made of it.
#[test]
fn a_scene_of_too_many_placements_is_refused_early() {
    let dir = tmp("placements");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let n = bvhscope::scene::MAX_PLACEMENTS + 1;
    let one = "{\"file\": \"t.obj\"}";
    let text = format!("{{\"meshes\": [{}]}}", vec![one; n].join(","));
    let path = dir.join("many.json");
    std::fs::write(&path, text).unwrap();
    let _one = MEASURING.lock().unwrap_or_else(|p| p.into_inner());
    let before = LIVE.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    let e = bvhscope::scene::describe(&path).unwrap_err().to_string();
    assert!(
        e.ends_with(&format!("meshes: {n} placements, more than the {} bvhscope reads from one file", n - 1)),
        "{e}"
    );
    let grew = PEAK.load(Ordering::Relaxed) - before;
    assert!(grew < 64 << 20, "refused before the JSON was parsed: {} MB", grew >> 20);
}

/// A read-only file is not replaced by an output of that name (the atomic rename would replace
/// it whatever its mode): refused as a shell's `>` refuses it, the file untouched.
#[cfg(unix)]
#[test]
fn a_read_only_target_is_refused() {
    use std::os::unix::fs::PermissionsExt;
    let keep = tmp("keep.png");
    std::fs::write(&keep, b"mine").unwrap();
    std::fs::set_permissions(&keep, std::fs::Permissions::from_mode(0o444)).unwrap();
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let r = bvhscope(&["render", torus, "--size", "16x16", "-o", &s(&keep)]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(err.contains("keep.png: is read-only: refusing to replace it"), "{err}");
    assert_eq!(std::fs::read(&keep).unwrap(), b"mine");
}

/// `check`'s rays: the frame's, then seven aimed at each triangle (its corners, edge midpoints and
/// centre), then the random ones; each aimed ray goes through its point.
#[test]
fn checks_aim_rays_at_every_triangle() {
    let mesh = bvhscope::mesh::generate::torus_knot(2, 3, 0.3, 32, 4);
    let camera = bvhscope::render::Camera::framing(&mesh.bounds(), 8, 6);
    let set = bvhscope::explain::check::RaySet::checking(&mesh, &camera, 100);
    let tris = mesh.triangle_count() as u64;
    assert_eq!(set.len(), 48 + 7 * tris + 100);
    for t in [0, 5, tris - 1] {
        let v = mesh.triangle(t as u32);
        let points = [v[0], v[1], v[2], (v[0] + v[1]) * 0.5, (v[1] + v[2]) * 0.5, (v[2] + v[0]) * 0.5];
        for (k, p) in points.iter().enumerate() {
            let (ray, pixel) = set.ray(48 + 7 * t + k as u64);
            assert!(pixel.is_none());
            let at = ray.origin() + ray.dir();
            assert!((at - *p).length() < 1e-4, "triangle {t} point {k}: {at} vs {p}");
        }
    }
}
