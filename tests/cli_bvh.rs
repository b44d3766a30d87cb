//! The command line's bring-your-own-BVH commands as a user runs them: `check` of exported and
//! broken dumps, dumps that number triangles as the file does, the format's snippets, and
//! `render --bvh` through an imported tree.

mod cli_support;

use cli_support::{bvhscope, render_small_visits, tmp};
use std::path::PathBuf;
use std::process::Command;

/// `export-bvh` writes a built-in tree; `check` passes it (exit 0, the imported row equal to the
/// strategy's), finds a shrunken leaf box (exit 1, naming the node and the triangle, with wrong
/// rays), and refuses an unreadable dump in one line (exit 2).
#[test]
fn check_passes_an_exported_tree_and_names_what_is_wrong_with_a_broken_one() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let (good, bad, junk) = (tmp("good-bvh.txt"), tmp("bad-bvh.txt"), tmp("junk-bvh.json"));
    let p = |x: &PathBuf| x.to_str().unwrap().to_string();
    let out = bvhscope(&["export-bvh", torus, "--strategy", "midpoint", "-o", &p(&good)]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let check = |file: &PathBuf| bvhscope(&["check", torus, "--bvh", &p(file), "--rays", "20000", "--size", "64x48"]);
    let out = check(&good);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("0 defects"), "{text}");
    let row = |name: &str| {
        text.lines()
            .find(|l| l.starts_with(name))
            .unwrap()
            .split_whitespace()
            .skip(2) // "imported: FILE", "Midpoint, binary"
            .collect::<Vec<_>>()
    };
    assert_eq!(row("imported:"), row("Midpoint"), "the same nodes, depth, SAH, EPO and work per ray");

    // Shrink the first leaf's box to half its width in x.
    let dump = std::fs::read_to_string(&good).unwrap();
    let mut leaf = None;
    let lines: Vec<String> = dump
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let w: Vec<&str> = l.split_whitespace().collect();
            if leaf.is_none() && w.first() == Some(&"node") && w.get(7) == Some(&"leaf") {
                let node = dump.lines().take(i).filter(|x| x.starts_with("node ")).count();
                leaf = Some(node);
                let (lo, hi): (f32, f32) = (w[1].parse().unwrap(), w[4].parse().unwrap());
                let mut w: Vec<String> = w.iter().map(|s| s.to_string()).collect();
                w[4] = ((lo + hi) / 2.0).to_string();
                return w.join(" ");
            }
            l.to_string()
        })
        .collect();
    std::fs::write(&bad, lines.join("\n")).unwrap();
    let leaf = leaf.unwrap();
    let out = check(&bad);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(
        text.contains(&format!("1 leaf's box does not hold all its triangles: leaf node {leaf} (triangle ")),
        "{text}"
    );
    assert!(text.lines().any(|l| l.starts_with("bounds (")), "grouped: {text}");
    // The example ray, traced through the imported tree, misses what the linear scan hits.
    let example = text.lines().find(|l| l.contains("hit differently")).expect("wrong rays");
    let (flag, value) = match example.split("--pixel ").nth(1) {
        Some(rest) => ("--pixel", rest.split([' ', ')']).next().unwrap().to_string()),
        None => ("--ray", example.split("--ray ").nth(1).unwrap().split([' ', ')']).next().unwrap().to_string()),
    };
    let want: u32 =
        example.split("the linear scan hits triangle ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    let out = bvhscope(&["trace", torus, "--bvh", &p(&bad), flag, &value, "--size", "64x48", "--format", "json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["build"].as_str().unwrap().starts_with("imported:"));
    assert_ne!(v["hit"]["triangle"].as_u64(), Some(want as u64), "{example}");

    std::fs::write(&junk, r#"{"format": "bvhscope-bvh", "version": 7, "primitives": [], "nodes": []}"#).unwrap();
    let out = check(&junk);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("junk-bvh.json") && err.contains("version 7"), "{err}");
}

/// `check` of a small mesh: a few rays and a small frame.
fn check_small(mesh: &std::path::Path, dump: &std::path::Path) -> std::process::Output {
    let (m, d) = (mesh.to_str().unwrap(), dump.to_str().unwrap());
    bvhscope(&["check", m, "--bvh", d, "--rays", "2000", "--size", "32x24"])
}

/// Primitives are the file's triangle numbers, zero-area ones included (the loader drops those):
/// an exported dump of a mesh with a zero-area face skips its number, and the checker warns that
/// it is in no leaf without calling it a defect.
#[test]
fn dumps_number_triangles_as_the_file_does() {
    let obj = tmp("with-degenerate.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 2 1 0\nv 4 0 0\nv 5 0 0\nv 4 1 0\n\
         f 1 2 3\nf 1 2 2\nf 4 5 6\nf 7 8 9\n",
    )
    .unwrap();
    let dump = tmp("with-degenerate.json");
    let out = bvhscope(&["export-bvh", obj.to_str().unwrap(), "-o", dump.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&dump).unwrap()).unwrap();
    let mut prims: Vec<u64> = v["primitives"].as_array().unwrap().iter().map(|p| p.as_u64().unwrap()).collect();
    prims.sort();
    assert_eq!(prims, vec![0, 2, 3], "the zero-area face is number 1 in the file");
    let out = check_small(&obj, &dump);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(
        text.contains("1 degenerate (zero-area) triangle is in no leaf: harmless, no ray can hit it: triangle 1"),
        "{text}"
    );
}

