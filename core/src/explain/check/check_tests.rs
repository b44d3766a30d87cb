//! The checker's tests: each defect class on small hand-made dumps, shuffled and 4-wide trees,
//! duplicated references, the text and gzip forms, round trips.

use super::*;
use crate::bvh::{Accelerator, BuildParams, Bvh};
use crate::dump::DumpNode;
use crate::mesh::generate;

/// Four triangles in a row along x, each a unit square's half: triangle k spans x k..k+1.
pub(super) fn row() -> Mesh {
    let mut p = Vec::new();
    let mut t = Vec::new();
    for k in 0..4 {
        let i = p.len() as u32;
        let x = k as f32;
        p.extend([Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 0.0, 0.0), Vec3::new(x, 1.0, 0.0)]);
        t.push([i, i + 1, i + 2]);
    }
    Mesh::from_triangles("row", p, t)
}

pub(super) fn node(min: [f32; 3], max: [f32; 3]) -> DumpNode {
    DumpNode { min, max, children: None, first: None, count: None, axis: None }
}

/// A correct dump of `row()` with its nodes out of order: root 0 with children 3 and 1; leaf 3
/// holds primitives[0..2] = T1, T0, leaf 1 holds [2..4] = T3, T2; node 2, an empty leaf, is
/// never reached (a warning).
pub(super) fn good() -> BvhDump {
    let mut root = node([0.0, 0.0, 0.0], [4.0, 1.0, 0.0]);
    root.children = Some(vec![3, 1]);
    root.axis = Some(0);
    let mut left = node([0.0, 0.0, 0.0], [2.0, 1.0, 0.0]);
    (left.first, left.count) = (Some(0), Some(2));
    let mut right = node([2.0, 0.0, 0.0], [4.0, 1.0, 0.0]);
    (right.first, right.count) = (Some(2), Some(2));
    let spare = node([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]);
    let mut spare = spare;
    (spare.first, spare.count) = (Some(0), Some(0));
    BvhDump {
        format: "bvhscope-bvh".into(),
        version: 1,
        mesh: None,
        primitives: vec![1, 0, 3, 2],
        nodes: vec![root, right, spare, left],
    }
}

pub(super) fn camera(mesh: &Mesh) -> crate::render::Camera {
    crate::render::Camera::framing_up(&mesh.bounds(), 32, 24, crate::render::UpAxis::Y, 45.0)
}

/// The findings and the traced tree of `d` over `mesh`, with `n` random rays.
pub(super) fn run(d: &BvhDump, mesh: &Mesh, n: u64) -> (Vec<Finding>, Option<AnyBvh>) {
    let s = Subject { dump: d, dump_path: "test.json".as_ref(), mesh, mesh_path: "test.obj".as_ref() };
    let c = check(&s, &camera(mesh), n, TraceOptions::default(), &WorkControl::new()).unwrap();
    (c.findings, c.tree.map(|(b, _)| b))
}

/// Whether a finding of `f` is a defect of `group` about `node` and `tri` whose line says `words`.
pub(super) fn has(f: &[Finding], group: Group, node: Option<u32>, tri: Option<u32>, words: &str) -> bool {
    f.iter().any(|x| {
        x.defect && x.group == group && x.node == node && x.triangle == tri && x.line(usize::MAX).contains(words)
    })
}

#[test]
fn a_correct_shuffled_dump_has_no_defect_and_traces_like_the_linear_scan() {
    let mesh = row();
    let (f, bvh) = run(&good(), &mesh, 2000);
    assert!(f.iter().all(|f| !f.defect), "{f:?}");
    assert_eq!(f.iter().filter(|f| f.node == Some(2)).count(), 1, "node 2 is never reached: a warning");
    let Some(AnyBvh::Binary(bvh)) = bvh else { panic!("a binary tree") };
    assert_eq!(bvh.nodes.len(), 3);
}

