//! Per-ray work counters, and the sink trait that lets the traversal count for free when nobody
//! is listening: `NoStats` has empty inlined methods, so the counting code compiles away in the
//! plain traversal (measured in `benches/`), while `RayCounters` feeds the heatmaps. A sink that
//! sets `STEPS` (`bvh::trace::Trace`) is also told every step of the walk, in order; for every
//! other sink `STEPS` is a constant false and the step reports compile away.

use crate::geometry::TriangleHit;

/// A node of the walk. In the binary layout every node, leaves included, is a `Node` (its index in
/// the node array); in the 4-wide layout a `Node` is a wide node and a leaf lives in a slot of its
/// parent (`Leaf`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NodeId {
    Node(u32),
    Leaf { node: u32, slot: u8 },
}

impl std::fmt::Display for NodeId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NodeId::Node(n) => write!(f, "node {n}"),
            NodeId::Leaf { node, slot } => write!(f, "leaf {node}.{slot}"),
        }
    }
}

/// How many of the stack's top entries a walk reports with each change (`step_stack`): more than
/// one step changes (an 8-wide node pushes at most seven, then sorts them).
pub const REPORTED_STACK: usize = 32;

/// Where the traversal reports its work. Implementations must be cheap: these run per node.
pub trait TraversalStats {
    fn node_visited(&mut self);
    fn leaf_visited(&mut self);
    fn box_tests(&mut self, n: u32);
    fn triangle_tests(&mut self, n: u32);

    /// A node of the top level of a two-level BVH (`TwoLevelBvh`). The work of both levels counts
    /// in the totals above; a sink that tells the levels apart also counts it here.
    #[inline(always)]
    fn top_node_visited(&mut self) {
        self.node_visited();
    }
    /// Box tests of the top level (also counted in the totals).
    #[inline(always)]
    fn top_box_tests(&mut self, n: u32) {
        self.box_tests(n);
    }
    /// The ray was transformed into an instance's object space to enter its mesh's BVH.
    #[inline(always)]
    fn instance_entered(&mut self) {}

    /// Whether the walks report each step below (`Trace` and `visits::NodeVisits` do). The walks test it before
    /// each report, so for the other sinks no step costs anything, not even its arguments.
    const STEPS: bool = false;
    /// The walk is over a two-level BVH: its steps outside a placement are the top level's.
    #[inline(always)]
    fn step_levels(&mut self) {}
    /// A box was tested against the ray: `child`'s, with the parameters at which the ray enters
    /// and leaves it (`None`: missed, or entered beyond the closest hit so far). The root's box
    /// is tested first.
    #[inline(always)]
    fn step_box(&mut self, _child: NodeId, _interval: Option<(f32, f32)>) {}
    /// The walk moved to `node` (an interior node, or in the binary layout a leaf).
    #[inline(always)]
    fn step_enter(&mut self, _node: NodeId) {}
    /// The walk reached the leaf `node`.
    #[inline(always)]
    fn step_leaf(&mut self, _node: NodeId) {}
    /// The stack after a push, a pop or a sort: its `len` entries in all, and the top ones
    /// (`REPORTED_STACK` of them, or all when fewer), bottom first: (node, entry parameter).
    /// Entries below the reported ones are as they were at the last report (a walk changes only
    /// the top of its stack between reports), so a deep tree's trace costs no more per step.
    #[inline(always)]
    fn step_stack(&mut self, _len: usize, _top: &[(NodeId, f32)]) {}
    /// `node` was popped and dropped: the ray enters it at `t`, beyond the closest hit so far.
    #[inline(always)]
    fn step_skip(&mut self, _node: NodeId, _t: f32) {}
    /// Triangle `prim` (its id in the mesh the walk is over) was tested; a hit is nearer than any
    /// before it, so it is the new closest hit.
    #[inline(always)]
    fn step_triangle(&mut self, _prim: u32, _hit: Option<TriangleHit>) {}
    /// The walk went into placement `instance` of a two-level BVH: its mesh's triangles are
    /// numbered from `first_prim` in the scene, and the ray in its object space is `ray`.
    #[inline(always)]
    fn step_instance(&mut self, _instance: u32, _first_prim: u32, _ray: &crate::geometry::Ray) {}
    /// The walk came back out of the placement it went into.
    #[inline(always)]
    fn step_instance_done(&mut self) {}
}

