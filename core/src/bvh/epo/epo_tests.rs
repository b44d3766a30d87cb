use super::measure::*;
use super::*;
use crate::bvh::epo::sample::Estimator;
use crate::bvh::hierarchy::Hierarchy;
use crate::bvh::node::{Bvh, BvhNode};
use crate::bvh::params::{BuildParams, Layout, Strategy};
use crate::geometry::Aabb;
use crate::mesh::{generate, Mesh};
use crate::random::Rng;
use glam::Vec3;

/// The definition, brute force: every node against every triangle not in its subtree.
fn brute_terms(bvh: &Bvh, h: &Hierarchy) -> Vec<f64> {
    let total: f64 = bvh.tris.iter().map(triangle_area).sum();
    let c = bvh.params.cost;
    bvh.nodes
        .iter()
        .enumerate()
        .map(|(n, node)| {
            let sum: f64 = (0..bvh.tris.len())
                .filter(|&s| !h.holds(n, s as u32))
                .map(|s| clipped_area(&bvh.tris[s], &node.bounds()))
                .sum();
            let w = if node.is_leaf() { c.intersection as f64 * node.count as f64 } else { c.traversal as f64 };
            w * sum / total
        })
        .collect()
}

fn build(mesh: &Mesh, strategy: Strategy, max_leaf_size: u32) -> Bvh {
    Bvh::build(mesh, &BuildParams { strategy, max_leaf_size, layout: Layout::Binary, ..BuildParams::default() })
}

/// `count` random triangles in the box -1..1, of every size from specks to the whole box.
fn soup(count: u32, seed: u64) -> Mesh {
    let mut rng = Rng::new(seed);
    let mut positions = Vec::new();
    for _ in 0..count {
        let size = 2f32.powf(rng.range(-6.0, 1.0));
        let c = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
        for _ in 0..3 {
            positions.push(c + Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)) * size);
        }
    }
    Mesh::from_triangles("soup", positions, (0..count).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect())
}

/// A flat `k` by `k` grid of squares in the plane y = 0, two triangles each, next to a tilted one:
/// triangles lying on the faces of their boxes (the box is closed, so they count in full).
fn grid(k: u32) -> Mesh {
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for (lift, y0) in [(0.0, 0.0), (0.5, 1.0)] {
        let base = positions.len() as u32;
        for i in 0..=k {
            for j in 0..=k {
                let (x, z) = (i as f32 / k as f32, j as f32 / k as f32);
                positions.push(Vec3::new(x, y0 + lift * x, z));
            }
        }
        for i in 0..k {
            for j in 0..k {
                let v = |a: u32, b: u32| base + a * (k + 1) + b;
                triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
                triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
            }
        }
    }
    Mesh::from_triangles("grid", positions, triangles)
}

fn meshes() -> Vec<(&'static str, Mesh)> {
    vec![
        ("soup", soup(300, 1)),
        ("needles", generate::needles(150, 2)),
        ("grid", grid(10)),
        ("cornell box", generate::cornell_box()),
        ("knot", generate::torus_knot(2, 3, 0.3, 48, 6)),
    ]
}

fn assert_close(what: &str, got: f64, want: f64) {
    assert!((got - want).abs() <= 1e-12 + 1e-9 * want.abs(), "{what}: {got} vs {want}");
}

/// Two leaves under a root, both triangles in the plane z = 0 and overlapping in x:
/// T0 = (0,0) (2,0) (0,2), area 2, in leaf 1 with box x 0..2; T1 = (1,0) (3,0) (3,2), area 2, in
/// leaf 2 with box x 1..3. Leaf 1's box holds the part of T1 with x ≤ 2: the triangle (1,0)
/// (2,0) (2,1), area 1/2; leaf 2's box the part of T0 with x ≥ 1: (1,0) (2,0) (1,1), area 1/2.
/// The root holds both. EPO = (1·½ + 1·½) / 4 = 0.25 with C_isect = 1 and one triangle a leaf.
#[test]
fn two_overlapping_leaves_by_hand() {
    let tris = vec![
        [Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0)],
        [Vec3::new(1.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0), Vec3::new(3.0, 2.0, 0.0)],
    ];
    let b = |t: &[Vec3; 3]| Aabb::from_points(t);
    let bvh = Bvh {
        nodes: vec![
            BvhNode::interior(b(&tris[0]).union(b(&tris[1])), 1, 0),
            BvhNode::leaf(b(&tris[0]), 0, 1),
            BvhNode::leaf(b(&tris[1]), 1, 1),
        ],
        prim_ids: vec![0, 1],
        tris,
        params: BuildParams { layout: Layout::Binary, ..BuildParams::default() },
        report: Default::default(),
    };
    assert_eq!(clipped_area(&bvh.tris[1], &bvh.nodes[1].bounds()), 0.5);
    assert_eq!(clipped_area(&bvh.tris[0], &bvh.nodes[2].bounds()), 0.5);
    assert_eq!(node_terms(&bvh, &Hierarchy::of(&bvh)), vec![0.0, 0.125, 0.125]);
    assert_eq!(of(&bvh), 0.25);
}

