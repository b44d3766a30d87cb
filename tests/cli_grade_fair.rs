//! `bvhscope grade` held to what a teacher must defend in front of a class, through the command
//! line: a class folder given as one path, links out of a submission refused with nothing of
//! their targets in any report file, a file name with escape sequences printed harmlessly, the
//! time limit kept on a tree whose boxes all overlap, and two runs into one `--out` that never
//! mix. (core/src/explain/grade/fair_tests.rs: the yardstick, the order of findings, the times
//! under load.)

mod cli_support;

use cli_support::{bvhscope, tmp};
use serde_json::Value;
use std::path::{Path, PathBuf};

const TORUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
const SMALL: [&str; 6] = ["--size", "48x32", "--rays", "500", "--time-rays", "64"];

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

fn export(mesh: &str, out: &Path, strategy: &str) {
    let r = bvhscope(&["export-bvh", mesh, "-o", &s(out), "--strategy", strategy]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
}

fn fresh(name: &str) -> PathBuf {
    let d = tmp(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn grade_args(mesh: &str, subs: &[PathBuf], out: &Path, extra: &[&str]) -> Vec<String> {
    let mut args: Vec<String> = vec!["grade".into(), mesh.into()];
    args.extend(subs.iter().map(|p| s(p)));
    args.extend(["--out".into(), s(out)]);
    args.extend(extra.iter().map(|a| a.to_string()));
    args
}

fn run(args: &[String]) -> std::process::Output {
    bvhscope(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

fn report_json(out: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("grade.json")).unwrap()).unwrap()
}

/// Every file of the report folder, as bytes.
fn report_bytes(out: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut v = Vec::new();
    for dir in [out.to_path_buf(), out.join("images")] {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_file() {
                v.push((p.clone(), std::fs::read(&p).unwrap()));
            }
        }
    }
    v
}

/// The class folder a learning platform hands out, given as one path, with a link to the
/// teacher's solution and a link to the teacher's notes in it: each entry a student, the two
/// links refused as links, and nothing of the secret folder in the HTML, the CSV or the JSON.
#[cfg(unix)]
#[test]
fn a_class_folder_is_graded_and_links_out_of_it_reach_no_report_file() {
    use std::os::unix::fs::symlink;
    let d = fresh("fair-links");
    let (class, secret) = (d.join("class"), d.join("secret"));
    std::fs::create_dir_all(class.join("dee")).unwrap();
    std::fs::create_dir_all(&secret).unwrap();
    export(TORUS, &secret.join("solution.json"), "sah");
    std::fs::write(secret.join("notes.txt"), "SECRET-NOTES the answer is SAH with 16 bins\n").unwrap();
    export(TORUS, &class.join("ana.json"), "midpoint");
    export(TORUS, &class.join("dee/bvh.txt"), "sah");
    symlink("../secret/solution.json", class.join("mallory.json")).unwrap();
    symlink("../secret/notes.txt", class.join("eve.txt")).unwrap();
    let out = d.join("report");
    let r = run(&grade_args(TORUS, std::slice::from_ref(&class), &out, &SMALL));
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let json = report_json(&out);
    let rows: Vec<(&str, &str)> = json["students"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| (s["name"].as_str().unwrap(), s["verdict"].as_str().unwrap()))
        .collect();
    assert_eq!(rows, [("ana", "correct"), ("dee", "correct"), ("eve", "no_dump"), ("mallory", "no_dump")]);
    for k in [2, 3] {
        let why = json["students"][k]["reason"].as_str().unwrap();
        assert!(why.contains("is a symbolic link") && why.contains("links are never followed"), "{why}");
    }
    for (path, bytes) in report_bytes(&out) {
        let text = String::from_utf8_lossy(&bytes);
        assert!(!text.contains("SECRET") && !text.contains("secret/"), "{} quotes the secret folder", path.display());
    }
    let stdout = String::from_utf8_lossy(&r.stdout);
    assert!(!stdout.contains("SECRET"), "{stdout}");
}

/// A student's file named with an escape sequence and a newline: printed escaped, so no ESC
/// byte reaches the terminal (it would retitle it or recolour the table) and the table's rows
/// stay one line each; the report's files name the student as the file is named.
#[cfg(unix)]
#[test]
fn a_file_name_with_escape_sequences_never_reaches_the_terminal_raw() {
    let d = fresh("fair-escape");
    let name = "evil\u{1b}]0;pwned\u{7}\u{1b}[31mred\nrow.json";
    export(TORUS, &d.join(name), "sah");
    let out = d.join("report");
    let r = run(&grade_args(TORUS, &[d.join(name)], &out, &SMALL));
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    for (what, bytes) in [("stdout", &r.stdout), ("stderr", &r.stderr)] {
        assert!(!bytes.contains(&0x1b) && !bytes.contains(&0x07), "{what}: {}", String::from_utf8_lossy(bytes));
    }
    let stdout = String::from_utf8_lossy(&r.stdout);
    assert_eq!(stdout.lines().count(), 2, "a header and one row: {stdout}");
    assert!(stdout.contains("evil\\u{1b}]0;pwned\\u{7}"), "{stdout}");
    assert_eq!(report_json(&out)["students"][0]["name"], "evil\u{1b}]0;pwned\u{7}\u{1b}[31mred\nrow");
}

/// A correct tree whose every box is the root's makes each ray visit every node: `--max-seconds
/// 5` stops it within half as much again (the check's rays, the timing and the images all hear
/// the limit), and the class goes on.
#[test]
fn the_time_limit_is_kept_on_a_tree_whose_boxes_all_overlap() {
    let d = fresh("fair-limit");
    // A 20,000-triangle knot: its tree of 40,000 nodes costs 40,000 box tests a ray.
    let mesh = d.join("knot.obj");
    let m = bvhscope_core::mesh::generate::torus_knot(2, 3, 0.3, 500, 20);
    let mut text = Vec::new();
    bvhscope_core::mesh::write_obj(&m, &mut text).unwrap();
    std::fs::write(&mesh, text).unwrap();
    export(&s(&mesh), &d.join("sah.json"), "sah");
    let mut fat: Value = serde_json::from_str(&std::fs::read_to_string(d.join("sah.json")).unwrap()).unwrap();
    let (min, max) = (fat["nodes"][0]["min"].clone(), fat["nodes"][0]["max"].clone());
    for n in fat["nodes"].as_array_mut().unwrap() {
        n["min"] = min.clone();
        n["max"] = max.clone();
    }
    std::fs::write(d.join("fat.json"), fat.to_string()).unwrap();
    let out = d.join("report");
    let args = grade_args(&s(&mesh), &[d.join("fat.json"), d.join("sah.json")], &out, &["--max-seconds", "5"]);
    let r = run(&args);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let json = report_json(&out);
    let fat = &json["students"][0];
    assert_eq!(fat["verdict"], "timed_out", "{}", fat["reason"]);
    let spent = fat["seconds"].as_f64().unwrap();
    assert!(spent < 7.5, "--max-seconds 5 took {spent:.1} s");
    assert_eq!(json["students"][1]["verdict"], "correct", "the class goes on");
}

/// Two runs into one `--out` at once, each over another class: the folder holds one whole
/// report, its page's images its own students' (never the other run's), and no image of an
/// earlier, larger class survives a later run.
#[test]
fn two_runs_into_one_folder_never_mix() {
    let d = fresh("fair-concurrent");
    for (name, strategy) in [("a1.json", "midpoint"), ("a2.json", "sah"), ("a3.json", "lbvh"), ("b1.json", "ploc")] {
        export(TORUS, &d.join(name), strategy);
    }
    let out = d.join("report");
    let class_a: Vec<PathBuf> = ["a1.json", "a2.json", "a3.json"].iter().map(|n| d.join(n)).collect();
    let class_b = vec![d.join("b1.json")];
    let exe = env!("CARGO_BIN_EXE_bvhscope");
    let spawn =
        |class: &[PathBuf]| std::process::Command::new(exe).args(grade_args(TORUS, class, &out, &SMALL)).output();
    let (a, b) = std::thread::scope(|sc| {
        let a = sc.spawn(|| spawn(&class_a).unwrap());
        let b = sc.spawn(|| spawn(&class_b).unwrap());
        (a.join().unwrap(), b.join().unwrap())
    });
    assert!(
        a.status.success() && b.status.success(),
        "{}{}",
        String::from_utf8_lossy(&a.stderr),
        String::from_utf8_lossy(&b.stderr)
    );
    let consistent = |out: &Path| {
        let json = report_json(out);
        let students = json["students"].as_array().unwrap();
        let mut want: Vec<String> = students
            .iter()
            .flat_map(|s| {
                [
                    s["images"]["visits"].as_str().unwrap().to_string(),
                    s["images"]["difference"].as_str().unwrap().to_string(),
                ]
            })
            .collect();
        want.sort();
        let mut have: Vec<String> = std::fs::read_dir(out.join("images"))
            .unwrap()
            .map(|e| format!("images/{}", e.unwrap().file_name().to_string_lossy()))
            .collect();
        have.sort();
        assert_eq!(have, want, "the images are exactly the report's");
        let html = std::fs::read_to_string(out.join("grade.html")).unwrap();
        for img in &have {
            let bytes = std::fs::read(out.join(img)).unwrap();
            assert!(html.contains(&base64(&bytes)), "the page shows {img} as written");
        }
        let csv = std::fs::read_to_string(out.join("grade.csv")).unwrap();
        assert_eq!(csv.lines().count(), students.len() + 1, "the CSV's students are the JSON's");
        students.len()
    };
    let n = consistent(&out);
    assert!(n == 1 || n == 3, "one of the two classes: {n}");
    // Then the larger class, then the smaller: none of the larger's images is left.
    assert!(spawn(&class_a).unwrap().status.success());
    assert!(spawn(&class_b).unwrap().status.success());
    assert_eq!(consistent(&out), 1);
    // Nothing is left beside the report either.
    let beside: Vec<String> =
        std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(beside.iter().all(|n| !n.starts_with('.')), "{beside:?}");
}

/// A report folder that holds anything else is not replaced: the user's files stay.
#[test]
fn a_folder_holding_other_files_is_not_taken_for_a_report() {
    let d = fresh("fair-foreign");
    export(TORUS, &d.join("ana.json"), "sah");
    let out = d.join("mine");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("thesis.tex"), "keep me").unwrap();
    let r = run(&grade_args(TORUS, &[d.join("ana.json")], &out, &SMALL));
    assert_eq!(r.status.code(), Some(2));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("holds thesis.tex, which is not part of a grade report"), "{err}");
    assert_eq!(std::fs::read_to_string(out.join("thesis.tex")).unwrap(), "keep me");
}

/// Standard base64, as the page inlines images.
fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut o = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            o.push(if k <= c.len() { A[(n >> (18 - 6 * k) & 63) as usize] as char } else { '=' });
        }
    }
    o
}
