//! bvhscope's own trees on the class's mesh and camera: what every submission is measured
//! against. Built and measured once per layout the class uses (binary from the start; a 4- or
//! 8-wide layout when a dump of that width first comes), then dropped: the figures stay, and of
//! the SAH tree its counted frame, for the students' difference images. The checker's reference
//! (the linear scan's hits) is built here too, once for the class.

use super::measure::{measure, time_linear, time_together, timed, tracer, Quality, Timing, RUNS};
use super::Setup;
use crate::bvh::{AnyBvh, BuildParams, Bvh, Layout, Strategy};
use crate::dump::{import, BvhDump};
use crate::explain::check::Reference;
use crate::mesh::Mesh;
use crate::render::Frame;
use crate::work::WorkControl;
use serde::Serialize;
use std::sync::Arc;

/// One of bvhscope's trees, measured.
#[derive(Clone, Debug, Serialize)]
pub struct ReferenceTree {
    /// The strategy's name on the command line and in rubrics (`sah`, `midpoint`).
    pub strategy: &'static str,
    /// "SAH binned, binary".
    pub name: String,
    pub quality: Quality,
}

/// The references of one layout.
struct LayoutRefs {
    layout: Layout,
    /// SAH binned first.
    trees: Vec<ReferenceTree>,
    /// The SAH tree's counted frame.
    sah_frame: Frame,
    /// The SAH tree itself: every tree of this layout is timed in the same rounds as it.
    sah_tree: AnyBvh,
    /// Its time per ray, timed once for the layout: every tree's time per ray is its ratio to
    /// the SAH tree (timed in the same rounds) times this, so a busy moment moves no figure.
    sah_ns: f64,
    /// Its speed-up over the linear scan (timed once for the class).
    sah_speedup: f64,
    /// The most nodes any reference visits for a pixel: the top of the class's heatmap scale.
    visits_max: f32,
}

/// The reference trees of every layout met so far, how trees are timed, and what the checker
/// holds every submission's rays against.
pub struct References {
    pub timing: Timing,
    /// Seconds `new` took (the linear scan timed, the checker's reference and the binary layout's
    /// trees built and timed): part of the class's grading time.
    pub seconds: f64,
    layouts: Vec<LayoutRefs>,
    /// The linear scan's hits (past 4,096 triangles through bvhscope's SAH tree, which the tests
    /// hold equal to it): built once for the class, not once per submission.
    pub truth: Reference,
}

impl References {
    /// The strategies built: SAH binned (the ratios and differences are against it), then the
    /// rubric's others in its order.
    pub fn strategies(setup: &Setup) -> Vec<Strategy> {
        let mut s = vec![Strategy::SahBinned];
        s.extend(setup.rubric.references.iter().copied().filter(|&r| r != Strategy::SahBinned));
        s
    }

    /// The linear scan timed and the binary layout's references built: what any class needs.
    pub fn new(setup: &Setup) -> References {
        let start = std::time::Instant::now();
        let rays = setup.time_rays.clamp(1, setup.camera.width as usize * setup.camera.height as usize);
        let (linear_ns_per_ray, linear_rays) = time_linear(setup.mesh, &setup.camera, setup.trace, rays);
        let timing = Timing { rays, runs: RUNS, linear_rays, linear_ns_per_ray };
        let mut r = References { timing, seconds: 0.0, layouts: Vec::new(), truth: Reference::of(setup.mesh) };
        r.ensure(Layout::Binary, setup);
        r.seconds = start.elapsed().as_secs_f64();
        r
    }

