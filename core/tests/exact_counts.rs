//! The traversal counters to the exact count. Trees built by hand (a few triangles placed so the
//! midpoint builder's tree can be drawn on paper), rays whose work is worked out by hand, every
//! layout, both traversal orders, closest and any hit, both triangle tests. Then the relation
//! between the binary and the wide layout's counts on the same tree (documented in `bvh::wide`),
//! on many rays over a generated mesh.

use bvhscope_core::bvh::{
    Accelerator, AnyBvh, BuildParams, Bvh, Layout, LinearScan, RayCounters, SplitStrategy, TraceOptions,
    TraversalOrder, WideBvh,
};
use bvhscope_core::geometry::{Ray, TriangleTest};
use bvhscope_core::mesh::{generate, Mesh};
use glam::Vec3;

const ORDERS: [TraversalOrder; 2] = [TraversalOrder::SplitAxisSign, TraversalOrder::EntryDistance];
const TESTS: [TriangleTest; 2] = [TriangleTest::Watertight, TriangleTest::MollerTrumbore];

/// Midpoint splits, one triangle per leaf: the tree follows from the centroids alone.
fn params() -> BuildParams {
    BuildParams { strategy: SplitStrategy::Midpoint, max_leaf_size: 1, ..BuildParams::default() }
}

/// A triangle in the plane z = `z` with its centroid at (`x`, 0, `z`): corners (x ∓ 0.5, -0.5) and
/// (x, 1), so its box is x ± 0.5, y -0.5..1.
fn tri_at(positions: &mut Vec<Vec3>, x: f32, z: f32) -> [u32; 3] {
    let i = positions.len() as u32;
    positions.extend([Vec3::new(x - 0.5, -0.5, z), Vec3::new(x + 0.5, -0.5, z), Vec3::new(x, 1.0, z)]);
    [i, i + 1, i + 2]
}

fn counts(n: u32, b: u32, l: u32, t: u32) -> RayCounters {
    RayCounters { nodes_visited: n, box_tests: b, leaves_visited: l, triangle_tests: t, ..RayCounters::ZERO }
}

/// The closest hit's triangle and counters, and the any-hit answer and counters.
fn run(accel: &impl Accelerator, ray: &Ray, opts: TraceOptions) -> (Option<u32>, RayCounters, bool, RayCounters) {
    let (mut closest, mut any) = (RayCounters::ZERO, RayCounters::ZERO);
    let hit = accel.closest_hit(&mut ray.clone(), opts, &mut closest).map(|h| h.prim);
    let found = accel.any_hit(ray, opts, &mut any);
    (hit, closest, found, any)
}

/// Four triangles in a row along x (centroids x = 0, 2, 4, 6, all in z = 0), facing the rays.
///
/// Binary tree (midpoint of the centroids on x, the widest axis): root splits at 3 into A = {0, 2}
/// and B = {4, 6}; A at 1 into leaves T0 | T1, B at 5 into T2 | T3. Seven nodes, depth 2.
/// Wide tree: the root takes A and B, then opens B (the two have equal area; the later one wins
/// the tie), then A: one node with the four leaves as its children.
fn row() -> Mesh {
    let mut p = Vec::new();
    let tris = [0.0, 2.0, 4.0, 6.0].map(|x| tri_at(&mut p, x, 0.0)).to_vec();
    Mesh::from_triangles("row", p, tris)
}

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

