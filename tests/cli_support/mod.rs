//! What the command-line tests share: the binary run as a user runs it, temporary files, a small
//! mesh of our own. (Apart from `common`, which the app's UI tests include too and which cannot
//! name the `bvhscope` binary.)
#![allow(dead_code)]

use std::path::PathBuf;

/// The `bvhscope` binary run with `args`, as a user runs it.
pub fn bvhscope(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_bvhscope")).args(args).output().expect("runs")
}

#[path = "../../core/tests/common/scratch.rs"]
pub mod scratch;

/// `name` in this test process's folder (removed when the process exits: `scratch`).
pub fn tmp(name: &str) -> PathBuf {
    scratch::shared("cli").join(name)
}

/// A small mesh of our own: four triangles forming a tent. Each call writes its own file: tests
/// run in parallel, and rewriting one shared file let a test read it half written.
pub fn tent() -> PathBuf {
    static CALLS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let p = tmp(&format!("tent-{}.obj", CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed)));
    std::fs::write(&p, "o tent\nv -1 0 -1\nv 1 0 -1\nv 0 1 0\nv -1 0 1\nv 1 0 1\nf 1 2 3\nf 3 4 5\nf 1 3 4\nf 2 5 3\n")
        .unwrap();
    p
}

/// `render MESH` of a small binary-layout visits heatmap with `extra` options; its stderr.
pub fn render_small_visits(mesh: &str, extra: &[&str]) -> String {
    let mut args = vec!["render", mesh, "--size", "48x32", "--view", "visits", "--layout", "binary"];
    args.extend(extra);
    let out = bvhscope(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stderr).into_owned()
}
