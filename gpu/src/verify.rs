//! Every tree a GPU builder makes is checked before anyone traces, draws or writes it: its
//! structure (each node reached once from the root, children and triangle ranges in bounds:
//! `checked_depth`), its coverage (every triangle of the mesh in exactly one leaf, the leaf's
//! triangle the mesh's) and its boxes (each holds its children's, each leaf's its triangles'). A
//! builder run past a driver's limit came back with a cycle and 17,579 of 20,000 triangles in no
//! leaf, and `export-bvh` wrote it; now that is an error naming the first thing wrong, never a
//! tree.

use crate::binary::checked_depth;
use crate::device::GpuError;
use bvhscope_core::bvh::Bvh;
use bvhscope_core::geometry::Aabb;
use bvhscope_core::mesh::Mesh;

/// `bvh`, built on the GPU over `mesh` by `builder`, when it is sound; else the error.
pub(crate) fn verified(builder: &str, bvh: Bvh, mesh: &Mesh) -> Result<Bvh, GpuError> {
    match problem(&bvh, mesh) {
        None => Ok(bvh),
        Some(why) => Err(GpuError::Broken { builder: builder.into(), why }),
    }
}

/// The first thing wrong with `bvh` as a tree over `mesh`, if any.
pub fn problem(bvh: &Bvh, mesh: &Mesh) -> Option<String> {
    let n = mesh.triangle_count();
    if n == 0 {
        return None;
    }
    if let Err(e) = checked_depth(bvh) {
        return Some(e.to_string());
    }
    if bvh.prim_ids.len() != n {
        return Some(format!("its leaves hold {} triangles, the mesh has {n}", bvh.prim_ids.len()));
    }
    let mut seen = vec![false; n];
    for (slot, &p) in bvh.prim_ids.iter().enumerate() {
        match seen.get_mut(p as usize) {
            None => return Some(format!("leaf slot {slot} names triangle {p}, past the mesh's {n}")),
            Some(s) if *s => return Some(format!("triangle {p} is in two leaf slots")),
            Some(s) => *s = true,
        }
        if bvh.tris[slot] != mesh.triangle(p) {
            return Some(format!("leaf slot {slot} holds other corners than triangle {p}"));
        }
    }
    // Every slot in exactly one reached leaf: the leaves' counts add up to the slots (each node is
    // reached once and each range is in bounds, so no slot is counted twice unless ranges overlap).
    let mut covered = vec![false; n];
    for (i, node) in bvh.nodes.iter().enumerate() {
        let b = node.bounds();
        if node.is_leaf() {
            let (f, c) = (node.index as usize, node.count as usize);
            if bvh.nodes.len() > 1 || c > 0 {
                for (s, (slot, tri)) in covered[f..f + c].iter_mut().zip(&bvh.tris[f..f + c]).enumerate() {
                    let s = f + s;
                    if std::mem::replace(slot, true) {
                        return Some(format!("leaf slot {s} is in two leaves (node {i}'s among them)"));
                    }
                    if !b.contains_box(&Aabb::from_points(tri)) {
                        return Some(format!("leaf node {i}'s box does not hold its triangle in slot {s}"));
                    }
                }
            }
        } else {
            for c in [node.index as usize, node.index as usize + 1] {
                if !b.contains_box(&bvh.nodes[c].bounds()) {
                    return Some(format!("node {i}'s box does not hold its child node {c}'s"));
                }
            }
        }
    }
    if let Some(s) = covered.iter().position(|&c| !c) {
        return Some(format!("leaf slot {s} (triangle {}) is in no leaf", bvh.prim_ids[s]));
    }
    None
}