#[test]
fn clipping_keeps_what_is_inside() {
    let t = [Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
    let unit = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    assert_eq!(clipped_area(&t, &unit), 0.5, "all inside");
    assert_eq!(clipped_area(&t, &Aabb::new(Vec3::splat(2.0), Vec3::splat(3.0))), 0.0, "all outside");
    // The square 0..0.5 in x and y cuts the corner x, y ≤ 0.5: all of it below x + y ≤ 1.
    let corner = Aabb::new(Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.5, 0.5, 1.0));
    assert!((clipped_area(&t, &corner) - 0.25).abs() < 1e-12);
    // A tilted triangle through a box: the part inside has the area of the box's cross-section.
    let tilted = [Vec3::new(-4.0, -4.0, -4.0), Vec3::new(4.0, -4.0, 4.0), Vec3::new(0.0, 8.0, 0.0)];
    let a = clipped_area(&tilted, &unit); // the plane z = x, cut by |x|,|y| ≤ 1: a 2 by 2√2 rectangle
    assert!((a - 4.0 * 2f64.sqrt()).abs() < 1e-9, "{a}");
    assert_eq!(triangle_area(&tilted), clipped_area(&tilted, &Aabb::from_points(&tilted)));
}

/// Within the default budget small meshes are measured exactly: every node's term equals the
/// brute-force sum, on random soups, needles, flat grids, axis-aligned boxes and a knot, with
/// trees that nest (SAH, midpoint, LBVH, PLOC) and trees whose leaves hold cut triangles (SBVH).
#[test]
fn measure_equals_the_definition_on_small_meshes() {
    for (name, mesh) in meshes() {
        for strategy in [Strategy::SahBinned, Strategy::Midpoint, Strategy::Lbvh, Strategy::Ploc, Strategy::Sbvh] {
            for leaf in [1, 4] {
                let bvh = build(&mesh, strategy, leaf);
                let h = Hierarchy::of(&bvh);
                let epo = measure(&bvh, &h);
                assert!(
                    epo.is_exact() && epo.std_error == 0.0 && epo.samples == 0,
                    "{name} {strategy:?}: {}",
                    epo.method()
                );
                assert!(epo.work <= epo.budget, "{name} {strategy:?}");
                let brute = brute_terms(&bvh, &h);
                for (n, (&got, &want)) in epo.terms.iter().zip(&brute).enumerate() {
                    assert_close(&format!("{name} {strategy:?} leaf {leaf} node {n}"), got, want);
                }
                assert_close(&format!("{name} {strategy:?} sum"), epo.value, brute.iter().sum());
                assert_eq!(epo.value, of(&bvh), "{name}: `of` is `measure`'s value");
                for n in [0, bvh.nodes.len() / 2, bvh.nodes.len() - 1] {
                    assert_close(&format!("{name} node_term {n}"), node_term(&bvh, &h, n), brute[n]);
                }
            }
        }
    }
}

