//! Turning a frame into pixels: the normal view (n·0.5+0.5, as the handout's normal integrator),
//! depth, and heatmaps of per-ray work through a perceptual colour map.

use super::{ColorMap, Frame};
use crate::bvh::{RayCounters, SahCost};
use image::RgbImage;
use rayon::prelude::*;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum View {
    #[default]
    Normals,
    Depth,
    /// Nodes visited per ray.
    Visits,
    /// Triangle tests per ray.
    TriTests,
    /// traversal-cost·nodes + intersection-cost·triangle tests, with the SAH constants.
    Cost,
    /// Nodes visited per ray in the top level of a two-level BVH.
    TopVisits,
    /// Nodes visited per ray in the bottom level (the meshes' BVHs).
    BottomVisits,
    /// Instances whose mesh BVH the ray entered.
    Instances,
}

impl View {
    /// Whether the view is about the levels of a two-level BVH (all zero for a single BVH).
    pub fn is_per_level(self) -> bool {
        matches!(self, View::TopVisits | View::BottomVisits | View::Instances)
    }

    pub fn is_heatmap(self) -> bool {
        !matches!(self, View::Normals | View::Depth)
    }

    /// The heatmap's value for one ray.
    pub fn metric(self, c: &RayCounters, cost: SahCost) -> f32 {
        match self {
            View::Visits => c.nodes_visited as f32,
            View::TriTests => c.triangle_tests as f32,
            View::Cost => c.cost(cost),
            View::TopVisits => c.top_nodes_visited as f32,
            View::BottomVisits => c.bottom_nodes_visited() as f32,
            View::Instances => c.instances_entered as f32,
            View::Normals | View::Depth => 0.0,
        }
    }
}

/// Which values map to the two ends of the colour map.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum HeatRange {
    /// The frame's own minimum and maximum.
    #[default]
    Auto,
    /// A fixed range, so two strategies can be compared on one scale.
    Fixed { min: f32, max: f32 },
}

/// The numbers behind a heatmap: what it shows, the range mapped, and the frame's statistics over
/// all traced rays (hit and missed).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Legend {
    pub title: String,
    /// What the image is of: mesh, strategy, layout (set by whoever knows them; drawn into an
    /// exported PNG's legend strip, so a file says what it shows). Empty when unknown.
    pub subject: String,
    /// How the range was chosen, when that needs saying (a difference's percentile); empty
    /// otherwise. Drawn on a line of its own.
    pub note: String,
    pub colormap: ColorMap,
    pub range_min: f32,
    pub range_max: f32,
    pub min: f32,
    pub max: f32,
    pub mean: f64,
}

/// The pixel with the `k`-th most work (0: the hottest) of `view`'s metric in a complete counted
/// frame, with its value: ties by row, then column, so the order is the same every time. `None`
/// when the frame is not complete and counted, the view is no heatmap, or `k` is past the pixels.
pub fn hottest(frame: &Frame, view: View, cost: SahCost, k: usize) -> Option<(u32, u32, f32)> {
    if !frame.is_complete() || !frame.counted() || !view.is_heatmap() {
        return None;
    }
    let (w, h) = (frame.width(), frame.height());
    let mut all: Vec<(f32, u32)> = (0..w * h).map(|i| (view.metric(&frame.counters(i % w, i / w), cost), i)).collect();
    if k >= all.len() {
        return None;
    }
    // Most work first; of equal work, the first pixel in reading order.
    let order = |a: &(f32, u32), b: &(f32, u32)| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1));
    let (_, &mut (v, i), _) = all.select_nth_unstable_by(k, order);
    Some((i % w, i / w, v))
}

/// Min, max and mean of a heatmap metric over the traced rays.
pub fn metric_stats(frame: &Frame, view: View, cost: SahCost) -> (f32, f32, f64) {
    let (mut lo, mut hi, mut sum, mut n) = (f32::INFINITY, f32::NEG_INFINITY, 0f64, 0u64);
    for (_, c) in frame.traced() {
        let v = view.metric(&c, cost);
        lo = lo.min(v);
        hi = hi.max(v);
        sum += v as f64;
        n += 1;
    }
    if n == 0 {
        (0.0, 0.0, 0.0)
    } else {
        (lo, hi, sum / n as f64)
    }
}