/// Two triangles whose boxes overlap along the split axis, at different depths: TL (centroid
/// x = -1) wide, x -3..1, in z = -1.5; TR (centroid x = 1) small, x 0.5..1.5, in z = 0. The
/// centroids spread 2 in x and 1.5 in z, so the root splits on x: left TL, right TR.
fn overlapping() -> Mesh {
    let p = vec![
        Vec3::new(-3.0, -0.5, -1.5),
        Vec3::new(1.0, -0.5, -1.5),
        Vec3::new(-1.0, 1.0, -1.5),
        Vec3::new(0.5, -0.5, 0.0),
        Vec3::new(1.5, -0.5, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
    ];
    Mesh::from_triangles("overlapping", p, vec![[0, 1, 2], [3, 4, 5]])
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
    let mut state = 0x9e37_79b9_u32;
    let mut rand = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
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

// ---- Deeper trees: several wide nodes, leaves of one and of two triangles, the far child
// ---- holding a hit, the split-axis rule reading the node's own axis.

/// A child slot of a wide node, for shape assertions: an interior wide node (its index) or a
/// leaf (the mesh's triangles it holds, in leaf order).
#[derive(Debug, PartialEq)]
enum Slot {
    Node(u32),
    Leaf(Vec<u32>),
}

/// The binary tree's leaves left to right: (depth, the mesh's triangles in leaf order).
fn binary_leaves(bvh: &Bvh) -> Vec<(u32, Vec<u32>)> {
    fn go(bvh: &Bvh, i: usize, depth: u32, out: &mut Vec<(u32, Vec<u32>)>) {
        let n = &bvh.nodes[i];
        if n.is_leaf() {
            out.push((depth, n.prims().map(|k| bvh.prim_ids[k]).collect()));
        } else {
            go(bvh, n.index as usize, depth + 1, out);
            go(bvh, n.index as usize + 1, depth + 1, out);
        }
    }
    let mut out = Vec::new();
    go(bvh, 0, 0, &mut out);
    out
}

/// Each wide node's slots, in node order.
fn wide_slots(w: &WideBvh) -> Vec<Vec<Slot>> {
    w.nodes
        .iter()
        .map(|n| {
            n.slots()
                .map(|s| {
                    let (first, count) = (n.child[s] as usize, n.count[s] as usize);
                    if count == 0 {
                        Slot::Node(n.child[s])
                    } else {
                        Slot::Leaf(w.prim_ids[first..first + count].to_vec())
                    }
                })
                .collect()
        })
        .collect()
}

/// Both layouts of the same binary tree, through `AnyBvh` as the app builds them.
fn both_layouts(mesh: &Mesh, params: BuildParams) -> (Bvh, WideBvh) {
    let binary = match AnyBvh::build(mesh, &BuildParams { layout: Layout::Binary, ..params }) {
        AnyBvh::Binary(b) => b,
        _ => panic!("asked for the binary layout"),
    };
    let wide = match AnyBvh::build(mesh, &BuildParams { layout: Layout::Wide4, ..params }) {
        AnyBvh::Wide(w) => w,
        _ => panic!("asked for the 4-wide layout"),
    };
    (binary, wide)
}

/// A triangle in the plane x = `x`, facing along x: corners (y, z) = (-0.5, ∓0.5) and (1, 0), so
/// its centroid is (x, 0, 0) and its box is flat in x, y -0.5..1, z -0.5..0.5.
fn tri_facing_x(positions: &mut Vec<Vec3>, x: f32) -> [u32; 3] {
    let i = positions.len() as u32;
    positions.extend([Vec3::new(x, -0.5, -0.5), Vec3::new(x, -0.5, 0.5), Vec3::new(x, 1.0, 0.0)]);
    [i, i + 1, i + 2]
}

/// A corridor of eight triangles T0..T7 in the planes x = 0, 2, ..., 14, one behind the other for
/// a ray along x.
fn corridor() -> Mesh {
    let mut p = Vec::new();
    let tris = (0..8).map(|k| tri_facing_x(&mut p, 2.0 * k as f32)).collect();
    Mesh::from_triangles("corridor", p, tris)
}

/// Rays through the corridor: along +x from x = -5 and along -x from x = 19, at (y, z) = (0, 0),
/// which is inside every triangle; along +x at (y, z) = (0.9, 0.4), inside every box but beside
/// every triangle (at y = 0.9 a triangle spans z ±0.033); straight down (-z) at x = 7, between the
/// halves T0..T3 (x 0..6) and T4..T7 (x 8..14). Entries along +x from -5: T_k at 5 + 2k.
fn corridor_rays() -> [Ray; 4] {
    [
        Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X),
        Ray::new(Vec3::new(19.0, 0.0, 0.0), -Vec3::X),
        Ray::new(Vec3::new(-5.0, 0.9, 0.4), Vec3::X),
        Ray::new(Vec3::new(7.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0)),
    ]
}

/// One triangle per leaf, by midpoint and by equal-count splits (evenly spaced centroids: the
/// median is the midpoint). Binary: root over x 0..14 splits at 7 into A = T0..T3 (x 0..6) and
/// B = T4..T7 (x 8..14); A at 3 into AA = {T0, T1}, AB = {T2, T3}; B at 11 into BA = {T4, T5},
/// BB = {T6, T7}; each of those into its two leaves. 15 nodes, 8 leaves, all at depth 3.
/// Wide: the root takes A and B, opens B (equal areas; the later wins the tie) into BA and BB,
/// then A (area 33 against 13) into AA and AB: slots AA, BA, BB, AB, wide nodes 1 to 4, each with
/// its two leaves. 5 wide nodes.
#[test]
fn the_corridor_of_one_triangle_leaves_counts_exactly() {
    let mesh = corridor();
    for strategy in [SplitStrategy::Midpoint, SplitStrategy::EqualCount] {
        let (binary, wide) = both_layouts(&mesh, BuildParams { strategy, ..params() });
        assert_eq!(binary.nodes.len(), 15, "{strategy:?}");
        assert_eq!(binary_leaves(&binary), (0..8).map(|k| (3, vec![k])).collect::<Vec<_>>(), "{strategy:?}");
        assert!(binary.nodes.iter().filter(|n| !n.is_leaf()).all(|n| n.axis == 0), "{strategy:?}: all splits on x");
        use Slot::{Leaf as L, Node as N};
        let expected = vec![
            vec![N(1), N(2), N(3), N(4)],
            vec![L(vec![0]), L(vec![1])],
            vec![L(vec![4]), L(vec![5])],
            vec![L(vec![6]), L(vec![7])],
            vec![L(vec![2]), L(vec![3])],
        ];
        assert_eq!(wide_slots(&wide), expected, "{strategy:?}");

        let [forward, backward, beside, between] = corridor_rays();
        for order in ORDERS {
            for test in TESTS {
                let opts = TraceOptions { order, test };
                // Along +x, every box ahead: both orders take the left (smaller x, entered first)
                // child. Binary: root box (1); root visited, A (entry 5) and B (13) tested (+2),
                // B pushed; A visited, AA (5) and AB (9) tested (+2), AB pushed; AA visited, T0
                // (5) and T1 (7) tested (+2), T1 pushed; T0 visited, a leaf, 1 triangle: hit at 5.
                // T1, AB and B are popped beyond the hit and skipped. 4 nodes, 7 box tests, 1
                // leaf, 1 triangle; any hit stops at the same place.
                let c = counts(4, 7, 1, 1);
                assert_eq!(run(&binary, &forward, opts), (Some(0), c, true, c), "{strategy:?} {opts:?}");
                // Wide: root box (1); root visited, its four children tested (+4), all hit:
                // pushed, sorted, AA (5) taken; AA visited, T0 (5) and T1 (7) tested (+2), T1
                // pushed; T0 reached, 1 triangle, hit at 5; T1, AB, BA, BB skipped. 2 nodes, 7
                // box tests, 1 leaf, 1 triangle.
                let c = counts(2, 7, 1, 1);
                assert_eq!(run(&wide, &forward, opts), (Some(0), c, true, c), "{strategy:?} {opts:?}");

                // Along -x, the mirror image: the right child is both nearer and, by the
                // direction's negative x, the split-axis rule's pick. B, BB, T7 (hit at 5).
                let c = counts(4, 7, 1, 1);
                assert_eq!(run(&binary, &backward, opts), (Some(7), c, true, c), "{strategy:?} {opts:?}");
                let c = counts(2, 7, 1, 1);
                assert_eq!(run(&wide, &backward, opts), (Some(7), c, true, c), "{strategy:?} {opts:?}");

                // Beside every triangle, through every box: no hit prunes anything, every node
                // is visited. Binary: 15 nodes (7 interior, 8 leaves), box tests 1 + 2 × 7 = 15,
                // 8 leaves, 8 triangles.
                let c = counts(15, 15, 8, 8);
                assert_eq!(run(&binary, &beside, opts), (None, c, false, c), "{strategy:?} {opts:?}");
                // Wide: 5 nodes, box tests 1 + 4 (root) + 4 × 2 = 13, the same 8 leaves and 8
                // triangles.
                let c = counts(5, 13, 8, 8);
                assert_eq!(run(&wide, &beside, opts), (None, c, false, c), "{strategy:?} {opts:?}");

                // Down between the halves: inside the root's box (x 0..14), outside A's and B's.
                // Binary: root box, root visited, A and B missed: 1 node, 3 box tests. Wide: root
                // box, root visited, AA, BA, BB, AB all missed: 1 node, 5 box tests, more than the
                // binary walk's 3, where the ray beside the triangles made fewer (13 < 15).
                let c = counts(1, 3, 0, 0);
                assert_eq!(run(&binary, &between, opts), (None, c, false, c), "{strategy:?} {opts:?}");
                let c = counts(1, 5, 0, 0);
                assert_eq!(run(&wide, &between, opts), (None, c, false, c), "{strategy:?} {opts:?}");
            }
        }
    }
}

/// Two triangles per leaf (midpoint): root splits at 7 into A = T0..T3 and B = T4..T7, A at 3
/// into leaves {T0, T1} and {T3, T2}, B at 11 into {T4, T5} and {T6, T7}. 7 nodes, depth 2. (The
/// builder's in-place partition is not stable: it leaves T3 before T2, and, after two partitions,
/// T6 before T7.) Wide: one node whose four slots are those leaves (AA, BA, BB, AB, as above).
#[test]
fn the_corridor_of_two_triangle_leaves_counts_exactly() {
    let mesh = corridor();
    let (binary, wide) = both_layouts(&mesh, BuildParams { max_leaf_size: 2, ..params() });
    assert_eq!(binary.nodes.len(), 7);
    let leaves: Vec<(u32, Vec<u32>)> = vec![(2, vec![0, 1]), (2, vec![3, 2]), (2, vec![4, 5]), (2, vec![6, 7])];
    assert_eq!(binary_leaves(&binary), leaves);
    use Slot::Leaf as L;
    assert_eq!(wide_slots(&wide), vec![vec![L(vec![0, 1]), L(vec![4, 5]), L(vec![6, 7]), L(vec![3, 2])]]);

    let [forward, backward, beside, between] = corridor_rays();
    for order in ORDERS {
        for test in TESTS {
            let opts = TraceOptions { order, test };
            // Along +x. Binary: root box (1); root visited, A and B tested (+2), B pushed; A
            // visited, {T0, T1} (entry 5) and {T2, T3} (9) tested (+2); the leaf {T0, T1} visited:
            // T0 hit at 5, then T1 tested too (at 7, beyond the hit) for the closest hit: 3 nodes,
            // 5 box tests, 1 leaf, 2 triangles. Any hit stops after T0: 1 triangle.
            assert_eq!(run(&binary, &forward, opts), (Some(0), counts(3, 5, 1, 2), true, counts(3, 5, 1, 1)));
            // Wide: root box (1), the node visited, four leaves tested (+4), all hit, the nearest
            // {T0, T1} taken: 1 node, 5 box tests, 1 leaf, 2 triangles (any hit: 1).
            assert_eq!(run(&wide, &forward, opts), (Some(0), counts(1, 5, 1, 2), true, counts(1, 5, 1, 1)));

            // Along -x: the leaf {T6, T7} is reached first, and in leaf order T6 (at 7) comes
            // before T7 (at 5): the closest hit tests both and keeps T7; any hit stops at T6,
            // the farther one, after 1 test.
            assert_eq!(run(&binary, &backward, opts), (Some(7), counts(3, 5, 1, 2), true, counts(3, 5, 1, 1)));
            assert_eq!(run(&wide, &backward, opts), (Some(7), counts(1, 5, 1, 2), true, counts(1, 5, 1, 1)));

            // Beside every triangle: binary 7 nodes (3 interior, 4 leaves), 1 + 2 × 3 = 7 box
            // tests, 4 leaves, 8 triangles; wide 1 node, 1 + 4 = 5 box tests, 4 leaves, 8
            // triangles.
            assert_eq!(run(&binary, &beside, opts), (None, counts(7, 7, 4, 8), false, counts(7, 7, 4, 8)));
            assert_eq!(run(&wide, &beside, opts), (None, counts(1, 5, 4, 8), false, counts(1, 5, 4, 8)));

            // Between the halves: binary root and its two children's boxes (1 node, 3 tests);
            // wide root and its four leaves' boxes (1 node, 5 tests).
            assert_eq!(run(&binary, &between, opts), (None, counts(1, 3, 0, 0), false, counts(1, 3, 0, 0)));
            assert_eq!(run(&wide, &between, opts), (None, counts(1, 5, 0, 0), false, counts(1, 5, 0, 0)));
        }
    }
}

/// The overlapping pair again (TL wide and deep, TR small and near the top), split on x, and the
/// same pair with x and y swapped, split on y: a ray at (0.7, -0.4) in the split plane's
/// coordinates passes through both triangles (TR at y = -0.4 spans x 0.53..1.47, TL spans
/// -2.87..0.87). From above (z = 5, down) it hits TR at t = 5 and TL at 6.5; from below (z = -5,
/// up) TL at 3.5 and TR at 5. The direction's component on the split axis is +0 or -0: the
/// split-axis rule then takes the left child (TL) or the right one (TR) first, whatever the
/// distances say; its component on the other axis of x and y has the opposite sign, so a rule
/// reading the wrong axis would pick the other child.
#[test]
fn the_far_child_first_finds_a_hit_that_does_not_end_the_closest_hit() {
    for split_axis in [0u8, 1] {
        let mut mesh = overlapping();
        let swap = |v: Vec3| if split_axis == 1 { Vec3::new(v.y, v.x, v.z) } else { v };
        mesh.positions = mesh.positions.iter().map(|&p| swap(p)).collect();
        let (binary, wide) = both_layouts(&mesh, params());
        assert_eq!(binary.nodes.len(), 3);
        assert_eq!(binary.nodes[0].axis, split_axis);
        assert_eq!(binary_leaves(&binary), vec![(1, vec![0]), (1, vec![1])], "left TL, right TR");
        use Slot::Leaf as L;
        assert_eq!(wide_slots(&wide), vec![vec![L(vec![0]), L(vec![1])]]);

        // (origin z, direction z, sign of zero on the split axis: true = -0, right child first)
        for (z, dz, neg) in [(5.0, -1.0, false), (5.0, -1.0, true), (-5.0, 1.0, false), (-5.0, 1.0, true)] {
            let (on, off) = if neg { (-0.0, 0.0) } else { (0.0, -0.0) };
            let dir = swap(Vec3::new(on, off, dz));
            assert_eq!(dir[split_axis as usize].is_sign_negative(), neg);
            let r = Ray::new(swap(Vec3::new(0.7, -0.4, z)), dir);
            // Which triangle is nearer, and whether the split-axis rule takes the other first.
            let (near, far_first) = if z > 0.0 { (1, !neg) } else { (0, neg) };
            let what = format!("split on {split_axis}, from z = {z}, -0: {neg}");
            for test in TESTS {
                // Entry distance: root box (1); root visited, both boxes tested (+2) and hit;
                // the near child visited (a leaf, 1 triangle, hit); the far one, entered beyond
                // that hit, popped and skipped. 2 nodes, 3 box tests, 1 leaf, 1 triangle, and
                // any hit does the same.
                let c = counts(2, 3, 1, 1);
                let opts = TraceOptions { order: TraversalOrder::EntryDistance, test };
                assert_eq!(run(&binary, &r, opts), (Some(near), c, true, c), "{what} {opts:?}");
                // Split-axis sign. When it picks the near child, as above. When it picks the far
                // one: the far leaf visited, its triangle hit (the farther hit); the near child,
                // popped, is entered before that hit, so it is visited too and its triangle
                // gives the closest hit: 3 nodes, 3 box tests, 2 leaves, 2 triangles. Any hit
                // stops at the far triangle's hit: 2 nodes, 3 box tests, 1 leaf, 1 triangle.
                let opts = TraceOptions { order: TraversalOrder::SplitAxisSign, test };
                let closest = if far_first { counts(3, 3, 2, 2) } else { c };
                assert_eq!(run(&binary, &r, opts), (Some(near), closest, true, c), "{what} {opts:?}");
                // Wide, either order: the nearer of the two leaves first (entry 5 against 6.5, or
                // 3.5 against 5), the other skipped: root box (1), the node (1, +2), 1 leaf.
                for order in ORDERS {
                    let opts = TraceOptions { order, test };
                    let c = counts(1, 3, 1, 1);
                    assert_eq!(run(&wide, &r, opts), (Some(near), c, true, c), "{what} {opts:?}");
                }
            }
        }
    }
}

/// An empty mesh: each layout tests the (empty) root box once and does nothing else.
#[test]
fn an_empty_mesh_costs_one_box_test() {
    let mesh = Mesh::from_triangles("empty", Vec::new(), Vec::new());
    let (binary, wide) = both_layouts(&mesh, params());
    let r = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
    for order in ORDERS {
        let opts = TraceOptions { order, test: TriangleTest::Watertight };
        let c = counts(0, 1, 0, 0);
        assert_eq!(run(&binary, &r, opts), (None, c, false, c));
        assert_eq!(run(&wide, &r, opts), (None, c, false, c));
    }
}

/// The documented relation (`bvh::wide`) on the hand-built trees, exactly, for each ray that hits
/// nothing: the same leaves and triangle tests in both layouts, wide node visits no more than
/// binary interior visits, and binary box tests = 1 + 2 × interior visits once the root is
/// entered. The numbers themselves are checked above; this checks they relate as documented.
#[test]
fn the_hand_built_trees_relate_as_documented() {
    let meshes = [row(), corridor(), overlapping()];
    let rays = [
        corridor_rays()[2],
        corridor_rays()[3],
        Ray::new(Vec3::new(3.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0)),
        Ray::new(Vec3::new(2.45, 0.9, 5.0), Vec3::new(0.0, 0.0, -1.0)),
        Ray::new(Vec3::new(0.75, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0)),
        Ray::new(Vec3::new(-1.0, 0.9, 5.0), Vec3::new(0.0, 0.0, -1.0)),
        Ray::new(Vec3::new(30.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0)),
    ];
    let mut checked = 0;
    for mesh in &meshes {
        let linear = LinearScan::new(mesh);
        for max_leaf_size in [1, 2] {
            let (binary, wide) = both_layouts(mesh, BuildParams { max_leaf_size, ..params() });
            for r in &rays {
                if linear.any_hit(r, TraceOptions::default(), &mut bvhscope_core::bvh::NoStats) {
                    continue;
                }
                for order in ORDERS {
                    let opts = TraceOptions { order, test: TriangleTest::Watertight };
                    let (_, cb, _, ab) = run(&binary, r, opts);
                    let (_, cw, _, aw) = run(&wide, r, opts);
                    assert_eq!((cb, cw), (ab, aw), "no hit: any hit does the closest hit's work");
                    assert_eq!((cb.leaves_visited, cb.triangle_tests), (cw.leaves_visited, cw.triangle_tests));
                    let interior = cb.nodes_visited - cb.leaves_visited;
                    assert!(cw.nodes_visited <= interior, "{r:?}: {cw:?} against {cb:?}");
                    if cb.nodes_visited > 0 {
                        assert_eq!(cb.box_tests, 1 + 2 * interior);
                    }
                    checked += 1;
                }
            }
        }
    }
    assert!(checked >= 30, "{checked} cases");
}