#[test]
fn each_defect_names_its_node_or_triangle() {
    let mesh = row();
    let find = |d: &BvhDump| run(d, &mesh, 500).0;
    // Structure: a child past the end.
    let mut d = good();
    d.nodes[0].children = Some(vec![3, 9]);
    assert!(has(&find(&d), Group::Structure, Some(0), None, "node 0: child 9 (the last node is 3)"));
    // A leaf range past the end of the primitives.
    let mut d = good();
    d.nodes[1].count = Some(5);
    assert!(has(
        &find(&d),
        Group::Structure,
        Some(1),
        None,
        "1 leaf range runs past the end of primitives: node 1: 2..7"
    ));
    // A primitive that is no triangle of the mesh.
    let mut d = good();
    d.primitives[2] = 40;
    assert!(has(&find(&d), Group::Structure, Some(1), None, "primitives[2] = 40 (node 1"));
    // Both leaf and interior; too many children.
    let mut d = good();
    d.nodes[3].children = Some(vec![1, 2]);
    assert!(has(&find(&d), Group::Structure, Some(3), None, "both a leaf"));
    // A split axis that is no axis.
    let mut d = good();
    d.nodes[0].axis = Some(7);
    assert!(has(&find(&d), Group::Structure, Some(0), None, "node 0 (axis 7)"));
    let mut d = good();
    d.nodes[0].children = Some(vec![3, 1, 2, 2, 2, 2, 2, 2, 2]);
    assert!(has(&find(&d), Group::Structure, Some(0), None, "2 to 8 are supported): node 0 (9 children)"));
    // Reached twice: a cycle and two parents.
    let mut d = good();
    d.nodes[3].children = Some(vec![0, 1]);
    (d.nodes[3].first, d.nodes[3].count) = (None, None);
    assert!(has(&find(&d), Group::Structure, Some(0), None, "reached twice: node 0 (from node 3: a cycle)"));
    let mut d = good();
    d.nodes[0].children = Some(vec![1, 1]);
    assert!(has(&find(&d), Group::Structure, Some(1), None, "node 1 (from node 0: two parents)"));
    // An inverted box and a NaN box.
    let mut d = good();
    d.nodes[1].min[0] = 5.0;
    assert!(has(&find(&d), Group::Structure, Some(1), None, "node 1 on x (min 5 > max 4)"));
    let mut d = good();
    d.nodes[1].max[1] = f32::NAN;
    assert!(has(&find(&d), Group::Structure, Some(1), None, "NaN"));
    // Coverage: a triangle in no leaf.
    let mut d = good();
    d.primitives = vec![1, 0, 3, 3];
    assert!(has(&find(&d), Group::Coverage, None, Some(2), "1 triangle is in no leaf: triangle 2"));
    // Bounds: the leaf's box too small, and an ancestor's.
    let mut d = good();
    d.nodes[1].max[0] = 3.5;
    let f = find(&d);
    assert!(has(&f, Group::Bounds, Some(1), Some(3), "leaf node 1 (triangle 3 by 0.5 on +x)"), "{f:?}");
    assert!(has(&f, Group::Rays, None, Some(3), "hit differently"), "rays past x = 3.5 miss the leaf: {f:?}");
    let mut d = good();
    d.nodes[0].max[0] = 3.0;
    let f = find(&d);
    assert!(
        has(&f, Group::Bounds, Some(0), Some(3), "node 0's box does not contain its child node 1 (by 1 on +x): 1 triangle below node 1 sticks out of node 0's box: triangle 3 by 1 on +x (leaf node 1)"),
        "the root cause once, the leaf's box not blamed: {f:?}"
    );
    assert_eq!(f.iter().filter(|f| f.group == Group::Bounds).count(), 1, "{f:?}");
}

