//! Two builds compared pixel by pixel: the difference B − A of a heatmap metric over the same
//! camera, shown through a diverging colour map centred on zero (blue where B does less work than
//! A, red where it does more, white where they agree) on a range symmetric about zero.

use super::{ColorMap, Frame, Legend, View};
use crate::bvh::SahCost;
use image::RgbImage;

/// B − A of `view`'s metric at every pixel, row by row; `None` unless both frames are complete,
/// counted and of one size.
pub fn difference(a: &Frame, b: &Frame, view: View, cost: SahCost) -> Option<Vec<f32>> {
    let ready = |f: &Frame| f.is_complete() && f.counted();
    if !ready(a) || !ready(b) || (a.width(), a.height()) != (b.width(), b.height()) || !view.is_heatmap() {
        return None;
    }
    let (w, h) = (a.width(), a.height());
    Some(
        (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| view.metric(&b.counters(x, y), cost) - view.metric(&a.counters(x, y), cost))
            .collect(),
    )
}

/// The difference as an image and its legend: the range is ±`range` if given, else ± the largest
/// difference; the legend's min, mean and max are the differences'.
pub fn difference_image(width: u32, d: &[f32], view: View, range: Option<f32>) -> (RgbImage, Legend) {
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
    let m = range.unwrap_or(lo.abs().max(hi.abs())).max(1e-20);
    let map = ColorMap::Diverging;
    let img = RgbImage::from_fn(width, height, |x, y| image::Rgb(map.map(0.5 + 0.5 * d[(y * width + x) as usize] / m)));
    let legend = Legend {
        title: format!("{} per ray: B - A", view.label().to_lowercase()),
        subject: String::new(),
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
    use crate::bvh::{AnyBvh, BuildParams, SplitStrategy};
    use crate::mesh::generate;
    use crate::render::{render, Camera, RenderSettings, UpAxis};

    fn frame(strategy: SplitStrategy) -> Frame {
        let mesh = generate::torus_knot(2, 3, 0.3, 96, 8);
        let bvh = AnyBvh::build(&mesh, &BuildParams::with_strategy(strategy));
        let camera = Camera::framing_up(&mesh.bounds(), 64, 48, UpAxis::Y, 45.0);
        render(&bvh, &mesh, &camera, &RenderSettings { count: true, ..Default::default() })
    }

    /// Two separate builds with the same settings differ nowhere; different strategies do, and
    /// each pixel's difference is B's count minus A's.
    #[test]
    fn identical_builds_differ_nowhere_and_others_pixel_by_pixel() {
        let cost = SahCost::default();
        let (a, a2, b) =
            (frame(SplitStrategy::Midpoint), frame(SplitStrategy::Midpoint), frame(SplitStrategy::SahBinned));
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
        let (img, legend) = difference_image(a.width(), &d, View::Visits, None);
        assert_eq!(legend.range_max, legend.min.abs().max(legend.max));
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
