//! The readers and the checker under random input, in process: random bytes as a dump (JSON,
//! gzip, text), a scene and an OBJ never panic, hang or allocate without bound; random trees
//! over a small mesh, correct or broken in every way the checker knows, are never passed when
//! they are wrong: a dump the checker finds no defect in traces every ray as the linear scan does.
//! `FUZZ_CASES=N` runs N cases of each instead of the default (CI keeps it short; the closing
//! note of issue 34 gives a long run's count).

#[path = "common/scratch.rs"]
mod scratch;

use bvhscope_core::bvh::{Accelerator, LinearScan, NoStats, TraceOptions};
use bvhscope_core::dump::{BvhDump, DumpNode};
use bvhscope_core::explain::check::{check, check_tree, Subject};
use bvhscope_core::geometry::Ray;
use bvhscope_core::mesh::{generate, Mesh};
use bvhscope_core::random::Rng;
use bvhscope_core::render::{Camera, UpAxis};
use bvhscope_core::work::WorkControl;
use proptest::prelude::*;
use std::path::PathBuf;
use std::time::{Duration, Instant};

fn cases(default: u32) -> u32 {
    std::env::var("FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn dir() -> PathBuf {
    scratch::shared("fuzz")
}

/// Run `f` on a thread of its own; a panic is a failure, and so is taking longer than `limit`.
fn bounded<T: Send + 'static>(limit: Duration, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)));
    });
    match rx.recv_timeout(limit) {
        Ok(Ok(v)) => v,
        Ok(Err(_)) => panic!("panicked"),
        Err(_) => panic!("took longer than {limit:?}"),
    }
}

/// The beginnings a reader may meet: each form's header, so random bytes reach past it.
const HEADS: [&[u8]; 6] = [
    b"",
    b"bvhscope-bvh 1\n",
    b"{\"format\": \"bvhscope-bvh\", \"version\": 1, ",
    b"\xef\xbb\xbf",
    b"\x1f\x8b",
    b"{\"meshes\": [",
];

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(300), failure_persistence: None, ..ProptestConfig::default() })]

    /// Random bytes after a format's header: every reader answers, none panics or runs on.
    #[test]
    fn random_bytes_are_read_or_refused(head in 0usize..HEADS.len(), body in proptest::collection::vec(any::<u8>(), 0..400), k in 0u64..1_000_000) {
        let mut bytes = HEADS[head].to_vec();
        bytes.extend(&body);
        let path = dir().join(format!("case-{k}.json"));
        std::fs::write(&path, &bytes).unwrap();
        let mesh = generate::torus_knot(2, 3, 0.3, 16, 4);
        let p = path.clone();
        bounded(Duration::from_secs(20), move || {
            if let Ok(d) = BvhDump::read(&p, 1 << 20) {
                let _ = check_tree(&d, &mesh);
            }
            let text = String::from_utf8_lossy(&bytes).into_owned();
            let _ = bvhscope_core::scene::parse_scene_file(&p, &text);
            let _ = bvhscope_core::mesh::parse_obj(&p, &text);
        });
        let _ = std::fs::remove_file(&path);
    }
}

/// A small mesh whose triangles are spread out (so a wrong box loses hits rays can find).
fn mesh() -> Mesh {
    generate::torus_knot(2, 3, 0.35, 24, 5)
}

