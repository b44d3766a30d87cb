//! One ray's trace (`bvh::trace`) against the traversal that renders: for every strategy and layout,
//! both orders, on rays over the shared meshes (and a generated one), the trace's totals are the
//! counting sink's counts exactly, its last closest hit is `closest_hit`'s, and every child the walk
//! goes to first is the one the order rule in use picks. Two levels too.

mod common;
#[path = "../core/tests/common/scratch.rs"]
mod scratch;

use bvhscope::bvh::{
    trace_ray, Accelerator, AnyBvh, BuildParams, Layout, NodeId, RayCounters, SceneBuild, StepKind, Strategy,
    TraceLevel, TraceOptions, TraceStep, TraversalOrder,
};
use bvhscope::geometry::{Ray, TriangleTest};
use bvhscope::mesh::{generate, Mesh};
use bvhscope::random::Rng;
use glam::Vec3;

/// Rays from around the mesh towards points of its box (many hit, many pass by), and rays from
/// points on its triangles (starting on the surface), from a fixed seed.
fn rays(mesh: &Mesh, n: usize) -> Vec<Ray> {
    let b = mesh.bounds();
    let (c, r) = (b.center(), b.extent().length());
    let mut rng = Rng::new(0x2545_f491);
    let centred = |rng: &mut Rng| Vec3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5);
    (0..n)
        .map(|i| {
            let dir = centred(&mut rng).normalize_or(Vec3::Y);
            if i % 4 == 3 {
                let [a, p, q] = mesh.triangle(rng.below(mesh.triangle_count() as u64) as u32);
                Ray::new((a + p + q) / 3.0, dir)
            } else {
                let from = c + dir * r;
                let to = c + centred(&mut rng) * b.extent();
                Ray::new(from, to - from)
            }
        })
        .collect()
}

fn counts_of(c: RayCounters) -> (u32, u32, u32, u32, u32) {
    (c.nodes_visited, c.box_tests, c.leaves_visited, c.triangle_tests, c.instances_entered)
}

/// Check that each time the walk had two or more hit children, it went first to the one the
/// rule picks: the nearest entry (entry-distance order, the wide layout, the top level), or in
/// the binary layout under the handout's rule the side the ray's sign on the split axis picks
/// (`axis_of` gives a binary node's split axis).
fn check_order(steps: &[TraceStep], ray: &Ray, order: TraversalOrder, axis_of: Option<&dyn Fn(u32) -> usize>) {
    let mut i = 0;
    while i < steps.len() {
        let StepKind::Enter { node: parent, .. } = steps[i].kind else {
            i += 1;
            continue;
        };
        let level = steps[i].level;
        let mut hits: Vec<(NodeId, f32)> = Vec::new();
        let mut j = i + 1;
        while let Some(StepKind::BoxTest { node, hit, t_entry, .. }) = steps.get(j).map(|s| &s.kind) {
            if *hit {
                hits.push((*node, t_entry.unwrap()));
            }
            j += 1;
        }
        if hits.len() >= 2 {
            let next = steps[j..].iter().find_map(|s| match s.kind {
                StepKind::Enter { node, .. } | StepKind::Leaf { node, .. } if s.level == level => Some(node),
                _ => None,
            });
            let next = next.expect("a node with hit children goes on to one of them");
            let (_, t_next) = *hits.iter().find(|h| h.0 == next).expect("it goes to a hit child");
            let by_axis = order == TraversalOrder::SplitAxisSign && level != TraceLevel::Top;
            match (by_axis, axis_of) {
                (true, Some(axis_of)) => {
                    // Binary layout: children are adjacent, left first.
                    let NodeId::Node(p) = parent else { panic!("binary nodes are Node") };
                    let left = hits.iter().map(|h| h.0).min_by_key(|n| match n {
                        NodeId::Node(k) => *k,
                        _ => u32::MAX,
                    });
                    let neg = ray.dir()[axis_of(p)].is_sign_negative();
                    let expected = if neg {
                        hits.iter().map(|h| h.0).max_by_key(|n| match n {
                            NodeId::Node(k) => *k,
                            _ => 0,
                        })
                    } else {
                        left
                    };
                    assert_eq!(Some(next), expected, "split-axis rule at {parent}: {hits:?}");
                }
                _ => {
                    let nearest = hits.iter().map(|h| h.1).fold(f32::INFINITY, f32::min);
                    assert_eq!(t_next, nearest, "nearest first at {parent}: went to {next}, hits {hits:?}");
                }
            }
        }
        i = j;
    }
}

