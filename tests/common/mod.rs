//! Helpers shared by the integration tests.
#![allow(dead_code)]

use bvhscope::bvh::{Bvh, BvhNode};
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
    eprintln!("notice: {} not found; skipping tests on shared meshes", dir.display());
    None
}

pub fn shared_mesh(name: &str) -> Option<Mesh> {
    let path = shared_models()?.join(name);
    Some(load_obj(&path).unwrap_or_else(|e| panic!("{e}")).0)
}

/// The structure every BVH must have, whatever the strategy.
pub fn check_invariants(bvh: &Bvh, mesh: &Mesh) {
    let n = mesh.triangle_count();
    assert_eq!(bvh.prim_ids.len(), n, "primitive array length");
    let mut seen = vec![0u32; n];
    for &p in &bvh.prim_ids {
        seen[p as usize] += 1;
    }
    assert!(seen.iter().all(|&c| c == 1), "prim_ids is not a permutation");
    for (i, &p) in bvh.prim_ids.iter().enumerate() {
        assert_eq!(bvh.tris[i], mesh.triangle(p), "reordered triangle {i}");
    }

    let mut leaf_ranges = Vec::new();
    let mut reached = 0usize;
    let mut stack = vec![(0usize, None::<Aabb>)];
    while let Some((i, parent)) = stack.pop() {
        reached += 1;
        let node: &BvhNode = &bvh.nodes[i];
        if let Some(pb) = parent {
            assert!(pb.contains_box(&node.bounds), "node {i} box sticks out of its parent");
        }
        if node.is_leaf() {
            assert!(node.count as u32 <= bvh.params.max_leaf_size, "leaf {i} has {} > max", node.count);
            for k in node.prims() {
                for v in bvh.tris[k] {
                    assert!(node.bounds.contains_box(&Aabb::new(v, v)), "leaf {i} does not contain its triangle");
                }
            }
            leaf_ranges.push(node.prims());
        } else {
            let l = node.index as usize;
            assert!(l > i && l + 1 < bvh.nodes.len(), "child index of node {i}");
            stack.push((l, Some(node.bounds)));
            stack.push((l + 1, Some(node.bounds)));
        }
    }
    assert_eq!(reached, bvh.nodes.len(), "every node is reachable exactly once");
    leaf_ranges.sort_by_key(|r| r.start);
    let mut next = 0;
    for r in &leaf_ranges {
        assert_eq!(r.start, next, "leaf ranges must tile the primitive array without gaps or overlap");
        next = r.end;
    }
    assert_eq!(next, n, "leaf ranges must cover every triangle");
}
