//! The traversal counters to the exact count. Trees built by hand (a few triangles placed so the
//! midpoint builder's tree can be drawn on paper), rays whose work is worked out by hand, every
//! layout, both traversal orders, closest and any hit, both triangle tests. Then the relation
//! between the binary and the wide layout's counts on the same tree (documented in `bvh::wide`),
//! on many rays over a generated mesh. Deeper hand-built trees are in `exact_counts_deeper.rs`.

mod counting;

use bvhscope_core::bvh::{
    Accelerator, BuildParams, Bvh, LinearScan, RayCounters, TraceOptions, TraversalOrder, WideBvh,
};
use bvhscope_core::geometry::{Ray, TriangleTest};
use bvhscope_core::mesh::{generate, Mesh};
use counting::*;
use glam::Vec3;

#[test]
fn the_row_of_four_is_built_as_drawn() {
    let bvh = Bvh::build(&row(), &params());
    assert_eq!(bvh.nodes.len(), 7, "root, A, B and four leaves");
    assert_eq!(bvh.nodes.iter().filter(|n| n.is_leaf()).count(), 4);
    assert!(bvh.nodes.iter().filter(|n| n.is_leaf()).all(|n| n.count == 1));
    let wide = WideBvh::from_binary(bvh);
    assert_eq!(wide.nodes.len(), 1, "one wide node");
    assert_eq!(wide.nodes[0].valid, 0b1111, "with four children");
    assert!(wide.nodes[0].count.iter().all(|&c| c == 1), "all leaves of one triangle");
}

#[test]
fn the_row_of_four_counts_exactly() {
    let mesh = row();
    let binary = Bvh::build(&mesh, &params());
    let wide = WideBvh::from_binary(binary.clone());
    let down = |x: f32| Ray::new(Vec3::new(x, 0.0, 5.0), -Vec3::Z);
    for order in ORDERS {
        for test in TESTS {
            let opts = TraceOptions { order, test };
            // Straight down onto T0: only one child box is hit at each node, so both orders
            // agree. Binary: the root's box (1 test); root visited, A and B tested (+2), A hit;
            // A visited, T0 and T1 tested (+2), T0 hit; T0 visited, a leaf, 1 triangle test.
            // 3 nodes, 5 box tests, 1 leaf, 1 triangle. Any hit: the same, stopping at T0.
            let r = down(0.0);
            assert_eq!(run(&binary, &r, opts), (Some(0), counts(3, 5, 1, 1), true, counts(3, 5, 1, 1)), "{opts:?}");
            // Wide: the root box (1); the one node visited, its four children tested (+4), T0
            // hit; T0 reached as a child, a leaf (not a node visit in the wide layout).
            assert_eq!(run(&wide, &r, opts), (Some(0), counts(1, 5, 1, 1), true, counts(1, 5, 1, 1)), "{opts:?}");

            // Onto T3, the last leaf: the same work on the other side.
            let r = down(6.0);
            assert_eq!(run(&binary, &r, opts), (Some(3), counts(3, 5, 1, 1), true, counts(3, 5, 1, 1)), "{opts:?}");
            assert_eq!(run(&wide, &r, opts), (Some(3), counts(1, 5, 1, 1), true, counts(1, 5, 1, 1)), "{opts:?}");

            // Between A and B (x = 3): inside the root's box, outside both children's. Binary:
            // root box (1), root visited, A and B tested and missed (+2): 1 node, 3 tests.
            let r = down(3.0);
            assert_eq!(run(&binary, &r, opts), (None, counts(1, 3, 0, 0), false, counts(1, 3, 0, 0)), "{opts:?}");
            // Wide: root box (1), the node visited, four children tested, none hit.
            assert_eq!(run(&wide, &r, opts), (None, counts(1, 5, 0, 0), false, counts(1, 5, 0, 0)), "{opts:?}");

            // Inside T1's box but beside the triangle (its corner region at x = 2.45, y = 0.9):
            // the leaf is reached and its one triangle tested, in vain.
            let r = Ray::new(Vec3::new(2.45, 0.9, 5.0), -Vec3::Z);
            assert_eq!(run(&binary, &r, opts), (None, counts(3, 5, 1, 1), false, counts(3, 5, 1, 1)), "{opts:?}");
            assert_eq!(run(&wide, &r, opts), (None, counts(1, 5, 1, 1), false, counts(1, 5, 1, 1)), "{opts:?}");

            // Beside the root's box: one box test, nothing visited, in both layouts.
            let r = down(10.0);
            assert_eq!(run(&binary, &r, opts), (None, counts(0, 1, 0, 0), false, counts(0, 1, 0, 0)), "{opts:?}");
            assert_eq!(run(&wide, &r, opts), (None, counts(0, 1, 0, 0), false, counts(0, 1, 0, 0)), "{opts:?}");
        }
    }
}

