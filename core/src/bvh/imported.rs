//! A BVH another program wrote (`dump`), made into one of bvhscope's own layouts so that every
//! view and command traces it with the same traversal as the built-in strategies: a binary dump
//! becomes a `Bvh`, a dump with nodes of 3 or 4 children a 4-wide `WideBvh`, one with nodes of up
//! to 8 children an 8-wide one (each dump node one wide node, its children in the order written). Boxes are kept as written, so a wrong box misses rays as it
//! would in the student's renderer; nodes are renumbered, and `Imported` keeps the dump's id of
//! each so that traces and the tree view name nodes as the student's program does.

use super::dump::BvhDump;
use super::wide::WideNode;
use super::{AnyBvh, BuildParams, Bvh, BvhNode, Layout, NodeId, WideBvh};
use crate::geometry::Aabb;
use crate::mesh::Mesh;

/// What tells an imported tree from a built one: its file, and the dump's id of each node.
#[derive(Clone, Debug)]
pub struct Imported {
    /// The dump's file name, for captions ("imported: FILE").
    pub name: String,
    /// Where it was read from (for the `bvhscope trace --bvh` command that repeats a trace).
    pub path: std::path::PathBuf,
    /// For each node of the traced tree (binary node i, or wide node i), the dump's id.
    pub node_ids: Vec<u32>,
    /// Wide layout: the dump's id of the leaf in slot s of wide node i, at `width·i + s`
    /// (`u32::MAX` where the slot holds no leaf). Empty for the binary layout.
    pub leaf_ids: Vec<u32>,
    /// Children per wide node (4 or 8; 2 for the binary layout).
    pub width: usize,
    /// Wide layout: the binary tree the tree view and the node inspector show (as they show the
    /// binary tree a built 4-wide tree was collapsed from): each node of k > 2 children split
    /// into binary nodes over its children in the order written, the added nodes' boxes the union
    /// of their children's; with the dump's id of each node (`u32::MAX` for an added one).
    pub binary: Option<(std::sync::Arc<Bvh>, Vec<u32>)>,
}

impl Imported {
    /// "imported: FILE", as the strategy list, captions and tables name the tree.
    pub fn label(&self) -> String {
        format!("imported: {}", self.name)
    }

    /// A node as a trace names it, by the dump's id.
    pub fn dump_id(&self, id: NodeId) -> Option<u32> {
        match id {
            NodeId::Node(i) => self.node_ids.get(i as usize).copied(),
            NodeId::Leaf { node, slot } => {
                self.leaf_ids.get(node as usize * self.width + slot as usize).copied().filter(|&d| d != u32::MAX)
            }
        }
    }

    /// The traced tree's node that is the dump's node `dump` (`None` for one not reached from the
    /// root, or an empty leaf, which the traced tree leaves out).
    pub fn node_of_dump(&self, dump: u32) -> Option<NodeId> {
        if let Some(i) = self.node_ids.iter().position(|&d| d == dump) {
            return Some(NodeId::Node(i as u32));
        }
        let k = self.leaf_ids.iter().position(|&d| d == dump)?;
        Some(NodeId::Leaf { node: (k / self.width) as u32, slot: (k % self.width) as u8 })
    }

    /// The binary tree node that is the dump's node `dump`, in the binary tree the tree view shows
    /// (`SceneBvh::binary_tree`): this tree, or for a 4-wide one its binarised form.
    pub fn binary_node_of_dump(&self, dump: u32) -> Option<u32> {
        let ids = self.binary.as_ref().map_or(&self.node_ids, |(_, ids)| ids);
        ids.iter().position(|&d| d == dump).map(|i| i as u32)
    }

    /// The dump's id of binary tree node `node` (`None` for a node added to binarise the tree).
    pub fn dump_of_binary_node(&self, node: u32) -> Option<u32> {
        let ids = self.binary.as_ref().map_or(&self.node_ids, |(_, ids)| ids);
        ids.get(node as usize).copied().filter(|&d| d != u32::MAX)
    }

    /// A trace step with nodes named by the dump's ids and triangles by their numbers in the file.
    pub fn rename(&self, step: &super::Step, mesh: &Mesh) -> super::Step {
        step.renamed(|id| self.dump_id(id).map_or(id, NodeId::Node), |t| mesh.file_number(t))
    }
}

/// Why a dump cannot be traced.
pub fn untraceable(dump: &BvhDump) -> Option<String> {
    let kids = dump.nodes.iter().filter_map(|n| n.children.as_ref().map(|k| k.len()));
    let widest = kids.clone().max().unwrap_or(2);
    let binary = widest == 2;
    let (most, cap) = if binary { (u16::MAX as u32, "65,535") } else { (u8::MAX as u32, "255") };
    if widest > 8 || kids.clone().any(|k| k < 2) {
        return Some("its nodes have fewer than 2 or more than 8 children".into());
    }
    let big = dump.nodes.iter().filter(|n| n.children.is_none()).filter_map(|n| n.count).max().unwrap_or(0);
    (big > most).then(|| {
        format!(
            "a leaf holds {big} triangles; a {} tree's leaves hold at most {cap}",
            if binary { "binary" } else { "wide" }
        )
    })
}

