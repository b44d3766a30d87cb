//! Which ray–triangle test a walk runs: the run-time choice (`TriangleTest`, declared once in
//! `options.rs` for the CLI, the app and scene files) and, for callers outside the hot loop, the
//! test it names. The walks themselves take the test as a type parameter (`bvh::accel::dispatch`).

use super::ray::Ray;
use super::stored_triangle::MollerTrumboreStored;
use super::triangle::{MollerTrumbore, TriangleHit, TriangleIntersector, Watertight};
use glam::Vec3;

/// Which triangle test the traversal uses; chosen at run time, compiled as a type parameter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum TriangleTest {
    /// Woop, Benthin & Wald 2013: no gaps along shared edges, no double hits at vertices.
    #[default]
    Watertight,
    /// Möller & Trumbore 1997: the test students usually write first; can miss rays through edges.
    MollerTrumbore,
    /// Möller–Trumbore on stored edges and normal, Embree's form (`stored_triangle`): less work a
    /// triangle, 48 more bytes of it; can miss rays through edges.
    MollerTrumboreStored,
}

/// Intersect with a run-time choice of test (for callers outside the hot loop).
pub fn intersect_triangle(test: TriangleTest, ray: &Ray, tri: &[Vec3; 3]) -> Option<TriangleHit> {
    match test {
        TriangleTest::Watertight => Watertight::intersect(&Watertight::prepare(ray), ray, tri),
        TriangleTest::MollerTrumbore => MollerTrumbore::intersect(&(), ray, tri),
        TriangleTest::MollerTrumboreStored => MollerTrumboreStored::intersect(&(), ray, tri),
    }
}
