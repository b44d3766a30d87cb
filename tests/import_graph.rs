//! The file-level import graph points one way (ARCHITECTURE.md, "Layers"; issue 62): inside
//! `core/src/{bvh,render,geometry,mesh,scene}` and `src/cli`, counted on the files' own `use`
//! lines, no two files import each other, directly or through others, and no file imports its
//! folder's `mod.rs` (or an enclosing one's): a `mod.rs` declares modules and the crate's public
//! face, and the crate imports each name from the file that defines it. Test modules are exempt
//! (`use super::*` is how a test reads what it tests).

#[path = "../core/tests/common/scratch.rs"]
mod scratch;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// `text` with comments and the insides of string and character literals blanked (same length),
/// so that braces and `use` inside them are not read as code.
fn strip(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let blank = |out: &mut Vec<u8>, from: usize, to: usize| {
        for c in &mut out[from..to.min(b.len())] {
            if *c != b'\n' {
                *c = b' ';
            }
        }
    };
    let mut i = 0;
    while i < b.len() {
        let ident_before = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if b[i..].starts_with(b"//") {
            let end = text[i..].find('\n').map_or(b.len(), |k| i + k);
            blank(&mut out, i, end);
            i = end;
        } else if b[i..].starts_with(b"/*") {
            let (mut depth, mut j) = (1, i + 2);
            while j < b.len() && depth > 0 {
                if b[j..].starts_with(b"/*") {
                    depth += 1;
                    j += 2;
                } else if b[j..].starts_with(b"*/") {
                    depth -= 1;
                    j += 2;
                } else {
                    j += 1;
                }
            }
            blank(&mut out, i, j);
            i = j;
        } else if !ident_before && (b[i..].starts_with(b"r#") || b[i..].starts_with(b"r\"")) {
            let hashes = b[i + 1..].iter().take_while(|&&c| c == b'#').count();
            let open = i + 1 + hashes;
            if b.get(open) != Some(&b'"') {
                i += 1;
                continue;
            }
            let close = format!("\"{}", "#".repeat(hashes));
            let end = text[open + 1..].find(&close).map_or(b.len(), |k| open + 1 + k);
            blank(&mut out, open + 1, end);
            i = end + close.len();
        } else if b[i] == b'"' {
            let mut j = i + 1;
            while j < b.len() && b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            blank(&mut out, i + 1, j);
            i = j + 1;
        } else if b[i] == b'\'' {
            // A character literal ('x', '\n', '\u{..}'), not a lifetime ('a).
            let len = if b.get(i + 1) == Some(&b'\\') {
                b.get(i + 3..).and_then(|r| r.iter().position(|&c| c == b'\'')).map(|k| k + 4)
            } else {
                text[i + 1..].chars().next().and_then(|c| {
                    let n = c.len_utf8();
                    (b.get(i + 1 + n) == Some(&b'\'')).then_some(n + 2)
                })
            };
            match len {
                Some(n) => {
                    blank(&mut out, i + 1, i + n - 1);
                    i += n;
                }
                None => i += 1,
            }
        } else {
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// A use tree (`a::{b, c::{d as e}}`) as its paths.
fn expand(tree: &str, prefix: &[String], out: &mut Vec<Vec<String>>) {
    for item in split_top(tree) {
        let item = item.trim();
        if item.is_empty() {
            continue;
        }
        match item.find('{') {
            None => {
                let path = item.split(" as ").next().unwrap_or(item);
                let mut p = prefix.to_vec();
                p.extend(path.split("::").map(str::trim).filter(|s| !s.is_empty()).map(String::from));
                out.push(p);
            }
            Some(k) => {
                let mut p = prefix.to_vec();
                p.extend(item[..k].split("::").map(str::trim).filter(|s| !s.is_empty()).map(String::from));
                expand(&item[k + 1..item.rfind('}').unwrap_or(item.len())], &p, out);
            }
        }
    }
}

fn split_top(t: &str) -> Vec<&str> {
    let (mut parts, mut depth, mut start) = (Vec::new(), 0, 0);
    for (i, c) in t.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&t[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&t[start..]);
    parts
}

/// One crate's source files by module path (`["bvh", "wide"]` for `bvh/wide/mod.rs`).
struct Crate {
    root: PathBuf,
    modules: BTreeMap<Vec<String>, PathBuf>,
}

impl Crate {
    fn read(root: &Path) -> Crate {
        let mut modules = BTreeMap::new();
        let mut todo = vec![root.to_path_buf()];
        while let Some(dir) = todo.pop() {
            for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
                let path = entry.expect("a directory entry").path();
                if path.is_dir() {
                    todo.push(path);
                } else if path.extension().is_some_and(|e| e == "rs") && path.file_name() != Some("main.rs".as_ref()) {
                    modules.insert(module_path(root, &path), path);
                }
            }
        }
        Crate { root: root.to_path_buf(), modules }
    }

    /// The file an absolute path (from the crate's root) names: its longest prefix that is a module.
    fn file_of(&self, path: &[String]) -> Option<&PathBuf> {
        (0..=path.len()).rev().find_map(|k| self.modules.get(&path[..k]))
    }

    /// Whether `file` is a test module: named `*_tests.rs` (how every test file is named), or
    /// declared under `#[cfg(test)]` by its parent module.
    fn is_test_file(&self, file: &Path) -> bool {
        if file.to_string_lossy().ends_with("_tests.rs") {
            return true;
        }
        let me = module_path(&self.root, file);
        let Some((name, parent)) = me.split_last() else { return false };
        let Some(parent_file) = self.modules.get(parent) else { return false };
        let text = strip(&std::fs::read_to_string(parent_file).expect("a source file"));
        let decl = format!("mod {name};");
        text.lines().collect::<Vec<_>>().windows(2).any(|w| w[0].contains("cfg(test)") && w[1].trim().ends_with(&decl))
    }

    /// Every file each file of the crate imports on its `use` lines (test modules left out).
    fn imports(&self) -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
        let mut graph: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
        for (me, file) in &self.modules {
            if self.is_test_file(file) {
                continue;
            }
            let text = strip(&std::fs::read_to_string(file).expect("a source file"));
            let inline = inline_modules(&text);
            let targets = graph.entry(file.clone()).or_default();
            let mut at = 0;
            while let Some(k) = text[at..].find("use ") {
                let start = at + k;
                at = start + 4;
                let line_start = text[..start].rfind('\n').map_or(0, |n| n + 1);
                let before = text[line_start..start].trim();
                let visibility = before == "pub" || (before.starts_with("pub(") && before.ends_with(')'));
                let inside: Vec<&InlineModule> = inline.iter().filter(|m| m.range.contains(&start)).collect();
                if !(before.is_empty() || visibility) || inside.iter().any(|m| m.test) {
                    continue;
                }
                // Inside `mod x { … }`, `self` and `super` start from `x`.
                let mut here = me.clone();
                here.extend(inside.iter().map(|m| m.name.clone()));
                let Some(end) = text[at..].find(';') else { break };
                let mut paths = Vec::new();
                expand(&text[at..at + end], &[], &mut paths);
                for p in paths {
                    // A relative path names a child module of the file's own module.
                    let declares = inside.is_empty();
                    if let Some(target) = self.resolve(&here, declares, &p).and_then(|abs| self.file_of(&abs)) {
                        if target != file {
                            targets.insert(target.clone());
                        }
                    }
                }
            }
        }
        graph
    }

    /// A `use` path of the file at module path `me` as an absolute module path; `None` for
    /// another crate's.
    fn resolve(&self, me: &[String], declares: bool, p: &[String]) -> Option<Vec<String>> {
        let (first, rest) = p.split_first()?;
        let mut abs = match first.as_str() {
            "crate" => Vec::new(),
            "self" => me.to_vec(),
            "super" => {
                let mut m = me.to_vec();
                m.pop();
                let mut rest = rest;
                while rest.first().is_some_and(|s| s == "super") {
                    m.pop();
                    rest = &rest[1..];
                }
                m.extend(rest.iter().cloned());
                return Some(m);
            }
            // A path relative to a module this file declares.
            name => {
                let mut child = me.to_vec();
                child.push(name.to_string());
                if !(declares && self.modules.contains_key(&child)) {
                    return None;
                }
                child.extend(rest.iter().cloned());
                return Some(child);
            }
        };
        abs.extend(rest.iter().cloned());
        Some(abs)
    }
}

fn module_path(root: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(root).expect("a file under the root").with_extension("");
    let mut parts: Vec<String> = rel.iter().map(|s| s.to_string_lossy().into_owned()).collect();
    if parts.last().is_some_and(|l| l == "mod" || (parts.len() == 1 && l == "lib")) {
        parts.pop();
    }
    parts
}

/// An inline module (`mod x { … }`): its byte range, its name, and whether it is `#[cfg(test)]`.
struct InlineModule {
    range: std::ops::Range<usize>,
    name: String,
    test: bool,
}

/// The inline modules of a file's (stripped) text.
fn inline_modules(text: &str) -> Vec<InlineModule> {
    let mut out = Vec::new();
    let mut at = 0;
    while let Some(k) = text[at..].find("mod ") {
        let start = at + k;
        at = start + 4;
        if start > 0 && (text.as_bytes()[start - 1].is_ascii_alphanumeric() || text.as_bytes()[start - 1] == b'_') {
            continue;
        }
        let rest = &text[start + 4..];
        let name: String = rest.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
        let after = rest[name.len()..].trim_start();
        if name.is_empty() || !after.starts_with('{') {
            continue;
        }
        let open = text.len() - after.len();
        let mut depth = 0;
        for (i, c) in text[open..].char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        // `#[cfg(test)]` among the attributes just before `mod`.
                        let before = &text[..start];
                        let attrs = before.rfind([';', '}', '{']).map_or(before, |e| &before[e + 1..]);
                        out.push(InlineModule { range: start..open + i, name, test: attrs.contains("cfg(test)") });
                        break;
                    }
                }
                _ => {}
            }
        }
    }
    out
}

