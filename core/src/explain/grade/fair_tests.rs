//! A grade a teacher can defend: one yardstick for every tree (a far degenerate triangle kept
//! does not win), the most serious finding first, "wrong mesh" only for another mesh, folders and
//! class folders as handed out, links never followed, and times that a busy machine leaves
//! alone. (tests/cli_grade.rs: the same through the command line, with the report's files.)

use super::*;
use crate::bvh::{AnyBvh, BuildParams, Layout, Strategy};
use crate::dump::BvhDump;
use crate::mesh::{generate, parse_obj, write_obj, Mesh};
use crate::work::WorkControl;
use std::path::Path;

fn tmp(name: &str) -> PathBuf {
    crate::scratch::dir(&format!("fair-{name}"))
}

/// The knot with one zero-area triangle (three points on a line) far above it, read as an OBJ:
/// the loader leaves it out of the mesh, but it keeps its number (the last).
fn knot_and_far_degenerate(dir: &Path) -> (Mesh, PathBuf) {
    let knot = generate::torus_knot(2, 3, 0.3, 96, 8);
    let mut text = Vec::new();
    write_obj(&knot, &mut text).unwrap();
    let v = knot.positions.len();
    text.extend(format!("v 0 40 0\nv 1 40 0\nv 2 40 0\nf {} {} {}\n", v + 1, v + 2, v + 3).bytes());
    let path = dir.join("knot.obj");
    std::fs::write(&path, &text).unwrap();
    let (mesh, _) = parse_obj(&path, std::str::from_utf8(&text).unwrap()).unwrap();
    assert_eq!(mesh.file_triangle_count(), mesh.triangle_count() + 1, "the degenerate triangle is dropped");
    (mesh, path)
}

fn dump_of(mesh: &Mesh, strategy: Strategy) -> BvhDump {
    let params = BuildParams { strategy, layout: Layout::Binary, ..Default::default() };
    BvhDump::of_any(&AnyBvh::build(mesh, &params), mesh, None)
}

/// `dump` with file triangle `t` (in the box `lo..hi`) added to its highest leaf, that leaf's box
/// and its ancestors' grown to hold it: what a student's builder that keeps every triangle, and
/// puts a far one with its nearest neighbours, writes.
fn keeping(dump: &BvhDump, t: u32, lo: [f32; 3], hi: [f32; 3]) -> BvhDump {
    let mut d = dump.clone();
    let leaf = (0..d.nodes.len())
        .filter(|&i| d.nodes[i].children.is_none())
        .max_by(|&a, &b| d.nodes[a].max[1].total_cmp(&d.nodes[b].max[1]))
        .unwrap();
    let at = d.nodes[leaf].first.unwrap() + d.nodes[leaf].count.unwrap();
    d.primitives.insert(at as usize, t);
    for n in &mut d.nodes {
        if n.first.is_some_and(|f| f >= at) {
            n.first = n.first.map(|f| f + 1);
        }
    }
    d.nodes[leaf].count = d.nodes[leaf].count.map(|c| c + 1);
    let mut parent = vec![usize::MAX; d.nodes.len()];
    for (i, n) in d.nodes.iter().enumerate() {
        for &k in n.children.iter().flatten() {
            parent[k as usize] = i;
        }
    }
    let mut i = leaf;
    loop {
        let n = &mut d.nodes[i];
        for a in 0..3 {
            n.min[a] = n.min[a].min(lo[a]);
            n.max[a] = n.max[a].max(hi[a]);
        }
        if i == 0 {
            break d;
        }
        i = parent[i];
    }
}

fn setup<'a>(mesh: &'a Mesh, mesh_path: &'a Path) -> Setup<'a> {
    super::grade_tests::small_setup(mesh, mesh_path)
}

fn grade(setup: &Setup, dir: &Path, names: &[&str]) -> Vec<GradeRow> {
    let subs = discover(&names.iter().map(|n| dir.join(n)).collect::<Vec<_>>());
    let out = ReportDir::prepare(&dir.join("report"), Vec::new()).unwrap();
    grade_class(setup, References::new(setup), &subs, &out, &WorkControl::new(), |_| {}).rows
}