/// How many traced pixels' `view` metric falls in each of `bins` equal bins over `lo..=hi` (values
/// outside go to the end bins): the heatmap's histogram under the app's legend and `render
/// --histogram`'s table.
pub fn histogram(frame: &Frame, view: View, cost: SahCost, lo: f32, hi: f32, bins: usize) -> Vec<u32> {
    let n = bins.max(1);
    let mut out = vec![0u32; n];
    // In f64: a range of ±3e38 spans more than an f32 holds.
    let (lo, hi) = (lo as f64, hi as f64);
    let scale = if hi > lo { n as f64 / (hi - lo) } else { 0.0 };
    for (_, c) in frame.traced() {
        let b = ((view.metric(&c, cost) as f64 - lo) * scale).floor();
        out[(b.max(0.0) as usize).min(n - 1)] += 1;
    }
    out
}

/// The frame as an RGB image in the given view, one pixel per traced pixel (so a coarse pass's image
/// is 1/stride of the frame in each direction, to be shown stretched); for heatmaps also the
/// legend's numbers.
pub fn view_image(
    frame: &Frame,
    view: View,
    colormap: ColorMap,
    range: HeatRange,
    cost: SahCost,
) -> (RgbImage, Option<Legend>) {
    let black = [0, 0, 0];
    match view {
        View::Normals => (
            grid_image(frame, |s, _| {
                let c = (s.normal * 0.5 + 0.5) * 255.0;
                if s.is_hit() {
                    [c.x as u8, c.y as u8, c.z as u8]
                } else {
                    black
                }
            }),
            None,
        ),
        View::Depth => {
            let (mut near, mut far) = (f32::INFINITY, 0f32);
            for (s, _) in frame.traced().filter(|(s, _)| s.is_hit()) {
                near = near.min(s.t);
                far = far.max(s.t);
            }
            let span = (far - near).max(1e-20);
            let img = grid_image(frame, |s, _| {
                if !s.is_hit() {
                    return black;
                }
                // Near is bright, far is dim but still distinct from the black background.
                let g = (255.0 - 200.0 * (s.t - near) / span) as u8;
                [g, g, g]
            });
            (img, None)
        }
        _ => {
            let (min, max, mean) = metric_stats(frame, view, cost);
            let (lo, hi) = match range {
                HeatRange::Auto => (min, max),
                HeatRange::Fixed { min, max } => (min, max),
            };
            let scale = if hi > lo { 1.0 / (hi - lo) } else { 0.0 };
            let img = grid_image(frame, |_, c| colormap.map((view.metric(&c, cost) - lo) * scale));
            let title = format!("{} per ray", view.label().to_lowercase());
            (
                img,
                Some(Legend {
                    title,
                    subject: String::new(),
                    note: String::new(),
                    colormap,
                    range_min: lo,
                    range_max: hi,
                    min,
                    max,
                    mean,
                }),
            )
        }
    }
}

/// `view_image`'s image at the frame's full size: a coarse pass's pixels repeated over the blocks
/// they stand for (what the app shows stretched, as a file of the frame's size).
pub fn full_size(img: &RgbImage, frame: &Frame) -> RgbImage {
    let s = frame.stride().max(1);
    if img.dimensions() == (frame.width(), frame.height()) {
        return img.clone();
    }
    RgbImage::from_fn(frame.width(), frame.height(), |x, y| *img.get_pixel(x / s, y / s))
}

