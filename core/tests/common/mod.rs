//! Helpers shared by the integration tests of every package: the shared meshes, the structure
//! every BVH must have, a scene of many placements. Core's own tests use them, and the top-level
//! package's, the UI tests' and the GPU crate's include this file (`#[path]`), so each helper is
//! written once. Only `bvhscope_core` paths: every including package depends on it.
//! Where tests write their files is `scratch.rs` beside this file, included on its own by the
//! tests that write files (it needs `libc`, which not every including package has).
#![allow(dead_code)]

use bvhscope_core::bvh::{AnyBvh, BuildParams, Bvh, BvhNode, WideBvh};
use bvhscope_core::geometry::Aabb;
use bvhscope_core::mesh::{load_obj, Mesh};
use std::path::{Path, PathBuf};

/// `../shared/models` beside the checkout. Absent: tests skip with a notice, except under CI=true,
/// where the folder is promised and its absence is a failure.
pub fn shared_models() -> Option<PathBuf> {
    // The including package may be the workspace's root or a member one folder down: the
    // checkout is the first folder up with the workspace's Cargo.lock.
    let package = Path::new(env!("CARGO_MANIFEST_DIR"));
    let checkout = package.ancestors().find(|d| d.join("Cargo.lock").is_file()).unwrap_or(package);
    let dir = checkout.join("../shared/models");
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
    Some(load_obj(&path).unwrap_or_else(|e| panic!("{name}: {e}")).0)
}

/// The structure every BVH must have, whatever the strategy and layout.
pub fn check_any(bvh: &AnyBvh, mesh: &Mesh) {
    match bvh {
        AnyBvh::Binary(b) => check_invariants(b, mesh),
        AnyBvh::Wide(w) => check_wide(w, mesh),
        AnyBvh::Wide8(w) => check_wide(w, mesh),
    }
}

/// The leaf slots: a permutation of the triangles, or for the SBVH every triangle at least once
/// and at most its growth bound more references in all. Returns each triangle's references.
fn check_prims(prim_ids: &[u32], tris: &[[glam::Vec3; 3]], mesh: &Mesh, params: &BuildParams) -> Vec<u32> {
    let n = mesh.triangle_count();
    let mut seen = vec![0u32; n];
    for &p in prim_ids {
        seen[p as usize] += 1;
    }
    if params.strategy.splits_references() {
        assert!(seen.iter().all(|&c| c >= 1), "every triangle in a leaf");
        let bound = n + n * params.sbvh_growth as usize / 100;
        assert!(prim_ids.len() <= bound, "{} references, more than the growth bound {bound}", prim_ids.len());
    } else {
        assert_eq!(prim_ids.len(), n, "primitive array length");
        assert!(seen.iter().all(|&c| c == 1), "prim_ids is not a permutation");
    }
    for (i, &p) in prim_ids.iter().enumerate() {
        assert_eq!(tris[i], mesh.triangle(p), "reordered triangle {i}");
    }
    seen
}

