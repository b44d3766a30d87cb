//! The node inspector's tests: the hierarchy, each strategy's marker against the split its tree made,
//! the curves against a brute-force SAH, the SBVH's replayed nodes.

use super::*;
use crate::bvh::{BuildParams, Layout};
use crate::mesh::generate;

fn built(strategy: Strategy, leaf: u32) -> (Bvh, Hierarchy) {
    let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
    let bvh = Bvh::build(
        &mesh,
        &BuildParams { strategy, layout: Layout::Binary, max_leaf_size: leaf, ..BuildParams::default() },
    );
    let h = Hierarchy::of(&bvh);
    (bvh, h)
}

/// The wide layout's binary tree, built again, is the one a binary build makes: the node ids
/// the inspector shows are the same in both layouts.
#[test]
fn a_wide_trees_binary_tree_is_the_binary_build() {
    let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
    let params = BuildParams { layout: Layout::Wide4, ..BuildParams::default() };
    let wide = crate::bvh::AnyBvh::build(&mesh, &params);
    let binary = Bvh::build(&mesh, &BuildParams { layout: Layout::Binary, ..params });
    let again = wide.binary_tree(&mesh);
    assert!(again.nodes == binary.nodes && again.prim_ids == binary.prim_ids);
}

#[test]
fn the_hierarchy_knows_parents_depths_and_ranges() {
    let (bvh, h) = built(Strategy::SahBinned, 4);
    assert_eq!((h.first[0], h.count[0]), (0, bvh.prim_ids.len() as u32));
    for (i, n) in bvh.nodes.iter().enumerate().filter(|(_, n)| !n.is_leaf()) {
        let (l, r) = (n.index as usize, n.index as usize + 1);
        assert_eq!((h.parent[l], h.parent[r]), (i as u32, i as u32));
        assert_eq!(h.depth[l], h.depth[i] + 1);
        assert_eq!(h.first[l], h.first[i], "the left child's range starts the parent's");
        assert_eq!(h.first[r], h.first[l] + h.count[l], "the right one follows it");
    }
    assert!(h.other_slots.is_empty(), "no triangle in two leaves");
    for (prim, _) in bvh.prim_ids.iter().enumerate() {
        let leaf = h.leaf_of_prim(prim as u32).unwrap();
        let path = h.path(leaf);
        assert_eq!(path[0], 0);
        assert!(path.iter().all(|&a| h.holds(a as usize, h.slot_of_prim[prim])));
    }
}

/// The marker of the tree's own strategy is the split the tree has, at every interior node
/// where the strategy found one (elsewhere the builder fell back to equal count): the same
/// axis, the left child's triangles on the left, and the plane between the two children's
/// centroids. The inspector runs the builder's code, not a copy of it.
#[test]
fn each_trees_own_strategy_marks_the_split_it_made() {
    for strategy in Strategy::ALL.into_iter().filter(|s| s.splits_top_down()) {
        let (bvh, h) = built(strategy, 2);
        let mut checked = 0;
        for (i, n) in bvh.nodes.iter().enumerate().filter(|(_, n)| !n.is_leaf()) {
            let ins = inspect(&bvh, &h, i as u32).unwrap();
            let Some(m) = ins.markers.iter().find(|(s, _)| *s == strategy).unwrap().1 else { continue };
            let (l, r) = (n.index as usize, n.index as usize + 1);
            assert_eq!((m.axis, m.left, m.right), (n.axis, h.count[l], h.count[r]), "{strategy:?} node {i}");
            let centroids = |c: usize| {
                let range = h.first[c] as usize..(h.first[c] + h.count[c]) as usize;
                range.map(|s| Aabb::from_points(&bvh.tris[s]).center()[m.axis as usize]).collect::<Vec<_>>()
            };
            let (left, right) = (centroids(l), centroids(r));
            if strategy == Strategy::EqualCount {
                assert!(left.iter().all(|&c| c <= m.position) && right.iter().all(|&c| c >= m.position));
            } else {
                assert!(left.iter().all(|&c| c < m.position), "{strategy:?} node {i}");
                assert!(right.iter().all(|&c| c >= m.position), "{strategy:?} node {i}");
            }
            checked += 1;
        }
        let interior = bvh.nodes.iter().filter(|n| !n.is_leaf()).count();
        assert!(checked * 10 >= interior * 9, "{strategy:?}: {checked} of {interior} nodes have a marker");
    }
}

