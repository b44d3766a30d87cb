//! A BVH another program wrote (`dump`), made into one of bvhscope's own layouts so that every
//! view and command traces it with the same traversal as the built-in strategies: a binary dump
//! becomes a `Bvh`, a dump with nodes of 3 or 4 children a 4-wide `WideBvh`, one with nodes of up
//! to 8 children an 8-wide one (each dump node one wide node, its children in the order written).
//! Boxes are kept as written, so a wrong box misses rays as it would in the student's renderer;
//! nodes are renumbered, and `Imported` keeps the dump's id of each.

use super::BvhDump;
use crate::bvh::imported::Imported;
use crate::bvh::wide::WideNode;
use crate::bvh::{AnyBvh, BuildParams, Bvh, BvhNode, Layout, WideBvh};
use crate::geometry::Aabb;
use crate::mesh::Mesh;

/// Why a dump cannot be traced: nodes of more than 8 children (or fewer than 2).
pub fn untraceable(dump: &BvhDump) -> Option<String> {
    let mut kids = dump.nodes.iter().filter_map(|n| n.children.as_ref().map(|k| k.len()));
    kids.any(|k| !(2..=8).contains(&k)).then(|| "its nodes have fewer than 2 or more than 8 children".into())
}

/// The most triangles a leaf of the layout `dump` is traced in holds (65,535 binary, 255 wide),
/// and the dump's leaves that hold more: each is traced as a subtree of leaves of that many at
/// most, all with its box (the same hits; the counts include the added boxes).
pub fn oversized_leaves(dump: &BvhDump) -> (u32, Vec<u32>) {
    let cap = if widest(dump) == 2 { u16::MAX as u32 } else { u8::MAX as u32 };
    let big = dump.nodes.iter().enumerate().filter(|(_, n)| n.children.is_none() && n.count.is_some_and(|c| c > cap));
    (cap, big.map(|(i, _)| i as u32).collect())
}

/// The most children of a node of `dump` (2 for a tree of one leaf).
fn widest(dump: &BvhDump) -> usize {
    dump.nodes.iter().filter_map(|n| n.children.as_ref().map(|k| k.len())).max().unwrap_or(2)
}

/// The dump with each leaf of more than `cap` triangles made a binary subtree of leaves of at most
/// `cap`, each with the leaf's box; added nodes have ids from the returned number on.
fn leaves_split(dump: &BvhDump, cap: u32) -> (BvhDump, u32) {
    let mut out = dump.clone();
    let first_added = out.nodes.len() as u32;
    let mut i = 0;
    while i < out.nodes.len() {
        let n = &out.nodes[i];
        if let (true, Some(f), Some(c)) = (n.children.is_none(), n.first, n.count) {
            if c > cap {
                let half = c / 2;
                let (min, max) = (n.min, n.max);
                let leaf = |first, count| super::DumpNode {
                    min,
                    max,
                    children: None,
                    first: Some(first),
                    count: Some(count),
                    axis: None,
                };
                let k = out.nodes.len() as u32;
                out.nodes.push(leaf(f, half));
                out.nodes.push(leaf(f + half, c - half));
                let n = &mut out.nodes[i];
                (n.first, n.count, n.children) = (None, None, Some(vec![k, k + 1]));
            }
        }
        i += 1;
    }
    (out, first_added)
}

