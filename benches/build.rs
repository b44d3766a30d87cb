//! Finds Embree 3 for the `versus` benchmark, which races it when it is installed (Debian's
//! `libembree-dev`). Nothing else links it: `cargo test`, the app and the CLI never need it.
//! Found: the cfg `embree` is set and the bench links `libembree3`; not found: the bench prints a
//! notice and races the others. `EMBREE_DIR=/some/lib` names another folder; `BVHSCOPE_NO_EMBREE=1`
//! leaves Embree out. Installed after a build? `touch benches/build.rs` so this looks again.

use std::path::PathBuf;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(embree)");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=EMBREE_DIR");
    println!("cargo::rerun-if-env-changed=BVHSCOPE_NO_EMBREE");
    if std::env::var_os("BVHSCOPE_NO_EMBREE").is_some_and(|v| v == "1") {
        return;
    }
    let mut dirs: Vec<PathBuf> = std::env::var_os("EMBREE_DIR").map(PathBuf::from).into_iter().collect();
    // Only a library built for the target: cross-compiling (to aarch64 on an x86-64 machine, say)
    // must not pick up the machine's own Embree.
    let arch = std::env::var("CARGO_CFG_TARGET_ARCH").unwrap_or_default();
    dirs.push(PathBuf::from(format!("/usr/lib/{arch}-linux-gnu")));
    if std::env::var("HOST").ok() == std::env::var("TARGET").ok() {
        dirs.extend(["/usr/lib", "/usr/local/lib"].map(PathBuf::from));
    }
    if let Some(dir) = dirs.iter().find(|d| d.join("libembree3.so").exists()) {
        println!("cargo::rustc-cfg=embree");
        println!("cargo::rustc-link-search=native={}", dir.display());
    }
}