fn check_mesh(name: &str, mesh: &Mesh, n: usize) {
    let rays = rays(mesh, n);
    for strategy in Strategy::ALL {
        for layout in Layout::ALL {
            let bvh = AnyBvh::build(mesh, &BuildParams { strategy, layout, ..BuildParams::default() });
            for order in [TraversalOrder::SplitAxisSign, TraversalOrder::EntryDistance] {
                for test in TriangleTest::ALL {
                    let opts = TraceOptions { order, test };
                    for ray in &rays {
                        let what = format!("{name} {strategy:?} {layout:?} {opts:?} {ray:?}");
                        let mut counted = RayCounters::ZERO;
                        let hit = bvh.closest_hit(&mut ray.clone(), opts, &mut counted);
                        let (traced, trace) = trace_ray(&bvh, ray, opts);
                        assert_eq!(traced, hit, "{what}");
                        assert_eq!(counts_of(trace.counts()), counts_of(counted), "{what}");
                        assert_eq!(trace.last_hit(), hit.map(|h| (h.prim, h.t)), "{what}");
                        let axis = |k: u32| match &bvh {
                            AnyBvh::Binary(b) => b.nodes[k as usize].axis as usize,
                            AnyBvh::Wide(_) | AnyBvh::Wide8(_) => unreachable!(),
                        };
                        let axis_of: Option<&dyn Fn(u32) -> usize> =
                            matches!(bvh, AnyBvh::Binary(_)).then_some(&axis as &dyn Fn(u32) -> usize);
                        check_order(&trace.steps, ray, order, axis_of);
                    }
                }
            }
        }
    }
}

#[test]
fn the_trace_is_the_counted_traversal_on_a_generated_mesh() {
    check_mesh("knot", &generate::torus_knot(2, 3, 0.3, 128, 12), 600);
}

#[test]
fn the_trace_is_the_counted_traversal_on_the_shared_meshes() {
    for name in ["suzanne.obj", "moer-lite-lab1-bvh/models/Monkey.obj", "stanford-bunny.obj"] {
        let Some(mesh) = common::shared_mesh(name) else { return };
        check_mesh(name, &mesh, 400);
    }
}

#[test]
fn two_levels_are_traced_level_by_level() {
    let dir = scratch::shared("trace");
    let scene = bvhscope::scene::load_any(common::many_placements(&dir, 9)).unwrap();
    let p = BuildParams::default();
    let bvh = scene.build(&SceneBuild { bvh: p, top: Some(p) }, &Default::default()).unwrap();
    let flat = scene.flat_mesh().unwrap();
    let mut rays = rays(&flat, 300);
    // Straight down onto the first torus's ring: enters a placement and hits.
    rays.push(Ray::new(Vec3::new(1.0, 5.0, 0.0), -Vec3::Y));
    let mut entered = 0;
    for ray in &rays {
        let opts = TraceOptions::default();
        let mut counted = RayCounters::ZERO;
        let hit = bvh.closest_hit(&mut ray.clone(), opts, &mut counted);
        let (traced, trace) = trace_ray(&bvh, ray, opts);
        assert_eq!(traced, hit);
        assert_eq!(trace.counts(), counted, "{ray:?}");
        assert_eq!(trace.last_hit(), hit.map(|h| (h.prim, h.t)));
        check_order(&trace.steps, ray, opts.order, None);
        // Every bottom-level step sits between its placement's Instance and InstanceDone.
        let mut inside = None;
        for s in &trace.steps {
            match (&s.kind, s.level) {
                (StepKind::Instance { instance, .. }, TraceLevel::Top) => inside = Some(*instance),
                (StepKind::InstanceDone { instance }, TraceLevel::Bottom { instance: i }) => {
                    assert_eq!((Some(*instance), inside), (Some(i), Some(i)));
                    inside = None;
                }
                (_, TraceLevel::Bottom { instance }) => assert_eq!(inside, Some(instance), "{s:?}"),
                (_, TraceLevel::Top) => assert_eq!(inside, None, "{s:?}"),
                (_, TraceLevel::Mesh) => panic!("a two-level trace has no single-BVH steps"),
            }
        }
        entered += counted.instances_entered;
    }
    assert!(entered > 50, "the rays enter placements: {entered}");
}
