//! The command line under adversarial input (issue 34): a correct tree of any depth is checked,
//! traced and drawn; wrong trees are never passed; no output overwrites an input or a file of
//! another kind, and a refused or failed write leaves the old file; dumps that are not regular
//! files, or decompress without end, or ask for millions of references, are refused at once;
//! every finite heatmap range draws; the smaller refusals name what is wrong.

mod cli_support;
#[path = "common/mod.rs"]
mod common;

use cli_support::{bvhscope, tmp};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn p(x: &Path) -> String {
    x.to_str().unwrap().to_string()
}

/// `n` stacked unit triangles and a correct chain-shaped dump over them (depth n - 1), in files.
fn chain(n: u32, name: &str) -> (PathBuf, PathBuf) {
    let (obj, json) = (tmp(&format!("{name}.obj")), tmp(&format!("{name}.json")));
    let (o, d) = common::chain_texts(n, None);
    std::fs::write(&obj, o).unwrap();
    std::fs::write(&json, d).unwrap();
    (obj, json)
}

/// A chain of 140 (past the traversal stack's old fixed 128 entries: check panicked, then hung)
/// and one of 5,000: `check` passes it, `render` and `trace` draw and walk it.
#[test]
fn a_deep_correct_chain_is_checked_rendered_and_traced() {
    for n in [140, 5000] {
        let (obj, json) = chain(n, &format!("chain-{n}"));
        let start = Instant::now();
        let out =
            bvhscope(&["check", &p(&obj), "--bvh", &p(&json), "--rays", "5000", "--size", "32x24", "--no-compare"]);
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(0), "{text}{}", String::from_utf8_lossy(&out.stderr));
        assert!(text.contains("0 defects"), "{text}");
        assert!(start.elapsed() < Duration::from_secs(60));
        let png = tmp(&format!("chain-{n}.png"));
        let camera = format!("0.3,0.3,{}:0.3,0.3,0", n + 5);
        let out = bvhscope(&[
            "render",
            &p(&obj),
            "--bvh",
            &p(&json),
            "--view",
            "visits",
            "--size",
            "16x16",
            "--camera",
            &camera,
            "-o",
            &p(&png),
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(String::from_utf8_lossy(&out.stderr).contains("256 of 256 pixels hit") || n > 0);
        let out = bvhscope(&[
            "trace",
            &p(&obj),
            "--bvh",
            &p(&json),
            "--ray",
            &format!("0.25,0.25,{}:0,0,-1", n + 1),
            "--format",
            "json",
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["hit"]["triangle"].as_u64(), Some(n as u64 - 1), "the top triangle, through every level");
    }
}

/// Wrong trees the old checker passed: a triangle cut between two leaves whose boxes leave a gap
/// (x 0.51 to 0.56), and leaf boxes collapsed to points next to a far triangle (whose size made
/// the old tolerance huge). Both exit 1 and name the bounds.
#[test]
fn wrong_trees_that_used_to_pass_are_defective() {
    let obj = tmp("gap.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nv 6 5 5\nv 5 6 5\nf 1 2 3\nf 4 5 6\n").unwrap();
    let gap = tmp("gap.json");
    std::fs::write(
        &gap,
        r#"{"format":"bvhscope-bvh","version":1,"primitives":[0,0,1],"nodes":[
        {"min":[0,0,0],"max":[6,6,5],"children":[1,2]},
        {"min":[0,0,0],"max":[1,1,0],"children":[3,4]},
        {"min":[5,5,5],"max":[6,6,5],"first":2,"count":1},
        {"min":[0,0,0],"max":[0.51,1,0],"first":0,"count":1},
        {"min":[0.56,0,0],"max":[1,0.44,0],"first":1,"count":1}]}"#,
    )
    .unwrap();
    let out = bvhscope(&["check", &p(&obj), "--bvh", &p(&gap), "--rays", "1000", "--size", "16x16", "--no-compare"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains("triangle 0 around (0.5"), "{text}");

    // Four small triangles near the origin, one at 10⁶; the small ones' leaf boxes collapsed.
    let far = tmp("far.obj");
    let mut o = String::new();
    for k in 0..4 {
        let x = k as f32 * 0.1;
        o += &format!("v {x} 0 0\nv {} 0 0\nv {x} 0.1 0\n", x + 0.1);
    }
    o += "v 1e6 1e6 1e6\nv 1000001 1e6 1e6\nv 1e6 1000001 1e6\n";
    for k in 0..5 {
        o += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
    }
    std::fs::write(&far, o).unwrap();
    let dump = tmp("far.json");
    let out = bvhscope(&["export-bvh", &p(&far), "--max-leaf-size", "1", "-o", &p(&dump)]);
    assert!(out.status.success());
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&dump).unwrap()).unwrap();
    for n in v["nodes"].as_array_mut().unwrap() {
        if n.get("first").is_some() && n["min"][0].as_f64().unwrap() < 1.0 {
            n["max"] = n["min"].clone();
        }
    }
    std::fs::write(&dump, v.to_string()).unwrap();
    let out = bvhscope(&["check", &p(&far), "--bvh", &p(&dump), "--rays", "1000", "--size", "16x16", "--no-compare"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains("4 leaves' boxes do not hold all their triangles"), "{text}");
}

