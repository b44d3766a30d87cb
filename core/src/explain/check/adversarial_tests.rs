//! The checker against adversarial trees: correct trees deeper than any built one, tolerances
//! that must not grow with the scene, gaps between the leaves of a cut triangle.

use super::check_tests::*;
use super::*;
use crate::bvh::{Accelerator, BuildParams, Bvh};
use crate::mesh::generate;

/// A chain of `n` stacked unit triangles (triangle k at z = k), as a dump of depth `n`: node k
/// interior over (leaf of triangle k, node k + 1). Correct, and deeper than any built tree.
fn chain(n: u32) -> (Mesh, BvhDump) {
    let mut p = Vec::new();
    let mut t = Vec::new();
    for k in 0..n {
        let z = k as f32;
        p.extend([Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 0.0, z), Vec3::new(0.0, 1.0, z)]);
        t.push([3 * k, 3 * k + 1, 3 * k + 2]);
    }
    let mesh = Mesh::from_triangles("chain", p, t);
    let inner = n - 1;
    let mut nodes = Vec::new();
    for k in 0..inner {
        let mut d = node([0.0, 0.0, k as f32], [1.0, 1.0, (n - 1) as f32]);
        let next = if k + 1 < inner { k + 1 } else { inner + n - 1 };
        d.children = Some(vec![inner + k, next]);
        d.axis = Some(2);
        nodes.push(d);
    }
    for k in 0..n {
        let mut d = node([0.0, 0.0, k as f32], [1.0, 1.0, k as f32]);
        (d.first, d.count) = (Some(k), Some(1));
        nodes.push(d);
    }
    let dump = BvhDump { format: "bvhscope-bvh".into(), version: 1, mesh: None, primitives: (0..n).collect(), nodes };
    (mesh, dump)
}

/// A correct tree of any depth is checked and traced: a chain of 3,000 nodes (the traversal stack
/// spills past its fixed part; it used to panic at 128), every ray as the linear scan's.
#[test]
fn a_deep_correct_chain_checks_clean_and_traces() {
    let (mesh, dump) = chain(3000);
    let (f, bvh) = run(&dump, &mesh, 3000);
    assert!(f.iter().all(|f| !f.defect), "{f:?}");
    let bvh = bvh.expect("traced");
    assert!(crate::bvh::TreeStats::of(&bvh).max_depth >= 2999);
    // Rays along the stack hit the nearest triangle through every level.
    let linear = crate::bvh::LinearScan::new(&mesh);
    for k in 0..50 {
        let o = Vec3::new(0.25, 0.25, -1.0 - k as f32);
        for dir in [Vec3::Z, Vec3::new(0.001 * k as f32, 0.0, 1.0)] {
            let t = |h: Option<crate::bvh::Hit>| h.map(|h| (h.prim, h.t));
            let r = crate::geometry::Ray::new(o, dir);
            let a = bvh.closest_hit(&mut r.clone(), TraceOptions::default(), &mut crate::bvh::NoStats);
            let b = linear.closest_hit(&mut r.clone(), TraceOptions::default(), &mut crate::bvh::NoStats);
            assert_eq!(t(a), t(b));
        }
    }
}

/// The bounds tolerance is the triangle's, not the scene's: a far triangle at 10⁶ does not
/// excuse leaf boxes collapsed to points near the origin (it used to: 1e-6 of the scene's size).
#[test]
fn a_far_triangle_does_not_widen_the_tolerance() {
    let mut p = Vec::new();
    let mut t = Vec::new();
    for k in 0..4u32 {
        let x = k as f32 * 0.01;
        p.extend([Vec3::new(x, 0.0, 0.0), Vec3::new(x + 0.01, 0.0, 0.0), Vec3::new(x, 0.01, 0.0)]);
        t.push([3 * k, 3 * k + 1, 3 * k + 2]);
    }
    p.extend([Vec3::splat(1e6), Vec3::new(1e6 + 1.0, 1e6, 1e6), Vec3::new(1e6, 1e6 + 1.0, 1e6)]);
    t.push([12, 13, 14]);
    let mesh = Mesh::from_triangles("far", p, t);
    let mut d = BvhDump::of_bvh(
        &Bvh::build(
            &mesh,
            &BuildParams { layout: crate::bvh::Layout::Binary, max_leaf_size: 1, ..BuildParams::default() },
        ),
        &mesh,
        None,
    );
    assert!(check_tree(&d, &mesh).is_empty());
    for n in d.nodes.iter_mut().filter(|n| n.first.is_some() && n.min[0] < 1.0) {
        let c = [(n.min[0] + n.max[0]) / 2.0, (n.min[1] + n.max[1]) / 2.0, n.min[2]];
        (n.min, n.max) = (c, c);
    }
    let f = check_tree(&d, &mesh);
    assert!(f.iter().any(|f| f.defect && f.group == Group::Bounds && f.text.starts_with("4 leaves' boxes")), "{f:?}");
}