    /// Build the references of `layout` unless they are there.
    pub fn ensure(&mut self, layout: Layout, setup: &Setup) {
        if self.layouts.iter().any(|l| l.layout == layout) {
            return;
        }
        let mut built = Vec::new();
        let mut sah_frame = None;
        let mut visits_max = 1f32;
        // Nobody cancels the references: they are what the whole class is measured against.
        let control = WorkControl::new();
        for strategy in Self::strategies(setup) {
            let params = BuildParams { strategy, layout, ..setup.params };
            let tree = AnyBvh::build(setup.mesh, &params);
            let binarised = binarised(&tree, setup.mesh);
            let binary: Option<&Bvh> = match &tree {
                AnyBvh::Binary(b) => Some(b),
                AnyBvh::Wide(_) | AnyBvh::Wide8(_) => binarised.as_deref(),
            };
            let Ok((q, frame)) =
                measure(&tree, binary, setup.mesh, &setup.camera, setup.trace, setup.secondary, &control)
            else {
                unreachable!("nobody else holds this control")
            };
            visits_max = visits_max.max(frame.ray_summary().max_nodes_visited as f32);
            if strategy == Strategy::SahBinned {
                sah_frame = Some(frame);
            }
            built.push((strategy, tree, q));
        }
        // Each timed as a student's tree is (`time_against_sah`): beside the SAH tree (the SAH
        // tree beside a copy of itself), in rounds of two on the same rays. Timed all in one
        // round, three trees shared the cache, and the same tree read 194 ns per ray as a
        // reference and 127 as a student's (issue 59).
        let sah_tree = built[0].1.clone();
        let mut versus = Vec::with_capacity(built.len());
        let mut sah_ns = 0.0;
        for (k, (_, tree, _)) in built.iter().enumerate() {
            let (sah, theirs) = (tracer(&sah_tree, setup.trace), tracer(tree, setup.trace));
            let ns =
                time_together(&[&sah, &theirs], &setup.camera, self.timing.rays, &control).expect("nobody cancels it");
            if k == 0 {
                sah_ns = ns[0];
            }
            versus.push(ns[1] / ns[0].max(1e-9));
        }
        let sah_speedup = self.timing.linear_ns_per_ray / sah_ns.max(1e-9);
        let mut trees = Vec::new();
        for (k, (strategy, _, q)) in built.into_iter().enumerate() {
            let q = timed(q, versus[k] * sah_ns, versus[k], sah_speedup);
            let name = format!("{}, {}", strategy.label(), layout.name());
            trees.push(ReferenceTree { strategy: strategy.name(), name, quality: q });
        }
        let sah_frame = sah_frame.expect("SAH binned is always among the references");
        self.layouts.push(LayoutRefs { layout, trees, sah_frame, sah_tree, sah_ns, sah_speedup, visits_max });
    }

    /// The time per ray of `tree` and its ratio to bvhscope's SAH tree of `layout` (built), timed
    /// in the same rounds (`time_together`), the time being that ratio times the SAH tree's time
    /// for the layout, as the references' are; the SAH tree's speed-up over the linear scan.
    pub fn time_against_sah(
        &self,
        tree: &AnyBvh,
        layout: Layout,
        setup: &Setup,
        control: &WorkControl,
    ) -> Result<(f64, f64, f64), crate::work::Cancelled> {
        let l = self.of(layout).expect("the layout's references are built first");
        let (sah, theirs) = (tracer(&l.sah_tree, setup.trace), tracer(tree, setup.trace));
        let ns = time_together(&[&sah, &theirs], &setup.camera, self.timing.rays, control)?;
        let versus = ns[1] / ns[0].max(1e-9);
        Ok((versus * l.sah_ns, versus, l.sah_speedup))
    }

    fn of(&self, layout: Layout) -> Option<&LayoutRefs> {
        self.layouts.iter().find(|l| l.layout == layout)
    }

    /// The SAH tree of `layout`, once built.
    pub fn sah(&self, layout: Layout) -> Option<&ReferenceTree> {
        self.of(layout).map(|l| &l.trees[0])
    }

    /// The SAH tree's counted frame in `layout`.
    pub fn sah_frame(&self, layout: Layout) -> Option<&Frame> {
        self.of(layout).map(|l| &l.sah_frame)
    }

    /// The top of `layout`'s heatmap scale (nodes visited per pixel; at least 1).
    pub fn visits_max(&self, layout: Layout) -> f32 {
        self.of(layout).map_or(1.0, |l| l.visits_max)
    }

    /// Every reference tree, layout by layout in the order they were built.
    pub fn trees(&self) -> impl Iterator<Item = &ReferenceTree> {
        self.layouts.iter().flat_map(|l| l.trees.iter())
    }

    /// The heatmap scales, by layout name (for the report's captions).
    pub fn scales(&self) -> Vec<(&'static str, f32)> {
        self.layouts.iter().map(|l| (l.layout.name(), l.visits_max)).collect()
    }
}

/// A wide tree binarised as a wide student dump is (`Imported::binary`: each node of k children
/// split over its children in order), so the EPO of a wide reference and of a wide dump are
/// measured alike. `None` for a binary tree, which is its own.
fn binarised(tree: &AnyBvh, mesh: &Mesh) -> Option<Arc<Bvh>> {
    if let AnyBvh::Binary(_) = tree {
        return None;
    }
    let dump = BvhDump::of_any(tree, mesh, None);
    let (_, imported) = import(&dump, mesh, std::path::Path::new("reference")).ok()?;
    imported.binary.map(|(b, _)| b)
}