/// With a budget too small for every walk the rest is estimated: the walks that finished are
/// exact, the estimate lies within four standard errors of the definition, and the figure is the
/// same on any number of threads.
#[test]
fn an_estimate_within_its_stated_error() {
    for (name, mesh) in meshes() {
        for strategy in [Strategy::SahBinned, Strategy::Sbvh] {
            let bvh = build(&mesh, strategy, 4);
            let h = Hierarchy::of(&bvh);
            let brute = brute_terms(&bvh, &h);
            let want: f64 = brute.iter().sum();
            for budget in [1, 20 * bvh.nodes.len() as u64, 200 * bvh.nodes.len() as u64] {
                let epo = measure_within(&bvh, &h, budget);
                assert!(budget > 1 || !epo.is_exact(), "{name} {strategy:?}: a budget of 1 leaves walks unfinished");
                assert_eq!(epo.is_exact(), epo.samples == 0);
                let (mut exact_sum, mut estimated) = (0.0, 0.0);
                for (n, (&got, &b)) in epo.terms.iter().zip(&brute).enumerate() {
                    // An exact term is the definition's; an estimated one may be anything near.
                    if (got - b).abs() <= 1e-12 + 1e-9 * b {
                        exact_sum += b;
                    } else {
                        estimated += 1.0;
                        assert!(got >= 0.0, "{name} node {n}");
                    }
                }
                assert!(estimated <= (epo.terms.len() - epo.exact_nodes) as f64);
                assert!(exact_sum <= want + 1e-9);
                let err = (epo.value - want).abs();
                assert!(
                    err <= 4.0 * epo.std_error + 1e-9 * want,
                    "{name} {strategy:?} budget {budget}: {} vs {want} (error {err}, {})",
                    epo.text(),
                    epo.method()
                );
                let on = |threads| {
                    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                    pool.install(|| measure_within(&bvh, &h, budget))
                };
                assert_eq!(on(1), on(3), "{name}: the same on 1 and 3 threads");
            }
        }
    }
}

/// The stated error is honest: over many seeds the estimate falls within two standard errors of
/// the definition about as often as it should (94% for 16 replicates), by walks and by pairs, on
/// needles and on a knot, and the error shrinks as the budget grows.
#[test]
fn the_stated_error_is_honest() {
    let cases = [(generate::needles(400, 9), 400_000), (generate::torus_knot(2, 3, 0.3, 96, 6), 60_000)];
    for (mesh, budget) in cases {
        let bvh = build(&mesh, Strategy::SahBinned, 4);
        let h = Hierarchy::of(&bvh);
        let want: f64 = brute_terms(&bvh, &h).iter().sum();
        for by in [Estimator::Walks, Estimator::Pairs, Estimator::Best] {
            let estimates: Vec<Epo> = (0..40).map(|seed| measure_with(&bvh, &h, budget, seed, by)).collect();
            assert!(estimates.iter().all(|e| !e.is_exact()), "{by:?}: the budget leaves walks unfinished");
            let within = estimates.iter().filter(|e| (e.value - want).abs() <= 2.0 * e.std_error).count();
            assert!(within >= 32, "{} {by:?}: {within} of 40 within two standard errors", mesh.name);
            let (small, large) =
                (measure_with(&bvh, &h, budget / 10, 1, by), measure_with(&bvh, &h, budget * 4, 1, by));
            assert!(large.std_error < small.std_error, "{} {by:?}: {} vs {}", mesh.name, large.text(), small.text());
            // (Pairs on a knot, whose boxes are small, are far worse than walks: the pilot's
            // choice is not.)
            if by == Estimator::Best {
                assert!(large.std_error < 0.03 * want, "{}: {} vs {want}", mesh.name, large.text());
            }
        }
    }
}

/// A node array whose child links loop back (an imported tree that slipped past the checks)
/// gets a figure, not a walk for ever: the estimate's walks follow links forward only.
#[test]
fn a_tree_whose_links_loop_is_measured_in_bounded_time() {
    let mut bvh = build(&generate::torus_knot(2, 3, 0.3, 48, 6), Strategy::SahBinned, 4);
    let h = Hierarchy::of(&bvh);
    // The deepest interior node's children become the root's pair: a loop back to the top.
    let i = (0..bvh.nodes.len()).rev().find(|&i| !bvh.nodes[i].is_leaf()).expect("an interior node");
    bvh.nodes[i].index = bvh.nodes[0].index;
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for by in [Estimator::Walks, Estimator::Pairs] {
            let _ = tx.send(measure_with(&bvh, &h, 20_000, 1, by).value.is_finite());
        }
        // The inspector's exact share of one node: a walk without a cap.
        let _ = tx.send(node_term(&bvh, &h, 1).is_finite());
    });
    for _ in 0..3 {
        let finite = rx.recv_timeout(std::time::Duration::from_secs(120)).expect("the EPO of a looping tree ends");
        assert!(finite);
    }
}