/// The README's dumping snippets (examples/dump/): the C++ one compiled and run when a C++
/// compiler is present, the Python one when Python is; their dumps of a hand-made tree check clean.
#[test]
fn the_dumping_snippets_write_dumps_that_check_clean() {
    let dir = cli_support::scratch::shared("snippets");
    let row = dir.join("row.obj");
    let mut obj = String::new();
    for k in 0..4 {
        obj += &format!("v {k} 0 0\nv {} 0 0\nv {k} 1 0\n", k + 1);
    }
    for k in 0..4 {
        obj += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
    }
    std::fs::write(&row, obj).unwrap();
    let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/dump");
    let check = |dump: &std::path::Path| {
        let out = check_small(&row, dump);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let exe = dir.join("dump_bvh");
    match Command::new("c++").args(["-std=c++17", "-O1", "-o"]).arg(&exe).arg(examples.join("dump_bvh.cpp")).output() {
        Ok(out) if out.status.success() => {
            let run = Command::new(&exe).output().unwrap();
            let txt = dir.join("tree.txt");
            std::fs::write(&txt, run.stdout).unwrap();
            check(&txt);
        }
        Ok(out) => panic!("dump_bvh.cpp does not compile: {}", String::from_utf8_lossy(&out.stderr)),
        Err(_) => eprintln!("notice: no C++ compiler (c++): the C++ dumping snippet is not compiled"),
    }
    match Command::new("python3").arg(examples.join("dump_bvh.py")).output() {
        Ok(out) if out.status.success() => {
            let json = dir.join("tree.json");
            std::fs::write(&json, out.stdout).unwrap();
            check(&json);
        }
        Ok(out) => panic!("dump_bvh.py fails: {}", String::from_utf8_lossy(&out.stderr)),
        Err(_) => eprintln!("notice: no python3: the Python dumping snippet is not run"),
    }
    // The README walkthrough's broken dump: centroid boxes made from an exported tree are found
    // out, by the bounds they miss and the rays that miss with them.
    let (mid, bad) = (dir.join("mid.txt"), dir.join("centroid.txt"));
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    assert!(bvhscope(&["export-bvh", torus, "--strategy", "midpoint", "-o", mid.to_str().unwrap()]).status.success());
    if let Ok(out) = Command::new("python3").arg(examples.join("centroid_boxes.py")).arg(torus).arg(&mid).output() {
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        std::fs::write(&bad, out.stdout).unwrap();
        let out = bvhscope(&["check", torus, "--bvh", bad.to_str().unwrap(), "--rays", "2000", "--size", "48x32"]);
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(1), "{text}");
        assert!(text.contains("'s box leaves out") && text.contains("rays hit differently"), "{text}");
    }
}

/// `render --bvh FILE` traces an imported tree: an exported midpoint tree gives, pixel for pixel,
/// the counts of midpoint's own binary tree; with --against it is A of the difference.
#[test]
fn render_through_an_imported_tree() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let (dump, a, b, png, d) = (
        tmp("render-bvh.json"),
        tmp("render-bvh-a.csv"),
        tmp("render-bvh-b.csv"),
        tmp("render-bvh.png"),
        tmp("render-bvh-d.csv"),
    );
    let p = |x: &PathBuf| x.to_str().unwrap().to_string();
    assert!(bvhscope(&["export-bvh", torus, "--strategy", "midpoint", "-o", &p(&dump)]).status.success());
    let run = |extra: &[&str]| render_small_visits(torus, extra);
    run(&["--bvh", &p(&dump), "--counts", &p(&a), "-o", &p(&png)]);
    run(&["--strategy", "midpoint", "--counts", &p(&b), "-o", &p(&png)]);
    assert_eq!(
        std::fs::read_to_string(&a).unwrap(),
        std::fs::read_to_string(&b).unwrap(),
        "the same counts at every pixel"
    );
    let err = run(&["--bvh", &p(&dump), "--against", "sah", "--difference", &p(&d), "-o", &p(&png)]);
    assert!(err.contains("against A imported: render-bvh.json"), "{err}");

    // A 4-wide tree: exported, it checks clean with the same row as SAH's own 4-wide tree, and
    // traces pixel for pixel as that tree; a trace names its leaves by the dump's ids.
    let wide = tmp("render-bvh-wide.json");
    assert!(bvhscope(&["export-bvh", torus, "--layout", "wide4", "-o", &p(&wide)]).status.success());
    let out = bvhscope(&["check", torus, "--bvh", &p(&wide), "--rays", "5000", "--size", "48x32"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    let row = |name: &str| {
        let w: Vec<&str> = text.lines().find(|l| l.starts_with(name)).unwrap().split_whitespace().collect();
        w[w.len() - 6..].to_vec() // the six figures after the name
    };
    assert_eq!(row("imported:"), row("SAH binned, wide4"), "{text}");
    for (src, csv) in [(["--bvh", &p(&wide)], &a), (["--layout", "wide4"], &b)] {
        let args = [
            "render",
            torus,
            "--size",
            "48x32",
            "--view",
            "visits",
            src[0],
            src[1],
            "--counts",
            &p(csv),
            "-o",
            &p(&png),
        ];
        assert!(bvhscope(&args).status.success());
    }
    assert_eq!(std::fs::read_to_string(&a).unwrap(), std::fs::read_to_string(&b).unwrap(), "4-wide counts");
    let out =
        bvhscope(&["trace", torus, "--bvh", &p(&wide), "--pixel", "24,16", "--size", "48x32", "--format", "json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["build"], "imported: render-bvh-wide.json, wide4");
    let steps = v["steps"].to_string();
    assert!(steps.contains("\"step\":\"leaf\"") && !steps.contains("slot"), "leaves named as dump nodes: {steps}");
}