/// The dump as bvhscope traces it: binary when every interior node has two children, 4-wide when
/// none has more than four, 8-wide otherwise; leaves too large for the layout split
/// (`oversized_leaves`). The dump's structure must be sound (`explain::check::check_tree` finds
/// no structure defect); `Err` says why a tree cannot be traced when it cannot.
pub fn import(dump: &BvhDump, mesh: &Mesh, path: &std::path::Path) -> Result<(AnyBvh, Imported), String> {
    let name = crate::files::file_name(path);
    let path = path.to_path_buf();
    if let Some(why) = untraceable(dump) {
        return Err(why);
    }
    let dump_nodes = dump.nodes.len();
    let (cap, big) = oversized_leaves(dump);
    let split;
    let (dump, added) = if big.is_empty() {
        (dump, u32::MAX)
    } else {
        split = leaves_split(dump, cap);
        (&split.0, split.1)
    };
    // The dump's id of a traced node; none for a node added to split a leaf.
    let named =
        |ids: Vec<u32>| -> Vec<u32> { ids.into_iter().map(|d| if d >= added { u32::MAX } else { d }).collect() };
    let by_file = mesh.triangles_by_file_number();
    let copy = Leaves { dump, by_file: by_file.clone(), mesh, prim_ids: Vec::new(), tris: Vec::new() };
    let broken =
        || "its structure has defects, or its leaves hold no triangle (bvhscope check lists what is wrong)".to_string();
    if widest(dump) == 2 {
        let (bvh, ids) = to_binary(copy).ok_or_else(broken)?;
        let node_ids = named(ids);
        let imported = Imported { name, path, node_ids, leaf_ids: Vec::new(), dump_nodes, width: 2, binary: None };
        Ok((AnyBvh::Binary(bvh), imported))
    } else {
        let (wide, node_ids, leaf_ids, width) = if widest(dump) <= 4 {
            let (w, n, l) = to_wide::<4>(copy).ok_or_else(broken)?;
            (AnyBvh::Wide(w), n, l, 4)
        } else {
            let (w, n, l) = to_wide::<8>(copy).ok_or_else(broken)?;
            (AnyBvh::Wide8(w), n, l, 8)
        };
        let (node_ids, leaf_ids) = (named(node_ids), named(leaf_ids));
        let (bin, added_bin) = binarised(dump);
        let again = Leaves { dump: &bin, by_file, mesh, prim_ids: vec![], tris: vec![] };
        let (bvh, ids) = to_binary(again).ok_or_else(broken)?;
        let ids = ids.into_iter().map(|d| if d >= added_bin.min(added) { u32::MAX } else { d }).collect();
        let binary = Some((std::sync::Arc::new(bvh), ids));
        Ok((wide, Imported { name, path, node_ids, leaf_ids, dump_nodes, width, binary }))
    }
}

/// The dump with every node of k > 2 children split into binary nodes: children c0..ck-1 become
/// (c0..c⌈k/2⌉-1) and (the rest), each half one added node unless it is a single child (a
/// collapse run backwards). Added nodes have ids from the returned number on.
fn binarised(dump: &BvhDump) -> (BvhDump, u32) {
    let mut out = dump.clone();
    let first_added = out.nodes.len() as u32;
    let mut i = 0;
    while i < out.nodes.len() {
        if let Some(kids) = out.nodes[i].children.clone().filter(|k| k.len() > 2) {
            let (a, b) = kids.split_at(kids.len().div_ceil(2));
            let half = |out: &mut BvhDump, part: &[u32]| -> u32 {
                if let [one] = part {
                    return *one;
                }
                let b = Aabb::of(part.iter().filter_map(|&c| out.nodes.get(c as usize)).map(|n| n.bounds()));
                let (min, max) = (glam::Vec3::from(b.min).to_array(), glam::Vec3::from(b.max).to_array());
                let node =
                    super::DumpNode { min, max, children: Some(part.to_vec()), first: None, count: None, axis: None };
                out.nodes.push(node);
                out.nodes.len() as u32 - 1
            };
            let (l, r) = (half(&mut out, a), half(&mut out, b));
            out.nodes[i].children = Some(vec![l, r]);
        }
        i += 1;
    }
    (out, first_added)
}

/// The leaves' triangles copied into leaf order as they are reached (a triangle in two leaves is
/// there twice; primitives are file numbers, `Mesh::triangles_by_file_number`).
struct Leaves<'a> {
    dump: &'a BvhDump,
    by_file: Vec<Option<u32>>,
    mesh: &'a Mesh,
    prim_ids: Vec<u32>,
    tris: Vec<[glam::Vec3; 3]>,
}