/// The dump as bvhscope traces it: binary when every interior node has two children, 4-wide when
/// none has more than four, 8-wide otherwise. The dump's structure must be sound (`check::check_tree` finds no structure defect);
/// `Err` says why a tree cannot be traced when it cannot.
pub fn import(dump: &BvhDump, mesh: &Mesh, path: &std::path::Path) -> Result<(AnyBvh, Imported), String> {
    let name = path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned());
    let path = path.to_path_buf();
    if let Some(why) = untraceable(dump) {
        return Err(why);
    }
    let binary = dump.nodes.iter().all(|n| n.children.as_ref().is_none_or(|k| k.len() == 2));
    let copy = Leaves { dump, by_file: mesh.triangles_by_file_number(), mesh, prim_ids: Vec::new(), tris: Vec::new() };
    let broken = || "its structure has defects (bvhscope check lists them)".to_string();
    if binary {
        let (bvh, ids) = to_binary(copy).ok_or_else(broken)?;
        let imported = Imported { name, path, node_ids: ids, leaf_ids: Vec::new(), width: 2, binary: None };
        Ok((AnyBvh::Binary(bvh), imported))
    } else {
        let widest = dump.nodes.iter().filter_map(|n| n.children.as_ref().map(|k| k.len())).max().unwrap_or(2);
        let (wide, node_ids, leaf_ids, width) = if widest <= 4 {
            let (w, n, l) = to_wide::<4>(copy).ok_or_else(broken)?;
            (AnyBvh::Wide(w), n, l, 4)
        } else {
            let (w, n, l) = to_wide::<8>(copy).ok_or_else(broken)?;
            (AnyBvh::Wide8(w), n, l, 8)
        };
        let (split, added) = binarised(dump);
        let again =
            Leaves { dump: &split, by_file: mesh.triangles_by_file_number(), mesh, prim_ids: vec![], tris: vec![] };
        let (bvh, ids) = to_binary(again).ok_or_else(broken)?;
        let ids = ids.into_iter().map(|d| if d >= added { u32::MAX } else { d }).collect();
        let binary = Some((std::sync::Arc::new(bvh), ids));
        Ok((wide, Imported { name, path, node_ids, leaf_ids, width, binary }))
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
                let b = part
                    .iter()
                    .filter_map(|&c| out.nodes.get(c as usize))
                    .fold(Aabb::EMPTY, |b, n| b.union(n.bounds()));
                let (min, max) = (glam::Vec3::from(b.min).to_array(), glam::Vec3::from(b.max).to_array());
                let node = super::dump::DumpNode {
                    min,
                    max,
                    children: Some(part.to_vec()),
                    first: None,
                    count: None,
                    axis: None,
                };
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
                // An empty leaf's empty box is never entered.
                let (start, kept) = leaves.copy(d)?;
                if kept > 0 {
                    nodes[slot] = BvhNode::leaf(n.bounds(), start, kept as u16);
                }
            }
        }
    }
    let params = Leaves::params(Layout::Binary);
    Some((Bvh { nodes, prim_ids: leaves.prim_ids, tris: leaves.tris, params, report: Default::default() }, ids))
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
    };
    wide.store_leaves_by_coordinate();
    Some((wide, ids, leaf_ids))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{check::check_rays, Accelerator, RayCounters, TraceOptions, TreeStats, TreeView};
    use crate::mesh::generate;

    /// bvhscope's own trees, exported and imported again, trace every ray as the trees they were
    /// written from: the same hit and the same counts, binary and 4-wide alike; and each node's
    /// dump id leads back to it.
    #[test]
    fn export_then_import_traces_as_the_original_in_both_layouts() {
        let mesh = generate::torus_knot(2, 3, 0.3, 96, 8);
        let camera = crate::render::Camera::framing_up(&mesh.bounds(), 40, 30, crate::render::UpAxis::Y, 45.0);
        let rays = check_rays(&mesh, &camera, 500);
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
            for (r, _) in &rays {
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
        let camera = crate::render::Camera::framing_up(&mesh.bounds(), 24, 16, crate::render::UpAxis::Y, 45.0);
        for (r, _) in check_rays(&mesh, &camera, 300) {
            let t = |h: Option<crate::bvh::Hit>| h.map(|h| h.t);
            let a = wide.closest_hit(&mut r.clone(), TraceOptions::default(), &mut crate::bvh::NoStats);
            let b = bin.closest_hit(&mut r.clone(), TraceOptions::default(), &mut crate::bvh::NoStats);
            assert_eq!(t(a), t(b));
        }
    }

    /// Nodes of 9 children, and leaves too large for the layout, are refused with the reason.
    #[test]
    fn untraceable_trees_say_why() {
        let mesh = generate::torus_knot(2, 3, 0.3, 16, 4);
        let b = Bvh::build(&mesh, &BuildParams { layout: Layout::Binary, ..BuildParams::default() });
        let mut d = BvhDump::of_bvh(&b, &mesh, None);
        d.nodes[0].children.as_mut().unwrap().extend([1; 7]);
        assert!(import(&d, &mesh, "x".as_ref()).unwrap_err().contains("more than 8 children"));
        let mut d = BvhDump::of_bvh(&b, &mesh, None);
        d.nodes[0].children.as_mut().unwrap().push(2);
        let leaf = d.nodes.iter_mut().find(|n| n.children.is_none()).unwrap();
        leaf.count = Some(300);
        assert!(import(&d, &mesh, "x".as_ref()).unwrap_err().contains("at most 255"));
    }
}
