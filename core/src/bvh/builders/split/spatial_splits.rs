//! The SBVH's splitter: the binned object split or a spatial split (`spatial`), whichever is
//! cheaper, under the overlap test and the duplicate budget of Stich, Friedrich & Dietrich,
//! "Spatial Splits in Bounding Volume Hierarchies" (HPG 2009), §4.4. A spatial split is proposed
//! as a `Proposal::Cut`, whose references the driver takes (`Splitter::take_cut`).

use crate::bvh::builders::split::sah_binned::binned_planes;
use crate::bvh::builders::split::spatial::{area_of, bounds_of, spatial_partition, spatial_planes, Triangles};
use crate::bvh::builders::split::splitter::{BuildPrim, NodeInfo, PlaneSink, Proposal, Splitter};
use crate::bvh::params::BuildParams;
use crate::geometry::Aabb;

/// The SBVH's splitter (§4.4): the binned object split, and where its children's boxes overlap by
/// more than α of the root's area (or where there is none) a spatial split, priced by the bins
/// and then partitioned; the cheaper wins. A spatial split is proposed only when its duplicates
/// fit the node's budget (`NodeInfo::budget`); it is a `Proposal::Cut`, whose references the
/// driver takes (`Splitter::take_cut`). With no triangles to clip (the top level of two levels)
/// it makes object splits only.
pub struct SpatialSplits<'a> {
    /// `None`: no spatial splits (nothing to clip).
    tri: Option<Triangles<'a>>,
    bins: usize,
    /// α times the root's area: the overlap above which spatial splits are priced.
    min_overlap: f32,
    /// The references of the cut last proposed.
    cut: Option<(Vec<BuildPrim>, Vec<BuildPrim>)>,
    /// What the last proposal weighed (the node inspector's explanation).
    pub figures: Figures,
}

/// What `SpatialSplits` weighed at a node, besides the split it proposed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Figures {
    /// The area the object split's children's boxes share (the α test's λ).
    pub overlap: f32,
    /// Whether a spatial split was priced (the overlap test passed and budget was left).
    pub spatial_priced: bool,
    /// The duplicates a cheaper spatial split would have added, when that was over the budget.
    pub over_budget: Option<u64>,
}

impl<'a> SpatialSplits<'a> {
    /// For a tree whose root box is `root` (α is relative to its area).
    pub fn new(tri: Option<Triangles<'a>>, params: &BuildParams, root: &Aabb) -> Self {
        let area = if root.is_empty() { 0.0 } else { root.area() };
        let min_overlap = params.sbvh_alpha * area;
        SpatialSplits { tri, bins: params.sah_bins as usize, min_overlap, cut: None, figures: Figures::default() }
    }

    /// The proposal for `refs` (partitioned at the object split's plane), with the object
    /// split's planes reported to `objects` and the spatial split's to `spatials`.
    pub fn propose(
        &mut self,
        refs: &mut [BuildPrim],
        info: &NodeInfo,
        objects: &mut impl PlaneSink,
        spatials: &mut impl PlaneSink,
    ) -> Proposal {
        let n = refs.len();
        self.figures = Figures::default();
        self.cut = None;
        let object = match binned_planes(refs, info, self.bins, objects) {
            Proposal::Split { axis, mid, weighted: Some(w), plane } if mid > 0 && mid < n => {
                Some((axis, mid, w, plane))
            }
            _ => None,
        };
        if let Some((_, mid, _, _)) = object {
            self.figures.overlap = bounds_of(&refs[..mid]).intersection(bounds_of(&refs[mid..])).area();
        }
        let priced = info.budget > 0 && (object.is_none() || self.figures.overlap > self.min_overlap);
        if let Some(tri) = self.tri.filter(|_| priced) {
            self.figures.spatial_priced = true;
            let found = spatial_planes(refs, tri, &info.bounds, self.bins, spatials);
            if let Some(s) = found.filter(|s| object.is_none_or(|(_, _, w, _)| s.weighted < w)) {
                let (l, r) = spatial_partition(refs, tri, s.axis as usize, s.position);
                let added = (l.len() + r.len() - n) as u64;
                // A cut of references that all straddle the plane leaves both children as many as
                // the parent, but every such split spends budget, so the splitting ends.
                if added > info.budget {
                    self.figures.over_budget = Some(added);
                } else if !l.is_empty() && !r.is_empty() {
                    // The children as partitioned (unsplitting changes the bins' estimate) must
                    // still beat the object split.
                    let weighted = area_of(&l) * l.len() as f32 + area_of(&r) * r.len() as f32;
                    if object.is_none_or(|(_, _, w, _)| weighted < w) {
                        self.cut = Some((l, r));
                        return Proposal::Cut { axis: s.axis, plane: s.position, weighted };
                    }
                }
            }
        }
        match object {
            Some((axis, mid, w, plane)) => Proposal::Split { axis, mid, weighted: Some(w), plane },
            None => Proposal::None,
        }
    }
}

impl Splitter for SpatialSplits<'_> {
    fn prices_splits(&self) -> bool {
        true
    }

    fn split(&mut self, prims: &mut [BuildPrim], node: &NodeInfo) -> Proposal {
        self.propose(prims, node, &mut (), &mut ())
    }

    fn take_cut(&mut self) -> (Vec<BuildPrim>, Vec<BuildPrim>) {
        self.cut.take().expect("a cut was proposed")
    }
}