impl Leaves<'_> {
    /// Copy dump node `d`'s triangles: (first in leaf order, how many). A zero-area triangle the
    /// loader dropped cannot be hit and is left out.
    fn copy(&mut self, d: usize) -> Option<(u32, u32)> {
        let n = self.dump.nodes.get(d)?;
        let (f, c) = (n.first? as usize, n.count? as usize);
        let start = self.prim_ids.len() as u32;
        for &p in self.dump.primitives.get(f..f + c)? {
            if let Some(t) = *self.by_file.get(p as usize)? {
                self.prim_ids.push(t);
                self.tris.push(self.mesh.triangle(t));
            }
        }
        Some((start, self.prim_ids.len() as u32 - start))
    }

    fn params(layout: Layout) -> BuildParams {
        BuildParams { layout, ..BuildParams::default() }
    }
}

/// Nodes renumbered depth first so each node's two children are adjacent.
fn to_binary(mut leaves: Leaves) -> Option<(Bvh, Vec<u32>)> {
    let dump = leaves.dump;
    let mut ids = vec![0u32];
    let mut nodes = vec![BvhNode::leaf(Aabb::EMPTY, 0, 0)];
    // Slots of leaves that hold nothing to trace.
    let mut empty = Vec::new();
    // (dump node, its slot in `nodes`)
    let mut stack = vec![(0usize, 0usize)];
    while let Some((d, slot)) = stack.pop() {
        // A cycle would never end (the checker reports it; here it only stops the copy).
        if nodes.len() > 2 * dump.nodes.len() + 2 {
            return None;
        }
        let n = dump.nodes.get(d)?;
        match &n.children {
            Some(kids) => {
                let first = nodes.len();
                nodes.extend([BvhNode::leaf(Aabb::EMPTY, 0, 0); 2]);
                ids.extend([kids[0], kids[1]]);
                nodes[slot] = BvhNode::interior(n.bounds(), first as u32, n.axis.unwrap_or(0).min(2));
                stack.push((kids[1] as usize, first + 1));
                stack.push((kids[0] as usize, first));
            }
            None => {
                let (start, kept) = leaves.copy(d)?;
                if kept > 0 {
                    nodes[slot] = BvhNode::leaf(n.bounds(), start, kept as u16);
                } else {
                    empty.push(slot);
                }
            }
        }
    }
    let (nodes, ids) = without_empty(nodes, ids, &empty)?;
    let params = Leaves::params(Layout::Binary);
    Some((Bvh { nodes, prim_ids: leaves.prim_ids, tris: leaves.tris, params, report: Default::default() }, ids))
}

/// The binary tree without its empty leaves (a leaf of count 0, or of zero-area triangles only,
/// which no ray can hit): a node whose one child is empty is replaced by its other child. A binary
/// node of no triangles cannot be written (a count of 0 means interior), and a walk that took it
/// for one would follow children that are not there. `None` when nothing is left.
fn without_empty(nodes: Vec<BvhNode>, ids: Vec<u32>, empty: &[usize]) -> Option<(Vec<BvhNode>, Vec<u32>)> {
    if empty.is_empty() {
        return Some((nodes, ids));
    }
    let mut is_empty = vec![false; nodes.len()];
    for &e in empty {
        is_empty[e] = true;
    }
    let interior = |i: usize, is_empty: &[bool]| !is_empty[i] && !nodes[i].is_leaf();
    // Children come after their parents (numbered depth first): one pass back up.
    for i in (0..nodes.len()).rev() {
        if interior(i, &is_empty) {
            let l = nodes[i].index as usize;
            is_empty[i] = is_empty[l] && is_empty[l + 1];
        }
    }
    if is_empty[0] {
        return None;
    }
    // Past a node with one empty child, to the first node worth keeping.
    let keep = |mut i: usize| {
        while interior(i, &is_empty) {
            let l = nodes[i].index as usize;
            match (is_empty[l], is_empty[l + 1]) {
                (true, false) => i = l + 1,
                (false, true) => i = l,
                _ => break,
            }
        }
        i
    };
    let (mut out, mut out_ids) = (vec![nodes[0]], vec![ids[0]]);
    let mut stack = vec![(keep(0), 0usize)];
    while let Some((i, slot)) = stack.pop() {
        out[slot] = nodes[i];
        out_ids[slot] = ids[i];
        if interior(i, &is_empty) {
            let l = nodes[i].index as usize;
            let first = out.len();
            out.extend([nodes[l], nodes[l + 1]]);
            out_ids.extend([ids[l], ids[l + 1]]);
            out[slot].index = first as u32;
            stack.push((keep(l + 1), first + 1));
            stack.push((keep(l), first));
        }
    }
    Some((out, out_ids))
}

