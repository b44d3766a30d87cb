//! The checker's structure group: each node on its own (kind, children, leaf range, primitives,
//! box, axis), the count of references before any is followed, and the walk from the root (nodes
//! reached twice, never reached). Each kind of defect is one finding listing its nodes.

use super::{count, defect, max_references, warning, Finding, Group, Tally};
use crate::bvh::reach::{reach, Fault, Reach};
use crate::dump::BvhDump;
use crate::mesh::Mesh;
use glam::Vec3;
use std::ops::ControlFlow;

/// The tree as reached from the root: which nodes, and the parent each was first reached from.
pub(super) struct Walk {
    pub reached: Vec<bool>,
    pub parent: Vec<u32>,
}

/// Check `dump`'s structure into `out`. `None` when the dump cannot be walked further (no nodes,
/// or more references than a dump of this mesh can need: following them would cost without
/// bound).
pub(super) fn check(dump: &BvhDump, mesh: &Mesh, out: &mut Vec<Finding>) -> Option<Walk> {
    let (nodes, prims, tris) = (&dump.nodes, &dump.primitives, mesh.file_triangle_count());
    if nodes.is_empty() {
        out.push(defect(Group::Structure, None, None, "the dump has no nodes (node 0 is the root)".into()));
        return None;
    }
    // References first, from the leaves' counts alone.
    let references: u64 = nodes.iter().filter(|n| n.children.is_none()).filter_map(|n| n.count).map(u64::from).sum();
    let most = max_references(mesh);
    if references > most {
        out.push(defect(
            Group::Structure,
            None,
            None,
            format!(
                "the leaves hold {references} triangle references in all, more than a BVH of this mesh can need \
                 ({most}: 8 per triangle of its {tris}, and 4096); nothing further is checked"
            ),
        ));
        return None;
    }
    let s = Group::Structure;
    let mut both = Tally::new(
        s,
        true,
        "node is both a leaf (first/count) and interior (children)",
        "nodes are both a leaf (first/count) and interior (children)",
    );
    let mut neither = Tally::new(
        s,
        true,
        "node is neither a leaf nor interior (no children, no first/count)",
        "nodes are neither a leaf nor interior (no children, no first/count)",
    );
    let mut arity = Tally::new(
        s,
        true,
        "node has fewer than 2 or more than 8 children (2 to 8 are supported)",
        "nodes have fewer than 2 or more than 8 children (2 to 8 are supported)",
    );
    let mut past_node =
        Tally::new(s, true, "child index is past the last node", "child indices are past the last node");
    let mut half_leaf =
        Tally::new(s, true, "leaf has first or count but not both", "leaves have first or count but not both");
    let mut past_range =
        Tally::new(s, true, "leaf range runs past the end of primitives", "leaf ranges run past the end of primitives");
    let mut past_mesh =
        Tally::new(s, true, "primitive numbers no triangle of the mesh", "primitives number no triangle of the mesh");
    let mut not_finite =
        Tally::new(s, true, "box has a NaN or infinite coordinate", "boxes have a NaN or infinite coordinate");
    let mut inverted = Tally::new(s, true, "box is inverted (min above max)", "boxes are inverted (min above max)");
    let mut bad_axis = Tally::new(
        s,
        true,
        "node has a split axis other than 0, 1 or 2 (x, y, z)",
        "nodes have a split axis other than 0, 1 or 2 (x, y, z)",
    );
    let last = nodes.len() - 1;
    for (i, n) in nodes.iter().enumerate() {
        let id = Some(i as u32);
        let leafish = n.first.is_some() || n.count.is_some();
        match (&n.children, leafish) {
            (Some(_), true) => both.add(id, None, format!("node {i}")),
            (None, false) => neither.add(id, None, format!("node {i}")),
            _ => {}
        }
        if let Some(kids) = &n.children {
            if kids.len() < 2 || kids.len() > 8 {
                arity.add(id, None, format!("node {i} ({} children)", kids.len()));
            }
            for &k in kids.iter().filter(|&&k| k as usize > last) {
                past_node.add(id, None, format!("node {i}: child {k} (the last node is {last})"));
            }
        }
        if let Some(a) = n.axis.filter(|&a| a > 2) {
            bad_axis.add(id, None, format!("node {i} (axis {a})"));
        }
        if n.children.is_none() && leafish {
            match (n.first, n.count) {
                (Some(f), Some(c)) if f as u64 + c as u64 > prims.len() as u64 => past_range.add(
                    id,
                    None,
                    format!("node {i}: {f}..{} (there are {} primitives)", f as u64 + c as u64, prims.len()),
                ),
                (Some(f), Some(c)) => {
                    let (f, c) = (f as usize, c as usize);
                    for (k, &p) in prims[f..f + c].iter().enumerate().filter(|(_, &p)| p as usize >= tris) {
                        past_mesh.add(
                            id,
                            None,
                            format!("primitives[{}] = {p} (node {i}; the mesh has {tris} triangles)", f + k),
                        );
                    }
                }
                _ => half_leaf.add(id, None, format!("node {i}")),
            }
        }
        let (lo, hi) = (Vec3::from(n.min), Vec3::from(n.max));
        if !(lo.is_finite() && hi.is_finite()) {
            not_finite.add(id, None, format!("node {i}"));
        } else if let Some(a) = (0..3).find(|&a| lo[a] > hi[a]) {
            inverted.add(id, None, format!("node {i} on {} (min {} > max {})", ["x", "y", "z"][a], lo[a], hi[a]));
        }
    }
    for t in [both, neither, arity, past_node, half_leaf, past_range, past_mesh, not_finite, inverted, bad_axis] {
        t.finish(out);
    }
    Some(walk(dump, out))
}