/// The sink of the plain traversal: counts nothing, costs nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoStats;

impl TraversalStats for NoStats {
    #[inline(always)]
    fn node_visited(&mut self) {}
    #[inline(always)]
    fn leaf_visited(&mut self) {}
    #[inline(always)]
    fn box_tests(&mut self, _: u32) {}
    #[inline(always)]
    fn triangle_tests(&mut self, _: u32) {}
}

/// The work one ray (or, summed, many rays) did. Plain integers: no atomics in the hot loop; a
/// renderer keeps one per pixel and sums afterwards.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct RayCounters {
    /// Nodes taken from the stack and processed, interior and leaf.
    pub nodes_visited: u32,
    /// Ray–box slab tests.
    pub box_tests: u32,
    pub leaves_visited: u32,
    /// Ray–triangle tests.
    pub triangle_tests: u32,
    /// Of `nodes_visited`, those in the top level of a two-level BVH (0 for a single BVH).
    pub top_nodes_visited: u32,
    /// Of `box_tests`, those in the top level of a two-level BVH.
    pub top_box_tests: u32,
    /// Instances whose mesh BVH the ray entered.
    pub instances_entered: u32,
}

impl TraversalStats for RayCounters {
    #[inline(always)]
    fn node_visited(&mut self) {
        self.nodes_visited += 1;
    }
    #[inline(always)]
    fn leaf_visited(&mut self) {
        self.leaves_visited += 1;
    }
    #[inline(always)]
    fn box_tests(&mut self, n: u32) {
        self.box_tests += n;
    }
    #[inline(always)]
    fn triangle_tests(&mut self, n: u32) {
        self.triangle_tests += n;
    }
    #[inline(always)]
    fn top_node_visited(&mut self) {
        self.nodes_visited += 1;
        self.top_nodes_visited += 1;
    }
    #[inline(always)]
    fn top_box_tests(&mut self, n: u32) {
        self.box_tests += n;
        self.top_box_tests += n;
    }
    #[inline(always)]
    fn instance_entered(&mut self) {
        self.instances_entered += 1;
    }
}

impl RayCounters {
    /// No work (a `const` for static initialisers).
    pub const ZERO: RayCounters = RayCounters {
        nodes_visited: 0,
        box_tests: 0,
        leaves_visited: 0,
        triangle_tests: 0,
        top_nodes_visited: 0,
        top_box_tests: 0,
        instances_entered: 0,
    };

    /// Add another ray's counts (a pixel's secondary rays are summed; saturating, so a sum never wraps).
    pub fn add(&mut self, o: &RayCounters) {
        self.nodes_visited = self.nodes_visited.saturating_add(o.nodes_visited);
        self.box_tests = self.box_tests.saturating_add(o.box_tests);
        self.leaves_visited = self.leaves_visited.saturating_add(o.leaves_visited);
        self.triangle_tests = self.triangle_tests.saturating_add(o.triangle_tests);
        self.top_nodes_visited = self.top_nodes_visited.saturating_add(o.top_nodes_visited);
        self.top_box_tests = self.top_box_tests.saturating_add(o.top_box_tests);
        self.instances_entered = self.instances_entered.saturating_add(o.instances_entered);
    }

    /// Nodes visited in the bottom level (a single BVH's nodes are all bottom level).
    pub fn bottom_nodes_visited(&self) -> u32 {
        self.nodes_visited - self.top_nodes_visited
    }

    /// Combined cost of the ray under the SAH's own cost model: traversal steps plus triangle
    /// tests, weighted by the same constants the builder used.
    pub fn cost(&self, c: crate::bvh::SahCost) -> f32 {
        c.traversal * self.nodes_visited as f32 + c.intersection * self.triangle_tests as f32
    }
}
