//! Spatial splits: a plane that cuts triangles instead of sorting them to one side. Stich,
//! Friedrich & Dietrich, "Spatial Splits in Bounding Volume Hierarchies" (HPG 2009), §4.2–4.5.
//!
//! A node's references (a triangle and the box of the part of it this node holds) are binned by
//! position, not by centroid: each reference enters the bin of its box's lower corner and exits
//! the bin of its upper corner, and its box is chopped at every bin boundary in between, each
//! chop clipping the triangle itself (`split_reference`), so a bin's box holds only the parts of
//! triangles inside it. A plane between bins then costs A_L·n_L + A_R·n_R with n_L the entries
//! left of it and n_R the exits right of it: a reference that straddles the plane counts on both
//! sides, as it will be referenced by both children.
//!
//! The partition (§4.5, "reference unsplitting") then asks of each straddling reference whether
//! putting it wholly on one side is cheaper than splitting it: the SAH of the children with the
//! reference duplicated, against the side's box grown by the whole reference and the other
//! side's count one lower. A reference kept whole is not duplicated.
//!
//! The bins report every plane to a `PlaneSink`, so the node inspector's spatial cost curve is
//! what the build (the driver with `spatial_splits::SpatialSplits`) priced. Big nodes are binned and partitioned in parallel chunks
//! whose bins and lists are merged in order (counts add, boxes unite exactly), so the split does
//! not depend on the thread count.

use crate::bvh::builders::split::splitter::{is_active, BuildPrim, PlaneSink};
use crate::geometry::Aabb;
use crate::parallel::{concat, region};
use glam::{Vec3, Vec3A};
use rayon::prelude::*;

/// Nodes with at least this many references are binned and partitioned in parallel chunks of
/// `CHUNK` (fixed: the merged result must not depend on the thread count).
const PARALLEL_MIN: usize = 1 << 14;
const CHUNK: usize = 1 << 12;

/// The triangle of a reference's index.
pub type Triangles<'a> = &'a (dyn Fn(u32) -> [Vec3; 3] + Sync);

/// The parts of a reference (triangle `tri`, its box so far `b`) on each side of the plane at
/// `pos` on `axis`: the boxes of the triangle clipped to each half-space, each cut to `b`. A part
/// may be empty (`Aabb::is_empty`).
///
/// The clipped triangle's corners are its vertices on that side and the points where its edges
/// cross the plane. Those crossings are rounded, so each is widened by a few units in the last
/// place on the two other axes: a box may be a little larger than the exact part, never smaller,
/// which keeps every point of the triangle inside some leaf that references it (a ray aimed at it
/// must reach one). On `axis` itself the plane's position is exact.
pub fn split_reference(tri: &[Vec3; 3], b: &Aabb, axis: usize, pos: f32) -> (Aabb, Aabb) {
    let (mut left, mut right) = (Aabb::EMPTY, Aabb::EMPTY);
    for k in 0..3 {
        let (v, w) = (Vec3A::from(tri[k]), Vec3A::from(tri[(k + 1) % 3]));
        let (a, c) = (v[axis], w[axis]);
        if a <= pos {
            left = left.grow(v);
        }
        if a >= pos {
            right = right.grow(v);
        }
        if (a < pos && c > pos) || (a > pos && c < pos) {
            let t = (pos - a) / (c - a);
            let mut p = v + (w - v) * t;
            p[axis] = pos;
            let slack = v.abs().max(w.abs()) * (4.0 * f32::EPSILON);
            let mut s = slack;
            s[axis] = 0.0;
            let part = Aabb { min: p - s, max: p + s };
            left = left.union(part);
            right = right.union(part);
        }
    }
    let mut lb = *b;
    lb.max[axis] = lb.max[axis].min(pos);
    let mut rb = *b;
    rb.min[axis] = rb.min[axis].max(pos);
    // `intersection` gives `EMPTY` for a part that is not there, so the bins can union it.
    (left.intersection(lb), right.intersection(rb))
}