/// A midpoint tree that keeps the mesh's far zero-area triangle has a root box far larger than
/// the mesh's. Measured against its own root box it looked best of the class (its other boxes
/// are small beside that root); measured against the mesh's box, as every tree is, it costs more
/// than the SAH tree, and more than the same midpoint tree without the triangle, and the
/// checker says why its box is larger.
#[test]
fn a_tree_keeping_a_far_degenerate_triangle_is_measured_on_the_mesh_box_and_ranks_below_sah() {
    let d = tmp("yardstick");
    let (mesh, mesh_path) = knot_and_far_degenerate(&d);
    let far = mesh.file_triangle_count() as u32 - 1;
    let mid = dump_of(&mesh, Strategy::Midpoint);
    mid.write(&d.join("mid.json")).unwrap();
    keeping(&mid, far, [0.0, 40.0, 0.0], [2.0, 40.0, 0.0]).write(&d.join("deg.json")).unwrap();
    dump_of(&mesh, Strategy::SahBinned).write(&d.join("sam.json")).unwrap();
    let rows = grade(&setup(&mesh, &mesh_path), &d, &["deg.json", "mid.json", "sam.json"]);
    let [deg, mid, sam] = [&rows[0], &rows[1], &rows[2]];
    assert!(
        rows.iter().all(|r| r.verdict == Verdict::Correct),
        "{:?}",
        rows.iter().map(|r| &r.reason).collect::<Vec<_>>()
    );
    assert_eq!(sam.rank, Some(1));
    assert_eq!((mid.rank, deg.rank), (Some(2), Some(3)), "the kept triangle costs its box");
    let (q, m) = (deg.quality.as_ref().unwrap(), mid.quality.as_ref().unwrap());
    assert!(deg.versus_sah.unwrap().sah_cost > 1.0 && q.sah_cost > m.sah_cost, "{} vs {}", q.sah_cost, m.sah_cost);
    // The same rays for both: every ray that enters the mesh's box walks the new root first.
    assert!(q.root_nodes_per_ray > m.root_nodes_per_ray, "{} vs {}", q.root_nodes_per_ray, m.root_nodes_per_ray);
    let warn = deg.findings.iter().find(|f| f.line.starts_with("the root box is larger than the mesh's box")).unwrap();
    assert!(!warn.defect && warn.triangle == Some(far), "{warn:?}");
    assert!(
        warn.line.contains(&format!("it holds triangle {far}, a degenerate (zero-area) triangle")),
        "{}",
        warn.line
    );
    assert!(warn.line.contains("on +y"), "{}", warn.line);
    assert!(mid.findings.iter().all(|f| !f.line.starts_with("the root box")), "a tight tree has no such warning");
}

