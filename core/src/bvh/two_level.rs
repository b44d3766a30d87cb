//! The two-level BVH: a top-level BVH over instances, each instance a mesh's own BVH placed in the
//! world by a transform. A mesh used by many instances has one BVH, built once. The ray is moved
//! into an instance's object space (not the mesh into the world), and because the direction is
//! transformed without normalising, a hit's `t` means the same point in both spaces, so the closest
//! hit so far keeps pruning across instances. pbrt-v4 §7.1.4 ("Object Instancing"); the Moer-lite
//! renderer's design (a scene-level structure over shapes that each own a BVH).
//!
//! Hits carry global triangle ids: instance k's triangles are numbered after those of instances
//! 0..k, the order `scene::flatten` lays them out in, so a two-level hit names the same triangle
//! as the flattened single-level BVH's hit (and the flattened mesh can shade it).
//!
//! The top level is always a binary tree (a scene has few instances next to its triangles); its
//! strategy and leaf size are chosen separately from the bottom level's, which may be wide.

use super::builders::build_over_boxes;
use super::node::{walk_nodes, BvhNode};
use super::traverse::{walk, TopLevelWalk};
use super::tree::{NodeKind, TreeNode, TreeView};
use crate::bvh::accel::{Accelerator, Hit};
use crate::bvh::any::AnyBvh;
use crate::bvh::builders::common::build_work;
use crate::bvh::counters::TraversalStats;
use crate::bvh::params::{BuildParams, BuildReport};
use crate::geometry::{Aabb, Ray, TriangleIntersector};
use crate::mesh::Mesh;
use crate::work::{Cancelled, WorkControl};
use glam::{Affine3A, Vec3};
use std::time::{Duration, Instant};

/// One placement of a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// Which mesh (and bottom-level BVH).
    pub mesh: u32,
    pub to_world: Affine3A,
    pub to_object: Affine3A,
    /// World-space bounds of the placed mesh (of its transformed vertices).
    pub bounds: Aabb,
    /// Global id of the instance's first triangle.
    pub first_prim: u32,
}

/// The top level: a binary BVH whose leaves hold instances.
#[derive(Clone, Debug)]
pub struct TopLevel {
    pub nodes: Vec<BvhNode>,
    /// Leaf order → instance index (a leaf's `index..index + count` is a range of this).
    pub order: Vec<u32>,
    pub params: BuildParams,
    pub report: BuildReport,
}

impl TreeView for TopLevel {
    fn visit_nodes(&self, f: &mut dyn FnMut(&TreeNode) -> bool) {
        walk_nodes(&self.nodes, self.order.is_empty(), f)
    }
    /// The top level's primitives are instances.
    fn triangle_count(&self) -> usize {
        self.order.len()
    }
    fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<BvhNode>() + self.order.len() * 4
    }
    fn params(&self) -> &BuildParams {
        &self.params
    }
    fn report(&self) -> &BuildReport {
        &self.report
    }
}

/// A box of the bottom-level overlay: a node's box in its mesh's object space and the transform
/// that places it (so it is drawn as the parallelepiped the ray actually meets).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedBox {
    /// Unique over all instances' nodes (for colours).
    pub id: usize,
    pub bounds: Aabb,
    pub to_world: Affine3A,
}

#[derive(Clone, Debug)]
pub struct TwoLevelBvh {
    /// One BVH per mesh, shared by every instance of it.
    pub bottom: Vec<AnyBvh>,
    pub instances: Vec<Instance>,
    pub top: TopLevel,
    /// The parameters every mesh BVH was built with.
    pub bottom_params: BuildParams,
    /// Building the mesh BVHs (all of them) and the top level.
    pub bottom_time: Duration,
    pub top_time: Duration,
}

