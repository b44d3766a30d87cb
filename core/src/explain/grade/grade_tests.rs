//! The grader's parts on their own: the rubric's reading, discovery, ranking, the bounded EPO, the
//! page's encoding, and a small class graded end to end in memory. (tests/cli_grade.rs grades a
//! class through the command line: every kind of broken dump, the CSV, JSON and page.)

use super::html::{base64, esc};
use super::measure::epo_bounded;
use super::*;
use crate::bvh::{AnyBvh, Layout, Strategy};
use crate::dump::{import, BvhDump, DumpNode};
use crate::mesh::generate;
use std::path::Path;

pub(super) fn tmp(name: &str) -> PathBuf {
    crate::scratch::dir(&format!("grade-{name}"))
}

#[test]
fn base64_and_html_escapes_are_the_standard_ones() {
    // RFC 4648's test vectors.
    for (plain, coded) in
        [("", ""), ("f", "Zg=="), ("fo", "Zm8="), ("foo", "Zm9v"), ("foob", "Zm9vYg=="), ("foobar", "Zm9vYmFy")]
    {
        assert_eq!(base64(plain.as_bytes()), coded);
    }
    assert_eq!(base64(&[0xff, 0xfe, 0x00]), "//4A");
    assert_eq!(esc(r#"<a href="x">'b' & c</a>"#), "&lt;a href=&quot;x&quot;&gt;&#39;b&#39; &amp; c&lt;/a&gt;");
}

#[test]
fn a_rubric_is_read_field_by_field_and_a_mistake_names_the_file_and_the_field() {
    let p = Path::new("lab1/rubric.json");
    let text = r#"{
        "note": "lab 1", "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "size": [64, 48]},
        "rays": 500, "time_rays": 100, "required": ["structure", "rays"], "references": ["midpoint", "lbvh"],
        "rank_by": "nodes_per_ray", "good": {"sah_cost_within": 0.2, "max_depth_at_most": 30}
    }"#;
    let r = Rubric::parse(p, text).unwrap();
    assert_eq!(r.size, Some((64, 48)));
    assert_eq!((r.rays, r.time_rays, r.rank_by), (Some(500), Some(100), RankBy::NodesPerRay));
    assert_eq!(r.required, vec![Group::Structure, Group::Rays]);
    assert_eq!(r.references, vec![Strategy::Midpoint, Strategy::Lbvh]);
    assert_eq!(r.good, Good { sah_cost_within: Some(0.2), max_depth_at_most: Some(30), ..Good::default() });
    // What the report states parses back to the same rubric.
    let again = Rubric::parse(p, &r.to_json().to_string()).unwrap();
    assert_eq!(again, r);
    let def = Rubric::default();
    assert_eq!(Rubric { file: None, ..Rubric::parse(p, &def.to_json().to_string()).unwrap() }, def);

    let err = |text: &str| Rubric::parse(p, text).unwrap_err().to_string();
    assert_eq!(
        err(r#"{"rank": "sah_cost"}"#),
        "lab1/rubric.json: rank: unknown field (expected note, comment, mesh, camera, rays, time_rays, required, references, rank_by, good, size)"
    );
    assert!(err(r#"{"good": {"sah_within": 0.1}}"#).starts_with("lab1/rubric.json: good.sah_within: unknown field"));
    assert!(err(r#"{"camera": {"position": [0, 0, 1], "look_at": [0, 0, 0], "fov": 3}}"#)
        .contains("camera.fov: unknown field"));
    assert!(err(r#"{"good": {}, "good": {"sah_cost_within": 0.1}}"#).contains("the key \"good\" is given twice"));
    assert!(err(r#"{"required": ["rays"]}"#).contains("required: must hold \"structure\""));
    assert!(err(r#"{"references": ["sah", "octree"]}"#).contains("references[1]: \"octree\" is not one of midpoint"));
    assert!(err(r#"{"rays": -1}"#).contains("rays: expected a whole number from 0 to"));
    assert!(err(r#"{"good": {"sah_cost_within": "ten"}}"#).contains("good.sah_cost_within: expected a number"));
    assert!(err("[1, 2]").contains("(top level): expected an object, found an array"));
    assert!(err("{\n\"rays\": 1,\n}").starts_with("lab1/rubric.json: line 3:"));
}

/// The smallest dump (text form): what discovery takes for a dump.
pub(super) const TINY_DUMP: &str = "bvhscope-bvh 1\nprimitives 0\nnode 0 0 0 1 1 1 leaf 0 1\n";

/// Write `text` at `rel` below `d`, its folders made.
pub(super) fn put(d: &Path, rel: &str, text: &str) {
    let p = d.join(rel);
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    std::fs::write(p, text).unwrap();
}

#[test]
fn a_submission_is_a_file_or_a_folder_holding_one_dump() {
    let d = tmp("discover");
    let dump = TINY_DUMP;
    let write = |rel: &str, text: &str| put(&d, rel, text);
    write("alice.json.gz", "x");
    write("alice/bvh.txt", dump);
    write("bob/notes.txt", "my notes");
    write("bob/tree.txt", dump);
    write("bob/.hidden.json", dump);
    write("carol/a.txt", dump);
    write("carol/b.json", dump);
    write("dan/README.md", dump);
    let paths: Vec<PathBuf> =
        ["alice.json.gz", "alice", "bob", "carol", "dan", "nobody"].iter().map(|p| d.join(p)).collect();
    let subs = discover(&paths);
    let names: Vec<&str> = subs.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["alice", "alice (2)", "bob", "carol", "dan", "nobody"]);
    assert_eq!(subs[0].dump.as_deref(), Some(paths[0].as_path()), "a file is its own dump, whatever it holds");
    assert_eq!(subs[1].dump, Some(d.join("alice/bvh.txt")));
    assert_eq!(subs[2].dump, Some(d.join("bob/tree.txt")), "notes.txt is no dump, a hidden file is left out");
    let why = |i: usize| subs[i].problem.clone().unwrap_or_default();
    assert!(subs[3].dump.is_none() && why(3).contains("holds 2 dumps (a.txt, b.json)"), "{}", why(3));
    assert!(subs[4].dump.is_none() && why(4).contains("holds no dump"), "{}", why(4));
    assert_eq!(why(5), "no such file or folder");
    let slugs: std::collections::HashSet<&str> = subs.iter().map(|s| s.slug.as_str()).collect();
    assert_eq!(slugs.len(), subs.len(), "every student's images have their own names");
    assert_eq!(subs[1].slug, "002-alice-2");
}

fn row(name: &str, index: usize, verdict: Verdict, sah: f64) -> GradeRow {
    let sub = Submission { index, name: name.into(), slug: name.into(), path: name.into(), dump: None, problem: None };
    let mut r = GradeRow::not_checked(&sub, verdict, String::new());
    r.versus_sah = Some(VersusSah { sah_cost: sah, nodes_per_ray: 2.0 - sah, tri_tests_per_ray: 1.0, trace_time: 1.0 });
    r
}

#[test]
fn ranks_go_to_correct_rows_by_the_key_ties_share_a_place_and_are_the_same_in_any_order() {
    let rows = vec![
        row("dora", 0, Verdict::Correct, 1.2),
        row("carl", 1, Verdict::Correct, 1.0),
        row("bea", 2, Verdict::Defects, 0.5),
        row("abe", 3, Verdict::Correct, 1.2),
        row("zed", 4, Verdict::Correct, f64::NAN),
    ];
    let ranks = |mut rows: Vec<GradeRow>, by: RankBy| {
        rank(&mut rows, by);
        let mut v: Vec<(String, Option<usize>)> = rows.into_iter().map(|r| (r.name, r.rank)).collect();
        v.sort();
        v
    };
    let want = |v: [(&str, Option<usize>); 5]| v.iter().map(|(n, r)| (n.to_string(), *r)).collect::<Vec<_>>();
    let by_sah = want([("abe", Some(2)), ("bea", None), ("carl", Some(1)), ("dora", Some(2)), ("zed", Some(4))]);
    assert_eq!(ranks(rows.clone(), RankBy::SahCost), by_sah, "a NaN ranks last; defects get no rank");
    let mut reversed = rows.clone();
    reversed.reverse();
    assert_eq!(ranks(reversed, RankBy::SahCost), by_sah, "the order given does not matter");
    let by_nodes = ranks(rows, RankBy::NodesPerRay);
    assert_eq!(by_nodes[0], ("abe".to_string(), Some(1)), "0.8 nodes per ray ties with dora: one place");
    assert_eq!(by_nodes[3], ("dora".to_string(), Some(1)));
    assert_eq!(by_nodes[1], ("bea".to_string(), None));
    assert_eq!(by_nodes[2], ("carl".to_string(), Some(3)), "after two in first place, third");
}

/// A chain of leaves hanging off interior nodes whose boxes are all the root's: the EPO would
/// need time quadratic in the nodes, and is refused by its estimate instead.
#[test]
fn the_epo_of_a_tree_whose_boxes_all_overlap_is_refused_not_waited_for() {
    let mesh = generate::torus_knot(2, 3, 0.3, 500, 40);
    let n = mesh.triangle_count() as u32;
    let b = mesh.bounds();
    let (min, max) = (glam::Vec3::from(b.min).to_array(), glam::Vec3::from(b.max).to_array());
    let mut nodes = Vec::new();
    for i in 0..n - 1 {
        // The last interior node's second child is the last leaf, at 2n - 2 as well.
        nodes.push(DumpNode {
            min,
            max,
            children: Some(vec![2 * i + 1, 2 * i + 2]),
            first: None,
            count: None,
            axis: None,
        });
        nodes.push(DumpNode { min, max, children: None, first: Some(i), count: Some(1), axis: None });
    }
    nodes.push(DumpNode { min, max, children: None, first: Some(n - 1), count: Some(1), axis: None });
    let primitives = (0..n).map(|t| mesh.file_number(t)).collect();
    let dump = BvhDump { format: "bvhscope-bvh".into(), version: 1, mesh: None, primitives, nodes };
    let (tree, _) = import(&dump, &mesh, Path::new("chain.json")).unwrap();
    let AnyBvh::Binary(chain) = tree else { panic!("a binary dump is traced in the binary layout") };
    let start = std::time::Instant::now();
    let why = epo_bounded(&chain).unwrap_err();
    assert!(why.starts_with("not measured: its boxes overlap so much"), "{why}");
    assert!(start.elapsed().as_secs_f64() < 10.0, "the estimate is quick");
    let sah = crate::bvh::Bvh::build(&mesh, &crate::bvh::BuildParams { layout: Layout::Binary, ..Default::default() });
    assert_eq!(epo_bounded(&sah).unwrap(), crate::bvh::epo::of(&sah), "a sound tree's EPO is measured");
}

/// A tiny class's settings: a 48x32 frame, few rays, the default rubric.
pub(super) fn small_setup<'a>(mesh: &'a crate::mesh::Mesh, mesh_path: &'a Path) -> Setup<'a> {
    Setup {
        mesh,
        mesh_path,
        given_path: mesh_path,
        camera: crate::render::Camera::framing(&mesh.bounds(), 48, 32),
        rays: 2000,
        time_rays: 200,
        trace: Default::default(),
        params: Default::default(),
        dump_limit: 1 << 26,
        max_seconds: 60.0,
        rubric: Rubric::default(),
        secondary: None,
    }
}

/// Three students over a small knot: a midpoint tree, the SAH tree and a tree with a shrunk
/// leaf box; every row, rank and image as it should be.
#[test]
fn a_small_class_is_graded_ranked_and_drawn() {
    let d = tmp("class");
    let mesh = generate::torus_knot(2, 3, 0.3, 96, 8);
    let mesh_path = d.join("knot.obj");
    let build = |s| {
        AnyBvh::build(&mesh, &crate::bvh::BuildParams { strategy: s, layout: Layout::Binary, ..Default::default() })
    };
    let mid = BvhDump::of_any(&build(Strategy::Midpoint), &mesh, None);
    mid.write(&d.join("mia.txt")).unwrap();
    BvhDump::of_any(&build(Strategy::SahBinned), &mesh, None).write(&d.join("sam.json")).unwrap();
    let mut bad = mid.clone();
    let leaf = bad.nodes.iter().position(|n| n.count.is_some_and(|c| c >= 2)).unwrap();
    bad.nodes[leaf].max[0] = (bad.nodes[leaf].min[0] + bad.nodes[leaf].max[0]) / 2.0;
    bad.write(&d.join("bo.txt")).unwrap();
    let setup = small_setup(&mesh, &mesh_path);
    let subs = discover(&["mia.txt", "sam.json", "bo.txt"].map(|n| d.join(n)));
    let out = ReportDir::prepare(&d.join("report"), vec![(mesh_path.clone(), "the mesh".into())]).unwrap();
    let refs = References::new(&setup);
    let mut seen = 0;
    let graded = grade_class(&setup, refs, &subs, &out, &WorkControl::new(), |_| seen += 1);
    assert_eq!(seen, 3);
    let r = &graded.rows;
    assert_eq!(r.iter().map(|r| r.verdict).collect::<Vec<_>>(), [Verdict::Correct, Verdict::Correct, Verdict::Defects]);
    assert_eq!((r[0].rank, r[1].rank, r[2].rank), (Some(2), Some(1), None));
    assert_eq!(r[1].versus_sah.unwrap().sah_cost, 1.0, "the SAH tree exported is the reference's");
    assert_eq!(r[1].good, Some(true));
    // The box first, then the rays that hit wrongly because of it.
    assert!(r[2]
        .reason
        .starts_with(&format!("bounds: 1 leaf's box does not hold all its triangles: leaf node {leaf}")));
    assert!(r[2].findings.iter().any(|f| f.defect && f.node == Some(leaf as u32)));
    for row in &r[..2] {
        let img = row.images.as_ref().unwrap();
        assert!(out.read_image(&img.visits, 1 << 20).is_some() && out.read_image(&img.difference, 1 << 20).is_some());
    }
    let q = r[1].quality.as_ref().unwrap();
    assert_eq!(q.leaf_sizes.iter().sum::<usize>(), q.leaves);
    assert!(q.trace_ns_per_ray > 0.0 && q.speedup_over_linear > 0.0 && q.epo.is_some());
}

/// A class graded and its grade.json read back as the app reads it: the students in order, each
/// one's dump found again though the report names it relative to where `grade` ran (here the
/// class's folder, not the test's), the reason of those without a traceable tree; a report of
/// another format or version refused in one line naming the file.
#[test]
fn a_grade_report_is_read_back_with_its_paths_found_again() {
    let d = tmp("readback");
    let mesh = generate::torus_knot(2, 3, 0.3, 64, 6);
    let mesh_path = d.join("knot.obj");
    std::fs::write(&mesh_path, "# the class's mesh; only its name is read back\n").unwrap();
    let params = crate::bvh::BuildParams { strategy: Strategy::Midpoint, layout: Layout::Binary, ..Default::default() };
    let mid = BvhDump::of_any(&AnyBvh::build(&mesh, &params), &mesh, None);
    std::fs::create_dir_all(d.join("class/empty")).unwrap();
    mid.write(&d.join("class/mia.txt")).unwrap();
    mid.write(&d.join("class/moved.txt")).unwrap();
    mid.write(&d.join("class/gone.txt")).unwrap();
    let mut broken = mid.clone();
    broken.nodes[0].children = Some(vec![1, 99_999]);
    broken.write(&d.join("class/cy.txt")).unwrap();
    std::fs::write(d.join("class/junk.txt"), "not a dump").unwrap();
    let names = ["mia.txt", "cy.txt", "junk.txt", "empty", "moved.txt", "gone.txt"];
    let subs = discover(&names.map(|n| d.join("class").join(n)));
    let setup = small_setup(&mesh, &mesh_path);
    let mut out = ReportDir::prepare(&d.join("report"), vec![(mesh_path.clone(), "the mesh".into())]).unwrap();
    let graded = grade_class(&setup, References::new(&setup), &subs, &out, &WorkControl::new(), |_| {});
    out.publish().unwrap();
    // The paths as `grade` writes them when run in the class's parent folder: relative to it.
    let mut doc = document(&setup, &graded);
    let prefix = format!("{}/", d.display());
    let relative = |v: &mut serde_json::Value| {
        if let Some(p) = v.as_str().and_then(|p| p.strip_prefix(&prefix)) {
            *v = serde_json::Value::String(p.to_string());
        }
    };
    relative(&mut doc["mesh"]);
    for s in doc["students"].as_array_mut().unwrap() {
        relative(&mut s["dump"]);
    }
    // One dump moved into the report folder (the last place looked in), one gone altogether.
    std::fs::rename(d.join("class/moved.txt"), d.join("report/class-moved.txt")).unwrap();
    doc["students"][4]["dump"] = "class-moved.txt".into();
    std::fs::remove_file(d.join("class/gone.txt")).unwrap();
    std::fs::write(out.file(JSON_FILE), serde_json::to_string_pretty(&doc).unwrap()).unwrap();

    let r = GradeReport::read(out.root()).unwrap();
    assert_eq!(r.file, out.file(JSON_FILE), "a report folder is read through its grade.json");
    assert_eq!(r.mesh, Ok(d.join("knot.obj")), "found from the report folder's parent");
    assert_eq!((r.camera, r.trace), (setup.camera, setup.trace));
    let s = &r.students;
    assert_eq!(s.iter().map(|s| s.name.as_str()).collect::<Vec<_>>(), ["mia", "cy", "junk", "empty", "moved", "gone"]);
    let verdicts: Vec<Verdict> = s.iter().map(|s| s.verdict).collect();
    use Verdict::*;
    assert_eq!(verdicts, [Correct, Defects, Unreadable, NoDump, Correct, Correct]);
    assert_eq!(s.iter().map(|s| s.rank).collect::<Vec<_>>(), graded.rows.iter().map(|r| r.rank).collect::<Vec<_>>());
    assert_eq!(s[0].openable(), Ok(d.join("class/mia.txt").as_path()));
    assert_eq!(s[0].layout, Some(Layout::Binary));
    assert_eq!(s[4].openable(), Ok(d.join("report/class-moved.txt").as_path()), "found in the report folder");
    for (i, want) in [(1, "structure: "), (2, "not a bvhscope-bvh file"), (3, "holds no dump")] {
        let why = s[i].openable().unwrap_err();
        assert!(why.contains(want) && why == s[i].reason, "{}: {why}", s[i].name);
    }
    let gone = s[5].openable().unwrap_err();
    assert!(gone.starts_with("gone's dump class/gone.txt is not found (looked for class/gone.txt, "), "{gone}");
    assert!(gone.contains(&d.join("class/gone.txt").display().to_string()), "{gone}");
    assert!(is_report(out.root()) && is_report(&out.file(JSON_FILE)) && !is_report(&d.join("class/mia.txt")));

    let refused = |change: &dyn Fn(&mut serde_json::Value)| {
        let mut v = doc.clone();
        change(&mut v);
        let p = d.join("other.json");
        std::fs::write(&p, v.to_string()).unwrap();
        GradeReport::read(&p).unwrap_err().to_string()
    };
    let other = d.join("other.json").display().to_string();
    assert_eq!(
        refused(&|v| v["version"] = 2.into()),
        format!("{other}: version 2 of the bvhscope-grade format; this bvhscope reads version 1")
    );
    assert_eq!(
        refused(&|v| v["format"] = "bvhscope-bvh".into()),
        format!("{other}: not a bvhscope grade report: its format is \"bvhscope-bvh\"")
    );
    assert!(refused(&|v| v["students"] = 3.into()).starts_with(&format!("{other}: not a readable grade report: ")));
}
