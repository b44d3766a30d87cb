//! Where tests write their files: one folder per test process, `bvhscope-test-PID` in the
//! system's temporary folder, removed when the process exits, whether its tests passed or failed
//! (a process killed midway leaves it). Each test binary used to leave its folders behind, some
//! 140 MB a run of the test command. `BVHSCOPE_KEEP_TEST_FILES=1` keeps them, to look at after a
//! failure. Included by `#[path]` wherever tests write files (core's unit and integration tests,
//! the top-level package's and the UI tests'), so it is written once; it needs `libc` for
//! `atexit`, std having no hook that runs when the test harness exits.
#![allow(dead_code)]

use std::path::PathBuf;
use std::sync::Once;

/// This process's folder, made on first use (and its removal at exit arranged then).
pub fn root() -> PathBuf {
    static ARRANGED: Once = Once::new();
    ARRANGED.call_once(|| {
        if std::env::var_os("BVHSCOPE_KEEP_TEST_FILES").is_none() {
            // SAFETY: atexit(3) is given a function that takes nothing and returns nothing; it
            // touches only this process's own folder.
            unsafe {
                libc::atexit(remove_root);
            }
        }
    });
    let root = root_path();
    std::fs::create_dir_all(&root).unwrap();
    root
}

fn root_path() -> PathBuf {
    std::env::temp_dir().join(format!("bvhscope-test-{}", std::process::id()))
}

extern "C" fn remove_root() {
    let _ = std::fs::remove_dir_all(root_path());
}

/// Remove this process's folder now, unless `BVHSCOPE_KEEP_TEST_FILES` is set: for a process that
/// ends without running the `atexit` handlers (the UI tests, `support::end_without_teardown`).
pub fn remove_unless_kept() {
    if std::env::var_os("BVHSCOPE_KEEP_TEST_FILES").is_none() {
        remove_root();
    }
}

/// A fresh, empty folder `name` in this process's folder (emptied if this process made it
/// before: tests that share a name run one after the other in the same process only).
pub fn dir(name: &str) -> PathBuf {
    let d = root().join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The folder `name` in this process's folder, made if missing and never emptied: for helpers
/// that many tests of one process call to write their files side by side.
pub fn shared(name: &str) -> PathBuf {
    let d = root().join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}
