//! Two builds' frames of one camera as one picture, as the app's Compare shows them and
//! `render --against` writes them: both heatmaps on one colour scale, A left and B right of a
//! split (halves, or a wipe line), or their difference B − A (`diff`); each with its legend, and
//! the numbers behind the pair as CSV (x, y, a, b, b_minus_a). One function makes each, so the
//! app's exports and the command line's files are the same bytes.

use super::diff::{difference, difference_image, DiffRange};
use crate::bvh::SahCost;
use crate::render::colormap::ColorMap;
use crate::render::frame::Frame;
use crate::render::legend::draw_legend;
use crate::render::views::{grid_values, metric_stats, view_image, HeatRange, Legend, View};
use image::RgbImage;

/// How the pair is shown.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PairView {
    /// A on the left half, B on the right.
    #[default]
    Halves,
    /// A left of a line, B right of it.
    Wipe,
    /// B − A per pixel through a diverging colour map.
    Difference,
}

/// Everything but the frames that decides the pair's picture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairStyle {
    pub view: View,
    pub colormap: ColorMap,
    pub cost: SahCost,
    /// The heatmaps' range (`Auto`: the pair's one scale, `shared_range`).
    pub range: HeatRange,
    /// The difference's range, symmetric about zero.
    pub diff_range: DiffRange,
}

/// The one scale of both heatmaps: a fixed range as it is, else from the lower minimum to the
/// higher maximum (A's own range would clip B's hottest pixels).
pub fn shared_range(a: &Frame, b: &Frame, view: View, cost: SahCost, range: HeatRange) -> HeatRange {
    match range {
        HeatRange::Auto if view.is_heatmap() => {
            let (a0, a1, _) = metric_stats(a, view, cost);
            let (b0, b1, _) = metric_stats(b, view, cost);
            HeatRange::Fixed { min: a0.min(b0), max: a1.max(b1) }
        }
        r => r,
    }
}

/// A's and B's images of the pair (full frames of one size) on the one scale, and the legend:
/// its range the pair's, its min, mean and max A's (the title says so).
pub fn pair_images(a: &Frame, b: &Frame, s: &PairStyle) -> (RgbImage, RgbImage, Option<Legend>) {
    let range = shared_range(a, b, s.view, s.cost, s.range);
    let (img_a, mut legend) = view_image(a, s.view, s.colormap, range, s.cost);
    if let Some(l) = &mut legend {
        l.title += " (A and B on one scale; min, mean, max of A)";
    }
    let (img_b, _) = view_image(b, s.view, s.colormap, range, s.cost);
    (img_a, img_b, legend)
}

/// The column where B starts for a split at `split` (0: the left edge, 1: the right) of `width`.
pub fn split_column(width: u32, split: f32) -> u32 {
    (split.clamp(0.0, 1.0) * width as f32).round() as u32
}

/// A's columns left of the split, B's from it on, and a white line two pixels wide on the split
/// (as the app draws it over the viewport).
pub fn split_image(a: &RgbImage, b: &RgbImage, split: f32) -> RgbImage {
    let x0 = split_column(a.width(), split);
    RgbImage::from_fn(a.width(), a.height(), |x, y| {
        if x + 1 == x0 || x == x0 {
            image::Rgb([255, 255, 255])
        } else if x < x0 {
            *a.get_pixel(x, y)
        } else {
            *b.get_pixel(x, y)
        }
    })
}

/// The picture of the pair as `show` shows it (`split`: the wipe line's place, 0..1), with its
/// legend drawn below it; its legend's subject is `subject` (the mesh, A and B). `None` for a
/// difference of a view that is not a heatmap, or of frames not complete and counted.
pub fn pair_picture(
    a: &Frame,
    b: &Frame,
    show: PairView,
    split: f32,
    s: &PairStyle,
    subject: &str,
) -> Option<RgbImage> {
    let (img, legend) = match show {
        PairView::Difference => {
            let d = difference(a, b, s.view, s.cost)?;
            let (img, legend) = difference_image(a.width(), &d, s.view, s.diff_range);
            (img, Some(legend))
        }
        PairView::Halves | PairView::Wipe => {
            let (img_a, img_b, legend) = pair_images(a, b, s);
            let split = if show == PairView::Wipe { split } else { 0.5 };
            (split_image(&img_a, &img_b, split), legend)
        }
    };
    Some(match legend {
        Some(mut l) => {
            l.subject = subject.to_string();
            draw_legend(&img, &l)
        }
        None => img,
    })
}

/// The pair's numbers, one row per pixel from the top left: x, y, A's value, B's value and B − A
/// of `view`'s metric (a warp view's pixel is its group's value); `None` as `difference`.
pub fn difference_csv(a: &Frame, b: &Frame, view: View, cost: SahCost) -> Option<String> {
    use std::fmt::Write;
    let d = difference(a, b, view, cost)?;
    let (va, vb) = (grid_values(a, view, cost), grid_values(b, view, cost));
    let width = a.width();
    let mut o = String::from("x,y,a,b,b_minus_a\n");
    for (i, v) in d.iter().enumerate() {
        let (x, y) = (i as u32 % width, i as u32 / width);
        let _ = writeln!(o, "{x},{y},{},{},{v}", va[i], vb[i]);
    }
    Some(o)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_split_takes_a_left_of_the_line_and_b_right_of_it() {
        let a = RgbImage::from_pixel(10, 2, image::Rgb([1, 0, 0]));
        let b = RgbImage::from_pixel(10, 2, image::Rgb([2, 0, 0]));
        let img = split_image(&a, &b, 0.5);
        let row: Vec<u8> = (0..10).map(|x| img.get_pixel(x, 1)[0]).collect();
        assert_eq!(row, [1, 1, 1, 1, 255, 255, 2, 2, 2, 2]);
        assert_eq!(split_column(10, 0.26), 3);
        let left = split_image(&a, &b, 0.0);
        assert_eq!(left.get_pixel(0, 0)[0], 255, "at the left edge: the line, then B");
        assert_eq!(left.get_pixel(1, 0)[0], 2);
    }
}