/// The spatial split a node's bins price cheapest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpatialSplit {
    pub axis: u8,
    pub position: f32,
    /// A_L·n_L + A_R·n_R by the bins (straddling references counted on both sides).
    pub weighted: f32,
    pub left: u32,
    pub right: u32,
}

/// A spatial bin (named apart from the object split's `sah_binned::Bin`): the box of the parts of
/// references inside it, and how many references start (enter) and end (exit) in it.
#[derive(Clone, Copy, Debug)]
struct Slice {
    bounds: Aabb,
    enter: u32,
    exit: u32,
}

impl Slice {
    const EMPTY: Slice = Slice { bounds: Aabb::EMPTY, enter: 0, exit: 0 };
}

/// Bin `refs` into `slices` on `axis` (bins from `lo`, `width` wide): each enters the bin of its
/// box's lower corner, exits that of its upper corner, and its box is chopped at every boundary in
/// between, each chop clipping the triangle itself.
fn bin_axis(slices: &mut [Slice], refs: &[BuildPrim], tri: Triangles, axis: usize, lo: f32, width: f32) {
    let bins = slices.len();
    let bin_of = |x: f32| (((x - lo) / width) as usize).min(bins - 1);
    for r in refs {
        let b = r.bounds();
        let (first, last) = (bin_of(b.min[axis]), bin_of(b.max[axis]));
        slices[first].enter += 1;
        slices[last].exit += 1;
        let mut rest = b;
        if first < last {
            let t = tri(r.index());
            for (k, slice) in slices.iter_mut().enumerate().take(last).skip(first) {
                let (l, right) = split_reference(&t, &rest, axis, plane(lo, width, k + 1));
                slice.bounds = slice.bounds.union(l);
                rest = right;
            }
        }
        slices[last].bounds = slices[last].bounds.union(rest);
    }
}

/// The plane between bins `k - 1` and `k` of a node whose bins start at `lo` and are `width` wide:
/// the one formula for the chops of the binning, the planes priced and the partition.
#[inline]
fn plane(lo: f32, width: f32, k: usize) -> f32 {
    lo + k as f32 * width
}

/// Bin `bins` equal slices of `bounds` on each axis with the references `refs` (triangles from
/// `tri`), report every plane between bins with references on both sides to `sink`, and return
/// the cheapest (`None` when no axis has extent or no plane has both sides).
pub fn spatial_planes(
    refs: &[BuildPrim],
    tri: Triangles,
    bounds: &Aabb,
    bins: usize,
    sink: &mut impl PlaneSink,
) -> Option<SpatialSplit> {
    let n = refs.len() as u32;
    let mut best: Option<SpatialSplit> = None;
    let mut slices = vec![Slice::EMPTY; bins];
    for axis in 0..3 {
        let (lo, hi) = (bounds.min[axis], bounds.max[axis]);
        let width = (hi - lo) / bins as f32;
        if !(width > 0.0) || !width.is_finite() {
            continue;
        }
        slices.fill(Slice::EMPTY);
        if refs.len() >= PARALLEL_MIN {
            let merged = region(|| {
                refs.par_chunks(CHUNK)
                    .map(|c| {
                        let mut local = vec![Slice::EMPTY; bins];
                        bin_axis(&mut local, c, tri, axis, lo, width);
                        local
                    })
                    .reduce_with(|mut a, b| {
                        for (x, y) in a.iter_mut().zip(&b) {
                            (x.bounds, x.enter, x.exit) =
                                (x.bounds.union(y.bounds), x.enter + y.enter, x.exit + y.exit);
                        }
                        a
                    })
            });
            slices.copy_from_slice(&merged.expect("a big node has references"));
        } else {
            bin_axis(&mut slices, refs, tri, axis, lo, width);
        }
        // Right to left: the box and the exits of bins k.. for every plane k.
        let mut right_area = vec![0f32; bins];
        let mut right_count = vec![0u32; bins];
        let (mut acc, mut exits) = (Aabb::EMPTY, 0u32);
        for k in (1..bins).rev() {
            acc = acc.union(slices[k].bounds);
            exits += slices[k].exit;
            right_area[k] = acc.area();
            right_count[k] = exits;
        }
        let (mut acc, mut enters) = (Aabb::EMPTY, 0u32);
        for k in 1..bins {
            acc = acc.union(slices[k - 1].bounds);
            enters += slices[k - 1].enter;
            let (left, right) = (enters, right_count[k]);
            if left == 0 || right == 0 {
                continue;
            }
            let areas = [acc.area(), right_area[k]];
            let weighted = areas[0] * left as f32 + areas[1] * right as f32;
            let position = plane(lo, width, k);
            if is_active(sink) {
                sink.plane(axis, position, left, right, weighted, areas);
            }
            if best.is_none_or(|b| weighted < b.weighted) {
                best = Some(SpatialSplit { axis: axis as u8, position, weighted, left, right });
            }
        }
        debug_assert!(enters + slices[bins - 1].enter == n);
    }
    best
}