/// A random tree over `mesh`'s triangles as a dump: random splits of a random order, random
/// widths (2 to 8), boxes that hold their triangles, nodes in a random order.
fn random_tree(mesh: &Mesh, rng: &mut Rng) -> BvhDump {
    let n = mesh.triangle_count() as u32;
    let mut order: Vec<u32> = (0..n).collect();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.below(i as u64 + 1) as usize);
    }
    let width = 2 + rng.below(7) as usize;
    let leaf_max = 1 + rng.below(6) as usize;
    let mut nodes: Vec<DumpNode> = Vec::new();
    let bounds = |range: &[u32]| {
        let b = range
            .iter()
            .fold(bvhscope_core::geometry::Aabb::EMPTY, |b, &t| mesh.triangle(t).iter().fold(b, |b, &p| b.grow(p)));
        (glam::Vec3::from(b.min).to_array(), glam::Vec3::from(b.max).to_array())
    };
    // (node index, range of `order`)
    let mut stack = vec![(0usize, 0usize, order.len())];
    nodes.push(DumpNode { min: [0.0; 3], max: [0.0; 3], children: None, first: None, count: None, axis: None });
    while let Some((i, a, b)) = stack.pop() {
        let (min, max) = bounds(&order[a..b]);
        nodes[i].min = min;
        nodes[i].max = max;
        if b - a <= leaf_max {
            (nodes[i].first, nodes[i].count) = (Some(a as u32), Some((b - a) as u32));
            continue;
        }
        let k = (2 + rng.below(width as u64 - 1) as usize).min(b - a);
        // At least one cut strictly inside the range: two children or more.
        let mut cuts: Vec<usize> = (0..k - 1).map(|_| a + 1 + rng.below((b - a - 1) as u64) as usize).collect();
        cuts.sort();
        cuts.dedup();
        let mut edges = vec![a];
        edges.extend(cuts);
        edges.push(b);
        let mut kids = Vec::new();
        for w in edges.windows(2) {
            let c = nodes.len();
            nodes.push(DumpNode { min: [0.0; 3], max: [0.0; 3], children: None, first: None, count: None, axis: None });
            kids.push(c as u32);
            stack.push((c, w[0], w[1]));
        }
        nodes[i].children = Some(kids);
        nodes[i].axis = Some(rng.below(3) as u8);
    }
    BvhDump { format: "bvhscope-bvh".into(), version: 1, mesh: None, primitives: order, nodes }
}

/// One of the ways a dump goes wrong, at random places.
fn mutate(d: &mut BvhDump, rng: &mut Rng) -> &'static str {
    let n = d.nodes.len();
    let pick = |rng: &mut Rng| rng.below(n as u64) as usize;
    match rng.below(9) {
        0 => {
            // A box shrunk on one side.
            let i = pick(rng);
            let a = rng.below(3) as usize;
            let (lo, hi) = (d.nodes[i].min[a], d.nodes[i].max[a]);
            let cut = lo + (hi - lo) * rng.unit();
            if rng.unit() < 0.5 {
                d.nodes[i].max[a] = cut
            } else {
                d.nodes[i].min[a] = cut
            }
            "a box shrunk"
        }
        1 => {
            // A box moved a little.
            let i = pick(rng);
            let a = rng.below(3) as usize;
            let s = (d.nodes[i].max[a] - d.nodes[i].min[a]).max(1e-3) * 0.05;
            d.nodes[i].min[a] += s;
            d.nodes[i].max[a] += s;
            "a box moved"
        }
        2 => {
            // A primitive replaced by another triangle.
            if !d.primitives.is_empty() {
                let k = rng.below(d.primitives.len() as u64) as usize;
                d.primitives[k] = rng.below(d.primitives.len() as u64 + 3) as u32;
            }
            "a primitive changed"
        }
        3 => {
            // A leaf's count off by one.
            if let Some(l) = d.nodes.iter_mut().filter(|n| n.count.is_some()).nth(pick(rng) % n.max(1)) {
                l.count = l.count.map(|c| if rng.unit() < 0.5 { c.saturating_sub(1) } else { c + 1 });
            }
            "a count off by one"
        }
        4 => {
            // A child pointing elsewhere (a cycle, two parents, past the end).
            let i = pick(rng);
            if let Some(k) = d.nodes[i].children.as_mut() {
                let j = rng.below(k.len() as u64) as usize;
                k[j] = rng.below(n as u64 + 2) as u32;
            }
            "a child changed"
        }
        5 => {
            // A box collapsed to its centre.
            let i = pick(rng);
            let c = [0, 1, 2].map(|a| (d.nodes[i].min[a] + d.nodes[i].max[a]) / 2.0);
            (d.nodes[i].min, d.nodes[i].max) = (c, c);
            "a box collapsed"
        }
        6 => {
            // A triangle added to a leaf too (correct when its box still holds it).
            let t = rng.below(d.primitives.len() as u64) as u32;
            let first = d.primitives.len() as u32;
            d.primitives.push(t);
            d.nodes.push(DumpNode {
                min: [0.0; 3],
                max: [0.0; 3],
                children: None,
                first: Some(first),
                count: Some(1),
                axis: None,
            });
            let i = pick(rng);
            if let Some(k) = d.nodes[i].children.as_mut().filter(|k| k.len() < 8) {
                k.push(n as u32);
            }
            "a leaf added"
        }
        7 => {
            // A NaN or an infinity in a box.
            let i = pick(rng);
            d.nodes[i].max[rng.below(3) as usize] = if rng.unit() < 0.5 { f32::NAN } else { f32::INFINITY };
            "a box not finite"
        }
        _ => "unchanged",
    }
}