/// bvhscope's own tree, written and read back (JSON and text), is the same tree: the same
/// nodes, SAH cost and counts for every ray, and no finding.
#[test]
fn a_round_trip_gives_back_the_same_tree() {
    let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
    let bvh = Bvh::build(&mesh, &BuildParams { layout: crate::bvh::Layout::Binary, ..BuildParams::default() });
    let dump = BvhDump::of_bvh(&bvh, &mesh, None);
    let json: BvhDump = serde_json::from_str(&serde_json::to_string(&dump).unwrap()).unwrap();
    let dir = crate::scratch::shared("dump");
    let text_path = dir.join("tree.txt");
    std::fs::write(&text_path, dump.to_text()).unwrap();
    let text = BvhDump::read(&text_path, 1 << 30).unwrap();
    for back in [json, text] {
        let (f, imported) = run(&back, &mesh, 2000);
        assert!(f.iter().all(|f| !f.defect), "{f:?}");
        let Some(AnyBvh::Binary(imported)) = imported else { panic!("a binary tree") };
        assert_eq!(imported.nodes.len(), bvh.nodes.len());
        let (a, b) = (crate::bvh::TreeStats::of(&bvh).sah_cost, crate::bvh::TreeStats::of(&imported).sah_cost);
        assert!((a - b).abs() <= 1e-9 * a, "{a} vs {b}");
        for (r, _) in check_rays(&mesh, &camera(&mesh), 200) {
            let (mut ca, mut cb) = (crate::bvh::RayCounters::default(), crate::bvh::RayCounters::default());
            let ha = bvh.closest_hit(&mut r.clone(), TraceOptions::default(), &mut ca);
            let hb = imported.closest_hit(&mut r.clone(), TraceOptions::default(), &mut cb);
            assert_eq!((ha, ca), (hb, cb));
        }
    }
}

/// A triangle in two leaves (as spatial splits make) is fine, and traced in both; a 4-wide
/// tree is checked for structure, coverage and bounds, and traced.
#[test]
fn duplicated_references_and_four_wide_trees() {
    let mesh = row();
    let mut d = good();
    // Triangle 1 spans x 1..2: also put it in the right leaf, whose box then grows to hold it.
    d.primitives = vec![1, 0, 3, 2, 1];
    d.nodes[1].first = Some(2);
    d.nodes[1].count = Some(3);
    d.nodes[1].min[0] = 1.0;
    let (f, bvh) = run(&d, &mesh, 2000);
    assert!(f.iter().all(|f| !f.defect), "{f:?}");
    let Some(AnyBvh::Binary(bvh)) = bvh else { panic!("a binary tree") };
    assert_eq!(bvh.prim_ids.len(), 5, "triangle 1 twice");
    // Four leaves under one root: 4-wide.
    let leaf = |k: u32| {
        let mut n = node([k as f32, 0.0, 0.0], [k as f32 + 1.0, 1.0, 0.0]);
        (n.first, n.count) = (Some(k), Some(1));
        n
    };
    let mut root = node([0.0, 0.0, 0.0], [4.0, 1.0, 0.0]);
    root.children = Some(vec![1, 2, 3, 4]);
    let wide = BvhDump {
        format: "bvhscope-bvh".into(),
        version: 1,
        mesh: None,
        primitives: vec![0, 1, 2, 3],
        nodes: vec![root, leaf(0), leaf(1), leaf(2), leaf(3)],
    };
    let (f, bvh) = run(&wide, &mesh, 100);
    assert!(f.iter().all(|f| !f.defect), "{f:?}");
    let Some(AnyBvh::Wide(w)) = bvh else { panic!("a 4-wide tree") };
    assert_eq!((w.nodes.len(), w.nodes[0].valid), (1, 0b1111), "one wide node of four leaves");
    let mut broken = wide.clone();
    broken.nodes[3].max[0] = 2.5;
    let (f, _) = run(&broken, &mesh, 100);
    assert!(
        f.iter().any(|f| f.defect && f.group == Group::Bounds && f.node == Some(3) && f.triangle == Some(2)),
        "{f:?}"
    );
    // The box too small misses rays through the 4-wide traversal too, named by a pixel.
    assert!(f.iter().any(|f| f.defect && f.group == Group::Rays && f.text.contains("pixel")), "{f:?}");
}