/// The most serious finding first, whatever order the checker met them in: a triangle in no
/// leaf before a leaf box a sixth of the mesh too small, before a box off by a rounding, before
/// the rays that hit wrongly because of them.
#[test]
fn the_first_cause_is_the_most_serious_finding() {
    let d = tmp("severity");
    let mesh = generate::torus_knot(2, 3, 0.3, 96, 8);
    let mesh_path = d.join("knot.obj");
    let mut dump = dump_of(&mesh, Strategy::Midpoint);
    let leaves: Vec<usize> = (0..dump.nodes.len()).filter(|&i| dump.nodes[i].count.is_some_and(|c| c >= 2)).collect();
    // The first node of all: a box a hair too small (beyond the checker's few ulps).
    dump.nodes[1].max[0] -= 2e-6;
    // A leaf far in the array: a sixth of the mesh too small.
    let big = *leaves.last().unwrap();
    let extent = mesh.bounds().extent().x;
    dump.nodes[big].max[0] = dump.nodes[big].min[0].max(dump.nodes[big].max[0] - extent / 6.0);
    // A leaf in the middle drops its last triangle.
    let short = leaves[leaves.len() / 2];
    dump.nodes[short].count = Some(dump.nodes[short].count.unwrap() - 1);
    dump.write(&d.join("bo.json")).unwrap();
    let rows = grade(&setup(&mesh, &mesh_path), &d, &["bo.json"]);
    let r = &rows[0];
    assert_eq!(r.verdict, Verdict::Defects);
    assert!(r.reason.starts_with("coverage: 1 triangle is in no leaf"), "{}", r.reason);
    let groups: Vec<&str> = r.findings.iter().filter(|f| f.defect).map(|f| f.group.label()).collect();
    let bounds: Vec<&FindingLine> = r.findings.iter().filter(|f| f.defect && f.group == Group::Bounds).collect();
    assert_eq!(groups.first(), Some(&"coverage"), "{groups:?}");
    assert!(bounds.len() >= 2, "{bounds:?}");
    assert_eq!(bounds[0].node, Some(big as u32), "the box that misses by most first: {bounds:?}");
    assert_eq!(bounds.last().unwrap().node, Some(1), "the rounding last: {bounds:?}");
    let rays = r.findings.iter().position(|f| f.defect && f.group == Group::Rays).expect("rays hit wrongly");
    assert!(r.findings[..rays].iter().filter(|f| f.group == Group::Bounds).count() == bounds.len(), "the causes first");
    let warnings_after = r.findings.iter().skip_while(|f| f.defect).all(|f| !f.defect);
    assert!(warnings_after, "warnings after every defect");
}

/// One primitive number past the mesh is a defect naming its node, not another mesh; most of
/// them past it, or another mesh's name, is "wrong mesh".
#[test]
fn wrong_mesh_only_when_the_dump_is_of_another_mesh() {
    let d = tmp("wrong-mesh");
    let mesh = generate::torus_knot(2, 3, 0.3, 96, 8);
    let mesh_path = d.join("knot.obj");
    let tris = mesh.file_triangle_count() as u32;
    let mut one = dump_of(&mesh, Strategy::SahBinned);
    let at = one.primitives.len() / 2;
    one.primitives[at] = tris + 5;
    one.write(&d.join("one.json")).unwrap();
    let mut most = one.clone();
    for p in most.primitives.iter_mut().take(2 * tris as usize / 3) {
        *p += tris;
    }
    most.write(&d.join("most.json")).unwrap();
    let mut named = dump_of(&mesh, Strategy::SahBinned);
    named.mesh = Some("bunny.obj".into());
    named.primitives[0] = tris;
    named.write(&d.join("named.json")).unwrap();
    let rows = grade(&setup(&mesh, &mesh_path), &d, &["one.json", "most.json", "named.json"]);
    let leaf = one.nodes.iter().position(|n| {
        let (f, c) = (n.first.unwrap_or(0) as usize, n.count.unwrap_or(0) as usize);
        n.children.is_none() && (f..f + c).contains(&at)
    });
    assert_eq!(rows[0].verdict, Verdict::Defects, "{}", rows[0].reason);
    assert!(rows[0].reason.contains("primitive numbers no triangle of the mesh"), "{}", rows[0].reason);
    assert!(rows[0].reason.contains(&format!("node {}", leaf.unwrap())), "names the leaf: {}", rows[0].reason);
    assert_eq!(rows[1].verdict, Verdict::WrongMesh, "{}", rows[1].reason);
    assert!(rows[1].reason.contains("of its 1536 primitives number triangles past them"), "{}", rows[1].reason);
    assert_eq!(rows[2].verdict, Verdict::WrongMesh, "{}", rows[2].reason);
    assert!(rows[2].reason.starts_with("the dump was written for bunny.obj"), "{}", rows[2].reason);
}