/// What the build replay shows of a split (the tree's own strategy's plane, and the binned
/// SAH's bins) is what the inspector shows.
#[test]
fn own_split_is_the_inspectors_marker_of_the_trees_strategy() {
    for strategy in Strategy::ALL {
        let (bvh, h) = built(strategy, 4);
        for node in [0u32, 1, 2, 3] {
            let ins = inspect(&bvh, &h, node).unwrap();
            let (m, binned) = own_split(&bvh, &h, node);
            assert_eq!(m, ins.markers.iter().find(|(s, _)| *s == strategy).unwrap().1, "{strategy:?} {node}");
            let binning = matches!(strategy, Strategy::SahBinned | Strategy::Sbvh);
            let want = if binning { ins.binned.clone() } else { Default::default() };
            assert_eq!(binned, want);
        }
    }
}

/// An SBVH tree's inspector replays its build: at every interior node the SBVH marker is the
/// split the tree has (its axis, and as many references on each side as the children hold
/// when they are inspected in turn), spatial splits among them, and where the SBVH priced
/// spatial planes the curve's cheapest point is no dearer than its split.
#[test]
fn an_sbvh_trees_inspector_replays_its_build() {
    let mesh = generate::diagonal_rods(3, 6, 6.0, 0.03, 0.2);
    let params =
        BuildParams { strategy: Strategy::Sbvh, layout: Layout::Binary, sbvh_growth: 100, ..Default::default() };
    let bvh = Bvh::build(&mesh, &params);
    let h = Hierarchy::of(&bvh);
    let (mut spatial, mut curves) = (0, 0);
    for (i, n) in bvh.nodes.iter().enumerate().filter(|(_, n)| !n.is_leaf()) {
        let ins = inspect(&bvh, &h, i as u32).unwrap();
        let m = ins.markers.iter().find(|(s, _)| *s == Strategy::Sbvh).unwrap().1.unwrap();
        let count = |c: u32| inspect(&bvh, &h, c).unwrap().triangles;
        assert_eq!((m.axis, m.left, m.right), (n.axis, count(n.index), count(n.index + 1)), "node {i}");
        let e = ins.sbvh.unwrap();
        if e.split.unwrap().kind == crate::bvh::builders::driver::SplitKind::Spatial {
            spatial += 1;
            let cheapest = ins.spatial.iter().flatten().map(|p| p.cost).fold(f32::INFINITY, f32::min);
            assert!(cheapest <= m.cost * 1.0001, "node {i}: the bins' best {cheapest}, the split {}", m.cost);
        }
        curves += (!ins.spatial.iter().all(Vec::is_empty)) as u32;
        assert_eq!(ins.spatial.iter().all(Vec::is_empty), !e.spatial_priced, "node {i}");
    }
    assert!(spatial >= 5 && curves >= spatial, "{spatial} spatial splits, {curves} spatial curves");
    assert_eq!(spatial, bvh.report.spatial_splits, "the replay finds every spatial split the build made");
    assert_eq!(inspect(&bvh, &h, 0).unwrap().triangles as usize, mesh.triangle_count());
    // A cut triangle's hit point selects the leaf holding that part of it.
    let (&prim, others) = h.other_slots.iter().next().expect("cut triangles");
    let mut parts = 0;
    for &slot in others.iter().chain([&h.slot_of_prim[prim as usize]]) {
        let leaf = h.leaf_of_slot[slot as usize];
        let b = bvh.nodes[leaf as usize].bounds();
        let t = bvh.tris[slot as usize];
        let inside = (0..=20)
            .flat_map(|i| (0..=20 - i).map(move |j| (i as f32 / 20.0, j as f32 / 20.0)))
            .map(|(u, v)| t[0] * (1.0 - u - v) + t[1] * u + t[2] * v)
            .find(|p| {
                let others_hold = h.slots_of_prim(prim).filter(|&s| s != slot).any(|s| {
                    let o = bvh.nodes[h.leaf_of_slot[s as usize] as usize].bounds();
                    (0..3).all(|a| o.min[a] <= p[a] && p[a] <= o.max[a])
                });
                (0..3).all(|a| b.min[a] < p[a] && p[a] < b.max[a]) && !others_hold
            });
        if let Some(p) = inside {
            assert_eq!(h.leaf_of_hit(&bvh, prim, p), Some(leaf), "the part at {p:?}");
            parts += 1;
        }
    }
    assert!(parts >= 2, "{parts} parts of triangle {prim} found inside their own leaf only");
}

/// A built tree's own split cost, from its children's stored boxes, is the cost its
/// strategy's marker gives on the curve (both SAH strategies; the boxes are tight).
#[test]
fn own_cost_is_the_strategys_marker_cost_for_a_built_tree() {
    for strategy in [Strategy::SahSweep, Strategy::SahBinned] {
        let (bvh, h) = built(strategy, 4);
        for node in [0u32, 1, 2, 3, 4] {
            let ins = inspect(&bvh, &h, node).unwrap();
            let m = ins.markers.iter().find(|(s, _)| *s == strategy).unwrap().1.unwrap();
            let own = ins.own_cost.unwrap();
            assert!((own - m.cost).abs() <= 1e-4 * m.cost, "{strategy:?} {node}: {own} vs {}", m.cost);
        }
    }
}

