//! `bvhscope grade` as a teacher runs it, on a generated class over the torus asset: trees of
//! several strategies and layouts (a file each, and one in a folder), a tree broken in each way
//! the checker knows (a shrunk box, a missing triangle, a cycle, a child past the end), an
//! unreadable file, a dump for another mesh and an empty folder. Every row, the ranks of two runs,
//! the CSV (read back with the csv crate), the JSON and the page; the rubric; and outputs that
//! would overwrite an input.

mod cli_support;

use cli_support::{bvhscope, tmp};
use serde_json::Value;
use std::path::{Path, PathBuf};

const TORUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
const KNOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/knot.obj");
/// A small frame and few rays: the whole file runs in seconds.
const SMALL: [&str; 6] = ["--size", "48x32", "--rays", "500", "--time-rays", "64"];

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

fn export(mesh: &str, out: &Path, extra: &[&str]) {
    let mut args = vec!["export-bvh", mesh, "-o"];
    let o = s(out);
    args.push(&o);
    args.extend(extra);
    let r = bvhscope(&args);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
}

/// What a row must say: its verdict and the start of its reason.
struct Want {
    name: &'static str,
    verdict: &'static str,
    reason: String,
}

/// The class in a folder of its own: the submissions in the order given, and each row's wanted
/// verdict and reason (the broken trees' node and triangle numbers read from the dump).
fn make_class(dir: &Path) -> (Vec<PathBuf>, Vec<Want>) {
    std::fs::create_dir_all(dir.join("dave")).unwrap();
    std::fs::create_dir_all(dir.join("ivan")).unwrap();
    let p = |n: &str| dir.join(n);
    export(TORUS, &p("alice.txt"), &["--strategy", "midpoint"]);
    export(TORUS, &p("bob.json"), &["--strategy", "sah"]);
    export(TORUS, &p("carol.json"), &["--strategy", "sah", "--layout", "wide4"]);
    export(TORUS, &p("dave/bvh.json.gz"), &["--strategy", "equal-count"]);
    export(KNOT, &p("hank.txt"), &["--strategy", "sah"]);
    std::fs::write(p("gina.txt"), "this is not a BVH\n").unwrap();
    // The broken trees, each from the midpoint tree in JSON.
    export(TORUS, &p("base.json"), &["--strategy", "midpoint"]);
    let base: Value = serde_json::from_str(&std::fs::read_to_string(p("base.json")).unwrap()).unwrap();
    std::fs::remove_file(p("base.json")).unwrap();
    let nodes = base["nodes"].as_array().unwrap();
    let n = nodes.len();
    let leaf = nodes.iter().position(|x| x["count"].as_u64().is_some_and(|c| c >= 2)).unwrap();
    let inner = (1..n).find(|&i| nodes[i]["children"].is_array()).unwrap();
    let broken = |name: &str, edit: &dyn Fn(&mut Value)| {
        let mut v = base.clone();
        edit(&mut v);
        std::fs::write(p(name), serde_json::to_string(&v).unwrap()).unwrap();
    };
    broken("erin.json", &|v| {
        let x = &mut v["nodes"][leaf];
        let mid = (x["min"][0].as_f64().unwrap() + x["max"][0].as_f64().unwrap()) / 2.0;
        x["max"][0] = mid.into();
    });
    let (first, count) = (nodes[leaf]["first"].as_u64().unwrap(), nodes[leaf]["count"].as_u64().unwrap());
    let dropped = base["primitives"][(first + count - 1) as usize].as_u64().unwrap();
    broken("frank.json", &|v| v["nodes"][leaf]["count"] = (count - 1).into());
    broken("kim.json", &|v| v["nodes"][inner]["children"][0] = 0.into());
    broken("liam.json", &|v| v["nodes"][inner]["children"][0] = (n + 5).into());
    let names = [
        "alice.txt",
        "bob.json",
        "carol.json",
        "dave",
        "erin.json",
        "frank.json",
        "kim.json",
        "liam.json",
        "gina.txt",
        "hank.txt",
        "ivan",
    ];
    let want = |name, verdict, reason: String| Want { name, verdict, reason };
    let wants = vec![
        want("alice", "correct", String::new()),
        want("bob", "correct", String::new()),
        want("carol", "correct", String::new()),
        want("dave", "correct", String::new()),
        want("erin", "defects", format!("bounds: 1 leaf's box does not hold all its triangles: leaf node {leaf} (")),
        want("frank", "defects", format!("coverage: 1 triangle is in no leaf: triangle {dropped}")),
        want("kim", "defects", format!("structure: 1 node is reached twice: node 0 (from node {inner}: a cycle)")),
        want(
            "liam",
            "defects",
            format!(
                "structure: 1 child index is past the last node: node {inner}: child {} (the last node is {})",
                n + 5,
                n - 1
            ),
        ),
        want("gina", "unreadable", format!("{}: not a bvhscope-bvh file", s(&p("gina.txt")))),
        want("hank", "wrong mesh", "the dump was written for knot.obj, but is checked against torus.obj".into()),
        want("ivan", "no dump", format!("{}: the folder holds no dump", s(&p("ivan")))),
    ];
    (names.iter().map(|n| p(n)).collect(), wants)
}

