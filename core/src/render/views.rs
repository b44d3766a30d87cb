//! Turning a frame into pixels: the normal view (n·0.5+0.5, as the handout's normal integrator),
//! depth, and heatmaps of per-ray work through a perceptual colour map.

use super::exact_stats::exact_stats;
use super::warp::{WarpSize, WarpView, WarpWork};
use crate::bvh::{RayCounters, SahCost};
use crate::render::colormap::ColorMap;
use crate::render::frame::Frame;
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
    /// Per block of a GPU warp's pixels (8×4 for 32 lanes, 8×8 for 64): the most work (nodes
    /// visited + triangle tests) of its rays, which is what the warp takes (`render::warp`).
    WarpCost(WarpSize),
    /// Per block: its rays' mean work over the most work, the share of lane-steps that work.
    SimtEfficiency(WarpSize),
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

    /// The warp size of a view whose pixels show their warp group's value, not their own ray's:
    /// such a value needs the neighbours' counts (`grid_values`), never `metric` alone.
    pub fn warp(self) -> Option<WarpSize> {
        match self {
            View::WarpCost(w) | View::SimtEfficiency(w) => Some(w),
            _ => None,
        }
    }

    /// What a heatmap's legend calls its values.
    pub fn legend_title(self) -> String {
        match self {
            View::WarpCost(w) | View::SimtEfficiency(w) => {
                let (bw, bh) = w.block();
                let what = if matches!(self, View::WarpCost(_)) { "warp cost" } else { "SIMT efficiency" };
                format!("{what} per {bw}×{bh} block ({} lanes)", w.lanes())
            }
            _ => format!("{} per ray", self.label().to_lowercase()),
        }
    }

    /// The heatmap's value for one ray. For the warp views (`warp`), a ray alone: its own work
    /// (warp cost) or 1 (a lane of its own never idles); their pixels come from `grid_values`.
    pub fn metric(self, c: &RayCounters, cost: SahCost) -> f32 {
        match self {
            View::WarpCost(_) => WarpWork::Steps.of(c) as f32,
            View::SimtEfficiency(_) => 1.0,
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
    let w = frame.width();
    let mut all: Vec<(f32, u32)> = grid_values(frame, view, cost).into_iter().zip(0..).collect();
    if k >= all.len() {
        return None;
    }
    // Most work first; of equal work, the first pixel in reading order.
    let order = |a: &(f32, u32), b: &(f32, u32)| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1));
    let (_, &mut (v, i), _) = all.select_nth_unstable_by(k, order);
    Some((i % w, i / w, v))
}

