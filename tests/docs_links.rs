//! The README and the manual (`docs/src/`, an mdBook) say only what is there: every relative link and
//! every repository path they name in backticks exists, every chapter is in the book's summary and
//! every summary entry is a chapter, the README stays a five-minute read (at most 220 lines, the two
//! commands first), and every `bvhscope` command in the README's examples is a real subcommand that
//! takes each flag the example gives it.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The README, the architecture map and every chapter of the book.
fn documents() -> Vec<PathBuf> {
    let mut files = vec![root().join("README.md"), root().join("ARCHITECTURE.md")];
    let mut chapters: Vec<PathBuf> = std::fs::read_dir(root().join("docs/src"))
        .expect("docs/src")
        .map(|e| e.expect("an entry of docs/src").path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    chapters.sort();
    files.extend(chapters);
    files
}

/// The targets of `[text](target)` links in `text`, with their line numbers.
fn links(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let mut rest = line;
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let end = after.find(')').unwrap_or(after.len());
            let target = &after[..end];
            if !target.contains(char::is_whitespace) {
                out.push((n + 1, target.to_string()));
            }
            rest = &after[end..];
        }
    }
    out
}

/// Words in backticks that name a file or folder of this repository (they start with one of its
/// top folders and hold no pattern or placeholder), with their line numbers. ARCHITECTURE.md's
/// worked examples name files a reader would add, so only its links are checked.
fn repo_paths(text: &str) -> Vec<(usize, String)> {
    const TOPS: [&str; 12] = [
        "core/",
        "src/",
        "gpu/",
        "tests/",
        "benches/",
        "examples/",
        "scenes/",
        "lessons/",
        "assets/",
        "docs/",
        ".ci/",
        "ui-tests/",
    ];
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        for (k, word) in line.split('`').enumerate() {
            let word = word.trim_end_matches(['.', ',', ':', ';']);
            let plain = !word.contains(|c: char| c.is_whitespace() || "*{}<>|$".contains(c));
            if k % 2 == 1 && plain && TOPS.iter().any(|t| word.starts_with(t)) {
                out.push((n + 1, word.split("::").next().unwrap_or(word).to_string()));
            }
        }
    }
    out
}

#[test]
fn every_link_and_path_the_documents_name_exists() {
    let mut missing = Vec::new();
    for doc in documents() {
        let text = read(&doc);
        let dir = doc.parent().expect("a folder");
        let name = doc.strip_prefix(root()).unwrap_or(&doc).display().to_string();
        for (line, target) in links(&text) {
            if target.starts_with("http://") || target.starts_with("https://") || target.starts_with('#') {
                continue;
            }
            let file = target.split('#').next().unwrap_or(&target);
            if !dir.join(file).exists() {
                missing.push(format!("{name}:{line}: link {target}"));
            }
        }
        if name != "ARCHITECTURE.md" {
            for (line, path) in repo_paths(&text) {
                if !root().join(&path).exists() {
                    missing.push(format!("{name}:{line}: path {path}"));
                }
            }
        }
    }
    assert!(missing.is_empty(), "named but not there:\n{}", missing.join("\n"));
}

#[test]
fn the_books_summary_lists_every_chapter_once() {
    let summary = read(&root().join("docs/src/SUMMARY.md"));
    let listed: Vec<String> = links(&summary).into_iter().map(|(_, t)| t).collect();
    for t in &listed {
        assert!(root().join("docs/src").join(t).exists(), "SUMMARY.md lists {t}, which is not there");
        assert_eq!(listed.iter().filter(|u| *u == t).count(), 1, "SUMMARY.md lists {t} twice");
    }
    for doc in documents().iter().filter(|d| d.starts_with(root().join("docs/src"))) {
        let name = doc.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        if name != "SUMMARY.md" {
            assert!(listed.iter().any(|t| t == name), "{name} is a chapter the summary does not list");
        }
    }
    assert!(
        read(&root().join("docs/book.toml")).contains("src = \"src\""),
        "docs/book.toml names the chapters' folder"
    );
}

#[test]
fn the_readme_is_short_and_opens_with_the_two_commands() {
    let readme = read(&root().join("README.md"));
    let lines = readme.lines().count();
    assert!(lines <= 220, "the README has {lines} lines; the manual is docs/");
    let head: Vec<&str> = readme.lines().take(6).collect();
    assert!(head.iter().any(|l| l.starts_with("cargo run --release --locked")), "{head:?}");
    assert!(head.iter().any(|l| l.starts_with("cargo test --workspace --locked")), "{head:?}");
}

#[test]
fn the_readmes_commands_are_real_subcommands_with_real_flags() {
    let readme = read(&root().join("README.md"));
    let mut in_sh = false;
    let mut checked = 0;
    for line in readme.lines() {
        if line.starts_with("```") {
            in_sh = line.trim() == "```sh";
            continue;
        }
        let Some(args) = line.strip_prefix("bvhscope ").filter(|_| in_sh) else { continue };
        let args = args.split('#').next().unwrap_or(args);
        let sub = args.split_whitespace().next().expect("a subcommand");
        let help = std::process::Command::new(env!("CARGO_BIN_EXE_bvhscope"))
            .args([sub, "--help"])
            .output()
            .expect("bvhscope runs");
        assert!(help.status.success(), "`bvhscope {sub}` is not a subcommand: {line}");
        let help = String::from_utf8_lossy(&help.stdout);
        for flag in args.split_whitespace().filter(|w| w.starts_with('-')) {
            assert!(help.contains(flag), "`bvhscope {sub}` takes no {flag}: {line}");
        }
        checked += 1;
    }
    assert!(checked >= 8, "the README's examples: {checked} commands found");
}