/// `grade` of the class into `out` with `extra` options: its CSV records by student (header
/// first), and the JSON.
fn grade(class: &[PathBuf], out: &Path, extra: &[&str]) -> (Vec<csv::StringRecord>, Value) {
    let mut args: Vec<String> = vec!["grade".into(), TORUS.into()];
    args.extend(class.iter().map(|p| s(p)));
    args.extend(["--out".into(), s(out)]);
    args.extend(SMALL.iter().chain(extra).map(|a| a.to_string()));
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let r = bvhscope(&argv);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let mut reader = csv::Reader::from_path(out.join("grade.csv")).unwrap();
    let mut records = vec![reader.headers().unwrap().clone()];
    records.extend(reader.records().map(|r| r.expect("every record parses")));
    let json: Value = serde_json::from_str(&std::fs::read_to_string(out.join("grade.json")).unwrap()).unwrap();
    (records, json)
}

fn field<'a>(records: &'a [csv::StringRecord], row: usize, column: &str) -> &'a str {
    let i = records[0].iter().position(|h| h == column).unwrap_or_else(|| panic!("no column {column}"));
    &records[row + 1][i]
}

#[test]
fn a_class_is_graded_row_by_row_and_ranked_the_same_twice() {
    let dir = tmp("grade-class");
    let (class, wants) = make_class(&dir);
    let (a, json) = grade(&class, &dir.join("report-a"), &[]);
    assert_eq!(a.len(), wants.len() + 1, "a header and one record per student");
    for (i, w) in wants.iter().enumerate() {
        assert_eq!(a[i + 1].len(), a[0].len(), "every record has every field");
        assert_eq!(field(&a, i, "student"), w.name);
        assert_eq!(field(&a, i, "verdict"), w.verdict, "{}: {}", w.name, field(&a, i, "reason"));
        let reason = field(&a, i, "reason");
        assert!(reason.starts_with(&w.reason), "{}: {reason:?} should start with {:?}", w.name, w.reason);
        let measured = !field(&a, i, "sah_cost").is_empty();
        assert_eq!(
            measured,
            ["correct", "defects"].contains(&w.verdict) && !reason.starts_with("structure"),
            "{}",
            w.name
        );
    }
    // Ranked by SAH cost over the SAH tree of the same layout: bob's and carol's are bvhscope's
    // own SAH trees (1.0: they share first place), then midpoint, then equal count; no defects
    // ranked.
    let ranks: Vec<&str> = (0..wants.len()).map(|i| field(&a, i, "rank")).collect();
    assert_eq!(ranks, ["3", "1", "1", "4", "", "", "", "", "", "", ""]);
    assert_eq!((field(&a, 1, "sah_cost_vs_sah_tree"), field(&a, 2, "sah_cost_vs_sah_tree")), ("1.0000", "1.0000"));
    assert_eq!((field(&a, 1, "layout"), field(&a, 2, "layout")), ("binary", "wide4"));
    assert_eq!(field(&a, 1, "good"), "yes", "within 10 % of the SAH tree");
    assert_eq!(field(&a, 0, "good"), "no", "midpoint is more than 10 % above it on the torus");
    assert!(field(&a, 0, "not_good_because").starts_with("SAH cost +"));
    // The rays the checker found wrong are counted in a column of their own (issue 59: "misses"
    // held the rubric's words and was empty for a student whose tree missed rays): none for a
    // correct tree, some for erin's leaf box that leaves triangles out.
    let wrong = |name: &str| field(&a, wants.iter().position(|w| w.name == name).unwrap(), "wrong_rays").to_string();
    assert_eq!(wrong("bob"), "0");
    assert!(wrong("erin").parse::<u64>().is_ok_and(|n| n > 0), "erin's wrong rays: {:?}", wrong("erin"));
    assert_eq!(field(&a, 3, "dump"), s(&dir.join("dave/bvh.json.gz")), "a folder's one dump");
    // The same class again: the same ranks and verdicts.
    let (b, _) = grade(&class, &dir.join("report-b"), &[]);
    for (i, w) in wants.iter().enumerate() {
        for column in ["rank", "verdict", "reason", "sah_cost", "nodes_per_ray", "leaf_sizes"] {
            assert_eq!(field(&a, i, column), field(&b, i, column), "{} {column}", w.name);
        }
    }

    assert_eq!(json["format"], "bvhscope-grade");
    let students = json["students"].as_array().unwrap();
    assert_eq!(students.len(), wants.len());
    assert!(json["references"].as_array().unwrap().iter().any(|r| r["strategy"] == "midpoint"));
    let hank = &students[9];
    let kept = hank["findings"].as_array().unwrap();
    assert!(hank["findings_total"].as_u64().unwrap() > kept.len() as u64, "a dump for another mesh has many");
    for g in ["Structure", "Coverage", "Bounds", "Rays"] {
        assert!(kept.iter().filter(|f| f["group"] == g).count() <= 12, "the first twelve of {g} are kept");
    }
    let erin = &students[4];
    assert!(erin["findings"].as_array().unwrap().iter().any(|f| f["node"].as_u64().is_some() && f["defect"] == true));
    let html = std::fs::read_to_string(dir.join("report-a/grade.html")).unwrap();
    for (w, st) in wants.iter().zip(students) {
        assert!(html.contains(&format!("id=\"s-{}\"", st["slug"].as_str().unwrap())), "{} has a section", w.name);
        assert!(html.contains(&format!(">{}</a>", w.name)), "{} is in the table", w.name);
        let images = &st["images"];
        if w.verdict == "correct" {
            for kind in ["visits", "difference"] {
                let rel = images[kind].as_str().unwrap();
                let png = std::fs::read(dir.join("report-a").join(rel)).unwrap();
                assert!(png.starts_with(b"\x89PNG"), "{rel}");
            }
        }
    }
    assert_eq!(html.matches("src=\"data:image/png;base64,").count(), 2 * 6, "two images of each measured tree");
    assert!(!html.contains("http://") && !html.contains("https://"), "the page loads nothing");
    assert!(html.contains(&format!("leaf node {}", wants[4].reason.split("leaf node ").nth(1).unwrap())));
}