/// Files of `folder` that lie on a loop of imports among its files (Tarjan's strongly connected
/// components, those of more than one file).
fn loops(graph: &BTreeMap<PathBuf, BTreeSet<PathBuf>>, folder: &Path) -> Vec<Vec<PathBuf>> {
    let nodes: Vec<&PathBuf> = graph.keys().filter(|f| f.starts_with(folder)).collect();
    let mut index = BTreeMap::new();
    let mut low = BTreeMap::new();
    let mut stack: Vec<&PathBuf> = Vec::new();
    let mut found = Vec::new();
    fn visit<'a>(
        v: &'a PathBuf,
        graph: &'a BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        folder: &Path,
        index: &mut BTreeMap<&'a PathBuf, usize>,
        low: &mut BTreeMap<&'a PathBuf, usize>,
        stack: &mut Vec<&'a PathBuf>,
        found: &mut Vec<Vec<PathBuf>>,
    ) {
        let n = index.len();
        index.insert(v, n);
        low.insert(v, n);
        stack.push(v);
        for w in graph.get(v).into_iter().flatten().filter(|w| w.starts_with(folder)) {
            if !index.contains_key(w) {
                visit(w, graph, folder, index, low, stack, found);
                low.insert(v, low[v].min(low[w]));
            } else if stack.contains(&w) {
                low.insert(v, low[v].min(index[w]));
            }
        }
        if low[v] == index[v] {
            let mut component = Vec::new();
            while let Some(w) = stack.pop() {
                component.push(w.clone());
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                component.sort();
                found.push(component);
            }
        }
    }
    for v in nodes {
        if !index.contains_key(v) {
            visit(v, graph, folder, &mut index, &mut low, &mut stack, &mut found);
        }
    }
    found
}