impl TwoLevelBvh {
    /// Build a BVH per mesh with `bottom`, then the top level over the placements with `top`.
    /// `placements` are (mesh index, object-to-world transform); a singular transform is the
    /// caller's error (scene files reject them).
    pub fn build(
        meshes: &[&Mesh],
        placements: &[(u32, Affine3A)],
        top: &BuildParams,
        bottom: &BuildParams,
        control: &WorkControl,
    ) -> Result<TwoLevelBvh, Cancelled> {
        let t0 = Instant::now();
        // One progress over all of it: every mesh's build, then the top level's.
        let work = meshes.iter().map(|m| build_work(m.triangle_count(), bottom)).sum::<u64>()
            + build_work(placements.len(), top);
        control.set_total(work);
        let bottom_bvhs =
            meshes.iter().map(|m| AnyBvh::build_counted(m, bottom, control)).collect::<Result<Vec<_>, _>>()?;
        let bottom_time = t0.elapsed();
        let t1 = Instant::now();
        let mut first_prim = 0u32;
        let instances: Vec<Instance> = placements
            .iter()
            .map(|&(mesh, to_world)| {
                let m = meshes[mesh as usize];
                // The box of the transformed vertices, computed as `flatten` places them: tighter
                // than the transformed root box, and equal to the flattened mesh's box.
                let bounds = m.positions.iter().fold(Aabb::EMPTY, |b, &p| b.grow(to_world.transform_point3(p)));
                let inst = Instance { mesh, to_world, to_object: to_world.inverse(), bounds, first_prim };
                first_prim += m.triangle_count() as u32;
                inst
            })
            .collect();
        let boxes: Vec<Aabb> = instances.iter().map(|i| i.bounds).collect();
        let (nodes, order, report) = build_over_boxes(&boxes, top, control)?;
        let top = TopLevel { nodes, order, params: BuildParams { layout: super::Layout::Binary, ..*top }, report };
        let bottom_params = bottom_bvhs.first().map_or(*bottom, |b| *b.params());
        Ok(TwoLevelBvh { bottom: bottom_bvhs, instances, top, bottom_params, bottom_time, top_time: t1.elapsed() })
    }

    /// Triangles as the rays see them: every instance counts its mesh's triangles.
    pub fn instanced_triangle_count(&self) -> usize {
        self.instances.iter().map(|i| self.bottom[i.mesh as usize].triangle_count()).sum()
    }

    /// Bytes of the top level, the instances and each mesh BVH once.
    pub fn memory_bytes(&self) -> usize {
        self.top.memory_bytes()
            + self.instances.len() * std::mem::size_of::<Instance>()
            + self.bottom.iter().map(|b| b.memory_bytes()).sum::<usize>()
    }

    /// The bottom level's boxes at `depth` (in each mesh's BVH), for every instance. A mesh's boxes
    /// are gathered once and placed by each of its instances.
    pub fn bottom_boxes_at_depth(&self, depth: u32, include_shallower_leaves: bool) -> Vec<PlacedBox> {
        let per_mesh: Vec<Vec<(usize, Aabb)>> =
            self.bottom.iter().map(|b| b.boxes_at_depth(depth, include_shallower_leaves)).collect();
        let n = self.instances.len().max(1);
        let mut out = Vec::new();
        for (k, inst) in self.instances.iter().enumerate() {
            out.extend(per_mesh[inst.mesh as usize].iter().map(|&(id, bounds)| PlacedBox {
                id: id * n + k,
                bounds,
                to_world: inst.to_world,
            }));
        }
        out
    }

    /// Walk the top level nearest box first (`traverse::walk`, entry-distance order: the top level
    /// has no split-axis rule of its own). At each leaf, `enter` is called for its instances with
    /// the world ray (whose `t_max` it may shrink) and returns true to stop the traversal.
    #[inline(always)]
    fn traverse<S: TraversalStats>(
        &self,
        ray: &mut Ray,
        stats: &mut S,
        mut enter: impl FnMut(u32, &Instance, &mut Ray, &mut S) -> bool,
    ) {
        if S::STEPS {
            stats.step_levels();
        }
        if self.instances.is_empty() {
            return;
        }
        walk::<TopLevelWalk, true, S>(&self.top.nodes, ray, stats, |slots, ray, stats| {
            slots.into_iter().any(|slot| {
                let k = self.top.order[slot];
                enter(k, &self.instances[k as usize], ray, stats)
            })
        });
    }

