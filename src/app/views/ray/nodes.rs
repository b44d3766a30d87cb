//! The pinned ray's walk on the Tree view's binary tree: which of its nodes the walk entered and,
//! step by step, which node it is at, so the tree's rows and the icicle mark the ray the Ray view
//! steps through and a click on a marked node takes the Ray view to the step that entered it.
//! The synchronised query view of Madan & Nobre, "Visualizing Query Traversals Over BVHs Using
//! Treemaps", IEEE VIS 2023. Read from the Ray view's own trace (`PinnedRay::trace`), no walk of
//! its own; a wide tree's nodes are the binary nodes it was collapsed from (`wide_group_in`).

use super::PinnedRay;
use crate::app::views::node::Explained;
use crate::bvh::wide::{wide_group_in, WideNode};
use crate::bvh::{AnyBvh, Layout, NodeId, SceneBvh, StepKind, TraceLevel};
use std::collections::{HashMap, HashSet};

/// The walk of one pinned ray on the binary tree.
#[derive(Debug, PartialEq)]
pub struct RayOnTree {
    /// Per step: the binary node the walk is at after it (the node the viewport draws yellow),
    /// `None` before the root is entered.
    pub at: Vec<Option<u32>>,
    /// Each binary node the walk entered, with the first step (0-based) that entered it; a wide
    /// tree's collapsed interior nodes on the way count as entered at that step too.
    pub entered: HashMap<u32, usize>,
}

impl RayOnTree {
    /// The walk of `ray` on `e`'s binary tree, if `ray` was traced through the tree `e` explains
    /// (one level; `None` too if its nodes cannot be matched with the binary tree's boxes).
    pub fn of(ray: &PinnedRay, e: &Explained) -> Option<RayOnTree> {
        if !std::sync::Arc::ptr_eq(&ray.bvh, &e.bvh) {
            return None;
        }
        let SceneBvh::Single { bvh, .. } = &*ray.bvh else { return None };
        let walked: HashSet<NodeId> = ray
            .trace
            .steps
            .iter()
            .filter(|s| s.level == TraceLevel::Mesh)
            .filter_map(|s| match s.kind {
                StepKind::Enter { node, .. } | StepKind::Leaf { node, .. } => Some(node),
                _ => None,
            })
            .collect();
        let binary = match bvh {
            AnyBvh::Binary(b) => {
                let same = b.nodes.len() == e.tree.nodes.len();
                if !same {
                    return None;
                }
                walked.iter().filter_map(|&id| if let NodeId::Node(n) = id { Some((id, n)) } else { None }).collect()
            }
            AnyBvh::Wide(w) => wide_to_binary(&w.nodes, Layout::Wide4, e, &walked)?,
            AnyBvh::Wide8(w) => wide_to_binary(&w.nodes, Layout::Wide8, e, &walked)?,
        };
        let (mut at, mut entered) = (Vec::with_capacity(ray.trace.steps.len()), HashMap::new());
        let mut current = None;
        for (k, s) in ray.trace.steps.iter().enumerate() {
            if let (TraceLevel::Mesh, StepKind::Enter { node, .. } | StepKind::Leaf { node, .. }) = (s.level, &s.kind) {
                current = binary.get(node).copied();
                if let Some(n) = current {
                    // The node and the collapsed ones above it, up to one entered already.
                    for a in e.hierarchy.path(n).into_iter().rev() {
                        if entered.contains_key(&a) {
                            break;
                        }
                        entered.insert(a, k);
                    }
                }
            }
            at.push(current);
        }
        Some(RayOnTree { at, entered })
    }

    /// The step a click on `node` takes the Ray view to: the one that entered it.
    pub fn step_of(&self, node: u32) -> Option<usize> {
        self.entered.get(&node).copied()
    }
}

/// The binary node each walked node of a wide tree is: its wide nodes are collapsed from the
/// binary tree top down, slot k of a wide node over binary node b holding the k-th of
/// `wide_group_in(b).children`, so a walk from the root down the walked nodes pairs them. Every
/// pair's boxes are checked equal (`None` if one is not: not the tree the binary tree explains).
fn wide_to_binary<const W: usize>(
    wide: &[WideNode<W>],
    layout: Layout,
    e: &Explained,
    walked: &HashSet<NodeId>,
) -> Option<HashMap<NodeId, u32>> {
    let b = &e.tree.nodes;
    let mut out = HashMap::from([(NodeId::Node(0), 0u32)]);
    if b.first()?.is_leaf() {
        return Some(out);
    }
    let mut stack = vec![(0u32, 0u32)];
    while let Some((w, bin)) = stack.pop() {
        let g = wide_group_in(layout, b, &e.hierarchy, bin)?;
        let node = wide.get(w as usize)?;
        if g.top != bin || g.children.len() != node.slots().count() {
            return None;
        }
        for (slot, &kid) in g.children.iter().enumerate() {
            if node.slot_planes(slot) != b.get(kid as usize)?.bounds().planes() {
                return None;
            }
            let id = if node.count[slot] > 0 {
                NodeId::Leaf { node: w, slot: slot as u8 }
            } else {
                NodeId::Node(node.child[slot])
            };
            if walked.contains(&id) {
                out.insert(id, kid);
                if let NodeId::Node(c) = id {
                    stack.push((c, kid));
                }
            }
        }
    }
    Some(out)
}