#[test]
fn the_orders_differ_where_the_split_axis_rule_picks_the_far_child() {
    let mesh = overlapping();
    let binary = Bvh::build(&mesh, &params());
    assert_eq!(binary.nodes.len(), 3, "root and two leaves");
    assert_eq!(binary.nodes[0].axis, 0, "split on x");
    let wide = WideBvh::from_binary(binary.clone());
    assert_eq!((wide.nodes.len(), wide.nodes[0].valid), (1, 0b11), "one wide node, two leaves");

    // Straight down at x = 0.75: through TR (hit at t = 5) and through TL's box (entered at
    // t = 6.5) but beside TL itself (its slanted edge is at x = 0.33 there). The direction is
    // written out: `-Vec3::Z` would have x = -0, whose sign picks the right child.
    let r = Ray::new(Vec3::new(0.75, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
    for test in TESTS {
        // Entry distance: root box (1), root visited, both children tested (+2), both hit; TR
        // (entry 5) before TL (6.5, pushed). TR visited: a leaf, 1 triangle, hit at 5. TL is
        // popped beyond the hit and skipped. 2 nodes, 3 box tests, 1 leaf, 1 triangle.
        let by_distance = TraceOptions { order: TraversalOrder::EntryDistance, test };
        assert_eq!(run(&binary, &r, by_distance), (Some(1), counts(2, 3, 1, 1), true, counts(2, 3, 1, 1)));
        // Split-axis sign: the direction's x is +0, so the left child (TL, the far one) first:
        // TL visited, its triangle tested and missed; then TR from the stack (entry 5 is not
        // beyond any hit yet), tested and hit. 3 nodes, 3 box tests, 2 leaves, 2 triangles; any
        // hit does the same (TL holds no hit to stop at).
        let by_axis = TraceOptions { order: TraversalOrder::SplitAxisSign, test };
        assert_eq!(run(&binary, &r, by_axis), (Some(1), counts(3, 3, 2, 2), true, counts(3, 3, 2, 2)));
        // The wide layout always takes the nearest child first: root box (1), its node (1
        // visit, +2 box tests), TR then TL; TL skipped after the hit at 5.
        for opts in [by_distance, by_axis] {
            assert_eq!(run(&wide, &r, opts), (Some(1), counts(1, 3, 1, 1), true, counts(1, 3, 1, 1)));
        }
    }

    // From below (z = -5, up): TL's box first (entry 3.5) and TR's at 5. TL's triangle is missed,
    // TR's hit. Both orders now take TL first (+x sign: left; and nearer): 3 nodes, 2 leaves.
    let r = Ray::new(Vec3::new(0.75, 0.0, -5.0), Vec3::Z);
    for order in ORDERS {
        let opts = TraceOptions { order, test: TriangleTest::Watertight };
        assert_eq!(run(&binary, &r, opts), (Some(1), counts(3, 3, 2, 2), true, counts(3, 3, 2, 2)), "{opts:?}");
        assert_eq!(run(&wide, &r, opts), (Some(1), counts(1, 3, 2, 2), true, counts(1, 3, 2, 2)), "{opts:?}");
    }
}

/// Any hit stops at the first triangle that is hit and counts only the tests made: a leaf of
/// three stacked triangles, the ray through all three.
#[test]
fn any_hit_counts_only_the_triangle_tests_it_made() {
    let mut p = Vec::new();
    let tris = [0.0, -1.0, -2.0].map(|z| tri_at(&mut p, 0.0, z)).to_vec();
    let mesh = Mesh::from_triangles("stack", p, tris);
    let binary = Bvh::build(&mesh, &BuildParams { max_leaf_size: 3, ..params() });
    assert_eq!(binary.nodes.len(), 1, "one leaf of three");
    let wide = WideBvh::from_binary(binary.clone());
    let r = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
    for order in ORDERS {
        let opts = TraceOptions { order, test: TriangleTest::Watertight };
        // Closest: root box, the leaf (1 node in binary), all three triangles tested, the top
        // one the nearest. Any hit: the ray hits all three, so it stops after the leaf's first
        // triangle: one test, not three.
        let (hit, closest, found, any) = run(&binary, &r, opts);
        assert_eq!((hit, closest, found, any), (Some(0), counts(1, 1, 1, 3), true, counts(1, 1, 1, 1)));
        // Wide: the root is one node holding the leaf in its one slot.
        let (hit, closest, found, any) = run(&wide, &r, opts);
        assert_eq!((hit, closest, found, any), (Some(0), counts(1, 2, 1, 3), true, counts(1, 2, 1, 1)));
    }
}

/// The relation documented in `bvh::wide`: on the same tree, a ray that no hit prunes (it hits
/// nothing, so both layouts reach every leaf whose box it meets) reaches the same leaves and makes
/// the same triangle tests in both layouts; the wide layout visits at most as many nodes as the
/// binary one visits interior nodes (so does the 8-wide one, fewer in all than the 4-wide
/// one). In the binary layout, box tests = 1 + 2 × (nodes visited − leaves visited) for a ray that enters the root. (Box tests have no such bound between the
/// layouts: a wide node tests its grandchildren's boxes even where the binary walk culled them at
/// the child's box.)
#[test]
fn binary_and_wide_counts_relate_as_documented() {
    let mesh = generate::torus_knot(2, 3, 0.3, 256, 12);
    let binary = Bvh::build(&mesh, &BuildParams { max_leaf_size: 4, ..BuildParams::default() });
    let wide = WideBvh::from_binary(binary.clone());
    let wide8 = WideBvh::<8>::collapse(binary.clone());
    let linear = LinearScan::new(&mesh);
    let b = mesh.bounds();
    let (c, r) = (b.center(), b.extent().length());
    let mut rng = bvhscope_core::random::Rng::new(0x9e37_79b9);
    let mut rand = move || rng.unit();
    let (mut misses, mut crossing) = (0, 0);
    let (mut visits4, mut visits8) = (0u64, 0u64);
    for _ in 0..20_000 {
        let from = c + Vec3::new(rand() - 0.5, rand() - 0.5, rand() - 0.5).normalize_or(Vec3::X) * r;
        let to = c + Vec3::new(rand() - 0.5, rand() - 0.5, rand() - 0.5) * b.extent();
        let ray = Ray::new(from, to - from);
        let opts = TraceOptions::default();
        if linear.closest_hit(&mut ray.clone(), opts, &mut bvhscope_core::bvh::NoStats).is_some() {
            continue;
        }
        misses += 1;
        for order in ORDERS {
            let opts = TraceOptions { order, ..opts };
            let (mut cb, mut cw) = (RayCounters::ZERO, RayCounters::ZERO);
            assert!(binary.closest_hit(&mut ray.clone(), opts, &mut cb).is_none());
            assert!(wide.closest_hit(&mut ray.clone(), opts, &mut cw).is_none());
            assert_eq!(cb.leaves_visited, cw.leaves_visited, "{ray:?}");
            assert_eq!(cb.triangle_tests, cw.triangle_tests, "{ray:?}");
            assert!(cw.nodes_visited <= cb.nodes_visited - cb.leaves_visited || cb.nodes_visited == 0, "{ray:?}");
            // Eight wide: the same leaves and triangles; each node visited is an interior binary
            // node the ray enters, and in all fewer than four wide visits.
            let mut c8 = RayCounters::ZERO;
            assert!(wide8.closest_hit(&mut ray.clone(), opts, &mut c8).is_none());
            assert_eq!((c8.leaves_visited, c8.triangle_tests), (cw.leaves_visited, cw.triangle_tests), "{ray:?}");
            assert!(c8.nodes_visited <= cb.nodes_visited - cb.leaves_visited || cb.nodes_visited == 0, "{ray:?}");
            (visits4, visits8) = (visits4 + u64::from(cw.nodes_visited), visits8 + u64::from(c8.nodes_visited));
            if cb.nodes_visited > 0 {
                assert_eq!(cb.box_tests, 1 + 2 * (cb.nodes_visited - cb.leaves_visited), "{ray:?}");
            }
        }
        let mut cb = RayCounters::ZERO;
        binary.closest_hit(&mut ray.clone(), TraceOptions::default(), &mut cb);
        crossing += usize::from(cb.leaves_visited > 0);
    }
    assert!(
        misses > 2_000 && crossing > 500,
        "the rays exercise the relation: {misses} misses, {crossing} reach leaves"
    );
    assert!(visits8 < visits4, "eight wide visits fewer nodes: {visits8} vs {visits4}");
}