    /// The world ray in an instance's object space, over the same interval.
    #[inline(always)]
    fn object_ray(inst: &Instance, ray: &Ray) -> Ray {
        Ray::segment(
            inst.to_object.transform_point3(ray.origin()),
            inst.to_object.transform_vector3(ray.dir()),
            ray.t_min,
            ray.t_max,
        )
    }
}

impl Accelerator for TwoLevelBvh {
    fn trace<T: TriangleIntersector, const BY_DISTANCE: bool, const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        let mut best = None;
        self.traverse(ray, stats, |k, inst, ray, stats| {
            stats.instance_entered();
            let mut local = Self::object_ray(inst, ray);
            if S::STEPS {
                stats.step_instance(k, inst.first_prim, &local);
            }
            let hit = self.bottom[inst.mesh as usize].trace::<T, BY_DISTANCE, ANY, S>(&mut local, stats);
            if S::STEPS {
                stats.step_instance_done();
            }
            match hit {
                Some(h) => {
                    ray.t_max = h.t;
                    best = Some(Hit { prim: inst.first_prim + h.prim, ..h });
                    ANY
                }
                None => false,
            }
        });
        best
    }
}

/// The world-space corners of a box placed by a transform (corner k: x from bit 0, y from bit 1,
/// z from bit 2), for drawing.
pub fn placed_corners(b: &Aabb, to_world: &Affine3A) -> [Vec3; 8] {
    b.corners().map(|c| to_world.transform_point3(c))
}

