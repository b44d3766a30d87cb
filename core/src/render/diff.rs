//! Two builds compared pixel by pixel: the difference B − A of a heatmap metric over the same
//! camera, shown through a diverging colour map centred on zero (blue where B does less work than
//! A, red where it does more, white where they agree) on a range symmetric about zero.

use crate::bvh::SahCost;
use crate::render::colormap::ColorMap;
use crate::render::frame::Frame;
use crate::render::views::{Legend, View};
use image::RgbImage;

/// B − A of `view`'s metric at every pixel, row by row; `None` unless both frames are complete,
/// counted and of one size.
pub fn difference(a: &Frame, b: &Frame, view: View, cost: SahCost) -> Option<Vec<f32>> {
    let ready = |f: &Frame| f.is_complete() && f.counted();
    if !ready(a) || !ready(b) || (a.width(), a.height()) != (b.width(), b.height()) || !view.is_heatmap() {
        return None;
    }
    // Complete frames: the traced grid is every pixel, row by row. A warp view's pixel is its
    // group's value, which `grid_values` computes from the neighbours' counts.
    let (va, vb) = (super::views::grid_values(a, view, cost), super::views::grid_values(b, view, cost));
    Some(vb.iter().zip(&va).map(|(b, a)| b - a).collect())
}

/// The range of a difference image, symmetric about zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DiffRange {
    /// ±this.
    Fixed(f32),
    /// ± this percentile of |B − A| over the pixels where B and A differ (100: the largest
    /// difference). One outlier pixel would otherwise set the scale and leave the rest white.
    Percentile(f32),
}

/// The default: the 99th percentile.
pub const DEFAULT_PERCENTILE: f32 = 99.0;

impl From<Option<f32>> for DiffRange {
    /// A fixed range if given, else the default percentile.
    fn from(r: Option<f32>) -> Self {
        r.map_or(DiffRange::Percentile(DEFAULT_PERCENTILE), DiffRange::Fixed)
    }
}

/// The `p`th percentile of |v| over the nonzero values of `d` (0 when all are zero).
pub fn percentile_of_abs(d: &[f32], p: f32) -> f32 {
    let mut a: Vec<f32> = d.iter().map(|v| v.abs()).filter(|&v| v > 0.0).collect();
    if a.is_empty() {
        return 0.0;
    }
    let k = (((p.clamp(0.0, 100.0) / 100.0) * a.len() as f32).ceil() as usize).clamp(1, a.len()) - 1;
    *a.select_nth_unstable_by(k, f32::total_cmp).1
}

/// The difference as an image and its legend: the range is ± a fixed value or a percentile of
/// the differences (the legend's title says which, and how many pixels lie beyond it, drawn at
/// the ends of the scale); the legend's min, mean and max are the differences'.
pub fn difference_image(width: u32, d: &[f32], view: View, range: impl Into<DiffRange>) -> (RgbImage, Legend) {
    let height = (d.len() as u32).checked_div(width).unwrap_or(0);
    let (mut lo, mut hi, mut sum) = (f32::INFINITY, f32::NEG_INFINITY, 0f64);
    for &v in d {
        lo = lo.min(v);
        hi = hi.max(v);
        sum += v as f64;
    }
    if d.is_empty() {
        (lo, hi) = (0.0, 0.0);
    }
    let (m, how) = match range.into() {
        DiffRange::Fixed(r) => (r, "fixed".to_string()),
        DiffRange::Percentile(p) if p >= 100.0 => (lo.abs().max(hi.abs()), "the largest |B - A|".to_string()),
        DiffRange::Percentile(p) => (percentile_of_abs(d, p), format!("{p}th percentile of |B - A|")),
    };
    let m = m.max(1e-20);
    let beyond = d.iter().filter(|v| v.abs() > m).count();
    let clamped = if beyond > 0 { format!(", {beyond} pixels beyond") } else { String::new() };
    let map = ColorMap::Diverging;
    let img = RgbImage::from_fn(width, height, |x, y| image::Rgb(map.map(0.5 + 0.5 * d[(y * width + x) as usize] / m)));
    let legend = Legend {
        title: format!("{} per ray: B - A", view.label().to_lowercase()),
        subject: String::new(),
        note: format!("range: {how}{clamped}"),
        colormap: map,
        range_min: -m,
        range_max: m,
        min: lo,
        max: hi,
        mean: if d.is_empty() { 0.0 } else { sum / d.len() as f64 },
    };
    (img, legend)
}