/// A triangle referenced by two leaves whose boxes leave a gap between x = 0.51 and 0.56 (a
/// sample grid of the triangle never lands in it): the gap is found, and a ray through it misses
/// what the linear scan hits.
#[test]
fn a_gap_between_the_leaves_of_a_cut_triangle_is_found() {
    let mesh = Mesh::from_triangles(
        "two",
        vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::splat(5.0), Vec3::new(6.0, 5.0, 5.0), Vec3::new(5.0, 6.0, 5.0)],
        vec![[0, 1, 2], [3, 4, 5]],
    );
    let leaf = |min: [f32; 3], max: [f32; 3], first| {
        let mut n = node(min, max);
        (n.first, n.count) = (Some(first), Some(1));
        n
    };
    let mut root = node([0.0; 3], [6.0, 6.0, 5.0]);
    root.children = Some(vec![1, 2]);
    let mut inner = node([0.0; 3], [1.0, 1.0, 0.0]);
    inner.children = Some(vec![3, 4]);
    let nodes = vec![
        root,
        inner,
        leaf([5.0; 3], [6.0, 6.0, 5.0], 2),
        leaf([0.0; 3], [0.51, 1.0, 0.0], 0),
        leaf([0.56, 0.0, 0.0], [1.0, 0.44, 0.0], 1),
    ];
    let d = BvhDump { format: "bvhscope-bvh".into(), version: 1, mesh: None, primitives: vec![0, 0, 1], nodes };
    let f = check_tree(&d, &mesh);
    let cut = f.iter().find(|f| f.group == Group::Bounds && f.defect).expect("the gap is a defect");
    let around = cut.examples[0].split("around (").nth(1).unwrap();
    let x: f32 = around.split(',').next().unwrap().parse().unwrap();
    assert!(x > 0.51 && x < 0.56, "{cut:?}");
    // Without the gap the same tree is correct.
    let mut closed = d.clone();
    (closed.nodes[4].min[0], closed.nodes[4].max[1]) = (0.51, 0.49);
    assert!(check_tree(&closed, &mesh).iter().all(|f| !f.defect));
}

/// A leaf of more triangles than the layout's leaves hold (255 for a wide tree) is traced all the
/// same, as leaves of its box: its rays are checked (they used not to be: a warning, exit 0), and
/// every hit is the linear scan's.
#[test]
fn a_leaf_too_large_for_its_layout_is_traced_and_its_rays_checked() {
    let mesh = generate::torus_knot(2, 3, 0.3, 128, 6);
    assert!(mesh.triangle_count() > 3 * 256);
    let n = mesh.triangle_count() as u32;
    let b = mesh.bounds();
    let (lo, hi) = (Vec3::from(b.min).to_array(), Vec3::from(b.max).to_array());
    let mut root = node(lo, hi);
    root.children = Some(vec![1, 2, 3]);
    let parts = [(0, 300), (300, 300), (600, n - 600)];
    let mut nodes = vec![root];
    for (f, c) in parts {
        let mut l = node(lo, hi);
        (l.first, l.count) = (Some(f), Some(c));
        nodes.push(l);
    }
    let d = BvhDump { format: "bvhscope-bvh".into(), version: 1, mesh: None, primitives: (0..n).collect(), nodes };
    let (f, bvh) = run(&d, &mesh, 2000);
    assert!(f.iter().all(|f| !f.defect), "{f:?}");
    assert!(f.iter().any(|f| f.group == Group::Rays && f.text.contains("more than 255 triangles")), "{f:?}");
    assert_eq!(crate::bvh::TreeView::triangle_count(&bvh.unwrap()), n as usize);
    // Shrink one big leaf's box: its wrong rays are found.
    let mut broken = d.clone();
    broken.nodes[1].max[0] = broken.nodes[1].min[0];
    let (f, _) = run(&broken, &mesh, 2000);
    assert!(f.iter().any(|f| f.defect && f.group == Group::Rays), "{f:?}");
}

/// A small dump whose leaves ask for millions of references is refused before any is followed.
#[test]
fn references_are_bounded_before_they_are_followed() {
    let mesh = row();
    let mut d = good();
    d.primitives = vec![0; 65535];
    for _ in 0..2000 {
        let mut l = node([0.0; 3], [4.0, 1.0, 0.0]);
        (l.first, l.count) = (Some(0), Some(65535));
        d.nodes.push(l);
    }
    let start = std::time::Instant::now();
    let f = check_tree(&d, &mesh);
    assert!(f.iter().any(|f| f.defect && f.text.contains("more than a BVH of this mesh can need")), "{f:?}");
    assert_eq!(f.len(), 1, "nothing further is checked: {f:?}");
    assert!(start.elapsed().as_secs() < 5, "refused at once");
}