/// Each interior dump node one wide node (numbered depth first), each leaf a slot of its parent.
fn to_wide<const W: usize>(mut leaves: Leaves) -> Option<(WideBvh<W>, Vec<u32>, Vec<u32>)> {
    let dump = leaves.dump;
    let root = dump.nodes.first()?;
    let mut nodes = vec![WideNode::<W>::EMPTY];
    let mut ids = vec![0u32];
    let mut leaf_ids = vec![u32::MAX; W];
    // A tree of one leaf: the root wide node holds it in slot 0.
    if root.children.is_none() {
        let (start, kept) = leaves.copy(0)?;
        if kept > 0 {
            nodes[0].set(0, root.bounds(), start, kept as u8);
            leaf_ids[0] = 0;
        }
    }
    let mut stack = vec![(0usize, 0usize)];
    while let Some((d, w)) = stack.pop() {
        if nodes.len() > dump.nodes.len() + 1 {
            return None; // a cycle (see `to_binary`)
        }
        for (s, &k) in dump.nodes.get(d)?.children.iter().flatten().enumerate() {
            let c = dump.nodes.get(k as usize)?;
            if c.children.is_some() {
                let index = nodes.len();
                nodes.push(WideNode::EMPTY);
                ids.push(k);
                leaf_ids.extend([u32::MAX; W]);
                nodes[w].set(s, c.bounds(), index as u32, 0);
                stack.push((k as usize, index));
            } else {
                let (start, kept) = leaves.copy(k as usize)?;
                if kept > 0 {
                    nodes[w].set(s, c.bounds(), start, kept as u8);
                    leaf_ids[w * W + s] = k;
                }
            }
        }
    }
    let (prim_ids, tris) = (leaves.prim_ids, leaves.tris);
    let params = Leaves::params(if W == 8 { Layout::Wide8 } else { Layout::Wide4 });
    let mut wide = WideBvh {
        nodes,
        prim_ids,
        tris,
        root_bounds: root.bounds(),
        params,
        report: Default::default(),
        simd: crate::cpu::Simd::chosen(),
        stored: Default::default(),
    };
    wide.store_leaves_by_coordinate();
    Some((wide, ids, leaf_ids))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{Accelerator, NodeId, RayCounters, TraceOptions, TreeStats, TreeView};
    use crate::geometry::Ray;
    use crate::mesh::generate;

    /// `n` rays at `mesh` from random points around it.
    fn rays_at(mesh: &Mesh, n: usize) -> Vec<Ray> {
        let b = mesh.bounds();
        crate::random::Rng::rays_at(7, n, (b.min.into(), b.max.into()))
            .into_iter()
            .map(|(o, d)| Ray::new(o, d))
            .collect()
    }

    /// bvhscope's own trees, exported and imported again, trace every ray as the trees they were
    /// written from: the same hit and the same counts, binary and 4-wide alike; and each node's
    /// dump id leads back to it.
    #[test]
    fn export_then_import_traces_as_the_original_in_both_layouts() {
        let mesh = generate::torus_knot(2, 3, 0.3, 96, 8);
        let rays = rays_at(&mesh, 1500);
        for layout in Layout::ALL {
            let built = AnyBvh::build(&mesh, &BuildParams { layout, ..BuildParams::default() });
            let dump = match &built {
                AnyBvh::Binary(b) => BvhDump::of_bvh(b, &mesh, None),
                AnyBvh::Wide(w) => BvhDump::of_wide(w, &mesh, None),
                AnyBvh::Wide8(w) => BvhDump::of_wide(w, &mesh, None),
            };
            let (back, names) = import(&dump, &mesh, "t.json".as_ref()).unwrap();
            assert_eq!(back.params().layout, layout);
            let (a, b) = (TreeStats::of(&built), TreeStats::of(&back));
            assert_eq!((a.nodes, a.leaves), (b.nodes, b.leaves), "{layout:?}");
            assert!((a.sah_cost - b.sah_cost).abs() <= 1e-9 * a.sah_cost, "{layout:?}: {a:?} vs {b:?}");
            for r in &rays {
                let (mut ca, mut cb) = (RayCounters::default(), RayCounters::default());
                let ha = built.closest_hit(&mut r.clone(), TraceOptions::default(), &mut ca);
                let hb = back.closest_hit(&mut r.clone(), TraceOptions::default(), &mut cb);
                assert_eq!((ha, ca), (hb, cb), "{layout:?}");
            }
            for d in 0..dump.nodes.len() as u32 {
                let id = names.node_of_dump(d).unwrap_or_else(|| panic!("{layout:?}: dump node {d} is traced"));
                assert_eq!(names.dump_id(id), Some(d));
            }
        }
    }

    /// A 4-wide dump's binary form (what the tree view shows) holds the same leaves and reaches
    /// the same hit for every ray; each of its nodes that is a dump node is named by that id.
    #[test]
    fn a_four_wide_dump_is_binarised_for_the_tree_view() {
        let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
        let w = WideBvh::from_binary(Bvh::build(&mesh, &BuildParams::default()));
        let dump = BvhDump::of_wide(&w, &mesh, None);
        let (wide, names) = import(&dump, &mesh, "w.json".as_ref()).unwrap();
        let (bin, ids) = names.binary.clone().expect("a binarised tree");
        assert!(bin.nodes.iter().all(|n| n.is_leaf() || n.index as usize + 1 < bin.nodes.len()));
        let leaves = |t: &dyn crate::bvh::TreeView| TreeStats::of(t).leaves;
        assert_eq!(leaves(&*bin), leaves(&wide));
        assert_eq!(ids.len(), bin.nodes.len());
        for d in 0..dump.nodes.len() as u32 {
            let n = names.binary_node_of_dump(d).expect("every dump node is in the binary tree");
            assert_eq!(names.dump_of_binary_node(n), Some(d));
        }
        for r in rays_at(&mesh, 700) {
            let t = |h: Option<crate::bvh::Hit>| h.map(|h| h.t);
            let a = wide.closest_hit(&mut r.clone(), TraceOptions::default(), &mut crate::bvh::NoStats);
            let b = bin.closest_hit(&mut r.clone(), TraceOptions::default(), &mut crate::bvh::NoStats);
            assert_eq!(t(a), t(b));
        }
    }

    /// Nodes of 9 children are refused with the reason; a leaf too large for the layout is split
    /// into leaves of its box that hold the same triangles, the added nodes named by no dump id.
    #[test]
    fn untraceable_trees_say_why_and_large_leaves_are_split() {
        let mesh = generate::torus_knot(2, 3, 0.3, 16, 4);
        let b = Bvh::build(&mesh, &BuildParams { layout: Layout::Binary, ..BuildParams::default() });
        let mut d = BvhDump::of_bvh(&b, &mesh, None);
        d.nodes[0].children.as_mut().unwrap().extend([1; 7]);
        assert!(import(&d, &mesh, "x".as_ref()).unwrap_err().contains("more than 8 children"));
        let mut d = BvhDump::of_bvh(&b, &mesh, None);
        d.nodes[0].children.as_mut().unwrap().push(2);
        d.primitives = (0..300).map(|i| i % mesh.triangle_count() as u32).collect();
        let k = d.nodes.iter().position(|n| n.children.is_none()).unwrap();
        (d.nodes[k].first, d.nodes[k].count) = (Some(0), Some(300));
        assert_eq!(oversized_leaves(&d), (255, vec![k as u32]));
        let (w, names) = import(&d, &mesh, "x".as_ref()).unwrap();
        let AnyBvh::Wide(w) = w else { panic!("3 children: 4-wide") };
        let big_is_a_node = (0..w.nodes.len()).any(|i| names.dump_id(NodeId::Node(i as u32)) == Some(k as u32));
        assert!(big_is_a_node, "the big leaf is traced as a wide node of leaves");
        assert!(
            names.leaf_ids.iter().all(|&l| l == u32::MAX || (l as usize) < d.nodes.len()),
            "added leaves have no dump id"
        );
    }
}