/// The top level's leaves, as the statistics see them: how many instances each holds.
pub fn top_leaf_sizes(top: &TopLevel) -> Vec<u32> {
    let mut sizes = Vec::new();
    top.visit_nodes(&mut |n| {
        if let NodeKind::Leaf { count } = n.kind {
            sizes.push(count);
        }
        true
    });
    sizes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::accel::TraceOptions;
    use crate::bvh::counters::{NoStats, RayCounters};
    use crate::bvh::linear::LinearScan;
    use crate::bvh::params::Strategy;
    use crate::mesh::generate::torus;

    /// A torus placed four times (one of them rotated and scaled), and the same scene flattened.
    fn scene() -> (Mesh, Vec<(u32, Affine3A)>, Mesh) {
        let m = torus(1.0, 0.3, 24, 12);
        let placements: Vec<(u32, Affine3A)> = vec![
            (0, Affine3A::IDENTITY),
            (0, Affine3A::from_translation(Vec3::new(3.0, 0.0, 0.0))),
            (0, Affine3A::from_translation(Vec3::new(0.0, 0.0, -3.0))),
            (
                0,
                Affine3A::from_scale_rotation_translation(
                    Vec3::new(0.5, 2.0, 1.0),
                    glam::Quat::from_rotation_x(0.7),
                    Vec3::new(-2.5, 1.0, 0.5),
                ),
            ),
        ];
        let mut flat = Mesh::default();
        for (_, t) in &placements {
            let base = flat.positions.len() as u32;
            flat.positions.extend(m.positions.iter().map(|&p| t.transform_point3(p)));
            flat.triangles.extend(m.triangles.iter().map(|tri| tri.map(|v| v + base)));
        }
        (m, placements, flat)
    }

    #[test]
    fn two_level_hits_agree_with_the_linear_scan_of_the_flattened_scene() {
        let (m, placements, flat) = scene();
        let linear = LinearScan::new(&flat);
        for strategy in Strategy::ALL {
            let p = BuildParams::with_strategy(strategy);
            let two = TwoLevelBvh::build(&[&m], &placements, &p, &p, &WorkControl::new()).unwrap();
            assert_eq!(two.bottom.len(), 1, "one BVH for the one mesh");
            assert_eq!(two.instanced_triangle_count(), flat.triangle_count());
            let (mut hits, mut agree) = (0, 0);
            for i in 0..2000 {
                let a = i as f32 * 0.61;
                let origin = Vec3::new(a.cos() * 9.0, (i % 7) as f32 - 3.0, a.sin() * 9.0);
                let target =
                    Vec3::new((i % 11) as f32 * 0.5 - 2.5, (i % 5) as f32 * 0.4 - 1.0, (i % 13) as f32 * 0.4 - 2.5);
                let (mut r1, mut r2) = (Ray::new(origin, target - origin), Ray::new(origin, target - origin));
                let a = two.closest_hit(&mut r1, TraceOptions::default(), &mut NoStats);
                let b = linear.closest_hit(&mut r2, TraceOptions::default(), &mut NoStats);
                hits += b.is_some() as u32;
                // The object-space test rounds differently from the world-space one, so allow
                // a relative 1e-4 in t and a different triangle only at a shared edge (same t).
                agree += match (a, b) {
                    (Some(a), Some(b)) => ((a.t - b.t).abs() <= 1e-4 * b.t) as u32,
                    (None, None) => 1,
                    _ => 0,
                };
                assert_eq!(
                    two.any_hit(&Ray::new(origin, target - origin), TraceOptions::default(), &mut NoStats),
                    a.is_some()
                );
            }
            assert!(hits > 500, "the rays hit the scene ({hits})");
            assert!(agree >= 1995, "{strategy:?}: {agree} of 2000 rays agree");
        }
    }

    #[test]
    fn counters_tell_the_levels_apart() {
        let (m, placements, _) = scene();
        let p = BuildParams::default();
        let two = TwoLevelBvh::build(&[&m], &placements, &p, &p, &WorkControl::new()).unwrap();
        let mut c = RayCounters::default();
        let mut ray = Ray::new(Vec3::new(0.0, 5.0, 1.0), Vec3::new(0.0, -1.0, 0.0));
        assert!(two.closest_hit(&mut ray, TraceOptions::default(), &mut c).is_some());
        assert!(c.top_nodes_visited >= 1 && c.instances_entered >= 1);
        assert!(c.bottom_nodes_visited() >= 1 && c.triangle_tests >= 1);
        assert!(c.box_tests > c.top_box_tests, "totals include both levels");
    }

    #[test]
    fn bottom_boxes_are_placed_by_each_instance() {
        let (m, placements, _) = scene();
        let p = BuildParams::default();
        let two = TwoLevelBvh::build(&[&m], &placements, &p, &p, &WorkControl::new()).unwrap();
        let boxes = two.bottom_boxes_at_depth(0, false);
        assert_eq!(boxes.len(), placements.len(), "each instance shows its mesh's root");
        for (b, (_, t)) in boxes.iter().zip(&placements) {
            assert_eq!(b.to_world, *t);
            let corners = placed_corners(&b.bounds, &b.to_world);
            let world = corners.iter().fold(Aabb::EMPTY, |acc, &c| acc.grow(c));
            assert!(world.area() > 0.0);
        }
        let ids: std::collections::HashSet<usize> = two.bottom_boxes_at_depth(2, true).iter().map(|b| b.id).collect();
        assert_eq!(ids.len(), two.bottom_boxes_at_depth(2, true).len(), "ids are unique");
        assert_eq!(top_leaf_sizes(&two.top).iter().sum::<u32>(), 4);
    }

    #[test]
    fn a_scene_without_instances_misses_everything() {
        let two = TwoLevelBvh::build(&[], &[], &BuildParams::default(), &BuildParams::default(), &WorkControl::new())
            .unwrap();
        let mut ray = Ray::new(Vec3::ZERO, Vec3::X);
        assert!(two.closest_hit(&mut ray, TraceOptions::default(), &mut NoStats).is_none());
    }
}
