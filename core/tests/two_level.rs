//! The two-level BVH (top level over instances, a BVH per mesh) against the flattened scene's
//! single-level BVH: the same rays must find the same triangles at the same distances.

mod common;

use bvhscope_core::bvh::{AnyBvh, BuildParams, Layout, Strategy, TwoLevelBvh};
use bvhscope_core::mesh::{generate, Mesh};
use bvhscope_core::render::{render, Camera, Frame, RenderSettings};
use bvhscope_core::scene::{flatten, load_any, SceneInstances};
use bvhscope_core::work::WorkControl;
use glam::{Affine3A, Quat, Vec3};
use std::path::Path;
use std::sync::Arc;

fn every_params() -> Vec<BuildParams> {
    let mut v = Vec::new();
    for strategy in Strategy::ALL {
        for layout in Layout::ALL {
            v.push(BuildParams { strategy, layout, ..BuildParams::default() });
        }
    }
    v
}

fn frames(scene: &SceneInstances, camera: &Camera, top: &BuildParams, bottom: &BuildParams) -> (Frame, Frame) {
    let flat = flatten(Path::new("test"), scene).expect("flattens");
    let two = TwoLevelBvh::build(&scene.mesh_refs(), &scene.placements, top, bottom, &WorkControl::new()).unwrap();
    let single = AnyBvh::build(&flat, bottom);
    let settings = RenderSettings::default();
    (render(&two, &flat, camera, &settings), render(&single, &flat, camera, &settings))
}

/// The mesh with its coordinates rounded to multiples of 1/64, so adding a whole-number
/// translation is exact.
fn on_grid(mut m: Mesh) -> Mesh {
    for p in &mut m.positions {
        *p = (*p * 64.0).round() / 64.0;
    }
    m
}

#[test]
fn translated_instances_give_exactly_the_flattened_hits() {
    // With grid coordinates, whole-number translations and a camera at a whole-number position,
    // moving the ray into object space and moving the mesh into the world are both exact, so the
    // two structures must agree bit for bit, whatever the strategies of either level.
    let scene = SceneInstances {
        meshes: vec![
            Arc::new(on_grid(generate::torus(1.0, 0.35, 40, 16))),
            Arc::new(on_grid(generate::torus_knot(2, 3, 0.2, 128, 12))),
        ],
        placements: (0..12)
            .map(|i| {
                ((i % 2) as u32, Affine3A::from_translation(Vec3::new((i % 4) as f32 * 3.0, (i / 4) as f32 * 3.0, 0.0)))
            })
            .chain([(1, Affine3A::IDENTITY)])
            .collect(),
    };
    let camera = Camera {
        position: Vec3::new(4.0, 3.0, 14.0),
        look_at: Vec3::new(4.5, 3.0, 0.0),
        up: Vec3::Y,
        vfov_deg: 50.0,
        width: 96,
        height: 64,
    };
    for top in every_params().into_iter().filter(|p| p.layout == Layout::Binary) {
        for bottom in every_params() {
            let (two, single) = frames(&scene, &camera, &top, &bottom);
            let hits = single.full_samples().unwrap().iter().filter(|s| s.is_hit()).count();
            assert!(hits > 1000, "the camera sees the scene ({hits} hits)");
            for (i, (a, b)) in two.full_samples().unwrap().iter().zip(single.full_samples().unwrap()).enumerate() {
                assert_eq!(
                    (a.prim, a.t.to_bits()),
                    (b.prim, b.t.to_bits()),
                    "pixel {i}: top {:?}, bottom {:?} {:?}",
                    top.strategy,
                    bottom.strategy,
                    bottom.layout
                );
            }
        }
    }
}

#[test]
fn rotated_and_scaled_instances_agree_with_the_flattened_scene() {
    // A general transform rounds differently in object space than in the world, so a ray grazing
    // an edge may find the neighbouring triangle; the hit mask and distances must still agree.
    let placements: Vec<(u32, Affine3A)> = (0..40)
        .map(|i| {
            let f = i as f32;
            let t = Affine3A::from_scale_rotation_translation(
                Vec3::splat(0.5 + (i % 3) as f32 * 0.25),
                Quat::from_euler(glam::EulerRot::XYZ, f * 0.37, f * 0.91, f * 0.13),
                Vec3::new((i % 8) as f32 * 2.5, (i / 8) as f32 * 2.5, -(i % 5) as f32),
            );
            (0, t)
        })
        .collect();
    let scene = SceneInstances { meshes: vec![Arc::new(generate::torus(1.0, 0.3, 48, 16))], placements };
    let camera = Camera {
        position: Vec3::new(9.0, 5.0, 22.0),
        look_at: Vec3::new(9.0, 5.0, 0.0),
        up: Vec3::Y,
        vfov_deg: 45.0,
        width: 160,
        height: 100,
    };
    let p = BuildParams::default();
    let (two, single) = frames(&scene, &camera, &p, &p);
    let n = two.full_samples().unwrap().len();
    let mask_diff = common::hit_differences(&two, &single, |a, b| {
        assert!((a.t - b.t).abs() <= 1e-4 * b.t, "distances agree: {} vs {}", a.t, b.t);
    });
    assert!(single.full_samples().unwrap().iter().filter(|s| s.is_hit()).count() > n / 10, "the scene fills the view");
    assert!(mask_diff * 1000 <= n, "{mask_diff} of {n} pixels differ in hit or miss");
}

#[test]
fn the_moer_lite_scene_two_level_equals_flattened() {
    let Some(dir) = common::shared_models() else { return };
    let loaded = load_any(dir.join("moer-lite-lab1-bvh/scene.json")).expect("the Moer-lite scene loads");
    let scene = loaded.instances().expect("a scene file gives instances");
    let camera = Camera { width: 300, height: 200, ..loaded.camera.expect("the scene has a camera") };
    let p = BuildParams::default();
    let (two, single) = frames(scene, &camera, &p, &p);
    assert!(single.full_samples().unwrap().iter().any(|s| s.is_hit()));
    for (a, b) in two.full_samples().unwrap().iter().zip(single.full_samples().unwrap()) {
        assert_eq!((a.prim, a.t.to_bits()), (b.prim, b.t.to_bits()));
    }
}
