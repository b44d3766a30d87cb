//! Bring your own BVH: a finding's node or triangle selected in the imported tree.

use crate::app::state::{Action, BvhscopeApp, MessageKind};
use crate::bvh::SceneBvh;

impl BvhscopeApp {
    /// Select the node the dump calls `dump` in the tree view (showing the imported tree first).
    pub(in crate::app) fn select_dump_node(&mut self, dump: u32) {
        let Some(bvh) = self.import.traced(self.scene_id).cloned() else {
            let why = "the imported tree cannot be shown (its structure has defects)";
            return self.message(MessageKind::Info, format!("node {dump}: {why}"));
        };
        self.import.on = true;
        let Some(names) = bvh.import() else { return };
        match names.binary_node_of_dump(dump) {
            Some(n) => self.act(Action::SelectNode(n)),
            None => self.message(MessageKind::Info, format!("node {dump} is never reached from the root")),
        }
    }

    /// Select the leaf that holds the triangle the file numbers `t` (the leaf reached first, for
    /// a triangle in several), or say that none does.
    pub(in crate::app) fn select_triangle(&mut self, t: u32) {
        let Some(bvh) = self.import.traced(self.scene_id).cloned() else {
            return self.message(MessageKind::Info, format!("triangle {t}: the imported tree cannot be shown"));
        };
        self.import.on = true;
        let SceneBvh::Single { mesh, .. } = &*bvh else { return };
        let Some(Some(m)) = mesh.triangles_by_file_number().get(t as usize).copied() else {
            return self.message(MessageKind::Info, format!("triangle {t} has zero area: no ray can hit it"));
        };
        let leaf = self.nodes.current(Some(&bvh)).and_then(|e| e.hierarchy.leaf_of_prim(m));
        match leaf {
            Some(leaf) => {
                self.message(MessageKind::Info, format!("triangle {t}: in the leaf selected"));
                self.act(Action::SelectNode(leaf));
            }
            None if self.nodes.current(Some(&bvh)).is_none() => {
                self.message(MessageKind::Info, "The tree view is still being prepared: click again in a moment.")
            }
            None => self.message(MessageKind::Info, format!("triangle {t} is in no leaf of the imported tree")),
        }
    }
}