/// The walk from the root (`bvh::reach`): nodes reached twice (a cycle when the node is on the
/// path from the root to the one reaching it again, else two parents), never reached. A child
/// past the last node is a finding of the nodes on their own, above.
fn walk(dump: &BvhDump, out: &mut Vec<Finding>) -> Walk {
    let nodes = &dump.nodes;
    let mut twice = Tally::new(Group::Structure, true, "node is reached twice", "nodes are reached twice");
    let children = |i: usize, k: usize| nodes[i].children.as_deref().and_then(|c| c.get(k)).copied();
    let Reach { reached, parent, .. } = reach(nodes.len(), children, |fault| {
        if let Fault::Again { from, node, cycle } = fault {
            let why = if cycle { "a cycle" } else { "two parents" };
            twice.add(Some(node as u32), None, format!("node {node} (from node {from}: {why})"));
        }
        ControlFlow::Continue(())
    });
    twice.finish(out);
    // Reached leaves of no triangle: harmless, but a binary node cannot hold nothing.
    let mut empty = Tally::new(
        Group::Structure,
        false,
        "leaf holds no triangle: no ray finds anything in it, and bvhscope traces its parent as its other child",
        "leaves hold no triangle: no ray finds anything in them, and bvhscope traces each one's parent as its other child",
    );
    let hold_nothing =
        |(i, n): &(usize, &crate::dump::DumpNode)| reached[*i] && n.children.is_none() && n.count == Some(0);
    for (i, _) in nodes.iter().enumerate().filter(hold_nothing) {
        empty.add(Some(i as u32), None, format!("node {i}"));
    }
    empty.finish(out);
    let unreached: Vec<usize> = (0..nodes.len()).filter(|&i| !reached[i]).collect();
    if let Some(&first) = unreached.first() {
        let text =
            count(unreached.len(), "node is never reached from the root", "nodes are never reached from the root");
        let mut f = warning(Group::Coverage, Some(first as u32), None, text);
        f.examples = unreached.iter().map(|i| format!("node {i}")).collect();
        out.push(f);
    }
    Walk { reached, parent }
}