/// No output overwrites an input or is written under another kind's name; a refused write leaves
/// the file that was there (it used to leave `old.jpg` at 0 bytes).
#[test]
fn outputs_never_overwrite_inputs_or_misname_themselves() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let mesh = tmp("own.obj");
    std::fs::copy(torus, &mesh).unwrap();
    let before = std::fs::read(&mesh).unwrap();
    let refused = |args: &[&str], words: &str| {
        let out = bvhscope(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(words), "{args:?}: {err}");
    };
    refused(&["export-bvh", &p(&mesh), "-o", &p(&mesh)], "a dump is written as .json");
    refused(
        &["render", &p(&mesh), "--counts", &p(&mesh), "--size", "8x8", "-o", &p(&tmp("x.png"))],
        "must end in .csv",
    );
    assert_eq!(std::fs::read(&mesh).unwrap(), before, "the mesh is untouched");
    // A scene written over by the dump of its own mesh, by the file not the name.
    let scene = tmp("own-scene.json");
    std::fs::write(&scene, format!("{{\"meshes\": [{{\"file\": \"{}\"}}]}}", p(&mesh))).unwrap();
    let dotted = scene.parent().unwrap().join(".").join("own-scene.json");
    refused(&["export-bvh", &p(&scene), "-o", &p(&dotted)], "is also the mesh of this command");
    // A dump used as input and as the counts' output.
    let dump = tmp("own-dump.csv");
    assert!(bvhscope(&["export-bvh", &p(&mesh), "-o", &p(&tmp("own-dump.json"))]).status.success());
    std::fs::copy(tmp("own-dump.json"), &dump).unwrap();
    refused(
        &["render", &p(&mesh), "--bvh", &p(&dump), "--counts", &p(&dump), "--size", "8x8", "-o", &p(&tmp("y.png"))],
        "is also the BVH dump",
    );
    // A JPEG name: refused before anything is written, the old file kept.
    let jpg = tmp("old.jpg");
    std::fs::write(&jpg, "an old photo").unwrap();
    refused(&["render", &p(&mesh), "--size", "8x8", "-o", &p(&jpg)], "must end in .png");
    assert_eq!(std::fs::read(&jpg).unwrap(), b"an old photo");
    // .json.gz is gzip, read back as the same dump.
    let gz = tmp("own.json.gz");
    assert!(bvhscope(&["export-bvh", &p(&mesh), "-o", &p(&gz)]).status.success());
    assert!(std::fs::read(&gz).unwrap().starts_with(&[0x1f, 0x8b]));
    let out = bvhscope(&["check", &p(&mesh), "--bvh", &p(&gz), "--rays", "100", "--size", "8x8", "--no-compare"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stdout));
}