/// Every point of the sweep's curve is the SAH cost of the partition its plane makes, worked
/// out by brute force; the sweep SAH's marker is the curve's minimum; midpoint's sits at the
/// middle of the centroid bounds on their widest axis; binned points lie at bin boundaries.
#[test]
fn curves_and_markers_match_a_brute_force_sah() {
    let (bvh, h) = built(Strategy::Midpoint, 4);
    let c = bvh.params.cost;
    for node in [0u32, 1, 2, 5, 9] {
        let ins = inspect(&bvh, &h, node).unwrap();
        let (prims, info) = node_prims(&bvh, &h, node as usize);
        let area = info.bounds.area();
        for axis in 0..3 {
            assert!(!ins.sweep[axis].is_empty(), "node {node} axis {axis}");
            let mut sorted = prims.clone();
            sorted.sort_by(|a, b| a.centroid()[axis].total_cmp(&b.centroid()[axis]));
            for p in &ins.sweep[axis] {
                // The plane between the left-th and the next centroid (no two equal there).
                let (l, r) = sorted.split_at(p.left as usize);
                let (last, next) = (l[l.len() - 1].centroid()[axis], r[0].centroid()[axis]);
                assert!(last < next && last <= p.position && p.position <= next, "node {node} axis {axis}");
                assert_eq!(p.left + p.right, prims.len() as u32);
                let bounds = |s: &[BuildPrim]| Aabb::of(s.iter().map(BuildPrim::bounds));
                let weighted = bounds(l).area() * l.len() as f32 + bounds(r).area() * r.len() as f32;
                let brute = c.traversal + c.intersection * weighted / area;
                assert!((p.cost - brute).abs() <= 1e-5 * brute, "{} against {brute}", p.cost);
            }
            let distinct = sorted.windows(2).filter(|w| w[0].centroid()[axis] < w[1].centroid()[axis]).count();
            assert_eq!(ins.sweep[axis].len(), distinct, "a point between every two distinct centroids");
            let (lo, step) = (info.centroid_bounds.min[axis], info.centroid_bounds.extent()[axis] / ins.bins as f32);
            for p in &ins.binned[axis] {
                let k = (p.position - lo) / step;
                assert!((k - k.round()).abs() < 1e-3, "a binned plane at a bin boundary: {k}");
            }
        }
        let marker = |s| ins.markers.iter().find(|(m, _)| *m == s).unwrap().1.unwrap();
        let sweep = marker(Strategy::SahSweep);
        let min = ins.sweep.iter().flatten().map(|p| p.cost).fold(f32::INFINITY, f32::min);
        assert_eq!(sweep.cost, min, "node {node}: the sweep takes the curve's minimum");
        let mid = marker(Strategy::Midpoint);
        let w = info.centroid_bounds.widest_axis();
        assert_eq!(mid.axis as usize, w);
        assert_eq!(mid.position, info.centroid_bounds.center()[w]);
        let binned = marker(Strategy::SahBinned);
        let bmin = ins.binned.iter().flatten().map(|p| p.cost).fold(f32::INFINITY, f32::min);
        assert_eq!(binned.cost, bmin, "node {node}: the binned SAH takes its bins' minimum");
        assert!(sweep.cost <= binned.cost && sweep.cost <= mid.cost);
    }
}

/// Every plane's and every marker's cost, term by term: C_trav + C_isect·(A_L/A)·n_L +
/// C_isect·(A_R/A)·n_R adds up to the cost the curve and the marker give, and each side's chance
/// of being entered is at most one.
#[test]
fn each_split_cost_adds_up_term_by_term() {
    let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
    for cost in [SahCost::default(), SahCost { traversal: 2.5, intersection: 1.0 }] {
        let params = BuildParams { layout: Layout::Binary, cost, ..BuildParams::default() };
        let bvh = Bvh::build(&mesh, &params);
        let h = Hierarchy::of(&bvh);
        for node in [0u32, 1, 2, 5] {
            let ins = inspect(&bvh, &h, node).unwrap();
            let check = |t: CostTerms| {
                assert!(t.area_left <= 1.0 + 1e-5 && t.area_right <= 1.0 + 1e-5, "{t:?}");
                let sum = t.traversal + t.left_term + t.right_term;
                assert!((sum - t.cost).abs() <= 1e-4 * t.cost.max(1.0), "{sum} vs {t:?}");
                assert_eq!(t.traversal, cost.traversal);
            };
            for p in ins.sweep.iter().chain(&ins.binned).chain(&ins.spatial).flatten() {
                check(p.terms(ins.sah));
            }
            for m in ins.markers.iter().filter_map(|(_, m)| *m) {
                check(m.terms(ins.sah));
            }
        }
    }
}
