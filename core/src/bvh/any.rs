//! A built BVH in any layout behind one type: what the app, the CLI and the tests hold.

use super::tree::{TreeNode, TreeView};
use crate::bvh::accel::{Accelerator, Hit, TraceOptions};
use crate::bvh::counters::TraversalStats;
use crate::bvh::node::Bvh;
use crate::bvh::params::{BuildParams, BuildReport, Layout};
use crate::bvh::wide::wide_bvh::WideBvh;
use crate::geometry::TriangleIntersector;
use crate::mesh::Mesh;
use crate::work::{Cancelled, WorkControl};

#[derive(Clone, Debug)]
pub enum AnyBvh {
    Binary(Bvh),
    Wide(WideBvh),
    Wide8(WideBvh<8>),
}

impl AnyBvh {
    /// The binary tree as built: this one, or for the wide layout the binary tree it was collapsed
    /// from, built again (the build is deterministic: the same nodes in the same places). The node
    /// inspector's ids and the EPO are those of this tree.
    pub fn binary_tree<'a>(&'a self, mesh: &Mesh) -> std::borrow::Cow<'a, Bvh> {
        match self {
            AnyBvh::Binary(b) => std::borrow::Cow::Borrowed(b),
            AnyBvh::Wide(_) | AnyBvh::Wide8(_) => std::borrow::Cow::Owned(Bvh::build(
                mesh,
                &BuildParams { layout: Layout::Binary, ..*self.tree().params() },
            )),
        }
    }

    /// Make now what a walk with `opts` keeps with the tree (a wide tree's stored leaves for
    /// `MollerTrumboreStored`, made otherwise by its first walk), so that no walk waits for it.
    pub fn ready_for(&self, opts: crate::bvh::TraceOptions) {
        match self {
            AnyBvh::Wide8(w) => w.ready_for(opts),
            AnyBvh::Wide(w) => w.ready_for(opts),
            AnyBvh::Binary(_) => {}
        }
    }

    /// The tree's memory (`TreeView::memory_bytes`, which never depends on what was walked) plus
    /// what a walk with `opts` keeps beside it (`walk_bytes`).
    pub fn bytes_for(&self, opts: crate::bvh::TraceOptions) -> usize {
        self.tree().memory_bytes() + self.walk_bytes(opts)
    }

    /// What a walk with `opts` keeps beside the tree, whether it was made yet or not: a wide
    /// tree's stored leaves for `MollerTrumboreStored` where a SIMD walk reads them
    /// (`STORED_FLOATS` floats a triangle), else nothing.
    pub fn walk_bytes(&self, opts: crate::bvh::TraceOptions) -> usize {
        match self {
            AnyBvh::Wide8(w) => w.walk_bytes(opts),
            AnyBvh::Wide(w) => w.walk_bytes(opts),
            AnyBvh::Binary(_) => 0,
        }
    }

    /// Build the binary BVH with `params.strategy`, then lay it out as `params.layout` says.
    pub fn build(mesh: &Mesh, params: &BuildParams) -> AnyBvh {
        match Self::build_controlled(mesh, params, &WorkControl::new()) {
            Ok(b) => b,
            Err(Cancelled) => unreachable!("nobody else holds this control"),
        }
    }

    /// Build with a control whose total is set to this build's work (see `Bvh::build_controlled`).
    pub fn build_controlled(mesh: &Mesh, params: &BuildParams, control: &WorkControl) -> Result<AnyBvh, Cancelled> {
        control.set_total(super::builders::build_work(mesh.triangle_count(), params));
        Self::build_counted(mesh, params, control)
    }

    /// Build, advancing `control` without setting its total (`Bvh::build_counted`, which ends
    /// with `Bvh::finish`).
    pub(crate) fn build_counted(mesh: &Mesh, params: &BuildParams, control: &WorkControl) -> Result<AnyBvh, Cancelled> {
        Ok(Self::laid_out(Bvh::build_counted(mesh, params, control)?))
    }

    /// The steps after a builder that made `bvh` elsewhere (the GPU's): the reinsertion and the
    /// layout its parameters ask for, as after a build here.
    pub fn finish(bvh: Bvh) -> AnyBvh {
        match bvh.finish(&WorkControl::new()) {
            Ok(b) => Self::laid_out(b),
            Err(Cancelled) => unreachable!("nobody else holds this control"),
        }
    }

    /// A finished binary tree laid out as its parameters say: as it is, or collapsed 4 or 8 wide.
    fn laid_out(bvh: Bvh) -> AnyBvh {
        match bvh.params.layout {
            Layout::Binary => AnyBvh::Binary(bvh),
            Layout::Wide4 => AnyBvh::Wide(WideBvh::from_binary(bvh)),
            Layout::Wide8 => AnyBvh::Wide8(WideBvh::collapse(bvh)),
        }
    }

    fn tree(&self) -> &dyn TreeView {
        match self {
            AnyBvh::Binary(b) => b,
            AnyBvh::Wide(w) => w,
            AnyBvh::Wide8(w) => w,
        }
    }
}

impl Accelerator for AnyBvh {
    #[inline]
    fn trace<T: TriangleIntersector, const BY_DISTANCE: bool, const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut crate::geometry::Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        match self {
            AnyBvh::Binary(b) => b.trace::<T, BY_DISTANCE, ANY, S>(ray, stats),
            AnyBvh::Wide(w) => w.trace::<T, BY_DISTANCE, ANY, S>(ray, stats),
            AnyBvh::Wide8(w) => w.trace::<T, BY_DISTANCE, ANY, S>(ray, stats),
        }
    }

    fn traces_packets(&self) -> bool {
        true
    }

    #[inline]
    fn closest_hits(&self, rays: &mut [crate::geometry::Ray], hits: &mut [Option<Hit>], opts: TraceOptions) {
        match self {
            AnyBvh::Binary(b) => b.closest_hits(rays, hits, opts),
            AnyBvh::Wide(w) => w.closest_hits(rays, hits, opts),
            AnyBvh::Wide8(w) => w.closest_hits(rays, hits, opts),
        }
    }

    #[inline]
    fn any_hits(&self, rays: &[crate::geometry::Ray], occluded: &mut [bool], opts: TraceOptions) {
        match self {
            AnyBvh::Binary(b) => b.any_hits(rays, occluded, opts),
            AnyBvh::Wide(w) => w.any_hits(rays, occluded, opts),
            AnyBvh::Wide8(w) => w.any_hits(rays, occluded, opts),
        }
    }
}

impl TreeView for AnyBvh {
    fn visit_nodes(&self, f: &mut dyn FnMut(&TreeNode) -> bool) {
        self.tree().visit_nodes(f)
    }
    fn triangle_count(&self) -> usize {
        self.tree().triangle_count()
    }

    fn distinct_triangles(&self) -> usize {
        self.tree().distinct_triangles()
    }
    fn memory_bytes(&self) -> usize {
        self.tree().memory_bytes()
    }
    fn simd(&self) -> Option<crate::cpu::Simd> {
        self.tree().simd()
    }
    fn params(&self) -> &BuildParams {
        self.tree().params()
    }
    fn report(&self) -> &BuildReport {
        self.tree().report()
    }
}

#[cfg(test)]
#[path = "any_tests.rs"]
mod tests;
