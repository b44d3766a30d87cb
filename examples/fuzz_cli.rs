//! The whole command line under a mutation fuzzer: dumps (JSON, text, gzip), scene files and OBJ
//! files made from real ones by random mutations (bytes flipped, inserted, deleted, repeated;
//! numbers replaced by extreme ones; lines and JSON items duplicated or dropped) are given to
//! `check`, `render`, `trace`, `inspect` and `stats` as a user would, each run in its own process
//! with a time limit. A run passes when it ends by itself within the limit with exit code 0, 1 or 2
//! and prints no panic; anything else (a panic, a signal, a hang) is kept in the output folder.
//!
//! ```sh
//! cargo build --release && cargo run --release --example fuzz_cli -- [SECONDS] [OUT_DIR]
//! # or on a copy of the binary: BVHSCOPE_BIN=/tmp/bvhscope target/release/examples/fuzz_cli 1800
//! ```
//! It prints how many inputs it tried and what failed (issue 34's closing note has a run's count).

use bvhscope::random::Rng;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A number in 0..n (0 for n = 0) from the run's generator, seeded by the run's start (the inputs
/// are kept, so a failure reproduces).
fn below(r: &mut Rng, n: usize) -> usize {
    r.below(n as u64) as usize
}

const EXTREMES: [&str; 14] = [
    "0",
    "-1",
    "1e400",
    "-1e400",
    "NaN",
    "inf",
    "4294967295",
    "4294967296",
    "65536",
    "256",
    "1e-45",
    "3.4e38",
    "",
    "99999999999999999999",
];

/// One mutation of `bytes`.
fn mutate(bytes: &mut Vec<u8>, r: &mut Rng) {
    if bytes.is_empty() {
        bytes.push(b'{');
    }
    // Numbers replaced most often: the file stays readable and the checker goes deep.
    match below(r, 12) {
        0 => {
            let i = below(r, bytes.len());
            bytes[i] ^= 1 << below(r, 8);
        }
        1 => {
            let i = below(r, bytes.len() + 1);
            let n = 1 + below(r, 16);
            let junk: Vec<u8> = (0..n).map(|_| r.next_u64() as u8).collect();
            bytes.splice(i..i, junk);
        }
        2 => {
            let a = below(r, bytes.len());
            let b = (a + 1 + below(r, 64)).min(bytes.len());
            bytes.drain(a..b);
        }
        3 => {
            // Repeat a chunk (a node, a line) many times.
            let a = below(r, bytes.len());
            let b = (a + 1 + below(r, 200)).min(bytes.len());
            let chunk = bytes[a..b].to_vec();
            let times = 1 + below(r, 50);
            for _ in 0..times {
                bytes.splice(b..b, chunk.iter().copied());
            }
        }
        4..=9 => {
            // Replace a number by an extreme one.
            let starts: Vec<usize> = (0..bytes.len())
                .filter(|&i| bytes[i].is_ascii_digit() && (i == 0 || !bytes[i - 1].is_ascii_alphanumeric()))
                .collect();
            if starts.is_empty() {
                return;
            }
            let a = starts[below(r, starts.len())];
            let mut b = a;
            while b < bytes.len() && (bytes[b].is_ascii_digit() || b".eE-+".contains(&bytes[b])) {
                b += 1;
            }
            let with = EXTREMES[below(r, EXTREMES.len())].as_bytes().to_vec();
            bytes.splice(a..b, with);
        }
        _ => {
            // Drop or duplicate a line.
            let lines: Vec<usize> = (0..bytes.len()).filter(|&i| bytes[i] == b'\n').collect();
            if lines.len() < 2 {
                return;
            }
            let k = below(r, lines.len() - 1);
            let (a, b) = (lines[k] + 1, lines[k + 1] + 1);
            if below(r, 2) == 0 {
                bytes.drain(a..b);
            } else {
                let line = bytes[a..b].to_vec();
                bytes.splice(b..b, line);
            }
        }
    }
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

/// Run `bin args`, at most `limit`: (exit code or None for a signal, stderr, timed out).
fn run(bin: &Path, args: &[String], limit: Duration) -> (Option<i32>, String, bool) {
    let mut child = Command::new(bin)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let mut err = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = Vec::new();
        let _ = err.by_ref().take(1 << 16).read_to_end(&mut s);
        String::from_utf8_lossy(&s).into_owned()
    });
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return (status.code(), reader.join().unwrap(), false);
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return (None, reader.join().unwrap(), true);
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seconds: u64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(600);
    let out = PathBuf::from(args.get(2).cloned().unwrap_or_else(|| "fuzz-out".into()));
    std::fs::create_dir_all(&out).unwrap();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    // BVHSCOPE_BIN: a copy of the binary, so that rebuilding meanwhile does not pull it away.
    let bin = std::env::var_os("BVHSCOPE_BIN").map_or_else(|| root.join("target/release/bvhscope"), PathBuf::from);
    assert!(bin.exists(), "build the release binary first (cargo build --release)");
    let torus = root.join("assets/torus.obj");
    let work = std::env::temp_dir().join(format!("bvhscope-fuzz-cli-{}", std::process::id()));
    std::fs::create_dir_all(&work).unwrap();
    // Seeds: the torus's trees of each layout and form, a scene, the OBJ itself.
    let mut seeds: Vec<(String, Vec<u8>)> = Vec::new();
    for (layout, ext) in [("binary", "json"), ("wide4", "txt"), ("wide8", "json"), ("binary", "txt")] {
        let p = work.join(format!("seed-{layout}.{ext}"));
        let s = Command::new(&bin)
            .args([
                "export-bvh",
                torus.to_str().unwrap(),
                "--layout",
                layout,
                "--max-leaf-size",
                "3",
                "-o",
                p.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        assert!(s.status.success());
        seeds.push((format!("dump.{ext}"), std::fs::read(&p).unwrap()));
    }
    let scene = format!(
        "{{\"camera\": {{\"position\": [0, 1, 5], \"look_at\": [0, 0, 0], \"size\": [32, 24]}},\n \"meshes\": [\n  {{\"file\": \"{}\", \"transform\": {{\"translate\": [1, 0, 0], \"scale\": 0.5}}}},\n  {{\"file\": \"{}\", \"transform\": {{\"matrix\": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}}}}\n ],\n \"bvh\": {{\"strategy\": \"sah\", \"max_leaf_size\": 4}}\n}}\n",
        torus.display(),
        torus.display()
    );
    seeds.push(("scene.json".into(), scene.into_bytes()));
    let obj = std::fs::read(&torus).unwrap();
    seeds.push(("mesh.obj".into(), obj[..obj.len().min(20_000)].to_vec()));

    let r =
        &mut Rng::new(std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().as_nanos() as u64);
    let start = Instant::now();
    let (mut tried, mut runs, mut failures) = (0u64, 0u64, 0u64);
    let mut codes = std::collections::BTreeMap::new();
    let limit = Duration::from_secs(30);
    while start.elapsed() < Duration::from_secs(seconds) {
        let (name, seed) = &seeds[below(r, seeds.len())];
        let mut bytes = seed.clone();
        for _ in 0..1 + below(r, 3) {
            mutate(&mut bytes, r);
        }
        let gz = name.starts_with("dump.json") && below(r, 4) == 0;
        let file = work.join(if gz { format!("case-{tried}.json.gz") } else { format!("case-{tried}-{name}") });
        std::fs::write(&file, if gz { gzip(&bytes) } else { bytes.clone() }).unwrap();
        tried += 1;
        let f = file.to_str().unwrap().to_string();
        let t = torus.to_str().unwrap().to_string();
        let png = work.join("out.png").to_str().unwrap().to_string();
        let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<String>>();
        let commands: Vec<Vec<String>> = if name.starts_with("dump") {
            let node = below(r, 400).to_string();
            vec![
                s(&["check", &t, "--bvh", &f, "--rays", "300", "--size", "16x12", "--no-compare"]),
                s(&["render", &t, "--bvh", &f, "--size", "16x12", "--view", "visits", "-o", &png]),
                s(&["trace", &t, "--bvh", &f, "--pixel", "8,6", "--size", "16x12"]),
                s(&["inspect", &t, "--bvh", &f, "--node", &node, "--size", "16x12"]),
            ]
        } else {
            vec![s(&["stats", &f, "--no-rays"]), s(&["render", &f, "--size", "16x12", "--view", "cost", "-o", &png])]
        };
        let mut kept = false;
        for c in commands {
            runs += 1;
            let (code, err, timed_out) = run(&bin, &c, limit);
            *codes.entry(code.map_or("signal/kill".to_string(), |c| c.to_string())).or_insert(0u64) += 1;
            let bad = timed_out || !matches!(code, Some(0..=2)) || err.contains("panicked");
            if bad {
                failures += 1;
                let why = if timed_out { "hang".to_string() } else { format!("exit {code:?}") };
                eprintln!("FAILURE ({why}): bvhscope {}\n{err}", c.join(" "));
                if !kept {
                    let keep = out.join(file.file_name().unwrap());
                    std::fs::copy(&file, &keep).unwrap();
                    kept = true;
                }
            }
        }
        if !kept {
            let _ = std::fs::remove_file(&file);
        }
        if tried % 200 == 0 {
            eprintln!("{tried} inputs, {runs} runs, {failures} failures, {:.0?}", start.elapsed());
        }
    }
    println!(
        "{tried} inputs, {runs} command runs in {:.0?}: {failures} failures (panics, signals, hangs over {limit:?}); exit codes {codes:?}",
        start.elapsed()
    );
    let _ = std::fs::remove_dir_all(&work);
}