/// A student's folder with only a README is "no dump"; the one folder a learning platform hands
/// out, holding student folders or several dumps, is a class: each entry a student.
#[test]
fn a_folder_of_notes_is_no_dump_and_a_class_folder_is_its_entries() {
    let d = tmp("folders");
    let dump = super::grade_tests::TINY_DUMP;
    let write = |rel: &str, text: &str| super::grade_tests::put(&d, rel, text);
    write("class/ana/bvh.txt", dump);
    write("class/ben/README.txt", "my tree is in the attic\n");
    write("class/cy.json", "{}");
    write("class/dee.txt", dump);
    write("class/.DS_Store", "x");
    write("class/notes.md", "teacher's notes");
    let subs = discover(&[d.join("class")]);
    let names: Vec<&str> = subs.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["ana", "ben", "cy", "dee"], "the entries, in name order; hidden files and other names left out");
    assert_eq!(subs[0].dump, Some(d.join("class/ana/bvh.txt")));
    let ben = subs[1].problem.as_deref().unwrap_or_default();
    assert!(
        subs[1].dump.is_none() && ben.contains("holds no dump") && ben.contains("README.txt does not start as a dump"),
        "{ben}"
    );
    assert_eq!(subs[2].dump, Some(d.join("class/cy.json")), "a file is its own dump: the reader says what is wrong");
    // One student's folder given on its own is that student, not a class.
    let one = discover(&[d.join("class/ana")]);
    assert_eq!((one.len(), one[0].name.as_str()), (1, "ana"));
    // Several paths (`class/*`): each one a student, a folder of several dumps among them too.
    write("two/a.json", dump);
    write("two/b.json", dump);
    let many = discover(&[d.join("class/ana"), d.join("two")]);
    assert!(many[1].problem.as_deref().unwrap_or_default().contains("holds 2 dumps"), "{:?}", many[1].problem);
    assert_eq!(discover(&[d.join("two")]).len(), 2, "alone, a folder of several dumps is a class");
}

/// A submission is read only from inside itself: a link handed in (to the teacher's solution, to
/// any file) is refused with its row saying so, and so is a link in a student's folder that
/// leads out of it; its target is never read nor named. A link that stays inside the folder is
/// followed.
#[cfg(unix)]
#[test]
fn links_out_of_a_submission_are_refused_never_followed() {
    use std::os::unix::fs::symlink;
    let d = tmp("links");
    let mesh = generate::torus_knot(2, 3, 0.3, 96, 8);
    let mesh_path = d.join("knot.obj");
    std::fs::create_dir_all(d.join("secret")).unwrap();
    std::fs::create_dir_all(d.join("class/zoe/versions")).unwrap();
    std::fs::create_dir_all(d.join("class/yan")).unwrap();
    dump_of(&mesh, Strategy::SahBinned).write(&d.join("secret/solution.json")).unwrap();
    std::fs::write(d.join("secret/notes.txt"), "SECRET-ANSWER 42\n").unwrap();
    symlink("../secret/solution.json", d.join("class/mallory.json")).unwrap();
    symlink("../secret/notes.txt", d.join("class/eve.txt")).unwrap();
    symlink("../../secret/solution.json", d.join("class/yan/bvh.json")).unwrap();
    dump_of(&mesh, Strategy::Midpoint).write(&d.join("class/zoe/versions/v3.json")).unwrap();
    symlink("versions/v3.json", d.join("class/zoe/bvh.json")).unwrap();
    let subs = discover(&[d.join("class")]);
    let names: Vec<&str> = subs.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["eve", "mallory", "yan", "zoe"]);
    for s in &subs[..3] {
        let why = s.problem.as_deref().unwrap_or_default();
        assert!(s.dump.is_none() && why.contains("links are never followed"), "{}: {why}", s.name);
        assert!(!why.contains("secret"), "the target is not named: {why}");
    }
    assert_eq!(subs[3].dump, Some(std::fs::canonicalize(d.join("class/zoe/versions/v3.json")).unwrap()));
    let set = setup(&mesh, &mesh_path);
    let out = ReportDir::prepare(&d.join("report"), Vec::new()).unwrap();
    let rows = grade_class(&set, References::new(&set), &subs, &out, &WorkControl::new(), |_| {}).rows;
    let verdicts: Vec<Verdict> = rows.iter().map(|r| r.verdict).collect();
    assert_eq!(verdicts, [Verdict::NoDump, Verdict::NoDump, Verdict::NoDump, Verdict::Correct]);
    let text = serde_json::to_string(&rows).unwrap();
    assert!(!text.contains("SECRET") && !text.contains("secret"), "nothing of the secret folder in the rows");
}

