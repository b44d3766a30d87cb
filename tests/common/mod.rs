//! Helpers shared by the integration tests.
#![allow(dead_code)]

use bvhscope::bvh::{AnyBvh, Bvh, BvhNode, WideBvh};
use bvhscope::geometry::Aabb;
use bvhscope::mesh::{load_obj, Mesh};
use std::path::PathBuf;

/// `../shared/models` beside the checkout. Absent: tests skip with a notice, except under CI=true,
/// where the folder is promised and its absence is a failure.
pub fn shared_models() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/models");
    if dir.is_dir() {
        return Some(dir);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("CI=true but the shared test meshes are missing: {}", dir.display());
    }
    // Written to stderr directly: libtest captures `eprintln!` of passing tests, not this.
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "notice: {} not found; skipping tests on shared meshes", dir.display());
    None
}

pub fn shared_mesh(name: &str) -> Option<Mesh> {
    let path = shared_models()?.join(name);
    Some(load_obj(&path).unwrap_or_else(|e| panic!("{e}")).0)
}

/// The structure every BVH must have, whatever the strategy and layout.
pub fn check_any(bvh: &AnyBvh, mesh: &Mesh) {
    match bvh {
        AnyBvh::Binary(b) => check_invariants(b, mesh),
        AnyBvh::Wide(w) => check_wide(w, mesh),
    }
}

fn check_prims(prim_ids: &[u32], tris: &[[glam::Vec3; 3]], mesh: &Mesh) {
    let n = mesh.triangle_count();
    assert_eq!(prim_ids.len(), n, "primitive array length");
    let mut seen = vec![0u32; n];
    for &p in prim_ids {
        seen[p as usize] += 1;
    }
    assert!(seen.iter().all(|&c| c == 1), "prim_ids is not a permutation");
    for (i, &p) in prim_ids.iter().enumerate() {
        assert_eq!(tris[i], mesh.triangle(p), "reordered triangle {i}");
    }
}

fn check_tiling(mut ranges: Vec<std::ops::Range<usize>>, n: usize) {
    ranges.sort_by_key(|r| r.start);
    let mut next = 0;
    for r in &ranges {
        assert_eq!(r.start, next, "leaf ranges must tile the primitive array without gaps or overlap");
        next = r.end;
    }
    assert_eq!(next, n, "leaf ranges must cover every triangle");
}

/// The wide layout: every slot box inside its parent's, leaf ranges tiling the triangles, each
/// node reached exactly once, valid masks matching the slots.
pub fn check_wide(w: &WideBvh, mesh: &Mesh) {
    check_prims(&w.prim_ids, &w.tris, mesh);
    let mut ranges = Vec::new();
    let mut reached = vec![0u32; w.nodes.len()];
    let mut stack = vec![(0usize, w.root_bounds)];
    while let Some((i, parent)) = stack.pop() {
        reached[i] += 1;
        let node = &w.nodes[i];
        for slot in 0..4 {
            let used = node.valid & (1 << slot) != 0;
            if !used {
                assert!(node.slot_bounds(slot).is_empty(), "empty slot {slot} of node {i} must have an inverted box");
                continue;
            }
            let b = node.slot_bounds(slot);
            assert!(parent.contains_box(&b), "slot {slot} of node {i} sticks out of its parent");
            let (child, count) = (node.child[slot] as usize, node.count[slot] as usize);
            if count > 0 {
                assert!(count as u32 <= w.params.max_leaf_size);
                for t in &w.tris[child..child + count] {
                    for v in t {
                        assert!(b.contains_box(&Aabb::new(*v, *v)), "leaf slot does not contain its triangle");
                    }
                }
                ranges.push(child..child + count);
            } else {
                assert!(child > i && child < w.nodes.len(), "child index");
                stack.push((child, b));
            }
        }
    }
    if !w.prim_ids.is_empty() {
        assert!(reached.iter().all(|&c| c == 1), "every wide node is reached exactly once");
    }
    check_tiling(ranges, mesh.triangle_count());
}

/// The structure every binary BVH must have, whatever the strategy.
pub fn check_invariants(bvh: &Bvh, mesh: &Mesh) {
    let n = mesh.triangle_count();
    check_prims(&bvh.prim_ids, &bvh.tris, mesh);

    let mut leaf_ranges = Vec::new();
    let mut reached = 0usize;
    let mut stack = vec![(0usize, None::<Aabb>)];
    while let Some((i, parent)) = stack.pop() {
        reached += 1;
        let node: &BvhNode = &bvh.nodes[i];
        if let Some(pb) = parent {
            assert!(pb.contains_box(&node.bounds()), "node {i} box sticks out of its parent");
        }
        if node.is_leaf() {
            assert!(node.count as u32 <= bvh.params.max_leaf_size, "leaf {i} has {} > max", node.count);
            for k in node.prims() {
                for v in bvh.tris[k] {
                    assert!(node.bounds().contains_box(&Aabb::new(v, v)), "leaf {i} does not contain its triangle");
                }
            }
            leaf_ranges.push(node.prims());
        } else {
            let l = node.index as usize;
            assert!(l > i && l + 1 < bvh.nodes.len(), "child index of node {i}");
            stack.push((l, Some(node.bounds())));
            stack.push((l + 1, Some(node.bounds())));
        }
    }
    assert_eq!(reached, bvh.nodes.len(), "every node is reachable exactly once");
    check_tiling(leaf_ranges, n);
}

/// A scene file placing a generated 1,000-triangle torus `n` times on a grid.
pub fn many_placements(dir: &std::path::Path, n: usize) -> PathBuf {
    let torus = bvhscope::mesh::generate::torus(1.0, 0.3, 25, 20);
    assert_eq!(torus.triangle_count(), 1000);
    let obj = dir.join(format!("torus-{n}.obj"));
    bvhscope::mesh::write_obj(&torus, &mut std::fs::File::create(&obj).unwrap()).unwrap();
    let side = (n as f32).sqrt().ceil() as usize;
    let meshes: Vec<bvhscope::scene::SceneMesh> = (0..n)
        .map(|i| {
            let at = glam::Vec3::new((i % side) as f32 * 3.0, 0.0, (i / side) as f32 * 3.0);
            bvhscope::scene::SceneMesh::new(obj.clone(), glam::Affine3A::from_translation(at))
        })
        .collect();
    let camera = bvhscope::render::Camera::framing(&Aabb::new(glam::Vec3::ZERO, glam::Vec3::ONE), 64, 48);
    let text = bvhscope::scene::write_scene_file(&camera, &meshes, &bvhscope::bvh::BuildParams::default());
    let path = dir.join(format!("many-{n}.json"));
    std::fs::write(&path, text).unwrap();
    path
}
