//! One ray's walk, step by step: the statistics sink that records it. It plugs into the same walks
//! that render (`traverse::walk`, the wide walk, the two-level walk) through the step reports of
//! `TraversalStats`, which every other sink compiles away, so what it records is what the
//! traversal did, not a second implementation written for display. The lab's ordered traversal
//! (pbrt-v4 §7.3.5) is what a student sees: each box test, which child is entered first, what goes
//! on the stack, which popped node is skipped because it starts beyond the closest hit.
//!
//! The totals of a trace (entered nodes, box tests, leaves, triangle tests) are the counting sink's
//! counts for the same ray, step for step (`tests/ray_trace.rs`).

use crate::bvh::accel::{Accelerator, Hit, TraceOptions};
use crate::bvh::counters::{NodeId, RayCounters, TraversalStats};
use crate::geometry::{Ray, TriangleHit};
use std::collections::HashMap;

/// Which tree a step is in: the one BVH, or for two levels the top level or the mesh BVH of a
/// placement.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TraceLevel {
    Mesh,
    Top,
    Bottom { instance: u32 },
}

/// One step of the walk.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "step", rename_all = "snake_case")]
pub enum StepKind {
    /// A box test: `node`'s box, at `depth` (0: the root), hit or missed; a hit gives the
    /// parameters at which the ray enters and leaves the box.
    BoxTest { node: NodeId, depth: u32, hit: bool, t_entry: Option<f32>, t_exit: Option<f32> },
    /// The walk moved to `node`.
    Enter { node: NodeId, depth: u32, t_entry: f32, t_exit: f32 },
    /// The walk reached a leaf (its triangle tests follow).
    Leaf { node: NodeId, depth: u32 },
    /// `node` went on the stack, to be visited at `t_entry`; `stack` is the stack after it (its
    /// top `SHOWN_STACK` entries; `below` more under them, in a tree deeper than that).
    Push { node: NodeId, t_entry: f32, stack: Vec<(NodeId, f32)>, below: u32 },
    /// `node` came off the stack to be visited next.
    Pop { node: NodeId, t_entry: f32, stack: Vec<(NodeId, f32)>, below: u32 },
    /// `node` came off the stack and was dropped: the ray enters it at `t_entry`, beyond the
    /// closest hit so far (`closest_t`).
    Skip { node: NodeId, t_entry: f32, closest_t: f32, stack: Vec<(NodeId, f32)>, below: u32 },
    /// A ray–triangle test (`triangle`: the mesh's or the scene's triangle id).
    Triangle { triangle: u32, hit: bool, t: Option<f32>, u: Option<f32>, v: Option<f32> },
    /// The triangle just hit is the closest hit so far.
    ClosestHit { triangle: u32, t: f32 },
    /// The walk enters placement `instance`, the ray moved into its object space.
    Instance { instance: u32, origin: [f32; 3], dir: [f32; 3] },
    /// The walk is back in the top level.
    InstanceDone { instance: u32 },
}

/// One step of a ray's trace: what the walk did (`kind`) and in which level of the tree.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TraceStep {
    pub level: TraceLevel,
    #[serde(flatten)]
    pub kind: StepKind,
}