/// A file that is not a dump is named with what is wrong in bvhscope's words only: no word of
/// it reaches the report (a student's archive may hold anything).
#[test]
fn an_unreadable_file_is_reported_without_its_content() {
    let d = tmp("content");
    let mesh = generate::torus_knot(2, 3, 0.3, 32, 4);
    let mesh_path = d.join("knot.obj");
    let texts = [
        "bvhscope-bvh 1\nSECRET-A is here\n",
        "bvhscope-bvh 1 SECRET-B\n",
        "bvhscope-bvh 1\nnode SECRET-C 0 0 1 1 1 leaf 0 1\n",
        "{\"format\": \"SECRET-D\", \"version\": 1}",
        "{\"format\": \"bvhscope-bvh\", \"version\": 1, \"primitives\": [], \"nodes\": \"SECRET-E\"}",
        "{\"format\": \"bvhscope-bvh\", \"version\": 1, \"primitives\": [\"SECRET-F\"], \"nodes\": []}",
        "bvhscope-bvh 1\nnode 0 0 0 1 1 1 children 1 2 axis SECRET-G\n",
    ];
    let names: Vec<String> = (0..texts.len()).map(|k| format!("s{k}.txt")).collect();
    for (n, t) in names.iter().zip(texts) {
        std::fs::write(d.join(n), t).unwrap();
    }
    let rows = grade(&setup(&mesh, &mesh_path), &d, &names.iter().map(String::as_str).collect::<Vec<_>>());
    for r in &rows {
        assert_eq!(r.verdict, Verdict::Unreadable, "{}", r.reason);
        assert!(!r.reason.contains("SECRET"), "{}", r.reason);
        assert!(r.reason.starts_with(&d.join(&r.submission).display().to_string()), "names the file: {}", r.reason);
    }
    assert!(rows[2].reason.ends_with("line 2: a word where a number must be"), "{}", rows[2].reason);
}

/// How far apart two timings are: the larger over the smaller, less one.
fn apart(x: f64, y: f64) -> f64 {
    x.max(y) / x.min(y) - 1.0
}

/// Timing fairness is a systematic property: an unfair method (a tree timed alone against one
/// timed beside another, a reference timed in a round of three) puts the same tree 1.5 to 2×
/// apart on every try, while a busy machine's noise moves one try and not the next. So `measure`
/// is asked up to `TRIES` times and the test holds if any try comes within `tolerance`: noise
/// cannot fail it three times running (CI once read 1.06 against 1.22 on a single try), and a
/// bias beyond the tolerance fails every try. Each try's worst gap is returned with a label.
const TRIES: usize = 3;

fn fair_on_some_try(tolerance: f64, mut measure: impl FnMut() -> (f64, String)) {
    let mut seen = Vec::new();
    for _ in 0..TRIES {
        let (gap, what) = measure();
        if gap < tolerance {
            return;
        }
        seen.push(format!("{:.0} % ({what})", gap * 100.0));
    }
    panic!("{TRIES} tries, each more than {:.0} % apart: {}", tolerance * 100.0, seen.join("; "));
}

