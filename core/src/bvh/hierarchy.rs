//! Where each node of a binary tree sits: its parent, depth and range of the leaf order, and the
//! leaf of each triangle. The nodes do not store these; the tree view, the inspector, the replay,
//! EPO and the checker's tests all need them.

use super::Bvh;

/// Where each node sits in the binary tree: what the tree view, the breadcrumb and the inspector
/// need and the nodes do not store. Computed once per tree, O(nodes).
#[derive(Clone, Debug, Default)]
pub struct Hierarchy {
    /// The parent of each node (`u32::MAX` for the root).
    pub parent: Vec<u32>,
    pub depth: Vec<u32>,
    /// The subtree's triangles, a contiguous range of the leaf order: `first..first + count`.
    pub first: Vec<u32>,
    pub count: Vec<u32>,
    /// The leaf holding each slot of the leaf order.
    pub leaf_of_slot: Vec<u32>,
    /// The slot of each mesh triangle in the leaf order (of a triangle in several leaves, an
    /// SBVH's cut triangle, its last slot: `other_slots` has the rest).
    pub slot_of_prim: Vec<u32>,
    /// The other slots of triangles in several leaves (empty unless spatial splits cut some).
    pub other_slots: std::collections::HashMap<u32, Vec<u32>>,
}

impl Hierarchy {
    pub fn of(bvh: &Bvh) -> Hierarchy {
        let n = bvh.nodes.len();
        let mut h = Hierarchy {
            parent: vec![u32::MAX; n],
            depth: vec![0; n],
            first: vec![0; n],
            count: vec![0; n],
            leaf_of_slot: vec![0; bvh.prim_ids.len()],
            slot_of_prim: vec![u32::MAX; bvh.prim_ids.len()],
            other_slots: Default::default(),
        };
        // Parents come before their children in the node array, so one pass down sets parents and
        // depths, and one pass back up sums the ranges.
        for (i, node) in bvh.nodes.iter().enumerate() {
            if node.is_leaf() {
                h.first[i] = node.index;
                h.count[i] = node.count as u32;
                for s in node.prims() {
                    h.leaf_of_slot[s] = i as u32;
                }
            } else {
                for c in [node.index, node.index + 1] {
                    h.parent[c as usize] = i as u32;
                    h.depth[c as usize] = h.depth[i] + 1;
                }
            }
        }
        for i in (0..n).rev() {
            let node = &bvh.nodes[i];
            if !node.is_leaf() {
                let (l, r) = (node.index as usize, node.index as usize + 1);
                h.first[i] = h.first[l].min(h.first[r]);
                h.count[i] = h.count[l] + h.count[r];
            }
        }
        for (slot, &prim) in bvh.prim_ids.iter().enumerate() {
            if let Some(s) = h.slot_of_prim.get_mut(prim as usize) {
                if *s != u32::MAX {
                    h.other_slots.entry(prim).or_default().push(*s);
                }
                *s = slot as u32;
            }
        }
        h
    }

    /// Every slot of a triangle in the leaf order (more than one where spatial splits cut it).
    pub fn slots_of_prim(&self, prim: u32) -> impl Iterator<Item = u32> + '_ {
        let last = self.slot_of_prim.get(prim as usize).copied().filter(|&s| s != u32::MAX);
        last.into_iter().chain(self.other_slots.get(&prim).into_iter().flatten().copied())
    }

    /// The leaf that holds the part of triangle `prim` at `point` (a pixel's hit): its leaf, or of
    /// a triangle cut among several leaves the one whose box is nearest the point (holds it, but
    /// for rounding).
    pub fn leaf_of_hit(&self, bvh: &Bvh, prim: u32, point: glam::Vec3) -> Option<u32> {
        let away = |leaf: u32| {
            let b = bvh.nodes[leaf as usize].bounds();
            (glam::Vec3::from(b.min) - point).max(point - glam::Vec3::from(b.max)).max(glam::Vec3::ZERO).length()
        };
        let leaves = self.slots_of_prim(prim).filter_map(|s| self.leaf_of_slot.get(s as usize).copied());
        leaves.min_by(|&a, &b| away(a).total_cmp(&away(b)))
    }

    /// The node's ancestors from the root down, the node last: the breadcrumb.
    pub fn path(&self, node: u32) -> Vec<u32> {
        let mut out = vec![node];
        let mut n = node;
        while let Some(&p) = self.parent.get(n as usize).filter(|&&p| p != u32::MAX) {
            out.push(p);
            n = p;
        }
        out.reverse();
        out
    }

    /// The leaf that holds a mesh triangle (a pixel's hit: its leaf).
    pub fn leaf_of_prim(&self, prim: u32) -> Option<u32> {
        let slot = *self.slot_of_prim.get(prim as usize)?;
        self.leaf_of_slot.get(slot as usize).copied()
    }

    /// Whether leaf-order slot `slot` lies in `node`'s subtree.
    pub fn holds(&self, node: usize, slot: u32) -> bool {
        slot.wrapping_sub(self.first[node]) < self.count[node]
    }
}