impl TraceStep {
    /// The same step with nodes and triangles named otherwise (an imported tree's own node ids,
    /// the file's triangle numbers): `node` maps a node, `triangle` a triangle id.
    pub fn renamed(&self, node: impl Fn(NodeId) -> NodeId, triangle: impl Fn(u32) -> u32) -> TraceStep {
        let n = &node;
        let st = |v: &[(NodeId, f32)]| v.iter().map(|&(id, t)| (n(id), t)).collect::<Vec<_>>();
        let kind = match &self.kind {
            StepKind::BoxTest { node, depth, hit, t_entry, t_exit } => {
                StepKind::BoxTest { node: n(*node), depth: *depth, hit: *hit, t_entry: *t_entry, t_exit: *t_exit }
            }
            StepKind::Enter { node, depth, t_entry, t_exit } => {
                StepKind::Enter { node: n(*node), depth: *depth, t_entry: *t_entry, t_exit: *t_exit }
            }
            StepKind::Leaf { node, depth } => StepKind::Leaf { node: n(*node), depth: *depth },
            StepKind::Push { node, t_entry, stack, below } => {
                StepKind::Push { node: n(*node), t_entry: *t_entry, stack: st(stack), below: *below }
            }
            StepKind::Pop { node, t_entry, stack, below } => {
                StepKind::Pop { node: n(*node), t_entry: *t_entry, stack: st(stack), below: *below }
            }
            StepKind::Skip { node, t_entry, closest_t, stack, below } => StepKind::Skip {
                node: n(*node),
                t_entry: *t_entry,
                closest_t: *closest_t,
                stack: st(stack),
                below: *below,
            },
            StepKind::Triangle { triangle: tri, hit, t, u, v } => {
                StepKind::Triangle { triangle: triangle(*tri), hit: *hit, t: *t, u: *u, v: *v }
            }
            StepKind::ClosestHit { triangle: tri, t } => StepKind::ClosestHit { triangle: triangle(*tri), t: *t },
            other => other.clone(),
        };
        TraceStep { level: self.level, kind }
    }
}

/// What a trace knows of a node from its box test: its depth, and where the ray enters and leaves
/// its box (`None`: missed).
type Seen = (u32, Option<(f32, f32)>);

impl TraceStep {
    /// The depth of the node the step is about; `None` for a step of the node entered last (a
    /// stack operation, a triangle test), which a listing indents under that node.
    pub fn depth(&self) -> Option<u32> {
        match self.kind {
            StepKind::BoxTest { depth, .. } | StepKind::Enter { depth, .. } | StepKind::Leaf { depth, .. } => {
                Some(depth)
            }
            _ => None,
        }
    }

    /// The step in words without the stack it leaves (`text` adds it): what a list of steps shows
    /// on one line, the stack shown apart.
    pub fn brief(&self) -> String {
        let full = self.text();
        match full.split_once("  stack [") {
            Some((head, _)) => head.to_string(),
            None => full,
        }
    }

    /// The step in words, as `bvhscope trace` and the app's Ray panel list it.
    pub fn text(&self) -> String {
        let stack = |st: &[(NodeId, f32)], below: &u32| {
            let mut items: Vec<String> = st.iter().map(|(n, t)| format!("{n}@{t:.3}")).collect();
            if *below > 0 {
                items.insert(0, format!("… {below} below"));
            }
            format!("[{}]", items.join(", "))
        };
        match &self.kind {
            StepKind::BoxTest { node, hit: true, t_entry, t_exit, .. } => {
                format!("box of {node}: hit, t {:.4}..{:.4}", t_entry.unwrap_or(f32::NAN), t_exit.unwrap_or(f32::NAN))
            }
            StepKind::BoxTest { node, hit: false, .. } => format!("box of {node}: miss"),
            StepKind::Enter { node, depth, t_entry, t_exit } => {
                format!("enter {node} (depth {depth}, t {t_entry:.4}..{t_exit:.4})")
            }
            StepKind::Leaf { node, .. } => format!("leaf {node}: test its triangles"),
            StepKind::Push { node, t_entry, stack: st, below } => {
                format!("push {node} (enters at {t_entry:.4})  stack {}", stack(st, below))
            }
            StepKind::Pop { node, t_entry, stack: st, below } => {
                format!("pop {node} (enters at {t_entry:.4})  stack {}", stack(st, below))
            }
            StepKind::Skip { node, t_entry, closest_t, stack: st, below } => {
                format!(
                    "skip {node}: enters at {t_entry:.4}, beyond the closest hit {closest_t:.4}  stack {}",
                    stack(st, below)
                )
            }
            StepKind::Triangle { triangle, hit: true, t, u, v } => format!(
                "triangle {triangle}: hit t {:.4} u {:.4} v {:.4}",
                t.unwrap_or(f32::NAN),
                u.unwrap_or(f32::NAN),
                v.unwrap_or(f32::NAN)
            ),
            StepKind::Triangle { triangle, hit: false, .. } => format!("triangle {triangle}: miss"),
            StepKind::ClosestHit { triangle, t } => format!("closest hit so far: triangle {triangle} at t {t:.4}"),
            StepKind::Instance { instance, origin: o, dir: d } => format!(
                "enter placement {instance}: object-space ray from ({:.3}, {:.3}, {:.3}) along ({:.3}, {:.3}, {:.3})",
                o[0], o[1], o[2], d[0], d[1], d[2]
            ),
            StepKind::InstanceDone { instance } => format!("back from placement {instance}"),
        }
    }