/// A triangle twice in one leaf is a warning naming it and the leaf (not "cut among leaves").
#[test]
fn a_triangle_twice_in_one_leaf_is_a_warning() {
    let mesh = row();
    let mut d = good();
    d.primitives = vec![1, 0, 3, 2, 2];
    d.nodes[1].count = Some(3);
    let f = check_tree(&d, &mesh);
    assert!(f.iter().all(|f| !f.defect), "{f:?}");
    let w = f
        .iter()
        .find(|f| f.group == Group::Coverage && f.text.contains("referenced twice in one leaf"))
        .expect("a warning");
    assert_eq!(w.examples, ["triangle 2 (leaf node 1)"]);
}

/// The file's triangle numbering counts every face, degenerate ones included, wherever they are:
/// first, in the middle, last (a mesh ending with one used to be one triangle short), and quads
/// fan-triangulated. A dump that references them is correct (a warning says they are harmless);
/// one that leaves them out is correct too.
#[test]
fn degenerate_faces_keep_their_numbers_first_middle_and_last() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 2 0 0\n\
               f 1 1 2\nf 1 2 3\nf 1 2 4 3\nf 2 2 2\nf 2 5 4\nf 3 3 3\n";
    let (mesh, report) = crate::mesh::parse_obj("deg.obj", obj).unwrap();
    assert_eq!(report.degenerate_skipped, 3);
    assert_eq!(mesh.file_triangle_count(), 7, "1 + 1 + 2 (quad) + 1 + 1 + 1");
    assert_eq!(mesh.triangles_by_file_number().len(), 7);
    let b = mesh.bounds();
    let (lo, hi) = (Vec3::from(b.min).to_array(), Vec3::from(b.max).to_array());
    let dump = |prims: Vec<u32>| {
        let mut l = node(lo, hi);
        (l.first, l.count) = (Some(0), Some(prims.len() as u32));
        BvhDump { format: "bvhscope-bvh".into(), version: 1, mesh: None, primitives: prims, nodes: vec![l] }
    };
    let all = check_tree(&dump((0..7).collect()), &mesh);
    assert!(all.iter().all(|f| !f.defect), "{all:?}");
    let w = all.iter().find(|f| f.text.contains("are in leaves: harmless")).expect("named as harmless");
    assert_eq!(w.examples, ["triangle 0 (leaf node 0)", "triangle 4 (leaf node 0)", "triangle 6 (leaf node 0)"]);
    let some = check_tree(&dump(vec![1, 2, 3, 5]), &mesh);
    assert!(some.iter().all(|f| !f.defect), "{some:?}");
    assert!(some.iter().any(|f| f.text.contains("in no leaf: harmless") && f.examples.len() == 3), "{some:?}");
    // Leaving out a triangle with area is a defect.
    let short = check_tree(&dump(vec![1, 2, 5]), &mesh);
    assert!(short.iter().any(|f| f.defect && f.line(8) == "1 triangle is in no leaf: triangle 3"), "{short:?}");
}

/// Every tree bvhscope builds, of every strategy and layout, written as a dump, checks clean
/// with the exact bounds (the SBVH's clipped boxes included, within a few ulps).
#[test]
fn every_built_tree_checks_clean_with_the_exact_bounds() {
    for mesh in [generate::torus_knot(2, 3, 0.3, 64, 8), generate::diagonal_rods(2, 6, 4.0, 0.05, 0.3)] {
        for strategy in crate::bvh::Strategy::ALL {
            for layout in crate::bvh::Layout::ALL {
                let b =
                    AnyBvh::build(&mesh, &BuildParams { strategy, layout, sbvh_growth: 100, ..BuildParams::default() });
                let d = BvhDump::of_any(&b, &mesh, None);
                let f = check_tree(&d, &mesh);
                assert!(f.iter().all(|f| !f.defect), "{strategy:?} {layout:?}: {f:?}");
            }
        }
    }
}

/// The wrong mesh is said first, in one line, before the defects that follow from it.
#[test]
fn a_dump_of_another_mesh_says_so_first() {
    let mesh = row();
    let mut d = good();
    d.mesh = Some("models/teapot.obj".into());
    d.primitives[0] = 6319;
    let s = Subject { dump: &d, dump_path: "t.json".as_ref(), mesh: &mesh, mesh_path: "/x/Monkey.obj".as_ref() };
    let c = check(&s, &camera(&mesh), 0, TraceOptions::default(), &WorkControl::new()).unwrap();
    assert_eq!(
        c.findings[0].text,
        "the dump was written for teapot.obj, but is checked against Monkey.obj (4 triangles): is this the mesh it was built over?"
    );
    assert!(has(&c.findings, Group::Structure, Some(3), None, "primitives[0] = 6319"), "{:?}", c.findings);
}