/// An image of the frame's traced grid, `pixel(sample, counters)` per grid point, rows in parallel.
fn grid_image(frame: &Frame, pixel: impl Fn(&super::PixelSample, RayCounters) -> [u8; 3] + Sync) -> RgbImage {
    let (w, h) = frame.grid_size();
    let mut buf = vec![0u8; w as usize * h as usize * 3];
    if w == 0 {
        return RgbImage::new(0, h);
    }
    buf.par_chunks_mut(w as usize * 3).enumerate().for_each(|(gy, row)| {
        for (rgb, (s, c)) in row.chunks_exact_mut(3).zip(frame.grid_row(gy as u32)) {
            rgb.copy_from_slice(&pixel(s, c));
        }
    });
    RgbImage::from_raw(w, h, buf).expect("the buffer holds w×h pixels")
}

#[cfg(test)]
mod histogram_tests {
    use super::*;
    use crate::bvh::{AnyBvh, BuildParams};
    use crate::render::{render, Camera, RenderSettings, UpAxis};

    /// Every traced pixel is counted once, in the bin its value falls in.
    #[test]
    fn the_histogram_counts_every_pixel_in_its_bin() {
        let mesh = crate::mesh::generate::torus_knot(2, 3, 0.3, 64, 8);
        let bvh = AnyBvh::build(&mesh, &BuildParams::default());
        let camera = Camera::framing_up(&mesh.bounds(), 40, 30, UpAxis::Y, 45.0);
        let f = render(&bvh, &mesh, &camera, &RenderSettings { count: true, ..Default::default() });
        let cost = SahCost::default();
        let (lo, hi, _) = metric_stats(&f, View::Visits, cost);
        let h = histogram(&f, View::Visits, cost, lo, hi, 8);
        assert_eq!(h.iter().sum::<u32>(), 1200);
        let bin = |v: f32| (((v - lo) * 8.0 / (hi - lo)).floor() as usize).min(7);
        let mut want = vec![0u32; 8];
        for y in 0..30 {
            for x in 0..40 {
                want[bin(f.counters(x, y).nodes_visited as f32)] += 1;
            }
        }
        assert_eq!(h, want);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{AnyBvh, BuildParams};
    use crate::render::{render, render_passes, Camera, RenderSettings};
    use crate::work::WorkControl;

    #[test]
    fn a_coarse_pass_gives_one_image_pixel_per_traced_pixel() {
        let mesh = crate::mesh::generate::torus_knot(2, 3, 0.3, 128, 12);
        let cam = Camera::framing_from(&mesh.bounds(), 45, 29, glam::Vec3::new(0.3, 0.5, 1.0), 45.0);
        let bvh = AnyBvh::build(&mesh, &BuildParams::default());
        let settings = RenderSettings { count: true, progressive: true, ..Default::default() };
        let mut passes = Vec::new();
        render_passes(&bvh, &mesh, &cam, &settings, &Default::default(), &WorkControl::new(), |f, _| passes.push(f))
            .unwrap();
        assert_eq!(passes.iter().map(|f| f.stride()).collect::<Vec<_>>(), [8, 4, 2, 1]);
        let full = passes.last().unwrap();
        assert_eq!(full.full_samples(), render(&bvh, &mesh, &cam, &settings).full_samples());
        let cost = SahCost::default();
        let range = HeatRange::Fixed { min: 0.0, max: 60.0 };
        for view in [View::Normals, View::Visits, View::TriTests, View::Cost] {
            let (reference, _) = view_image(full, view, ColorMap::Viridis, range, cost);
            assert_eq!(reference.dimensions(), (45, 29));
            for f in &passes {
                let (img, _) = view_image(f, view, ColorMap::Viridis, range, cost);
                let s = f.stride();
                assert_eq!(img.dimensions(), (45u32.div_ceil(s), 29u32.div_ceil(s)), "{view:?} 1/{s}");
                for (gx, gy, p) in img.enumerate_pixels() {
                    assert_eq!(p, reference.get_pixel(gx * s, gy * s), "{view:?} 1/{s}: pixel ({gx}, {gy})");
                }
                let big = full_size(&img, f);
                assert_eq!(big.dimensions(), (45, 29));
                for (x, y, p) in big.enumerate_pixels() {
                    assert_eq!(p, reference.get_pixel(x - x % s, y - y % s), "{view:?} 1/{s} at full size: ({x}, {y})");
                }
            }
        }
    }
}