    /// The stack as it stands after this step, for steps that change it: its top entries (bottom
    /// first) and how many more are under them.
    pub fn stack(&self) -> Option<(&[(NodeId, f32)], u32)> {
        match &self.kind {
            StepKind::Push { stack, below, .. }
            | StepKind::Pop { stack, below, .. }
            | StepKind::Skip { stack, below, .. } => Some((stack, *below)),
            _ => None,
        }
    }
}

/// Where a trace's steps go: kept (`Vec<TraceStep>`, the app's Ray window), or written out as the
/// walk goes (`bvhscope trace`), so a walk of millions of steps needs no memory for them.
pub trait StepOut {
    fn put(&mut self, step: TraceStep);
}

impl StepOut for Vec<TraceStep> {
    fn put(&mut self, step: TraceStep) {
        self.push(step);
    }
}

/// The statistics sink that records the steps, into `steps` (kept, by default), at most
/// `max_steps` of them: past that the walk goes on to its hit, and is only counted (no step is
/// made, no node remembered), so memory does not grow with the walk's length. Its counting
/// methods do nothing: the counts of a trace are those of its steps (`counts`), every step, kept
/// or not.
#[derive(Clone, Debug, Default)]
pub struct Trace<O: StepOut = Vec<TraceStep>> {
    pub steps: O,
    /// Steps given to `steps`, and the most it takes.
    taken: u64,
    max_steps: u64,
    /// Steps past `max_steps`: counted, not made.
    dropped: u64,
    counts: RayCounters,
    last_hit: Option<(u32, f32)>,
    two_levels: bool,
    instance: Option<(u32, u32)>,
    /// Per level, each node's depth and box interval, learnt from its box test.
    seen: HashMap<(TraceLevel, NodeId), Seen>,
    /// The walk's stack, as its reports show it, and the depth of the node entered last: boxes
    /// tested next are its children.
    stack: Vec<(NodeId, f32)>,
    entered_depth: Option<u32>,
    /// The top level's stack and depth while the walk is inside a placement.
    outer: (Vec<(NodeId, f32)>, Option<u32>),
    closest_t: f32,
}

impl Trace {
    /// A trace that keeps every step.
    pub fn new() -> Self {
        Self::into(Vec::new(), u64::MAX)
    }
}

impl<O: StepOut> Trace<O> {
    /// A trace that gives its first `max_steps` steps to `out`.
    pub fn into(out: O, max_steps: u64) -> Self {
        Trace {
            steps: out,
            taken: 0,
            max_steps,
            dropped: 0,
            counts: RayCounters::ZERO,
            last_hit: None,
            two_levels: false,
            instance: None,
            seen: HashMap::new(),
            stack: Vec::new(),
            entered_depth: None,
            outer: (Vec::new(), None),
            closest_t: f32::INFINITY,
        }
    }

    /// The level the walk is in now.
    fn level(&self) -> TraceLevel {
        match (self.two_levels, self.instance) {
            (_, Some((instance, _))) => TraceLevel::Bottom { instance },
            (true, None) => TraceLevel::Top,
            (false, None) => TraceLevel::Mesh,
        }
    }

    /// Whether `max_steps` steps were made: the rest are counted only.
    fn full(&self) -> bool {
        self.taken >= self.max_steps
    }

    fn push(&mut self, kind: StepKind) {
        self.tally(&kind);
        if self.full() {
            self.dropped += 1;
            return;
        }
        self.taken += 1;
        self.steps.put(TraceStep { level: self.level(), kind });
    }