fn camera(mesh: &Mesh) -> Camera {
    Camera::framing_up(&mesh.bounds(), 24, 18, UpAxis::Y, 45.0)
}

/// The heart of "no false pass": a dump the checker finds no defect in traces every one of
/// thousands of rays the checker did not trace (another seed, other directions) as the linear scan.
#[test]
fn random_trees_correct_or_broken_are_never_passed_when_wrong() {
    let mesh = mesh();
    let linear = LinearScan::new(&mesh);
    let b = mesh.bounds();
    let probe: Vec<Ray> =
        Rng::rays_at(0xC0FFEE, 4000, (b.min.into(), b.max.into())).into_iter().map(|(o, d)| Ray::new(o, d)).collect();
    let mut rng = Rng::new(12345);
    let (mut passed, mut failed, mut kinds) = (0, 0, std::collections::BTreeMap::new());
    let start = Instant::now();
    for case in 0..cases(120) {
        let mut d = random_tree(&mesh, &mut rng);
        let mutations = rng.below(3);
        let mut what = Vec::new();
        for _ in 0..mutations {
            what.push(mutate(&mut d, &mut rng));
        }
        let s = Subject { dump: &d, dump_path: "fuzz.json".as_ref(), mesh: &mesh, mesh_path: "fuzz.obj".as_ref() };
        let c = check(&s, &camera(&mesh), 500, TraceOptions::default(), &WorkControl::new()).unwrap();
        let defects = c.findings.iter().filter(|f| f.defect).count();
        *kinds.entry((what.join(", "), defects > 0)).or_insert(0) += 1;
        if defects > 0 {
            failed += 1;
            continue;
        }
        passed += 1;
        let (bvh, _) = c.tree.expect("a dump without defects is traced");
        for r in &probe {
            let t = |h: Option<bvhscope_core::bvh::Hit>| h.map(|h| h.t);
            let got = bvh.closest_hit(&mut r.clone(), TraceOptions::default(), &mut NoStats);
            let want = linear.closest_hit(&mut r.clone(), TraceOptions::default(), &mut NoStats);
            assert_eq!(t(got), t(want), "case {case} ({what:?}) passed the check, yet a ray hits differently: {r:?}");
        }
    }
    eprintln!("{passed} passed, {failed} with defects, in {:.1?}: {kinds:?}", start.elapsed());
    assert!(passed > 0 && failed > 0, "both kinds were tried");
}

/// Every tree the checker passes or traces can be walked by every view: its statistics, its
/// hierarchy and the inspector of each node end (an empty leaf used to make the binary tree point
/// back at its root, and `inspect` ran out of memory).
#[test]
fn every_traced_tree_can_be_inspected_node_by_node() {
    use bvhscope_core::bvh::{AnyBvh, Hierarchy, TreeStats};
    use bvhscope_core::explain::inspect;
    let mesh = mesh();
    let mut rng = Rng::new(777);
    for _ in 0..cases(60) {
        let mut d = random_tree(&mesh, &mut rng);
        // Some leaves emptied (count 0), some triangles so made unreferenced.
        for _ in 0..rng.below(4) {
            let leaves: Vec<usize> = (0..d.nodes.len()).filter(|&i| d.nodes[i].count.is_some()).collect();
            let k = leaves[rng.below(leaves.len() as u64) as usize];
            d.nodes[k].count = Some(0);
        }
        let findings = check_tree(&d, &mesh);
        let Ok((bvh, names)) = bvhscope_core::explain::check::traceable(&findings, &d, &mesh, "e.json".as_ref()) else {
            continue;
        };
        let tree = match &bvh {
            AnyBvh::Binary(b) => b.clone(),
            _ => (*names.binary.clone().unwrap().0).clone(),
        };
        let stats = bounded(Duration::from_secs(20), {
            let bvh = bvh.clone();
            move || TreeStats::of(&bvh)
        });
        assert!(stats.nodes >= 1);
        bounded(Duration::from_secs(60), move || {
            let h = Hierarchy::of(&tree);
            for node in 0..tree.nodes.len() as u32 {
                assert!(h.path(node).len() <= tree.nodes.len());
                let _ = inspect::inspect(&tree, &h, node);
            }
        });
    }
}
