//! Building a binary BVH: the entry points (`Bvh::build`, `build_over_boxes`), which prepare the
//! primitives and hand them to the strategy's builder: the top-down driver (`driver`) with a
//! splitter (`split`), in place or over references (`sbvh`); the LBVH (`lbvh`); PLOC (`ploc`).
//! Reinsertion (`reinsert`) may follow any of them.

pub(crate) mod common;
pub mod driver;
pub mod lbvh;
pub mod morton;
pub(crate) mod ploc;
pub mod reinsert;
pub mod sbvh;
pub mod split;
pub mod strategy;
mod subtree;

use crate::bvh::builders::split::spatial::Triangles;
use crate::bvh::builders::split::splitter::BuildPrim;
use crate::bvh::node::{Bvh, BvhNode};
use crate::bvh::params::{BuildParams, BuildReport};
use crate::geometry::Aabb;
use crate::mesh::Mesh;
use crate::parallel::region;
use crate::work::{Cancelled, WorkControl};
pub use common::{build_work, HEURISTIC_DEPTH_LIMIT};
use common::{node_info, progress_levels, Overrides, Progress};
use driver::{build_subtree, Driver, InPlace};
use rayon::prelude::*;
use std::time::Instant;
use strategy::{Builder, Setup};

impl Bvh {
    /// Build a BVH over the mesh's triangles.
    pub fn build(mesh: &Mesh, params: &BuildParams) -> Bvh {
        match Self::build_controlled(mesh, params, &WorkControl::new()) {
            Ok(bvh) => bvh,
            Err(Cancelled) => unreachable!("nobody else holds this control"),
        }
    }

    /// Build with a control: its total is set to the build's work (`build_work`), its progress
    /// advances at every split and leaf, and a cancel request stops the build within a few
    /// hundred nodes.
    pub fn build_controlled(mesh: &Mesh, params: &BuildParams, control: &WorkControl) -> Result<Bvh, Cancelled> {
        control.set_total(build_work(mesh.triangle_count(), params));
        Self::build_counted(mesh, params, control)
    }

    /// Build, advancing `control`'s progress by `build_work` without setting its total: for
    /// callers that build several BVHs under one control (the two-level BVH).
    pub(crate) fn build_counted(mesh: &Mesh, params: &BuildParams, control: &WorkControl) -> Result<Bvh, Cancelled> {
        let t0 = Instant::now();
        let params = params.clamped();
        let n = mesh.triangle_count();
        if params.strategy.follows_morton_order() {
            let progress = Progress { control, levels: progress_levels(n, &params) };
            return lbvh::build_mesh(mesh, &params, &progress)?.finish(control);
        }
        let make = |i: usize| {
            let tri = mesh.triangle(i as u32);
            let bounds = Aabb::from_points(&tri);
            BuildPrim::new(bounds, i as u32)
        };
        let mut prims: Vec<BuildPrim> = if n >= 1 << 16 {
            region(|| (0..n).into_par_iter().map(make).collect())
        } else {
            (0..n).map(make).collect()
        };
        let setup_time = t0.elapsed();
        control.check()?;

        let tri = |i: u32| mesh.triangle(i);
        let (nodes, mut report) = build_nodes(&mut prims, Some(&tri), &params, control)?;
        report.setup_time = setup_time;

        let t2 = Instant::now();
        let (prim_ids, tris) = region(|| {
            let prim_ids: Vec<u32> = prims.par_iter().with_min_len(4096).map(|p| p.index()).collect();
            let tris = prim_ids.par_iter().with_min_len(4096).map(|&i| mesh.triangle(i)).collect();
            (prim_ids, tris)
        });
        report.reorder_time = t2.elapsed();
        Bvh { nodes, prim_ids, tris, params, report }.finish(control)
    }

    /// The step after any builder (here, or the GPU's): the reinsertion its parameters ask for.
    /// Laying it out follows (`AnyBvh::finish`).
    pub fn finish(mut self, control: &WorkControl) -> Result<Bvh, Cancelled> {
        let passes = self.params.reinsert_passes;
        if passes > 0 {
            control.check()?;
            self.report.reinsertion = Some(reinsert::optimise(&mut self, passes));
        }
        Ok(self)
    }
}

/// A binary BVH over arbitrary boxes (the top level of a two-level BVH, whose "primitives" are
/// instances): the nodes, and for each leaf slot the index of its box in `boxes`. Leaf `index`
/// fields point into that order, as they point into `Bvh::prim_ids` for triangles. Progress
/// advances by `build_work(boxes.len(), params)`; the total is the caller's to set.
pub fn build_over_boxes(
    boxes: &[Aabb],
    params: &BuildParams,
    control: &WorkControl,
) -> Result<(Vec<BvhNode>, Vec<u32>, BuildReport), Cancelled> {
    let t0 = Instant::now();
    let params = params.clamped();
    let mut prims: Vec<BuildPrim> = boxes.iter().enumerate().map(|(i, b)| BuildPrim::new(*b, i as u32)).collect();
    let setup_time = t0.elapsed();
    // No triangles to clip: an SBVH top level makes object splits only.
    let (nodes, mut report) = build_nodes(&mut prims, None, &params, control)?;
    report.setup_time = setup_time;
    Ok((nodes, prims.iter().map(|p| p.index()).collect(), report))
}

/// The splitting over prepared primitives, which it leaves in leaf order (the SBVH's references
/// replace them: more than one per triangle where spatial splits cut triangles of `tri`).
fn build_nodes(
    prims: &mut Vec<BuildPrim>,
    tri: Option<Triangles>,
    params: &BuildParams,
    control: &WorkControl,
) -> Result<(Vec<BvhNode>, BuildReport), Cancelled> {
    let t1 = Instant::now();
    let progress = Progress { control, levels: progress_levels(prims.len(), params) };
    let (nodes, over) = match params.strategy.builder() {
        Builder::TopDown { make, references } => {
            let root = if references { node_info(prims).bounds } else { Aabb::EMPTY };
            let setup = Setup { params, tri, root };
            let splitter = || make(&setup);
            if references {
                let (nodes, refs, over) = sbvh::build(std::mem::take(prims), params, &progress, &splitter)?;
                *prims = refs;
                (nodes, over)
            } else {
                let d = Driver { params, progress: &progress, splitter: &splitter };
                let (tree, _, over) = build_subtree(InPlace::root(prims), &d)?;
                (tree.into_nodes(), over)
            }
        }
        Builder::Morton => {
            let (tree, fallback) = lbvh::build(prims, params, &progress)?;
            (tree.into_nodes(), Overrides { fallback, ..Overrides::default() })
        }
        Builder::Clustering => {
            let (tree, _) = ploc::build(prims, params, params.ploc_radius as usize, &progress)?;
            (tree.into_nodes(), Overrides::default())
        }
    };
    let report = BuildReport {
        split_time: t1.elapsed(),
        fallback_splits: over.fallback,
        depth_limited_splits: over.depth_limited,
        spatial_splits: over.cut,
        ..Default::default()
    };
    Ok((nodes, report))
}

#[cfg(test)]
mod builders_tests;