/// How many pixels B does less, the same and more work at.
pub fn tally(d: &[f32]) -> (usize, usize, usize) {
    d.iter().fold((0, 0, 0), |(l, s, m), &v| {
        if v < 0.0 {
            (l + 1, s, m)
        } else if v > 0.0 {
            (l, s, m + 1)
        } else {
            (l, s + 1, m)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{AnyBvh, BuildParams, Strategy};
    use crate::mesh::generate;
    use crate::render::camera::{Camera, UpAxis};
    use crate::render::raycast::{render, RenderSettings};

    fn frame(strategy: Strategy) -> Frame {
        let mesh = generate::torus_knot(2, 3, 0.3, 96, 8);
        let bvh = AnyBvh::build(&mesh, &BuildParams::with_strategy(strategy));
        let camera = Camera::framing_up(&mesh.bounds(), 64, 48, UpAxis::Y, 45.0);
        render(&bvh, &mesh, &camera, &RenderSettings { count: true, ..Default::default() })
    }

    /// One outlier does not set the scale: the 99th percentile of the differing pixels does.
    #[test]
    fn a_percentile_range_ignores_an_outlier() {
        let mut d = vec![0.0f32; 1000];
        for (i, v) in d.iter_mut().enumerate().take(500) {
            *v = if i % 2 == 0 { 1.0 + (i % 3) as f32 } else { -2.0 };
        }
        d[999] = -47.0;
        assert_eq!(percentile_of_abs(&d, 100.0), 47.0);
        assert_eq!(percentile_of_abs(&d, 99.0), 3.0);
        let (_, l) = difference_image(100, &d, View::Visits, None);
        assert_eq!((l.range_min, l.range_max), (-3.0, 3.0));
        assert_eq!(l.note, "range: 99th percentile of |B - A|, 1 pixels beyond");
        assert_eq!(percentile_of_abs(&[0.0; 4], 99.0), 0.0);
    }

    /// Two separate builds with the same settings differ nowhere; different strategies do, and
    /// each pixel's difference is B's count minus A's.
    #[test]
    fn identical_builds_differ_nowhere_and_others_pixel_by_pixel() {
        let cost = SahCost::default();
        let (a, a2, b) = (frame(Strategy::Midpoint), frame(Strategy::Midpoint), frame(Strategy::SahBinned));
        let same = difference(&a, &a2, View::Visits, cost).unwrap();
        assert!(same.iter().all(|&v| v == 0.0));
        let (img, legend) = difference_image(a.width(), &same, View::Visits, None);
        let white = ColorMap::Diverging.map(0.5);
        assert!(img.pixels().all(|p| p.0 == white), "all neutral");
        assert_eq!((legend.min, legend.max), (0.0, 0.0));
        let d = difference(&a, &b, View::Visits, cost).unwrap();
        let (less, _, more) = tally(&d);
        assert!(less + more > 0, "midpoint and SAH differ somewhere");
        for (i, &v) in d.iter().enumerate() {
            let (x, y) = (i as u32 % a.width(), i as u32 / a.width());
            assert_eq!(v, b.counters(x, y).nodes_visited as f32 - a.counters(x, y).nodes_visited as f32);
        }
        let (img, legend) = difference_image(a.width(), &d, View::Visits, DiffRange::Percentile(100.0));
        assert_eq!(legend.range_max, legend.min.abs().max(legend.max));
        // The default: the 99th percentile of the pixels that differ, named in the title.
        let (_, p99) = difference_image(a.width(), &d, View::Visits, None);
        assert_eq!(p99.range_max, percentile_of_abs(&d, 99.0));
        assert!(p99.note.contains("99th percentile"), "{}", p99.note);
        // A pixel where B does less is bluer than red, one where it does more redder than blue.
        let at = |i: usize| img.get_pixel(i as u32 % a.width(), i as u32 / a.width()).0;
        if let Some(i) = d.iter().position(|&v| v < 0.0) {
            assert!(at(i)[2] > at(i)[0]);
        }
        if let Some(i) = d.iter().position(|&v| v > 0.0) {
            assert!(at(i)[0] > at(i)[2]);
        }
        assert!(difference(&a, &b, View::Normals, cost).is_none(), "only heatmaps have a difference");
    }
}
