//! What the grader writes and where, held to what it may touch: the report folder replaces only
//! the files its list names (`manifest`), the CSV's text cells never start a formula, and two
//! names of one file in a student's folder are one dump. (tests/cli_grade_out.rs: the same
//! through the command line.)

use super::grade_tests::{put, tmp, TINY_DUMP};
use super::*;

/// A report of `images` written into `root` and published.
fn report(root: &Path, images: &[&str]) -> Result<(), GradeError> {
    let mut dir = ReportDir::prepare(root, Vec::new())?;
    dir.write(CSV_FILE, b"rank,student\n1,ana\n")?;
    dir.write(JSON_FILE, b"{}")?;
    std::fs::write(dir.path_while_written(HTML_FILE), "<html></html>").unwrap();
    for name in images {
        dir.write_png(&ReportDir::image_name(name, "visits"), &image::RgbImage::new(2, 2))?;
    }
    dir.publish()
}

fn listing(root: &Path) -> Vec<String> {
    let mut v = Vec::new();
    for dir in [root.to_path_buf(), root.join(IMAGES_DIR)] {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            v.push(p.strip_prefix(root).unwrap().to_string_lossy().into_owned());
        }
    }
    v.sort();
    v
}

#[test]
fn a_report_folder_is_replaced_only_where_its_list_says() {
    let d = tmp("out-own");
    let root = d.join("report");
    report(&root, &["001-ana", "002-ben"]).unwrap();
    let list = std::fs::read_to_string(root.join(MANIFEST_FILE)).unwrap();
    assert!(list.starts_with("bvhscope-grade-files 1\n"), "{list}");
    for name in [CSV_FILE, JSON_FILE, HTML_FILE, "images/001-ana-visits.png"] {
        let bytes = std::fs::metadata(root.join(name)).unwrap().len();
        assert!(list.contains(&format!("file\t{bytes}\t{name}\n")), "{name} is listed: {list}");
    }
    assert!(list.contains("folder\timages\n"), "{list}");

    // Files of the user's in the report: refused by name, nothing removed.
    put(&root, "images/thesis/chapter1.tex", "\\chapter{}");
    let err = report(&root, &["001-ana"]).unwrap_err().to_string();
    assert!(
        err.contains("holds images/thesis/chapter1.tex, which the grade report written there did not write"),
        "{err}"
    );
    assert!(root.join("images/thesis/chapter1.tex").is_file() && root.join("images/002-ben-visits.png").is_file());
    std::fs::remove_dir_all(root.join("images/thesis")).unwrap();
    std::fs::create_dir(root.join("images/empty")).unwrap();
    let err = report(&root, &["001-ana"]).unwrap_err().to_string();
    assert!(err.contains("holds images/empty, which the grade report"), "{err}");
    std::fs::remove_dir(root.join("images/empty")).unwrap();
    // A report file of another size since is the user's.
    std::fs::write(root.join(JSON_FILE), "{\"edited\": true}").unwrap();
    let err = report(&root, &["001-ana"]).unwrap_err().to_string();
    assert!(err.contains("holds grade.json, changed since the grade report there wrote it"), "{err}");
    std::fs::write(root.join(JSON_FILE), "{}").unwrap();
    // A file the report lists but the user removed is no matter.
    std::fs::remove_file(root.join(HTML_FILE)).unwrap();

    report(&root, &["001-ana"]).unwrap();
    let want = [CSV_FILE, MANIFEST_FILE, HTML_FILE, JSON_FILE, IMAGES_DIR, "images/001-ana-visits.png"];
    let mut want: Vec<String> = want.map(String::from).to_vec();
    want.sort();
    assert_eq!(listing(&root), want, "the earlier report's files gone, the new one's in place");
    let left: Vec<String> =
        std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(left, ["report"], "nothing left beside it");
}

#[test]
fn a_folder_without_a_list_is_written_only_when_empty() {
    let d = tmp("out-theirs");
    let root = d.join("mine");
    put(&root, CSV_FILE, "name,mark\n");
    put(&root, JSON_FILE, "{}");
    let err = report(&root, &[]).unwrap_err().to_string();
    assert!(err.contains("holds grade.csv but no grade-files.txt") && err.contains("older bvhscope"), "{err}");
    assert_eq!(std::fs::read_to_string(root.join(CSV_FILE)).unwrap(), "name,mark\n");
    let other = d.join("notes");
    put(&other, "thesis.tex", "keep");
    let err = report(&other, &[]).unwrap_err().to_string();
    assert!(err.contains("holds thesis.tex, which is not part of a grade report"), "{err}");
    // A list that is not one of ours is no list.
    put(&other, MANIFEST_FILE, "file\t4\tthesis.tex\n");
    let err = report(&other, &[]).unwrap_err().to_string();
    assert!(err.contains("holds grade-files.txt, which is not a list of a grade report's files"), "{err}");
    let empty = d.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    report(&empty, &["001-ana"]).unwrap();
    assert!(empty.join(MANIFEST_FILE).is_file());
}

