//! What the tree reports about itself does not depend on what was walked.

use super::*;
use crate::bvh::accel::{Accelerator, TraceOptions};
use crate::bvh::counters::NoStats;
use crate::bvh::params::{BuildParams, Layout};
use crate::geometry::{Ray, TriangleTest};
use glam::Vec3;

/// The 8-wide tree's memory is the same before and after a walk with the stored-edges test (which
/// makes its stored leaves); `bytes_for` that test counts them, twelve floats a triangle, and
/// for the other tests is the memory; `walk_bytes`, told before the walk, is what they took.
#[test]
fn memory_does_not_depend_on_the_walks() {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..40u32 {
        let x = i as f32;
        positions.extend([Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 0.0, 0.0), Vec3::new(x, 1.0, 0.0)]);
        triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let mesh = Mesh::from_triangles("strip", positions, triangles);
    let bvh = AnyBvh::build(&mesh, &BuildParams { layout: Layout::Wide8, ..BuildParams::default() });
    let before = bvh.tree().memory_bytes();
    let stored = TraceOptions { test: TriangleTest::MollerTrumboreStored, ..TraceOptions::default() };
    let promised = bvh.walk_bytes(stored);
    let mut ray = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
    assert!(bvh.closest_hit(&mut ray, stored, &mut NoStats).is_some(), "the walk with the stored test hits");
    assert_eq!(bvh.tree().memory_bytes(), before, "a walk does not change the tree's memory");
    assert_eq!(bvh.bytes_for(stored), before + 48 * mesh.triangle_count());
    assert_eq!(bvh.bytes_for(TraceOptions::default()), before);
    // Told before the leaves were made, as the app tells it: what they took once made.
    let AnyBvh::Wide8(w) = &bvh else { panic!("an 8-wide tree") };
    assert_eq!(promised, std::mem::size_of_val(w.stored_leaves()));
    assert_eq!(bvh.walk_bytes(TraceOptions::default()), 0);
}