/// The checked folders: `(crate root, folders)`.
fn checked() -> [(PathBuf, &'static [&'static str]); 2] {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    [(here.join("core/src"), &["bvh", "render", "geometry", "mesh", "scene"]), (here.join("src"), &["cli"])]
}

/// The module file that holds a folder's declarations: `x/mod.rs`, or `x.rs` beside `x/`.
fn folder_module(file: &Path) -> Option<PathBuf> {
    if file.file_name() == Some("mod.rs".as_ref()) {
        return file.parent().map(Path::to_path_buf);
    }
    let dir = file.with_extension("");
    dir.is_dir().then_some(dir)
}

#[test]
fn no_file_imports_one_that_imports_it_back() {
    let mut problems = Vec::new();
    for (root, folders) in checked() {
        let graph = Crate::read(&root).imports();
        for folder in folders {
            for component in loops(&graph, &root.join(folder)) {
                let names: Vec<String> =
                    component.iter().map(|f| f.strip_prefix(&root).unwrap().display().to_string()).collect();
                problems.push(format!("a loop of imports: {}", names.join(", ")));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn no_file_imports_through_an_enclosing_module_file() {
    let mut problems = Vec::new();
    for (root, folders) in checked() {
        let graph = Crate::read(&root).imports();
        for (file, targets) in &graph {
            if !folders.iter().any(|f| file.starts_with(root.join(f))) {
                continue;
            }
            for target in targets {
                if let Some(dir) = folder_module(target) {
                    if file.starts_with(&dir) && folders.iter().any(|f| dir.starts_with(root.join(f))) {
                        let rel = |p: &Path| p.strip_prefix(&root).unwrap().display().to_string();
                        problems.push(format!("{} imports through {}", rel(file), rel(target)));
                    }
                }
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The checker itself: a made-up pair of files that import each other is a loop, and a file that
/// imports its folder's `mod.rs` is caught (so the two tests above can fail).
#[test]
fn the_checker_finds_a_loop_and_an_import_up() {
    let dir = scratch::shared("import-graph");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("a")).unwrap();
    std::fs::write(dir.join("lib.rs"), "pub mod a;\n").unwrap();
    std::fs::write(dir.join("a/mod.rs"), "mod x;\nmod y;\npub struct Up;\n#[cfg(test)]\nmod t;\n").unwrap();
    std::fs::write(
        dir.join("a/x.rs"),
        "use crate::a::y::{Y, self as why};\nuse super::Up;\npub struct X;\nmod inner {\n    use super::X;\n}\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("a/y.rs"),
        "// use crate::nothing;\nuse super::x::X; // \"}\"\npub struct Y;\n#[cfg(test)]\nmod tests {\n    use crate::a::Up;\n}\n",
    )
    .unwrap();
    std::fs::write(dir.join("a/t.rs"), "use super::*;\n").unwrap();
    let graph = Crate::read(&dir).imports();
    let a = dir.join("a");
    let found = loops(&graph, &a);
    assert_eq!(found, vec![vec![a.join("x.rs"), a.join("y.rs")]]);
    assert!(graph[&a.join("x.rs")].contains(&a.join("mod.rs")));
    assert_eq!(
        graph[&a.join("x.rs")].len(),
        2,
        "an inline module's `super` is its own file: {:?}",
        graph[&a.join("x.rs")]
    );
    assert!(!graph[&a.join("y.rs")].contains(&a.join("mod.rs")), "a test module's import is exempt");
    assert!(!graph.contains_key(&a.join("t.rs")) || graph[&a.join("t.rs")].is_empty(), "a test file is exempt");
    std::fs::remove_dir_all(&dir).unwrap();
}