#[cfg(unix)]
#[test]
fn a_link_in_a_report_folder_is_not_the_reports() {
    let d = tmp("out-link");
    let root = d.join("report");
    report(&root, &["001-ana"]).unwrap();
    put(&d, "precious.txt", "keep");
    // Named as a listed file, of its size even: a link is never the report's.
    let listed = root.join("images/001-ana-visits.png");
    std::fs::remove_file(&listed).unwrap();
    std::os::unix::fs::symlink(d.join("precious.txt"), &listed).unwrap();
    let err = report(&root, &[]).unwrap_err().to_string();
    assert!(err.contains("holds images/001-ana-visits.png, a symbolic link,"), "{err}");
    assert!(std::fs::symlink_metadata(&listed).is_ok());
    assert_eq!(std::fs::read_to_string(d.join("precious.txt")).unwrap(), "keep");
}

#[test]
fn csv_text_cells_never_start_a_formula_and_numbers_stay_numbers() {
    let sub = |name: &str| Submission {
        index: 0,
        name: name.into(),
        slug: "001-x".into(),
        path: PathBuf::from(format!("{name}.json")),
        dump: None,
        problem: None,
    };
    let names = ["=HYPERLINK(\"x\")", "+1", "-5.4", "@SUM(A1)", "\tx", "\ry", "ana", "'quoted"];
    let rows: Vec<GradeRow> = names
        .iter()
        .map(|n| {
            let mut r = GradeRow::not_checked(&sub(n), Verdict::NoDump, format!("{n}: no dump"));
            r.versus_sah = Some(VersusSah { sah_cost: -5.4, ..VersusSah::default() });
            r.misses = vec![format!("-{n}")];
            r
        })
        .collect();
    let recs = csv_records(&rows);
    let col = |name: &str| recs[0].iter().position(|h| h == name).unwrap();
    let students: Vec<&str> = recs[1..].iter().map(|r| r[col("student")].as_str()).collect();
    assert_eq!(students, ["'=HYPERLINK(\"x\")", "'+1", "'-5.4", "'@SUM(A1)", "'\tx", "'\ry", "ana", "'quoted"]);
    for (r, n) in recs[1..].iter().zip(names) {
        let escaped = n.starts_with(['=', '+', '-', '@', '\t', '\r']);
        let text = |v: String| if escaped { format!("'{v}") } else { v };
        assert_eq!(r[col("reason")], text(format!("{n}: no dump")));
        assert_eq!(r[col("submission")], text(format!("{n}.json")));
        assert_eq!(r[col("not_good_because")], format!("'-{n}"));
        assert_eq!(r[col("sah_cost_vs_sah_tree")], "-5.4000", "a number is not text");
    }
}

#[cfg(unix)]
#[test]
fn two_names_of_one_file_in_a_folder_are_one_dump() {
    let d = tmp("out-twice");
    put(&d, "zoe/bvh.json", TINY_DUMP);
    // A link named before the file and one after, and a hard link: one file still.
    std::os::unix::fs::symlink("bvh.json", d.join("zoe/a-link.json")).unwrap();
    std::os::unix::fs::symlink("bvh.json", d.join("zoe/copy.json")).unwrap();
    std::fs::hard_link(d.join("zoe/bvh.json"), d.join("zoe/hard.json")).unwrap();
    put(&d, "ana.txt", TINY_DUMP);
    for (paths, at) in [(vec![d.join("zoe")], 0), (vec![d.join("ana.txt"), d.join("zoe")], 1)] {
        let subs = discover(&paths);
        assert_eq!(subs.len(), paths.len(), "a folder of one dump given alone is a student, not a class");
        let zoe = &subs[at];
        assert_eq!((zoe.name.as_str(), &zoe.problem), ("zoe", &None));
        assert_eq!(zoe.dump, Some(d.join("zoe/bvh.json")), "the file by its own first name");
    }
    // Two files are still two dumps.
    put(&d, "zoe/other.json", TINY_DUMP);
    let subs = discover(&[d.join("ana.txt"), d.join("zoe")]);
    assert!(subs[1].problem.as_deref().unwrap_or_default().contains("holds 2 dumps (bvh.json, other.json)"));
}
