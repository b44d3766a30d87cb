//! How many rays visited each node: a statistics sink for the traversal that renders, which
//! counts the nodes the walk enters (its step reports, as the trace has them). Other sinks compile
//! the step reports away, so it costs nothing when not asked for. The tree view's "visits" column
//! and the icicle's visits colouring come from here.

use crate::bvh::{Accelerator, Bvh, NodeId, TraceOptions, TraversalStats};
use crate::render::Camera;
use crate::work::{Cancelled, WorkControl};
use rayon::prelude::*;

/// Per node of the binary tree, the rays that entered it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeVisits {
    pub counts: Vec<u32>,
}

impl NodeVisits {
    pub fn new(nodes: usize) -> Self {
        Self { counts: vec![0; nodes] }
    }
}

impl TraversalStats for NodeVisits {
    fn node_visited(&mut self) {}
    fn leaf_visited(&mut self) {}
    fn box_tests(&mut self, _: u32) {}
    fn triangle_tests(&mut self, _: u32) {}
    const STEPS: bool = true;
    #[inline]
    fn step_enter(&mut self, node: NodeId) {
        if let NodeId::Node(n) = node {
            if let Some(c) = self.counts.get_mut(n as usize) {
                *c += 1;
            }
        }
    }
}

/// The visits of every primary ray of `camera`'s frame (one per pixel, closest hit), traced
/// through `bvh` with `opts`, row by row in parallel; `Cancelled` once `control` is.
pub fn frame_visits(
    bvh: &Bvh,
    camera: &Camera,
    opts: TraceOptions,
    control: &WorkControl,
) -> Result<NodeVisits, Cancelled> {
    let rays = camera.ray_gen();
    let n = bvh.nodes.len();
    let rows: Vec<Option<NodeVisits>> = (0..camera.height)
        .into_par_iter()
        .fold(
            || Some(NodeVisits::new(n)),
            |acc, y| {
                let mut acc = acc?;
                if control.is_cancelled() {
                    return None;
                }
                for x in 0..camera.width {
                    let mut ray = rays.pixel_ray(x, y);
                    bvh.closest_hit(&mut ray, opts, &mut acc);
                }
                Some(acc)
            },
        )
        .collect();
    let mut total = NodeVisits::new(n);
    for part in rows {
        let part = part.ok_or(Cancelled)?;
        for (t, c) in total.counts.iter_mut().zip(part.counts) {
            *t += c;
        }
    }
    control.check()?;
    Ok(total)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{trace_ray, BuildParams, Layout, RayCounters, StepKind};
    use crate::mesh::generate;

    /// The visits of a frame add up to its rays' nodes-visited counts, and each node's count is
    /// the number of traced rays whose walk entered it.
    #[test]
    fn visits_agree_with_the_counters_and_the_traces() {
        let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
        let bvh = Bvh::build(&mesh, &BuildParams { layout: Layout::Binary, ..BuildParams::default() });
        let camera = Camera::framing_up(&bvh.root_bounds(), 24, 16, crate::render::UpAxis::Y, 45.0);
        let opts = TraceOptions::default();
        let visits = frame_visits(&bvh, &camera, opts, &WorkControl::new()).unwrap();
        let (mut counted, mut traced) = (0u64, vec![0u32; bvh.nodes.len()]);
        for y in 0..camera.height {
            for x in 0..camera.width {
                let ray = camera.ray_gen().pixel_ray(x, y);
                let mut c = RayCounters::default();
                bvh.closest_hit(&mut ray.clone(), opts, &mut c);
                counted += c.nodes_visited as u64;
                let (_, trace) = trace_ray(&bvh, &ray, opts);
                for s in &trace.steps {
                    if let StepKind::Enter { node: NodeId::Node(n), .. } = s.kind {
                        traced[n as usize] += 1;
                    }
                }
            }
        }
        assert_eq!(visits.counts.iter().map(|&c| c as u64).sum::<u64>(), counted);
        assert_eq!(visits.counts, traced);
        assert!(visits.counts[0] > 0 && visits.counts.contains(&0));
    }
}
