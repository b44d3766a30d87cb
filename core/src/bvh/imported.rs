//! What tells a tree imported from a dump (`crate::dump::import`) from a built one: its file, and
//! the dump's id of each node, so that traces and the tree view name nodes as the student's
//! program does.

use crate::bvh::counters::NodeId;
use crate::bvh::node::Bvh;
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
    /// Nodes in the dump (reached or not).
    pub dump_nodes: usize,
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
            NodeId::Node(i) => self.node_ids.get(i as usize).copied().filter(|&d| d != u32::MAX),
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
    pub fn rename(&self, step: &super::TraceStep, mesh: &Mesh) -> super::TraceStep {
        step.renamed(|id| self.dump_id(id).map_or(id, NodeId::Node), |t| mesh.file_number(t))
    }
}