/// Partition `refs` at the spatial plane `split` (§4.5): references wholly on one side go there;
/// a straddling one is split in two (its parts clipped by `split_reference`) or, when that is
/// cheaper by the SAH, kept whole on one side ("unsplitting"). Returns the two children's
/// references; a reference whose part on one side is empty (its box only touches the plane) goes
/// whole to the other.
pub fn spatial_partition(
    refs: &[BuildPrim],
    tri: Triangles,
    axis: usize,
    pos: f32,
) -> (Vec<BuildPrim>, Vec<BuildPrim>) {
    let sorted = if refs.len() >= PARALLEL_MIN {
        let parts: Vec<Sorted> = region(|| refs.par_chunks(CHUNK).map(|c| Sorted::of(c, tri, axis, pos)).collect());
        Sorted::merge(parts)
    } else {
        Sorted::of(refs, tri, axis, pos)
    };
    // The straddlers one by one, in order: each decision moves the boxes and counts the next sees.
    sorted.unsplit()
}

/// References sorted to the sides of a plane: those wholly on each side, the straddlers with their
/// two parts, and the children's boxes with every straddler split.
struct Sorted {
    left: Vec<BuildPrim>,
    right: Vec<BuildPrim>,
    straddling: Vec<(BuildPrim, Aabb, Aabb)>,
    lbox: Aabb,
    rbox: Aabb,
}

impl Sorted {
    fn of(refs: &[BuildPrim], tri: Triangles, axis: usize, pos: f32) -> Sorted {
        let mut s = Sorted {
            left: Vec::new(),
            right: Vec::new(),
            straddling: Vec::new(),
            lbox: Aabb::EMPTY,
            rbox: Aabb::EMPTY,
        };
        for r in refs {
            let b = r.bounds();
            if b.max[axis] <= pos {
                s.lbox = s.lbox.union(b);
                s.left.push(*r);
            } else if b.min[axis] >= pos {
                s.rbox = s.rbox.union(b);
                s.right.push(*r);
            } else {
                let (l, rr) = split_reference(&tri(r.index()), &b, axis, pos);
                match (l.is_empty(), rr.is_empty()) {
                    (false, false) => {
                        s.lbox = s.lbox.union(l);
                        s.rbox = s.rbox.union(rr);
                        s.straddling.push((*r, l, rr));
                    }
                    (true, _) => {
                        s.rbox = s.rbox.union(b);
                        s.right.push(*r);
                    }
                    (false, true) => {
                        s.lbox = s.lbox.union(b);
                        s.left.push(*r);
                    }
                }
            }
        }
        s
    }