#[test]
fn a_rubric_sets_what_is_required_what_is_good_and_the_key_and_a_mistake_is_named() {
    let dir = tmp("grade-rubric");
    let (class, wants) = make_class(&dir);
    let rubric = dir.join("rubric.json");
    // Bounds and rays not required: erin's shrunk box is then a defect that does not fail. The
    // mesh named is the one graded against (an absolute path; a relative one is the rubric's).
    let text = r#"{"note": "lab 1, week 3", "required": ["structure", "coverage"], "rank_by": "nodes_per_ray",
        "good": {"sah_cost_within": 0.5}, "references": ["midpoint", "equal-count"], "mesh": "TORUS"}"#;
    std::fs::write(&rubric, text.replace("TORUS", TORUS)).unwrap();
    let r = s(&rubric);
    let (rows, json) = grade(&class, &dir.join("report"), &["--rubric", &r]);
    let at = |name: &str| wants.iter().position(|w| w.name == name).unwrap();
    assert_eq!(field(&rows, at("erin"), "verdict"), "correct");
    assert!(!field(&rows, at("erin"), "rank").is_empty(), "a correct tree is ranked");
    assert_eq!(field(&rows, at("frank"), "verdict"), "defects", "coverage is still required");
    assert_eq!(field(&rows, at("alice"), "good"), "yes", "within 50 %");
    assert_eq!(json["rubric"]["rank_by"], "nodes_per_ray");
    assert_eq!(json["rubric_file"], r.as_str());
    let refs: Vec<&str> =
        json["references"].as_array().unwrap().iter().map(|t| t["strategy"].as_str().unwrap()).collect();
    assert_eq!(&refs[..3], ["sah", "midpoint", "equal-count"], "SAH binned always, first");
    let html = std::fs::read_to_string(dir.join("report/grade.html")).unwrap();
    assert!(html.contains("lab 1, week 3") && html.contains("defect (not required)"));

    let refused = |text: &str, want: &str| {
        std::fs::write(&rubric, text).unwrap();
        let (first, out) = (s(&class[0]), s(&dir.join("refused")));
        let o = bvhscope(&["grade", TORUS, &first, "--rubric", &r, "--out", &out]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains(want), "{err} should name {want}");
    };
    refused(r#"{"good": {"sah_within": 0.1}}"#, &format!("{r}: good.sah_within: unknown field"));
    refused(r#"{"mesh": "knot.obj"}"#, &format!("{r}: mesh: names"));
}

#[test]
fn the_report_never_overwrites_an_input() {
    let dir = tmp("grade-inputs");
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    // A student's dump that has the name of a report file, in the report's folder.
    let trap = out.join("grade.json");
    export(TORUS, &trap, &["--strategy", "sah"]);
    let before = std::fs::read(&trap).unwrap();
    let o = bvhscope(&["grade", TORUS, &s(&trap), "--out", &s(&out), "--size", "16x16"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("grade.json: is also the submission 'grade' of this command: refusing to overwrite it"),
        "{err}"
    );
    assert_eq!(std::fs::read(&trap).unwrap(), before);
    // A student's folder as the report's folder.
    let folder = dir.join("zoe");
    std::fs::create_dir_all(&folder).unwrap();
    export(TORUS, &folder.join("bvh.txt"), &[]);
    let o = bvhscope(&["grade", TORUS, &s(&folder), "--out", &s(&folder), "--size", "16x16"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("zoe: is also the submission 'zoe': write the report to another folder"), "{err}");
    assert!(!folder.join("grade.csv").exists());
}