/// Min, max and mean of a heatmap metric over the traced rays: the serial loop's figures, found
/// row by row in parallel (`exact_stats`).
pub fn metric_stats(frame: &Frame, view: View, cost: SahCost) -> (f32, f32, f64) {
    let stats = match view.warp() {
        Some(_) => {
            exact_stats(&grid_values(frame, view, cost), 4096, |values, acc| values.iter().for_each(|&v| acc.add(v)))
        }
        None => {
            let rows: Vec<u32> = (0..traced_size(frame).1).collect();
            exact_stats(&rows, 4, |rows, acc| {
                for &gy in rows {
                    frame.grid_row(gy).filter_map(|(s, c)| frame.value(view, s, &c, cost)).for_each(|v| acc.add(v));
                }
            })
        }
    };
    let serial = || {
        let (mut lo, mut hi, mut sum, mut n) = (f32::INFINITY, f32::NEG_INFINITY, 0f64, 0u64);
        for v in values(frame, view, cost) {
            lo = lo.min(v);
            hi = hi.max(v);
            sum += v as f64;
            n += 1;
        }
        (lo, hi, sum, n)
    };
    let (lo, hi, sum, n) = stats.unwrap_or_else(serial);
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
    for v in values(frame, view, cost) {
        let b = ((v as f64 - lo) * scale).floor();
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
            // Rows in parallel: a minimum and a maximum do not depend on the order.
            let rows = traced_size(frame).1;
            let (near, far) = crate::parallel::region(|| {
                (0..rows)
                    .into_par_iter()
                    .map(|gy| {
                        let hits = frame.grid_row(gy).filter(|(s, _)| s.is_hit());
                        hits.fold((f32::INFINITY, 0f32), |(n, f), (s, _)| (n.min(s.t), f.max(s.t)))
                    })
                    .reduce(|| (f32::INFINITY, 0f32), |a, b| (a.0.min(b.0), a.1.max(b.1)))
            });
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
            let colour = |v: f32| colormap.map((v - lo) * scale);
            let img = match view.warp() {
                None => grid_image(frame, |s, c| frame.value(view, s, &c, cost).map_or(NO_RAYS, colour)),
                Some(_) => {
                    let (w, h) = traced_size(frame);
                    let rgb = grid_values(frame, view, cost).into_iter().flat_map(colour).collect();
                    RgbImage::from_raw(w, h, rgb).expect("one value per traced pixel")
                }
            };
            let title = view.legend_title();
            let note = match frame.ray_kind() {
                (kind, n) if kind.is_secondary() => format!(
                    "mean of {n} {} ray{} per hit; grey: camera ray missed",
                    kind.name(),
                    if n == 1 { "" } else { "s" },
                ),
                _ => String::new(),
            };
            (
                img,
                Some(Legend {
                    title,
                    subject: String::new(),
                    note,
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

/// Columns and rows of the pixels traced so far (none before the first pass).
fn traced_size(frame: &Frame) -> (u32, u32) {
    if frame.stride() == 0 {
        (0, 0)
    } else {
        frame.grid_size()
    }
}

/// The heatmap's value at each traced pixel, row by row of the traced grid (every pixel of a
/// complete frame). A warp view groups the traced grid's pixels: exactly the GPU's warps once the
/// frame is complete; during a coarse pass, blocks of traced pixels stand for them.
pub fn grid_values(frame: &Frame, view: View, cost: SahCost) -> Vec<f32> {
    match view {
        View::WarpCost(size) | View::SimtEfficiency(size) => {
            let (w, h) = traced_size(frame);
            let counters: Vec<RayCounters> = frame.traced().map(|(_, c)| c).collect();
            let groups = WarpView::frame(w, h, &counters, size, WarpWork::Steps);
            match view {
                View::WarpCost(_) => groups.cost_image(),
                _ => groups.efficiency_image(),
            }
        }
        // A pixel without secondary rays counts as no work here (the hottest pixel, a
        // difference); the images mark it apart (`NO_RAYS`).
        _ => frame.traced().map(|(s, c)| frame.value(view, s, &c, cost).unwrap_or(0.0)).collect(),
    }
}

/// The colour of a pixel of a frame of secondary rays whose camera ray missed: it has no
/// secondary rays, which is not the same as rays that cost nothing.
pub const NO_RAYS: [u8; 3] = [96, 96, 96];

/// `grid_values` one by one; a per-ray view's without collecting them.
fn values(frame: &Frame, view: View, cost: SahCost) -> impl Iterator<Item = f32> + '_ {
    let grouped = view.warp().map(|_| grid_values(frame, view, cost));
    let per_ray = grouped.is_none().then(|| frame.traced().filter_map(move |(s, c)| frame.value(view, s, &c, cost)));
    grouped.into_iter().flatten().chain(per_ray.into_iter().flatten())
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
    crate::parallel::region(|| {
        buf.par_chunks_mut(w as usize * 3).enumerate().for_each(|(gy, row)| {
            for (rgb, (s, c)) in row.chunks_exact_mut(3).zip(frame.grid_row(gy as u32)) {
                rgb.copy_from_slice(&pixel(s, c));
            }
        })
    });
    RgbImage::from_raw(w, h, buf).expect("the buffer holds w×h pixels")
}

#[cfg(test)]
mod histogram_tests {
    use super::*;
    use crate::bvh::{AnyBvh, BuildParams};
    use crate::render::camera::{Camera, UpAxis};
    use crate::render::raycast::{render, RenderSettings};

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
    use crate::render::camera::Camera;
    use crate::render::raycast::{render, render_passes, RenderSettings};
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

#[cfg(test)]
mod warp_tests {
    use super::*;
    use crate::bvh::{AnyBvh, BuildParams};
    use crate::render::camera::Camera;
    use crate::render::raycast::{render, render_passes, RenderSettings};
    use crate::work::WorkControl;

    /// The warp views show each pixel's group: its cost (most steps) or efficiency (mean/max), the
    /// numbers `WarpView` gives from the frame's counts; legend, histogram and hottest pixel agree.
    #[test]
    fn warp_views_show_each_pixels_group_from_the_frames_counts() {
        let mesh = crate::mesh::generate::torus_knot(2, 3, 0.3, 64, 8);
        let bvh = AnyBvh::build(&mesh, &BuildParams::default());
        // 37×21: partial blocks on the right and at the bottom.
        let camera = Camera::framing_from(&mesh.bounds(), 37, 21, glam::Vec3::new(0.3, 0.5, 1.0), 45.0);
        let f = render(&bvh, &mesh, &camera, &RenderSettings { count: true, ..Default::default() });
        let counters: Vec<RayCounters> = f.traced().map(|(_, c)| c).collect();
        let cost = SahCost::default();
        for size in WarpSize::ALL {
            let groups = WarpView::frame(37, 21, &counters, size, WarpWork::Steps);
            let values = grid_values(&f, View::WarpCost(size), cost);
            assert_eq!(values, groups.cost_image());
            let (bw, bh) = size.block();
            // Every pixel of a block shows the block's most steps, which one of its rays took.
            for (i, &v) in values.iter().enumerate() {
                let (x, y) = (i as u32 % 37, i as u32 / 37);
                let block = (0..37 * 21).filter(|j| (j % 37) / bw == x / bw && (j / 37) / bh == y / bh);
                let most = block.map(|j| WarpWork::Steps.of(&counters[j as usize])).max().unwrap();
                assert_eq!(v, most as f32, "{size:?} pixel ({x}, {y})");
            }
            let eff = grid_values(&f, View::SimtEfficiency(size), cost);
            assert_eq!(eff, groups.efficiency_image());
            assert!(eff.iter().all(|&e| e > 0.0 && e <= 1.0));
            assert!(eff.iter().any(|&e| e < 1.0), "some lanes idle on the knot's silhouette");

            let view = View::WarpCost(size);
            let (lo, hi, mean) = metric_stats(&f, view, cost);
            assert_eq!(hi, groups.summary().max_cost as f32);
            assert_eq!(lo, values.iter().copied().fold(f32::INFINITY, f32::min));
            assert!((mean - values.iter().map(|&v| v as f64).sum::<f64>() / values.len() as f64).abs() < 1e-9);
            let (img, legend) = view_image(&f, view, ColorMap::Viridis, HeatRange::Auto, cost);
            let legend = legend.unwrap();
            assert_eq!(legend.title, format!("warp cost per {bw}×{bh} block ({} lanes)", size.lanes()));
            for (x, y, p) in img.enumerate_pixels() {
                let v = values[(y * 37 + x) as usize];
                assert_eq!(p.0, ColorMap::Viridis.map((v - lo) / (hi - lo)), "({x}, {y})");
            }
            assert_eq!(histogram(&f, view, cost, lo, hi, 5).iter().sum::<u32>(), 37 * 21);
            // The hottest pixel: the first one, in reading order, of a costliest block.
            let first = values.iter().position(|&v| v == hi).unwrap() as u32;
            assert_eq!(hottest(&f, view, cost, 0), Some((first % 37, first / 37, hi)));
            let same = crate::render::diff::difference(&f, &f, view, cost).unwrap();
            assert!(same.iter().all(|&d| d == 0.0));
        }
        assert_eq!(View::WarpCost(WarpSize::W64).warp(), Some(WarpSize::W64));
        assert_eq!(View::Cost.warp(), None);
    }

    /// During a coarse pass, a warp view groups the traced pixels: one image pixel per traced one.
    #[test]
    fn a_coarse_pass_of_a_warp_view_has_one_value_per_traced_pixel() {
        let mesh = crate::mesh::generate::torus_knot(2, 3, 0.3, 64, 8);
        let cam = Camera::framing_from(&mesh.bounds(), 45, 29, glam::Vec3::new(0.3, 0.5, 1.0), 45.0);
        let bvh = AnyBvh::build(&mesh, &BuildParams::default());
        let settings = RenderSettings { count: true, progressive: true, ..Default::default() };
        let mut passes = Vec::new();
        render_passes(&bvh, &mesh, &cam, &settings, &Default::default(), &WorkControl::new(), |f, _| passes.push(f))
            .unwrap();
        for f in &passes {
            let s = f.stride();
            for view in [View::WarpCost(WarpSize::W32), View::SimtEfficiency(WarpSize::W64)] {
                let (img, _) = view_image(f, view, ColorMap::Viridis, HeatRange::Auto, SahCost::default());
                assert_eq!(img.dimensions(), (45u32.div_ceil(s), 29u32.div_ceil(s)), "{view:?} 1/{s}");
                assert_eq!(grid_values(f, view, SahCost::default()).len(), img.len() / 3);
            }
        }
        let empty = Frame::new(8, 8, true);
        assert!(grid_values(&empty, View::WarpCost(WarpSize::W32), SahCost::default()).is_empty());
    }
}