    /// The chunks' lists one after the other, in order: what one pass over all of them makes.
    fn merge(parts: Vec<Sorted>) -> Sorted {
        let (mut lefts, mut rights, mut straddling) = (Vec::new(), Vec::new(), Vec::new());
        let (mut lbox, mut rbox) = (Aabb::EMPTY, Aabb::EMPTY);
        for p in parts {
            (lbox, rbox) = (lbox.union(p.lbox), rbox.union(p.rbox));
            lefts.push(p.left);
            rights.push(p.right);
            straddling.extend(p.straddling);
        }
        // Room for the straddlers `unsplit` adds to each side, without copying the lists again.
        let (left, right) = (concat(lefts, straddling.len()), concat(rights, straddling.len()));
        Sorted { left, right, straddling, lbox, rbox }
    }

    /// §4.5: each straddler is split in two, or kept whole on the side where that is cheaper.
    fn unsplit(self) -> (Vec<BuildPrim>, Vec<BuildPrim>) {
        let Sorted { mut left, mut right, straddling, mut lbox, mut rbox } = self;
        let (mut nl, mut nr) = ((left.len() + straddling.len()) as f32, (right.len() + straddling.len()) as f32);
        for (r, l, rr) in straddling {
            let whole = r.bounds();
            let split = lbox.area() * nl + rbox.area() * nr;
            let to_left = lbox.union(whole).area() * nl + rbox.area() * (nr - 1.0);
            let to_right = lbox.area() * (nl - 1.0) + rbox.union(whole).area() * nr;
            if to_left < split && to_left <= to_right {
                lbox = lbox.union(whole);
                nr -= 1.0;
                left.push(r);
            } else if to_right < split {
                rbox = rbox.union(whole);
                nl -= 1.0;
                right.push(r);
            } else {
                left.push(BuildPrim::new(l, r.index()));
                right.push(BuildPrim::new(rr, r.index()));
            }
        }
        (left, right)
    }
}

/// The box of some references (in parallel chunks for many: exact unions, any order).
pub(crate) fn bounds_of(refs: &[BuildPrim]) -> Aabb {
    let of = |r: &[BuildPrim]| Aabb::of(r.iter().map(BuildPrim::bounds));
    if refs.len() >= PARALLEL_MIN {
        region(|| refs.par_chunks(CHUNK).map(of).reduce(|| Aabb::EMPTY, |a, b| a.union(b)))
    } else {
        of(refs)
    }
}

