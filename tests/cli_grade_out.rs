//! What `bvhscope grade` writes, held to what it may touch and how its files are read: `--out`
//! replaces only the files a report of its own listed (anything else there is refused, named,
//! and kept), a spreadsheet opening `grade.csv` runs no student's name as a formula, and two
//! names of one dump in a student's folder are one dump.

mod cli_support;

use cli_support::{bvhscope, tmp};
use std::path::{Path, PathBuf};

const TORUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
const SMALL: [&str; 6] = ["--size", "24x16", "--rays", "200", "--time-rays", "16"];

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

fn fresh(name: &str) -> PathBuf {
    let d = tmp(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn export(out: &Path) {
    let r = bvhscope(&["export-bvh", TORUS, "-o", &s(out), "--strategy", "sah"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
}

/// `grade` of `subs` into `out`: the process's output.
fn grade(subs: &[PathBuf], out: &Path) -> std::process::Output {
    let mut args: Vec<String> = vec!["grade".into(), TORUS.into()];
    args.extend(subs.iter().map(|p| s(p)));
    args.extend(["--out".into(), s(out)]);
    args.extend(SMALL.iter().map(|a| a.to_string()));
    bvhscope(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// Refused with exit 2 and a message holding `want`.
fn refused(r: &std::process::Output, want: &str) {
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(err.contains(want), "{err} should say {want:?}");
}

/// Files put in an earlier report's `images/` (a thesis chapter, a mesh) are named and kept, the
/// earlier report too; a report file changed since is not ours either; once they are gone, the
/// report is replaced, none of the earlier one's files left.
#[test]
fn grade_out_replaces_only_what_its_own_report_wrote() {
    let d = fresh("grade-out-own");
    export(&d.join("ana.json"));
    export(&d.join("ben.json"));
    let out = d.join("report");
    let r = grade(&[d.join("ana.json"), d.join("ben.json")], &out);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let listed = std::fs::read_to_string(out.join("grade-files.txt")).unwrap();
    assert!(listed.starts_with("bvhscope-grade-files 1\n") && listed.contains("grade.csv"), "{listed}");
    let images = || {
        let mut v: Vec<String> = std::fs::read_dir(out.join("images"))
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        v.sort();
        v
    };
    assert_eq!(images().len(), 4, "two images of each of the two students");
    let json = std::fs::read(out.join("grade.json")).unwrap();

    std::fs::create_dir_all(out.join("images/thesis")).unwrap();
    std::fs::write(out.join("images/thesis/chapter1.tex"), "\\chapter{BVHs}").unwrap();
    std::fs::write(out.join("images/zz-model.obj"), "v 0 0 0\n").unwrap();
    let r = grade(&[d.join("ana.json")], &out);
    refused(&r, "holds images/thesis/chapter1.tex, which the grade report written there did not write");
    assert_eq!(std::fs::read_to_string(out.join("images/thesis/chapter1.tex")).unwrap(), "\\chapter{BVHs}");
    assert_eq!(std::fs::read(out.join("grade.json")).unwrap(), json, "the earlier report stays whole");
    std::fs::remove_dir_all(out.join("images/thesis")).unwrap();
    refused(&grade(&[d.join("ana.json")], &out), "holds images/zz-model.obj, which the grade report");
    assert!(out.join("images/zz-model.obj").is_file());
    std::fs::remove_file(out.join("images/zz-model.obj")).unwrap();

    // A report file edited since (another size) is the user's now.
    let csv = std::fs::read_to_string(out.join("grade.csv")).unwrap();
    std::fs::write(out.join("grade.csv"), format!("{csv}my notes\n")).unwrap();
    refused(&grade(&[d.join("ana.json")], &out), "holds grade.csv, changed since");
    std::fs::write(out.join("grade.csv"), &csv).unwrap();

    // Only the report's own files: replaced, one student's images left.
    let r = grade(&[d.join("ana.json")], &out);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert_eq!(images().len(), 2, "{:?}", images());
    let beside: Vec<String> =
        std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(beside.iter().all(|n| !n.starts_with('.')), "nothing left beside: {beside:?}");
}

/// A folder holding someone's own `grade.json` and `grade.csv`, with no list of a report's
/// files, is not taken for a report: refused, saying so, and left as it was. An empty folder
/// is written into.
#[test]
fn a_folder_of_grade_files_without_a_list_is_not_overwritten() {
    let d = fresh("grade-out-theirs");
    export(&d.join("ana.json"));
    let out = d.join("mine");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("grade.json"), "{\"my\": \"marks\"}").unwrap();
    std::fs::write(out.join("grade.csv"), "name,mark\nana,17\n").unwrap();
    let r = grade(&[d.join("ana.json")], &out);
    refused(&r, "holds grade.csv but no grade-files.txt");
    refused(&r, "older bvhscope");
    assert_eq!(std::fs::read_to_string(out.join("grade.json")).unwrap(), "{\"my\": \"marks\"}");
    assert_eq!(std::fs::read_to_string(out.join("grade.csv")).unwrap(), "name,mark\nana,17\n");

    let empty = d.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let r = grade(&[d.join("ana.json")], &empty);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(empty.join("grade-files.txt").is_file() && empty.join("grade.html").is_file());
}

/// A symbolic link in an earlier report is not the report's (it never writes one): refused, and
/// neither the link nor what it leads to is removed.
#[cfg(unix)]
#[test]
fn a_link_in_an_earlier_report_is_refused_and_kept() {
    let d = fresh("grade-out-link");
    export(&d.join("ana.json"));
    let out = d.join("report");
    assert!(grade(&[d.join("ana.json")], &out).status.success());
    std::fs::write(d.join("precious.txt"), "keep").unwrap();
    std::os::unix::fs::symlink("../../precious.txt", out.join("images/link.png")).unwrap();
    refused(&grade(&[d.join("ana.json")], &out), "holds images/link.png, a symbolic link,");
    assert!(std::fs::symlink_metadata(out.join("images/link.png")).is_ok());
    assert_eq!(std::fs::read_to_string(d.join("precious.txt")).unwrap(), "keep");
}

/// Students named `=1+2`, `+1`, `-5.4`, `@SUM(A1)`: `grade.csv` writes their names with a
/// leading `'`, so a spreadsheet shows them as text and runs nothing; the figures stay numbers.
#[test]
fn csv_cells_a_spreadsheet_would_run_are_escaped() {
    let d = fresh("grade-out-csv");
    let names = ["=1+2", "+1", "-5.4", "@SUM(A1)", "plain"];
    let subs: Vec<PathBuf> = names.iter().map(|n| d.join(format!("{n}.json"))).collect();
    for p in &subs {
        export(p);
    }
    let out = d.join("report");
    let r = grade(&subs, &out);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let mut reader = csv::Reader::from_path(out.join("grade.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    let students: Vec<&str> = rows.iter().map(|r| &r[col("student")]).collect();
    assert_eq!(students, ["'=1+2", "'+1", "'-5.4", "'@SUM(A1)", "plain"]);
    for r in &rows {
        assert!(r[col("sah_cost")].parse::<f64>().is_ok(), "a number stays a number: {:?}", &r[col("sah_cost")]);
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("grade.json")).unwrap()).unwrap();
    assert_eq!(json["students"][0]["name"], "=1+2", "the JSON names them as they are");
}

/// A student's folder holding `bvh.json` and a symbolic link to it has one dump, given alone or
/// with others.
#[cfg(unix)]
#[test]
fn a_link_to_a_dump_beside_it_is_the_same_dump() {
    let d = fresh("grade-out-twice");
    let zoe = d.join("zoe");
    std::fs::create_dir_all(&zoe).unwrap();
    export(&zoe.join("bvh.json"));
    std::os::unix::fs::symlink("bvh.json", zoe.join("copy.json")).unwrap();
    export(&d.join("ana.json"));
    for (subs, at) in [(vec![zoe.clone()], 0), (vec![d.join("ana.json"), zoe.clone()], 1)] {
        let out = d.join(format!("report-{at}"));
        let r = grade(&subs, &out);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("grade.json")).unwrap()).unwrap();
        let row = &json["students"][at];
        assert_eq!(
            (row["name"].as_str(), row["verdict"].as_str()),
            (Some("zoe"), Some("correct")),
            "{}",
            row["reason"]
        );
        assert_eq!(row["dump"].as_str(), Some(s(&zoe.join("bvh.json")).as_str()));
    }
}

/// The time after "graded in" in `text`.
fn graded_in(text: &str) -> &str {
    let at = text.find("graded in ").unwrap_or_else(|| panic!("no grading time in {text}")) + "graded in ".len();
    let end = text[at..].find(" s").unwrap();
    &text[at..at + end]
}

/// The terminal and the page give one grading time: the references built and timed, then the
/// students (the terminal's was its own, the report's writing included, the page's the students'
/// alone: they differed, issue 59). Enough rays timed that the references take a visible time.
#[test]
fn grade_prints_the_grading_time_the_page_gives() {
    let d = fresh("grade-out-time");
    export(&d.join("ana.json"));
    let out = d.join("report");
    let args =
        ["grade", TORUS, &s(&d.join("ana.json")), "--out", &s(&out), "--size", "160x120", "--time-rays", "19200"];
    let r = bvhscope(&args);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    let page = std::fs::read_to_string(out.join("grade.html")).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("grade.json")).unwrap()).unwrap();
    let seconds = json["seconds"].as_f64().unwrap();
    assert_eq!(graded_in(&err), graded_in(&page), "the terminal's time and the page's");
    assert_eq!(graded_in(&page), format!("{seconds:.1}"), "grade.json's");
}