/// bvhscope's 4-wide tree written as a dump checks clean: every node of 2 to 4 children, every
/// triangle in a leaf inside its boxes.
#[test]
fn an_exported_four_wide_tree_checks_clean() {
    let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
    let w = crate::bvh::WideBvh::from_binary(Bvh::build(&mesh, &BuildParams::default()));
    let d = BvhDump::of_wide(&w, &mesh, None);
    assert!(d.nodes.iter().any(|n| n.children.as_ref().is_some_and(|k| k.len() > 2)));
    let f = check_tree(&d, &mesh);
    assert!(f.is_empty(), "{f:?}");
    let tiny = Mesh::from_triangles("one", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
    let w = crate::bvh::WideBvh::from_binary(Bvh::build(&tiny, &BuildParams::default()));
    let d = BvhDump::of_wide(&w, &tiny, None);
    assert_eq!(d.nodes.len(), 1, "one leaf");
    assert!(check_tree(&d, &tiny).is_empty());
}

/// A dump compressed with gzip reads as the JSON it holds.
#[test]
fn a_gzip_dump_reads_like_its_json() {
    use std::io::Write;
    let dir = crate::scratch::shared("dump-gz");
    let d = good();
    let path = dir.join("tree.json.gz");
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(serde_json::to_string(&d).unwrap().as_bytes()).unwrap();
    std::fs::write(&path, gz.finish().unwrap()).unwrap();
    assert_eq!(BvhDump::read(&path, 1 << 20).unwrap(), d);
}

#[test]
fn unreadable_dumps_say_why() {
    let dir = crate::scratch::shared("dump-bad");
    let w = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        BvhDump::read(&p, 1 << 20).unwrap_err().to_string()
    };
    assert!(w("future.json", r#"{"format": "bvhscope-bvh", "version": 2, "primitives": [], "nodes": []}"#)
        .contains("version 2"));
    assert!(w("broken.json", r#"{"format": "bvhscope-bvh", "version": 1, "nodes": [}"#).contains("broken JSON"));
    assert!(w("other.json", r#"{"format": "gltf"}"#).contains("\"gltf\""));
    assert!(w("bad.txt", "bvhscope-bvh 1\nnode 0 0 0 1 1 x leaf 0 1\n").contains("line 2"));
}

/// An SBVH's tree, whose spatial splits cut triangles among leaves, checks clean (each part in
/// its own leaf's box covers the triangle); with the box of one leaf holding part of a cut
/// triangle shrunk to a point, the part left uncovered is named.
#[test]
fn an_sbvh_tree_checks_clean_and_an_uncovered_part_of_a_cut_triangle_is_named() {
    let mesh = generate::diagonal_rods(2, 6, 4.0, 0.05, 0.3);
    let params = BuildParams {
        strategy: crate::bvh::Strategy::Sbvh,
        layout: crate::bvh::Layout::Binary,
        sbvh_growth: 100,
        ..BuildParams::default()
    };
    let bvh = Bvh::build(&mesh, &params);
    assert!(bvh.prim_ids.len() > mesh.triangle_count() * 5 / 4, "spatial splits cut many slivers");
    let dump = BvhDump::of_bvh(&bvh, &mesh, None);
    let (f, traced) = run(&dump, &mesh, 4000);
    assert!(f.iter().all(|f| !f.defect), "{f:?}");
    assert_eq!(crate::bvh::TreeView::triangle_count(&traced.unwrap()), bvh.prim_ids.len());
    let mut refs = vec![0; mesh.triangle_count()];
    for &p in &bvh.prim_ids {
        refs[p as usize] += 1;
    }
    let mut named = 0;
    let cut = bvh
        .nodes
        .iter()
        .enumerate()
        .filter(|(_, n)| n.is_leaf())
        .flat_map(|(i, n)| n.prims().filter(|&s| refs[bvh.prim_ids[s] as usize] > 1).map(move |s| (i, s)));
    for (leaf, slot) in cut.take(8) {
        let mut broken = dump.clone();
        broken.nodes[leaf].max = broken.nodes[leaf].min;
        let tri = mesh.file_number(bvh.prim_ids[slot]);
        let (f, _) = run(&broken, &mesh, 0);
        named += f.iter().any(|f| {
            f.defect && f.group == Group::Bounds && f.line(usize::MAX).contains(&format!("triangle {tri} around"))
        }) as u32;
    }
    assert!(named >= 6, "{named} of 8 shrunk leaves of cut triangles named");
}