    /// Count a step as the counting sink counts its work.
    fn tally(&mut self, kind: &StepKind) {
        let top = self.level() == TraceLevel::Top;
        let c = &mut self.counts;
        match kind {
            StepKind::BoxTest { .. } => {
                c.box_tests += 1;
                c.top_box_tests += u32::from(top);
            }
            StepKind::Enter { .. } => {
                c.nodes_visited += 1;
                c.top_nodes_visited += u32::from(top);
            }
            StepKind::Leaf { .. } if !top => c.leaves_visited += 1,
            StepKind::Triangle { .. } => c.triangle_tests += 1,
            StepKind::Instance { .. } => c.instances_entered += 1,
            _ => {}
        }
    }

    fn depth(&self, node: NodeId) -> u32 {
        self.seen.get(&(self.level(), node)).map_or(0, |s| s.0)
    }

    /// The work of the whole walk, as the counting sink counts it (the steps past `max_steps`
    /// included).
    pub fn counts(&self) -> RayCounters {
        self.counts
    }

    /// The last closest hit recorded: (triangle, t).
    pub fn last_hit(&self) -> Option<(u32, f32)> {
        self.last_hit
    }

    /// Steps of the walk past `max_steps`, counted but not made (0 when all were).
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Steps made.
    pub fn taken(&self) -> u64 {
        self.taken
    }
}

impl<O: StepOut> TraversalStats for Trace<O> {
    #[inline]
    fn node_visited(&mut self) {}
    #[inline]
    fn leaf_visited(&mut self) {}
    #[inline]
    fn box_tests(&mut self, _: u32) {}
    #[inline]
    fn triangle_tests(&mut self, _: u32) {}

    const STEPS: bool = true;

    fn step_levels(&mut self) {
        self.two_levels = true;
    }

    fn step_box(&mut self, node: NodeId, interval: Option<(f32, f32)>) {
        let (t_entry, t_exit) = (interval.map(|i| i.0), interval.map(|i| i.1));
        if self.full() {
            return self.push(StepKind::BoxTest { node, depth: 0, hit: interval.is_some(), t_entry, t_exit });
        }
        // The box tested is a child of the node entered last (at this level), or the root.
        let depth = self.entered_depth.map_or(0, |d| d + 1);
        self.seen.insert((self.level(), node), (depth, interval));
        self.push(StepKind::BoxTest { node, depth, hit: interval.is_some(), t_entry, t_exit });
    }

    fn step_enter(&mut self, node: NodeId) {
        if self.full() {
            return self.push(StepKind::Enter { node, depth: 0, t_entry: f32::NAN, t_exit: f32::NAN });
        }
        let (depth, interval) = self.seen.get(&(self.level(), node)).copied().unwrap_or((0, None));
        let (t_entry, t_exit) = interval.unwrap_or((f32::NAN, f32::NAN));
        self.entered_depth = Some(depth);
        self.push(StepKind::Enter { node, depth, t_entry, t_exit });
    }

    fn step_leaf(&mut self, node: NodeId) {
        let depth = if self.full() { 0 } else { self.depth(node) };
        self.push(StepKind::Leaf { node, depth });
    }

    fn step_stack(&mut self, len: usize, top: &[(NodeId, f32)]) {
        // Past the steps made the stack is not mirrored (its steps are not counted work).
        if self.full() {
            return;
        }
        // The entries below the reported top are as they were: compare from there up.
        let base = len - top.len();
        let same = self.stack.get(base..).unwrap_or(&[]).iter().zip(top).take_while(|(a, b)| a == b).count();
        let kept = (base + same).min(self.stack.len());
        // Entries beyond what both share were popped (from the old stack), then pushed (from
        // the new one), in that order.
        for k in (kept..self.stack.len()).rev() {
            let (node, t_entry) = self.stack[k];
            let (stack, below) = shown(&self.stack[..k]);
            self.push(StepKind::Pop { node, t_entry, stack, below });
        }
        self.stack.truncate(kept);
        // (The mirror holds at least `base` entries when every change was reported.)
        for &e in &top[kept.saturating_sub(base)..] {
            self.stack.push(e);
            let (stack, below) = shown(&self.stack);
            self.push(StepKind::Push { node: e.0, t_entry: e.1, stack, below });
        }
    }