pub(crate) fn area_of(refs: &[BuildPrim]) -> f32 {
    bounds_of(refs).area()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inside(b: &Aabb, p: Vec3) -> bool {
        (0..3).all(|a| b.min[a] <= p[a] && p[a] <= b.max[a])
    }

    /// Every point of the triangle on one side of the plane lies in that side's part: sampled on
    /// a barycentric grid, at the vertices and where the edges cross the plane.
    #[test]
    fn the_parts_of_a_split_reference_hold_the_triangle() {
        let mut rng = crate::random::Rng::new(7);
        for _ in 0..2000 {
            let mut corner = || Vec3::new(rng.range(-100.0, 100.0), rng.range(-100.0, 100.0), rng.range(-100.0, 100.0));
            let tri = [corner(), corner(), corner()];
            let b = Aabb::from_points(&tri);
            let axis = rng.below(3) as usize;
            let pos = b.min[axis] + (b.max[axis] - b.min[axis]) * rng.unit();
            let (l, r) = split_reference(&tri, &b, axis, pos);
            assert!(l.is_empty() || (b.contains_box(&l) && l.max[axis] <= pos));
            assert!(r.is_empty() || (b.contains_box(&r) && r.min[axis] >= pos));
            for i in 0..=16 {
                for j in 0..=16 - i {
                    let (u, v) = (i as f32 / 16.0, j as f32 / 16.0);
                    let p = tri[0] * (1.0 - u - v) + tri[1] * u + tri[2] * v;
                    if p[axis] <= pos {
                        assert!(inside(&l, p) || p[axis] >= pos, "{p:?} left of {pos} on {axis}, outside {l:?}");
                    }
                    if p[axis] >= pos {
                        assert!(inside(&r, p) || p[axis] <= pos, "{p:?} right of {pos} on {axis}, outside {r:?}");
                    }
                }
            }
            for k in 0..3 {
                let (v, w) = (tri[k], tri[(k + 1) % 3]);
                if (v[axis] - pos) * (w[axis] - pos) < 0.0 {
                    let t = (pos as f64 - v[axis] as f64) / (w[axis] as f64 - v[axis] as f64);
                    let exact = v.as_dvec3() + (w.as_dvec3() - v.as_dvec3()) * t;
                    for part in [&l, &r] {
                        for a in (0..3).filter(|&a| a != axis) {
                            assert!(
                                part.min[a] as f64 <= exact[a] && exact[a] <= part.max[a] as f64,
                                "the exact crossing {exact:?} inside {part:?}"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn a_triangle_across_the_plane_is_cut_to_each_side() {
        let tri = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(4.0, 0.0, 0.0), Vec3::new(0.0, 4.0, 0.0)];
        let b = Aabb::from_points(&tri);
        let (l, r) = split_reference(&tri, &b, 0, 2.0);
        assert!((l.max.x - 2.0).abs() < 1e-6 && (l.max.y - 4.0).abs() < 1e-5);
        assert!((r.min.x - 2.0).abs() < 1e-6 && (r.max.y - 2.0).abs() < 1e-5, "the right part is half as tall: {r:?}");
        let (l, r) = split_reference(&tri, &b, 1, 5.0);
        assert_eq!(l, b, "a plane past the triangle leaves all of it on one side");
        assert!(r.is_empty());
    }

    /// A long thin diagonal triangle over 8 bins: it enters the first bin, exits the last, and the
    /// cheapest plane cuts it (both sides count it).
    #[test]
    fn spatial_bins_count_straddlers_on_both_sides() {
        let tris = [
            [Vec3::new(0.0, 0.0, 0.0), Vec3::new(8.0, 8.0, 0.0), Vec3::new(8.0, 8.1, 0.0)],
            [Vec3::new(0.0, 7.0, 0.0), Vec3::new(1.0, 8.0, 0.0), Vec3::new(0.0, 8.0, 0.0)],
            [Vec3::new(7.0, 0.0, 0.0), Vec3::new(8.0, 0.0, 0.0), Vec3::new(8.0, 1.0, 0.0)],
        ];
        let refs: Vec<BuildPrim> =
            tris.iter().enumerate().map(|(i, t)| BuildPrim::new(Aabb::from_points(t), i as u32)).collect();
        let bounds = Aabb::of(refs.iter().map(BuildPrim::bounds));
        let tri = |i: u32| tris[i as usize];
        let mut seen = Vec::new();
        struct Seen<'a>(&'a mut Vec<(usize, f32, u32, u32)>);
        impl PlaneSink for Seen<'_> {
            fn plane(&mut self, axis: usize, position: f32, left: u32, right: u32, _: f32, _: [f32; 2]) {
                self.0.push((axis, position, left, right));
            }
        }
        let best = spatial_planes(&refs, &tri, &bounds, 8, &mut Seen(&mut seen)).unwrap();
        assert!(seen.iter().filter(|p| p.0 == 0).all(|p| p.2 + p.3 >= 4), "the diagonal is on both sides: {seen:?}");
        assert_eq!((best.left, best.right), (2, 2));
        let (l, r) = spatial_partition(&refs, &tri, best.axis as usize, best.position);
        assert_eq!((l.len(), r.len()), (2, 2));
        assert!(l.iter().any(|p| p.index() == 0) && r.iter().any(|p| p.index() == 0));
        let whole = Aabb::from_points(&tris[0]).area();
        let parts: f32 = l.iter().chain(&r).filter(|p| p.index() == 0).map(|p| p.bounds().area()).sum();
        assert!(parts < whole, "the diagonal's two parts are smaller than its box: {parts} vs {whole}");
    }
}
