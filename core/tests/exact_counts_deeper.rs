//! The traversal counters to the exact count on deeper hand-built trees: several wide nodes,
//! leaves of one and of two triangles, the far child holding a hit, the split-axis rule reading
//! the node's own axis; the binary and wide layouts of each against each other.

mod counting;

use bvhscope_core::bvh::{
    Accelerator, AnyBvh, BuildParams, Bvh, Layout, LinearScan, Strategy, TraceOptions, TraversalOrder, WideBvh,
};
use bvhscope_core::geometry::{Ray, TriangleTest};
use bvhscope_core::mesh::Mesh;
use counting::*;
use glam::Vec3;

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
/// Wide (the grouping of least summed wide-node area, `CollapsePlan`; box areas: root 73, A and B
/// 33 each, AA, AB, BA, BB 13 each): the root's four slots shared one to A, three to B (46; two
/// and two cost 26 + 26, three and one 13 + 33, a tie the left's smaller share wins). A is a wide
/// node of its four leaves (33); B's three slots: BA a wide node of its two leaves (13), BB's two
/// leaves in the root. Slots: root A, BA, T6, T7; node 1 T0..T3; node 2 T4, T5. 3 wide nodes,
/// 73 + 33 + 13 = 119 of area, against 73 + 4 × 13 = 125 for four nodes of two leaves.
#[test]
fn the_corridor_of_one_triangle_leaves_counts_exactly() {
    let mesh = corridor();
    for strategy in [Strategy::Midpoint, Strategy::EqualCount] {
        let (binary, wide) = both_layouts(&mesh, BuildParams { strategy, ..params() });
        assert_eq!(binary.nodes.len(), 15, "{strategy:?}");
        assert_eq!(binary_leaves(&binary), (0..8).map(|k| (3, vec![k])).collect::<Vec<_>>(), "{strategy:?}");
        assert!(binary.nodes.iter().filter(|n| !n.is_leaf()).all(|n| n.axis == 0), "{strategy:?}: all splits on x");
        use Slot::{Leaf as L, Node as N};
        let expected = vec![
            vec![N(1), N(2), L(vec![6]), L(vec![7])],
            vec![L(vec![0]), L(vec![1]), L(vec![2]), L(vec![3])],
            vec![L(vec![4]), L(vec![5])],
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
                // pushed, sorted, A (5) taken; A visited, T0..T3 (5, 7, 9, 11) tested (+4), all
                // hit, T0 taken; T0 reached, 1 triangle, hit at 5; the rest skipped. 2 nodes, 9
                // box tests, 1 leaf, 1 triangle.
                let c = counts(2, 9, 1, 1);
                assert_eq!(run(&wide, &forward, opts), (Some(0), c, true, c), "{strategy:?} {opts:?}");

                // Along -x, the mirror image: the right child is both nearer and, by the
                // direction's negative x, the split-axis rule's pick. B, BB, T7 (hit at 5).
                let c = counts(4, 7, 1, 1);
                assert_eq!(run(&binary, &backward, opts), (Some(7), c, true, c), "{strategy:?} {opts:?}");
                // Wide: T7 is a slot of the root and the nearest of its four (entries 5, 7, 9,
                // 13): root box, root visited, four tests, T7 reached and hit. 1 node, 5 box tests.
                let c = counts(1, 5, 1, 1);
                assert_eq!(run(&wide, &backward, opts), (Some(7), c, true, c), "{strategy:?} {opts:?}");

                // Beside every triangle, through every box: no hit prunes anything, every node
                // is visited. Binary: 15 nodes (7 interior, 8 leaves), box tests 1 + 2 × 7 = 15,
                // 8 leaves, 8 triangles.
                let c = counts(15, 15, 8, 8);
                assert_eq!(run(&binary, &beside, opts), (None, c, false, c), "{strategy:?} {opts:?}");
                // Wide: 3 nodes, box tests 1 + 4 (root) + 4 (node 1) + 2 (node 2) = 11, the same 8
                // leaves and 8 triangles.
                let c = counts(3, 11, 8, 8);
                assert_eq!(run(&wide, &beside, opts), (None, c, false, c), "{strategy:?} {opts:?}");

                // Down between the halves: inside the root's box (x 0..14), outside A's and B's.
                // Binary: root box, root visited, A and B missed: 1 node, 3 box tests. Wide: root
                // box, root visited, A, BA, T6, T7 all missed: 1 node, 5 box tests, more than the
                // binary walk's 3, where the ray beside the triangles made fewer (11 < 15).
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
/// T6 before T7.) Wide: one node whose four slots are those leaves, left to right (no wide node
/// below the root: zero area beyond the root's).
#[test]
fn the_corridor_of_two_triangle_leaves_counts_exactly() {
    let mesh = corridor();
    let (binary, wide) = both_layouts(&mesh, BuildParams { max_leaf_size: 2, ..params() });
    assert_eq!(binary.nodes.len(), 7);
    let leaves: Vec<(u32, Vec<u32>)> = vec![(2, vec![0, 1]), (2, vec![3, 2]), (2, vec![4, 5]), (2, vec![6, 7])];
    assert_eq!(binary_leaves(&binary), leaves);
    use Slot::Leaf as L;
    assert_eq!(wide_slots(&wide), vec![vec![L(vec![0, 1]), L(vec![3, 2]), L(vec![4, 5]), L(vec![6, 7])]]);

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
