//! Explain a node: the state behind the Tree and Node windows. Once an image is done, the binary
//! tree as built (`AnyBvh::binary_tree`), its hierarchy and each node's end-point overlap are
//! prepared in the background (`Explained`); with the Tree window open, the visits of the frame's
//! rays per node too. The node selected here is the one the tree view, the icicle, the viewport
//! and the inspector show; its inspection (`explain::inspect`) is computed in the background too,
//! since a node of millions of triangles takes a moment to sweep.

use crate::bvh::{Bvh, Hierarchy, SceneBvh, TraceOptions};
use crate::explain::inspect::Inspection;
use crate::render::Camera;
use std::collections::HashSet;
use std::sync::Arc;

/// The binary tree behind a built BVH, with what the views need of it.
pub struct Explained {
    /// The BVH this explains (the app's current one while `Arc::ptr_eq`).
    pub bvh: Arc<SceneBvh>,
    pub tree: Arc<Bvh>,
    pub hierarchy: Hierarchy,
    /// Each node's term of the end-point overlap (`bvh::epo`), their sum, and two standard errors
    /// of it where it was estimated (`epo::Epo::error`).
    pub epo_terms: Vec<f64>,
    pub epo: f64,
    pub epo_error: Option<f64>,
    /// Each node's term of the tree's SAH cost: C(n)·A(n)/A(root).
    pub sah_terms: Vec<f64>,
}

impl Explained {
    pub fn new(bvh: Arc<SceneBvh>, tree: Arc<Bvh>) -> Explained {
        let hierarchy = Hierarchy::of(&tree);
        let measured = crate::bvh::epo::measure(&tree, &hierarchy);
        let (epo, epo_error) = (measured.value, measured.error());
        let epo_terms = measured.terms;
        let c = tree.params.cost;
        let root = tree.nodes.first().map_or(0.0, |n| n.bounds().area() as f64);
        let sah_terms = tree
            .nodes
            .iter()
            .map(|n| {
                let w = if n.is_leaf() { c.intersection as f64 * n.count as f64 } else { c.traversal as f64 };
                if root > 0.0 {
                    w * n.bounds().area() as f64 / root
                } else {
                    0.0
                }
            })
            .collect();
        Explained { bvh, tree, hierarchy, epo_terms, epo, epo_error, sah_terms }
    }

    /// The overlap of a node's children's boxes, as a share of the node's own area (0 for a leaf).
    pub fn child_overlap(&self, node: usize) -> f64 {
        let n = &self.tree.nodes[node];
        if n.is_leaf() || n.bounds().area() <= 0.0 {
            return 0.0;
        }
        let (l, r) = (&self.tree.nodes[n.index as usize], &self.tree.nodes[n.index as usize + 1]);
        crate::explain::inspect::Overlap::of(&l.bounds(), &r.bounds()).area as f64 / n.bounds().area() as f64
    }
}

/// The visits of a frame's rays per node of the binary tree, for one camera and traversal.
pub struct FrameVisits {
    pub explained: Arc<Explained>,
    pub camera: Camera,
    pub trace: TraceOptions,
    pub counts: Vec<u32>,
}

/// What the icicle colours its nodes by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Metric {
    #[default]
    Visits,
    Sah,
    Overlap,
    Epo,
    Depth,
}

impl Metric {
    pub const ALL: [Metric; 5] = [Metric::Visits, Metric::Sah, Metric::Overlap, Metric::Epo, Metric::Depth];
    pub fn label(self) -> &'static str {
        match self {
            Metric::Visits => "visits",
            Metric::Sah => "SAH share",
            Metric::Overlap => "child overlap",
            Metric::Epo => "EPO share",
            Metric::Depth => "depth",
        }
    }
    pub fn help(self) -> &'static str {
        match self {
            Metric::Visits => {
                "How many of the frame's primary rays entered the node (a binary traversal of the same rays)"
            }
            Metric::Sah => "The node's term of the tree's SAH cost: C(n)·A(n)/A(root)",
            Metric::Overlap => "The area of the box the two children share, over the node's own area",
            Metric::Epo => {
                "The node's term of the end-point overlap: surface of other triangles inside its box, weighted"
            }
            Metric::Depth => "The node's depth",
        }
    }
}

/// Where a key or a button moves the selection.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    Parent,
    Left,
    Right,
    Sibling,
}

#[derive(Default)]
pub struct NodeView {
    pub explained: Option<Arc<Explained>>,
    pub visits: Option<FrameVisits>,
    pub selected: Option<u32>,
    /// The tree view's open (expanded) nodes.
    pub open: HashSet<u32>,
    /// The selected node's inspection, once computed.
    pub inspection: Option<Arc<Inspection>>,
    /// The Tree and Node windows are shown.
    pub window: bool,
    pub metric: Metric,
    /// The Node window draws its three axes' cost curves on one cost range.
    pub shared_scale: bool,
}

impl NodeView {
    /// The prepared tree, if it is the current BVH's.
    pub fn current(&self, bvh: Option<&Arc<SceneBvh>>) -> Option<&Arc<Explained>> {
        self.explained.as_ref().filter(|e| bvh.is_some_and(|b| Arc::ptr_eq(&e.bvh, b)))
    }

    /// Select `node` and open its ancestors in the tree view.
    pub fn select(&mut self, node: u32) {
        let Some(e) = &self.explained else { return };
        if node as usize >= e.tree.nodes.len() {
            return;
        }
        for a in e.hierarchy.path(node) {
            if a != node {
                self.open.insert(a);
            }
        }
        if self.selected != Some(node) {
            self.inspection = None;
        }
        self.selected = Some(node);
    }

    /// No node selected (a new scene or another tree: its ids are not the old tree's).
    pub fn deselect(&mut self) {
        self.selected = None;
        self.inspection = None;
        self.open.clear();
    }

    /// The node one step from the selected one, if there is one.
    pub fn step(&self, step: Step) -> Option<u32> {
        let (e, n) = (self.explained.as_ref()?, self.selected?);
        let node = e.tree.nodes.get(n as usize)?;
        let parent = e.hierarchy.parent[n as usize];
        match step {
            Step::Parent => (parent != u32::MAX).then_some(parent),
            Step::Left => (!node.is_leaf()).then_some(node.index),
            Step::Right => (!node.is_leaf()).then_some(node.index + 1),
            Step::Sibling => {
                (parent != u32::MAX)
                    .then(|| e.tree.nodes[parent as usize].index)
                    .map(|l| if l == n { l + 1 } else { l })
            }
        }
    }

    /// The rows the tree view shows: every node under an open one, depth first.
    pub fn rows(&self) -> Vec<u32> {
        self.rows_showing(None)
    }

    /// The rows, with `also`'s ancestors open too (the pinned ray's node as the Ray view steps).
    pub fn rows_showing(&self, also: Option<u32>) -> Vec<u32> {
        let Some(e) = &self.explained else { return Vec::new() };
        let path = also.filter(|&n| (n as usize) < e.tree.nodes.len()).map(|n| e.hierarchy.path(n)).unwrap_or_default();
        let mut out = Vec::new();
        let mut stack = vec![0u32];
        while let Some(n) = stack.pop() {
            out.push(n);
            let node = &e.tree.nodes[n as usize];
            let open = self.open.contains(&n) || (path.contains(&n) && Some(n) != also);
            if !node.is_leaf() && open {
                stack.extend([node.index + 1, node.index]);
            }
        }
        out
    }
}