/// Dumps that would block, run forever or fill memory are refused at once, naming the file.
#[test]
fn special_files_bombs_and_reference_floods_are_refused_at_once() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let check = |dump: &str, extra: &[&str]| {
        let start = Instant::now();
        let mut args = vec!["check", torus, "--bvh", dump, "--rays", "10", "--size", "8x8", "--no-compare"];
        args.extend(extra);
        let out = bvhscope(&args);
        assert!(start.elapsed() < Duration::from_secs(30), "{dump}: at once");
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
        )
    };
    #[cfg(unix)]
    {
        let fifo = tmp("dump.fifo");
        let _ = std::fs::remove_file(&fifo);
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        let (code, err, _) = check(&p(&fifo), &[]);
        assert_eq!(code, Some(2));
        assert!(err.contains("is a FIFO (named pipe), not a regular file"), "{err}");
        let (code, err, _) = check("/dev/zero", &[]);
        assert_eq!(code, Some(2));
        assert!(err.contains("character device"), "{err}");
    }
    // 100 MB of spaces in 100 kB of gzip: stopped at the limit (64 MB for a small mesh; 16 here).
    let bomb = tmp("bomb.json.gz");
    {
        use std::io::Write;
        let mut gz = flate2::write::GzEncoder::new(std::fs::File::create(&bomb).unwrap(), flate2::Compression::best());
        let chunk = vec![b' '; 1 << 20];
        for _ in 0..100 {
            gz.write_all(&chunk).unwrap();
        }
        gz.finish().unwrap();
    }
    let (code, err, _) = check(&p(&bomb), &["--max-dump-mb", "16"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("decompresses to more than 16 MB"), "{err}");
    // 2,000 leaves of 65,535 references each, in a dump of a few hundred kB.
    let flood = tmp("flood.json");
    let prims: Vec<u32> = (0..65535).map(|i| i % 100).collect();
    let mut nodes =
        vec![serde_json::json!({"min": [-9, -9, -9], "max": [9, 9, 9], "children": (1..9).collect::<Vec<_>>()})];
    for _ in 0..8 {
        nodes.push(serde_json::json!({"min": [-9, -9, -9], "max": [9, 9, 9], "first": 0, "count": 65535}));
    }
    let v = serde_json::json!({"format": "bvhscope-bvh", "version": 1, "primitives": prims, "nodes": nodes});
    std::fs::write(&flood, v.to_string()).unwrap();
    let (code, _, text) = check(&p(&flood), &[]);
    assert_eq!(code, Some(1));
    assert!(text.contains("more than a BVH of this mesh can need"), "{text}");
    // More rays than the cap: a clear refusal, not an allocation.
    let out = bvhscope(&["check", torus, "--bvh", &p(&flood), "--rays", "18446744073709551615"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("100000000"), "{}", String::from_utf8_lossy(&out.stderr));
}

/// Every finite heatmap range draws (a legend used to index past the image), negative numbers
/// parse, and a histogram over ±3e38 has finite bins.
#[test]
fn any_finite_range_renders() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let png = tmp("range.png");
    for range in ["--range=-1e8:1", "--range=0:1e20", "--range=-3e38:3e38"] {
        let out = bvhscope(&["render", torus, "--view", "visits", range, "--size", "32x32", "-o", &p(&png)]);
        assert!(out.status.success(), "{range}: {}", String::from_utf8_lossy(&out.stderr));
    }
    let out = bvhscope(&["render", torus, "--view", "visits", "--range", "-5:5", "--size", "32x32", "-o", &p(&png)]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = bvhscope(&[
        "render",
        torus,
        "--view",
        "visits",
        "--range=0:1e20",
        "--against",
        "midpoint",
        "--size",
        "32x32",
        "-o",
        &p(&png),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = bvhscope(&[
        "render",
        torus,
        "--view",
        "visits",
        "--range=-3e38:3e38",
        "--histogram",
        "100",
        "--size",
        "32x32",
        "-o",
        &p(&png),
    ]);
    assert!(out.status.success());
    let csv = String::from_utf8_lossy(&out.stdout);
    assert!(csv.lines().skip(1).all(|l| l.split(',').all(|v| v.parse::<f64>().is_ok_and(f64::is_finite))), "{csv}");
}

/// The smaller refusals say what is wrong, and what is right loads.
#[test]
fn smaller_inputs_are_read_or_refused_with_the_reason() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let dump = |name: &str, bytes: &[u8]| {
        let path = tmp(name);
        std::fs::write(&path, bytes).unwrap();
        let out = bvhscope(&["check", torus, "--bvh", &p(&path), "--rays", "10", "--size", "8x8", "--no-compare"]);
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let leaf = b"node -2 -2 -2 2 2 2 leaf 0 0\n";
    // A byte-order mark and a Latin-1 comment are read.
    let (code, err) = dump("bom.txt", &[b"\xef\xbb\xbfbvhscope-bvh 1\n".as_slice(), leaf].concat());
    assert_eq!(code, Some(1), "read, and its one empty leaf leaves every triangle out: {err}");
    let (code, err) = dump("latin.txt", &[b"bvhscope-bvh 1\n# caf\xe9\n".as_slice(), leaf].concat());
    assert_eq!(code, Some(1), "{err}");
    for (name, bytes, words) in [
        ("null.json", b"null".as_slice(), "the JSON is null, not an object"),
        ("array.json", b"[]", "the JSON is an array, not an object"),
        ("nover.json", br#"{"format": "bvhscope-bvh", "primitives": [], "nodes": []}"#, "no \"version\" field"),
        ("head.txt", b"bvhscope-bvh 1 extra\n", "'extra' after 'bvhscope-bvh 1'"),
        ("axis.txt", b"bvhscope-bvh 1\nnode 0 0 0 1 1 1 children 1 2 axis 300\n", "axis '300' is not 0, 1 or 2"),
        ("after.txt", b"bvhscope-bvh 1\nnode 0 0 0 1 1 1 children 1 2 axis 1 more\n", "'more' after the axis"),
    ] {
        let (code, err) = dump(name, bytes);
        assert_eq!(code, Some(2), "{name}");
        assert!(err.contains(name) && err.contains(words), "{name}: {err}");
    }
    // A gzip file of two members reads as both; bytes after the last member are an error.
    use std::io::Write;
    let exported = tmp("members.json");
    assert!(bvhscope(&["export-bvh", torus, "-o", &p(&exported)]).status.success());
    let text = std::fs::read_to_string(&exported).unwrap();
    let gz = |s: &[u8]| {
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        e.write_all(s).unwrap();
        e.finish().unwrap()
    };
    let (a, b) = text.as_bytes().split_at(text.len() / 2);
    let (code, err) = dump("two.json.gz", &[gz(a), gz(b)].concat());
    assert_eq!(code, Some(0), "both members read: {err}");
    let (code, err) = dump("trailing.json.gz", &[gz(text.as_bytes()), b"junk".to_vec()].concat());
    assert_eq!(code, Some(2), "{err}");
    // A scene whose "meshes" is given twice; a matrix that scales by 1e-4 loads.
    let scene = |name: &str, text: &str| {
        let path = tmp(name);
        std::fs::write(&path, text).unwrap();
        let out = bvhscope(&["stats", &p(&path), "--no-rays"]);
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (code, err) = scene("twice.json", &format!("{{\"meshes\": [], \"meshes\": [{{\"file\": \"{torus}\"}}]}}"));
    assert_eq!(code, Some(2));
    assert!(err.contains("\"meshes\" is given twice"), "{err}");
    let m = "[[1e-4, 0, 0, 0], [0, 1e-4, 0, 0], [0, 0, 1e-4, 0], [0, 0, 0, 1]]";
    let (code, err) = scene(
        "small.json",
        &format!("{{\"meshes\": [{{\"file\": \"{torus}\", \"transform\": {{\"matrix\": {m}}}}}]}}"),
    );
    assert_eq!(code, Some(0), "{err}");
    // Cameras beyond what can be traced say so, not "up vector is zero".
    let out = bvhscope(&["render", torus, "--fov", "1e-30", "-o", &p(&tmp("f.png"))]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("is not an angle from 0.01 to 179.9 degrees"));
    let out = bvhscope(&["render", torus, "--camera", "1e20,0,0:0,0,0", "-o", &p(&tmp("f.png"))]);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("farther than 1e10"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A node the dump does not have.
    let own = tmp("node-dump.json");
    assert!(bvhscope(&["export-bvh", torus, "-o", &p(&own)]).status.success());
    let out = bvhscope(&["inspect", torus, "--bvh", &p(&own), "--node", "99999", "--size", "8x8"]);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--node 99999: the dump has"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