/// Two students who hand in the same tree get the same figures and the same rank, and their
/// trace times, timed in the same rounds as the SAH tree, are within 15 % of each other while
/// four threads keep this machine's cores busy.
#[test]
fn identical_trees_rank_alike_and_time_alike_on_a_busy_machine() {
    let d = tmp("busy");
    let mesh = generate::torus_knot(2, 3, 0.3, 300, 20);
    let mesh_path = d.join("knot.obj");
    let dump = dump_of(&mesh, Strategy::Midpoint);
    dump.write(&d.join("ann.json")).unwrap();
    dump.write(&d.join("bea.txt")).unwrap();
    let mut set = setup(&mesh, &mesh_path);
    set.time_rays = 4096;
    // Within 15 % either way: two timings on two cores shared with four busy threads and a
    // parallel test run came 10.1 % apart (and once 15.1 %); the unfairness this guards against
    // was 2× (and a reference's 194 ns per ray against its copy's 127).
    fair_on_some_try(0.15, || {
        let stop = std::sync::atomic::AtomicBool::new(false);
        let rows = std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| {
                    let mut x = 1u64;
                    while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                        x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
                    }
                });
            }
            let rows = grade(&set, &d, &["ann.json", "bea.txt"]);
            stop.store(true, std::sync::atomic::Ordering::Relaxed);
            rows
        });
        let (a, b) = (&rows[0], &rows[1]);
        assert_eq!(a.rank, b.rank);
        let (qa, qb) = (a.quality.clone().unwrap(), b.quality.clone().unwrap());
        assert_eq!((qa.sah_cost, qa.nodes_per_ray, qa.epo), (qb.sah_cost, qb.nodes_per_ray, qb.epo));
        let (ta, tb) = (a.versus_sah.unwrap().trace_time, b.versus_sah.unwrap().trace_time);
        let (sa, sb) = (qa.speedup_over_linear, qb.speedup_over_linear);
        let gap = apart(ta, tb).max(apart(sa, sb));
        (gap, format!("{ta:.3} and {tb:.3} of the SAH tree's time, speed-ups {sa:.0}× and {sb:.0}×"))
    });
}

/// A student who hands in bvhscope's own midpoint tree, and one who hands in its SAH tree, get
/// the figures of the report's midpoint and SAH references: every tree is timed the same way,
/// beside the SAH tree in rounds of two on the same rays. The references were timed all in one
/// round (three trees sharing the cache) and the students in pairs: the same tree read 194 ns
/// per ray as a reference and 127 as a student's (issue 59).
#[test]
fn a_reference_and_a_students_identical_tree_time_alike() {
    let d = tmp("reference-time");
    let mesh = generate::torus_knot(2, 3, 0.3, 300, 20);
    let mesh_path = d.join("knot.obj");
    let mut set = setup(&mesh, &mesh_path);
    set.time_rays = 4096;
    for (strategy, name) in [(Strategy::Midpoint, "mia.json"), (Strategy::SahBinned, "sam.json")] {
        let params = BuildParams { strategy, layout: Layout::Binary, ..set.params };
        BvhDump::of_any(&AnyBvh::build(&mesh, &params), &mesh, None).write(&d.join(name)).unwrap();
    }
    let subs = discover(&[d.join("mia.json"), d.join("sam.json")]);
    // Within 30 %: the unfairness this guards against was half again (194 against 127 ns per
    // ray); two timings of one tree on a machine busy with CI's other tests came 16 % apart. The
    // speed-up is a ratio of two timings in the same rounds, held to the same 30 %.
    let mut tries = 0;
    fair_on_some_try(0.3, || {
        tries += 1;
        let out = ReportDir::prepare(&d.join(format!("report-{tries}")), Vec::new()).unwrap();
        let graded = grade_class(&set, References::new(&set), &subs, &out, &WorkControl::new(), |_| {});
        let reference = |s: &str| graded.references.trees().find(|r| r.strategy == s).unwrap().quality.clone();
        let mut worst = (0.0, String::new());
        for (row, strategy) in graded.rows.iter().zip(["midpoint", "sah"]) {
            let (theirs, ours) = (row.quality.clone().unwrap(), reference(strategy));
            assert_eq!(theirs.nodes_per_ray, ours.nodes_per_ray, "{strategy}: the same tree");
            let (a, b) = (theirs.trace_ns_per_ray, ours.trace_ns_per_ray);
            let (sa, sb) = (theirs.speedup_over_linear, ours.speedup_over_linear);
            let gap = apart(a, b).max(apart(sa, sb));
            if gap >= worst.0 {
                let what = format!("{strategy}: {a:.1} ns per ray as a student's, {b:.1} as the reference, speed-ups {sa:.0}× and {sb:.0}×");
                worst = (gap, what);
            }
        }
        worst
    });
}