    fn step_skip(&mut self, node: NodeId, t: f32) {
        if self.full() {
            return;
        }
        // The walk popped it: it is the mirror's top.
        if self.stack.last().is_some_and(|e| e.0 == node) {
            self.stack.pop();
        }
        let (stack, below) = shown(&self.stack);
        self.push(StepKind::Skip { node, t_entry: t, closest_t: self.closest_t, stack, below });
    }

    fn step_triangle(&mut self, prim: u32, hit: Option<TriangleHit>) {
        let triangle = prim + self.instance.map_or(0, |i| i.1);
        let (t, u, v) = (hit.map(|h| h.t), hit.map(|h| h.u), hit.map(|h| h.v));
        self.push(StepKind::Triangle { triangle, hit: hit.is_some(), t, u, v });
        if let Some(h) = hit {
            self.closest_t = h.t;
            self.last_hit = Some((triangle, h.t));
            self.push(StepKind::ClosestHit { triangle, t: h.t });
        }
    }

    fn step_instance(&mut self, instance: u32, first_prim: u32, ray: &Ray) {
        let (origin, dir) = (ray.origin().to_array(), ray.dir().to_array());
        self.push(StepKind::Instance { instance, origin, dir });
        self.instance = Some((instance, first_prim));
        // The mesh BVH's walk has its own stack, empty at its start.
        self.seen.retain(|k, _| !matches!(k.0, TraceLevel::Bottom { .. }));
        self.outer = (std::mem::take(&mut self.stack), self.entered_depth.take());
    }

    fn step_instance_done(&mut self) {
        if let Some((instance, _)) = self.instance {
            // The last step inside the placement.
            self.push(StepKind::InstanceDone { instance });
            self.instance = None;
            (self.stack, self.entered_depth) = std::mem::take(&mut self.outer);
        }
    }
}

/// Levels a listing of the steps indents by; deeper steps are indented as far and marked with
/// their depth, so a tree thousands deep lists in lines of a readable width.
pub const MAX_INDENT: u32 = 16;

/// The indent of a step at `depth` in a listing (`bvhscope trace`): two spaces a level.
pub fn indent(depth: u32) -> String {
    indent_by(depth, 2)
}

/// The indent of a step at `depth`, `width` spaces a level (the app's Ray window uses one: its
/// lines share a window's width with the numbers).
pub fn indent_by(depth: u32, width: usize) -> String {
    if depth <= MAX_INDENT {
        " ".repeat(depth as usize * width)
    } else {
        format!("{}[depth {depth}] ", " ".repeat(MAX_INDENT as usize * width))
    }
}

/// Entries of the stack a step keeps: its top ones (a trace of a tree thousands deep would
/// otherwise keep thousands per step).
pub const SHOWN_STACK: usize = 16;

/// The top `SHOWN_STACK` entries of `stack`, bottom first, and how many are under them.
fn shown(stack: &[(NodeId, f32)]) -> (Vec<(NodeId, f32)>, u32) {
    let below = stack.len().saturating_sub(SHOWN_STACK);
    (stack[below..].to_vec(), below as u32)
}

/// Trace `ray`'s closest hit through `accel` with `opts`, recording every step.
pub fn trace_ray<A: Accelerator + ?Sized>(accel: &A, ray: &Ray, opts: TraceOptions) -> (Option<Hit>, Trace) {
    trace_query_into(accel, ray, opts, false, Trace::new())
}

/// `trace_ray` for a query, with the steps given to `trace`'s output as the walk makes them: the
/// closest hit, or with `any` (shadow and ambient-occlusion rays) the first hit the walk finds,
/// where it stops.
pub fn trace_query_into<A: Accelerator + ?Sized, O: StepOut>(
    accel: &A,
    ray: &Ray,
    opts: TraceOptions,
    any: bool,
    mut trace: Trace<O>,
) -> (Option<Hit>, Trace<O>) {
    let mut r = *ray;
    let hit = match any {
        false => accel.closest_hit(&mut r, opts, &mut trace),
        true => {
            super::accel::dispatch!(opts, |T, BY_DISTANCE| accel.trace::<T, BY_DISTANCE, true, _>(&mut r, &mut trace))
        }
    };
    (hit, trace)
}
