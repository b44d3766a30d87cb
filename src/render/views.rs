//! Turning a frame into pixels: the normal view (n·0.5+0.5, as the handout's normal integrator),
//! depth, and heatmaps of per-ray work through a perceptual colour map.

use super::{ColorMap, Frame, PixelSample};
use crate::bvh::SahCost;
use image::RgbImage;

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
    pub const ALL: [View; 8] = [
        View::Normals,
        View::Depth,
        View::Visits,
        View::TriTests,
        View::Cost,
        View::TopVisits,
        View::BottomVisits,
        View::Instances,
    ];

    /// Whether the view is about the levels of a two-level BVH (all zero for a single BVH).
    pub fn is_per_level(self) -> bool {
        matches!(self, View::TopVisits | View::BottomVisits | View::Instances)
    }

    pub fn short_name(self) -> &'static str {
        match self {
            View::Normals => "normals",
            View::Depth => "depth",
            View::Visits => "visits",
            View::TriTests => "tri-tests",
            View::Cost => "cost",
            View::TopVisits => "top-visits",
            View::BottomVisits => "bottom-visits",
            View::Instances => "instances",
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            View::Normals => "Normals",
            View::Depth => "Depth",
            View::Visits => "Nodes visited",
            View::TriTests => "Triangle tests",
            View::Cost => "Combined cost",
            View::TopVisits => "Top-level nodes visited",
            View::BottomVisits => "Bottom-level nodes visited",
            View::Instances => "Instances entered",
        }
    }

    pub fn is_heatmap(self) -> bool {
        !matches!(self, View::Normals | View::Depth)
    }

    /// The heatmap's value for one ray.
    pub fn metric(self, s: &PixelSample, cost: SahCost) -> f32 {
        match self {
            View::Visits => s.counters.nodes_visited as f32,
            View::TriTests => s.counters.triangle_tests as f32,
            View::Cost => s.counters.cost(cost),
            View::TopVisits => s.counters.top_nodes_visited as f32,
            View::BottomVisits => s.counters.bottom_nodes_visited() as f32,
            View::Instances => s.counters.instances_entered as f32,
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
    pub colormap: ColorMap,
    pub range_min: f32,
    pub range_max: f32,
    pub min: f32,
    pub max: f32,
    pub mean: f64,
}

/// Min, max and mean of a heatmap metric over the traced rays.
pub fn metric_stats(frame: &Frame, view: View, cost: SahCost) -> (f32, f32, f64) {
    let (mut lo, mut hi, mut sum, mut n) = (f32::INFINITY, f32::NEG_INFINITY, 0f64, 0u64);
    for s in frame.traced() {
        let v = view.metric(s, cost);
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

/// The frame as an RGB image in the given view; for heatmaps also the legend's numbers.
pub fn view_image(
    frame: &Frame,
    view: View,
    colormap: ColorMap,
    range: HeatRange,
    cost: SahCost,
) -> (RgbImage, Option<Legend>) {
    let (w, h) = (frame.width, frame.height);
    match view {
        View::Normals => (
            RgbImage::from_fn(w, h, |x, y| {
                let s = frame.sample(x, y);
                let c = (s.normal * 0.5 + 0.5) * 255.0;
                if s.is_hit() {
                    image::Rgb([c.x as u8, c.y as u8, c.z as u8])
                } else {
                    image::Rgb([0, 0, 0])
                }
            }),
            None,
        ),
        View::Depth => {
            let (mut near, mut far) = (f32::INFINITY, 0f32);
            for s in frame.traced().filter(|s| s.is_hit()) {
                near = near.min(s.t);
                far = far.max(s.t);
            }
            let span = (far - near).max(1e-20);
            (
                RgbImage::from_fn(w, h, |x, y| {
                    let s = frame.sample(x, y);
                    if !s.is_hit() {
                        return image::Rgb([0, 0, 0]);
                    }
                    // Near is bright, far is dim but still distinct from the black background.
                    let g = (255.0 - 200.0 * (s.t - near) / span) as u8;
                    image::Rgb([g, g, g])
                }),
                None,
            )
        }
        _ => {
            let (min, max, mean) = metric_stats(frame, view, cost);
            let (lo, hi) = match range {
                HeatRange::Auto => (min, max),
                HeatRange::Fixed { min, max } => (min, max),
            };
            let scale = if hi > lo { 1.0 / (hi - lo) } else { 0.0 };
            let img = RgbImage::from_fn(w, h, |x, y| {
                image::Rgb(colormap.map((view.metric(frame.sample(x, y), cost) - lo) * scale))
            });
            let title = format!("{} per ray", view.label().to_lowercase());
            (img, Some(Legend { title, colormap, range_min: lo, range_max: hi, min, max, mean }))
        }
    }
}
