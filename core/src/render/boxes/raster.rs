//! Segments drawn into an RGB image: antialiased lines of a given width, each pixel covered by
//! how far its centre lies inside the line's outline (a capsule: `width / 2` around the segment,
//! plus half a pixel of falloff), blended over what is there in the order given. Plain arithmetic
//! in one thread: the same segments give the same bytes every run.

use glam::{DVec2, Vec2};
use image::RgbImage;
use std::ops::Range;

/// A line to draw over the image, in its units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub a: Vec2,
    pub b: Vec2,
    pub rgb: [u8; 3],
    pub width: f32,
}

/// Draw `segments` into `img`, touching only the pixels in `columns` × `rows` (the part of a
/// larger picture the segments' coordinates are of, from its top left corner).
pub fn draw_segments(img: &mut RgbImage, segments: &[Segment], columns: Range<u32>, rows: Range<u32>) {
    let columns = columns.start..columns.end.min(img.width());
    let rows = rows.start..rows.end.min(img.height());
    if columns.is_empty() || rows.is_empty() {
        return;
    }
    for s in segments {
        draw_one(img, s, &columns, &rows);
    }
}

/// One segment: along its longer axis, pixel by pixel, the few pixels across it that the
/// outline can reach.
fn draw_one(img: &mut RgbImage, s: &Segment, columns: &Range<u32>, rows: &Range<u32>) {
    let reach = (s.width.max(0.0) as f64) * 0.5 + 0.5;
    let (a, b) = (s.a.as_dvec2(), s.b.as_dvec2());
    if !(a.is_finite() && b.is_finite()) || reach <= 0.5 {
        return;
    }
    // The segment's part near the drawn area (a clipped edge may end far off the image).
    let margin = reach + 1.0;
    let lo = DVec2::new(columns.start as f64, rows.start as f64) - margin;
    let hi = DVec2::new(columns.end as f64, rows.end as f64) + margin;
    let Some((a, b)) = clip(a, b, lo, hi) else { return };
    let d = b - a;
    // Iterate over the longer axis: `along` picks it, `across` the other.
    let steep = d.y.abs() > d.x.abs();
    type Axis = fn(DVec2) -> f64;
    let (along, across): (Axis, Axis) =
        if steep { (|p: DVec2| p.y, |p: DVec2| p.x) } else { (|p: DVec2| p.x, |p: DVec2| p.y) };
    let (along_range, across_range) = if steep { (rows, columns) } else { (columns, rows) };
    let slope = if along(d) == 0.0 { 0.0 } else { across(d) / along(d) };
    let span = reach * (1.0 + slope.abs()) + 1.0;
    let first = (along(a).min(along(b)) - reach).floor().max(along_range.start as f64) as u32;
    let last = (along(a).max(along(b)) + reach).floor().min(along_range.end as f64 - 1.0);
    if last < first as f64 {
        return;
    }
    for i in first..=last as u32 {
        let centre_along = i as f64 + 0.5;
        let line = across(a) + (centre_along - along(a)) * slope;
        let j0 = (line - span).floor().max(across_range.start as f64) as u32;
        let j1 = (line + span).floor().min(across_range.end as f64 - 1.0);
        if j1 < j0 as f64 {
            continue;
        }
        for j in j0..=j1 as u32 {
            let (x, y) = if steep { (j, i) } else { (i, j) };
            let centre = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
            let coverage = (reach - distance_to_segment(centre, a, b)).min(1.0);
            if coverage > 0.0 {
                blend(img.get_pixel_mut(x, y), s.rgb, coverage);
            }
        }
    }
}

fn distance_to_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let len2 = d.length_squared();
    let t = if len2 > 0.0 { ((p - a).dot(d) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a + d * t).distance(p)
}

fn blend(px: &mut image::Rgb<u8>, rgb: [u8; 3], coverage: f64) {
    for (dst, src) in px.0.iter_mut().zip(rgb) {
        let (d, s) = (*dst as f64, src as f64);
        *dst = (d + (s - d) * coverage).round().clamp(0.0, 255.0) as u8;
    }
}

/// The part of segment ab inside the box lo..hi (Liang–Barsky); None if it misses the box.
fn clip(a: DVec2, b: DVec2, lo: DVec2, hi: DVec2) -> Option<(DVec2, DVec2)> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-d.x, a.x - lo.x), (d.x, hi.x - a.x), (-d.y, a.y - lo.y), (d.y, hi.y - a.y)] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then(|| (a + d * t0, a + d * t1))
}