/// Leaves (box, slot range) hold their triangles: one referenced once lies inside its leaf's box;
/// one cut among several leaves (SBVH) has every point inside one of them (a barycentric grid of
/// 12 steps a side, edges and vertices included). Leaves never hold one triangle twice.
fn check_leaves_hold(
    leaves: &[(Aabb, std::ops::Range<usize>)],
    prim_ids: &[u32],
    tris: &[[glam::Vec3; 3]],
    refs: &[u32],
) {
    let inside = |b: &Aabb, v: glam::Vec3| b.contains_box(&Aabb::new(v, v));
    let mut parts: std::collections::HashMap<u32, Vec<Aabb>> = Default::default();
    for (b, range) in leaves {
        let mut here: Vec<u32> = prim_ids[range.clone()].to_vec();
        here.sort();
        assert!(here.windows(2).all(|w| w[0] != w[1]), "a leaf holds a triangle twice");
        for k in range.clone() {
            if refs[prim_ids[k] as usize] == 1 {
                assert!(tris[k].iter().all(|&v| inside(b, v)), "a leaf does not contain its triangle");
            } else {
                parts.entry(prim_ids[k]).or_default().push(*b);
            }
        }
    }
    for (p, boxes) in parts {
        let t = tris[prim_ids.iter().position(|&q| q == p).unwrap()];
        const STEPS: u32 = 12;
        for i in 0..=STEPS {
            for j in 0..=STEPS - i {
                let (u, v) = (i as f32 / STEPS as f32, j as f32 / STEPS as f32);
                let q = match (i, j) {
                    (0, 0) => t[0],
                    (STEPS, _) => t[1],
                    (_, STEPS) => t[2],
                    _ => t[0] * (1.0 - u - v) + t[1] * u + t[2] * v,
                };
                // Interpolated points round: a few units in the last place of slack.
                let slack = q.abs().max_element() * 4.0 * f32::EPSILON;
                let near = |b: &Aabb| (0..3).all(|a| b.min[a] - slack <= q[a] && q[a] <= b.max[a] + slack);
                assert!(boxes.iter().any(near), "triangle {p} cut among {} leaves: {q:?} is in none", boxes.len());
            }
        }
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
pub fn check_wide<const W: usize>(w: &WideBvh<W>, mesh: &Mesh) {
    let tris = w.leaf_order_triangles();
    let refs = check_prims(&w.prim_ids, &tris, mesh, &w.params);
    let mut ranges = Vec::new();
    let mut leaves = Vec::new();
    let mut reached = vec![0u32; w.nodes.len()];
    let mut stack = vec![(0usize, w.root_bounds)];
    while let Some((i, parent)) = stack.pop() {
        reached[i] += 1;
        let node = &w.nodes[i];
        for slot in 0..W {
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
                leaves.push((b, child..child + count));
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
    check_leaves_hold(&leaves, &w.prim_ids, &tris, &refs);
    check_tiling(ranges, w.prim_ids.len());
}

/// The structure every binary BVH must have, whatever the strategy.
pub fn check_invariants(bvh: &Bvh, mesh: &Mesh) {
    let refs = check_prims(&bvh.prim_ids, &bvh.tris, mesh, &bvh.params);
    let mut leaves = Vec::new();
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
            leaves.push((node.bounds(), node.prims()));
            leaf_ranges.push(node.prims());
        } else {
            let l = node.index as usize;
            assert!(l > i && l + 1 < bvh.nodes.len(), "child index of node {i}");
            stack.push((l, Some(node.bounds())));
            stack.push((l + 1, Some(node.bounds())));
        }
    }
    assert_eq!(reached, bvh.nodes.len(), "every node is reachable exactly once");
    check_leaves_hold(&leaves, &bvh.prim_ids, &bvh.tris, &refs);
    check_tiling(leaf_ranges, bvh.prim_ids.len());
}

/// A scene file placing a generated 1,000-triangle torus `n` times on a grid.
pub fn many_placements(dir: &Path, n: usize) -> PathBuf {
    let torus = bvhscope_core::mesh::generate::torus(1.0, 0.3, 25, 20);
    assert_eq!(torus.triangle_count(), 1000);
    let obj = dir.join(format!("torus-{n}.obj"));
    bvhscope_core::mesh::write_obj(&torus, &mut std::fs::File::create(&obj).unwrap()).unwrap();
    let side = (n as f32).sqrt().ceil() as usize;
    let meshes: Vec<bvhscope_core::scene::SceneMesh> = (0..n)
        .map(|i| {
            let at = glam::Vec3::new((i % side) as f32 * 3.0, 0.0, (i / side) as f32 * 3.0);
            bvhscope_core::scene::SceneMesh::new(obj.clone(), glam::Affine3A::from_translation(at))
        })
        .collect();
    let camera = bvhscope_core::render::Camera::framing(&Aabb::new(glam::Vec3::ZERO, glam::Vec3::ONE), 64, 48);
    let text = bvhscope_core::scene::write_scene_file(&camera, &meshes, &bvhscope_core::bvh::BuildParams::default());
    let path = dir.join(format!("many-{n}.json"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Two finished frames of one camera, pixel by pixel: how many pixels one hits and the other
/// misses; `both(a, b)` is called for every pixel both hit, where a test compares what it found.
pub fn hit_differences(
    a: &bvhscope_core::render::Frame,
    b: &bvhscope_core::render::Frame,
    mut both: impl FnMut(&bvhscope_core::render::PixelSample, &bvhscope_core::render::PixelSample),
) -> usize {
    let mut differ = 0;
    for (x, y) in a.full_samples().unwrap().iter().zip(b.full_samples().unwrap()) {
        if x.is_hit() != y.is_hit() {
            differ += 1;
        } else if x.is_hit() {
            both(x, y);
        }
    }
    differ
}
