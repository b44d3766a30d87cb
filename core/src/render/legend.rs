//! Drawing a heatmap's legend into an image (for PNG export): a colour bar with its end values and
//! the frame's min / mean / max, in the 8×8 bitmap font of the `font8x8` crate.

use super::Legend;
use font8x8::UnicodeFonts;
use image::{Rgb, RgbImage};
use rayon::prelude::*;

const PAD: u32 = 8;
const TEXT_SCALE: u32 = 2;
const LINE: u32 = 8 * TEXT_SCALE;

/// Width of `s` drawn at `scale` (8 pixels per character per unit of scale).
fn text_width(s: &str, scale: u32) -> u32 {
    s.chars().count() as u32 * 8 * scale
}

fn draw_text(img: &mut RgbImage, x: u32, y: u32, s: &str, color: Rgb<u8>, scale: u32) {
    for (i, ch) in s.chars().enumerate() {
        let glyph = font8x8::BASIC_FONTS.get(ch).or_else(|| font8x8::LATIN_FONTS.get(ch)).unwrap_or([0; 8]);
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8u32 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                for dy in 0..scale {
                    for dx in 0..scale {
                        let px = x + (i as u32 * 8 + col) * scale + dx;
                        let py = y + row as u32 * scale + dy;
                        if px < img.width() && py < img.height() {
                            img.put_pixel(px, py, color);
                        }
                    }
                }
            }
        }
    }
}

/// A line of text in a `LINE`-high row: at the legend's scale when it fits in `width`, else at
/// half that (an 8-pixel font), so a long mesh name in a small image stays whole.
fn draw_line(img: &mut RgbImage, x: u32, y: u32, s: &str, color: Rgb<u8>, width: u32) {
    let scale = if text_width(s, TEXT_SCALE) <= width { TEXT_SCALE } else { 1 };
    draw_text(img, x, y + (LINE - 8 * scale) / 2, s, color, scale);
}

/// Format a legend number compactly: integers as integers, others with one decimal, and very
/// large or very small ones in scientific notation (`-1e8`, `3.4e38`), so that any finite range
/// has labels a few characters long.
pub fn fmt_value(v: f64) -> String {
    if v != 0.0 && !(1e-2..1e6).contains(&v.abs()) {
        // Three significant digits, trailing zeros dropped: 1e20, 2.5e-3, -3.4e38.
        let s = format!("{v:.2e}");
        let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        return format!("{mantissa}e{exp}");
    }
    if (v - v.round()).abs() < 1e-9 {
        format!("{}", v.round() as i64)
    } else {
        format!("{v:.1}")
    }
}

/// Height of the strip `draw_legend` appends for `legend`.
pub fn legend_height(legend: &Legend) -> u32 {
    let lines = 3 + u32::from(!legend.subject.is_empty()) + u32::from(!legend.note.is_empty());
    PAD * (lines + 1) + LINE * lines
}

/// The image with a legend strip appended below it: the title, what the image is of (mesh,
/// strategy, layout), the colour bar with its range, and the frame's min / mean / max.
pub fn draw_legend(img: &RgbImage, legend: &Legend) -> RgbImage {
    let strip = legend_height(legend);
    let lo = fmt_value(legend.range_min as f64);
    let hi = fmt_value(legend.range_max as f64);
    // Wide enough for both range labels and a bar between them, whatever the image's width.
    let labels = PAD + text_width(&lo, TEXT_SCALE) + PAD + 4 * LINE + PAD + text_width(&hi, TEXT_SCALE) + PAD;
    let (w, h) = (img.width().max(2 * PAD + 10 * LINE).max(labels), img.height());
    let mut out = below(img, w, h + strip, [24, 24, 24]);
    let white = Rgb([235, 235, 235]);
    let grey = Rgb([170, 170, 170]);
    let mut y = h + PAD;
    draw_line(&mut out, PAD, y, &legend.title, white, w - 2 * PAD);
    for line in [&legend.subject, &legend.note].into_iter().filter(|l| !l.is_empty()) {
        y += LINE + PAD;
        draw_line(&mut out, PAD, y, line, grey, w - 2 * PAD);
    }
    // Colour bar between the two range labels.
    let bar_y = y + LINE + PAD;
    let bar_x0 = PAD + text_width(&lo, TEXT_SCALE) + PAD;
    let bar_x1 = w.saturating_sub(PAD + text_width(&hi, TEXT_SCALE) + PAD).max(bar_x0 + 1);
    draw_text(&mut out, PAD, bar_y, &lo, white, TEXT_SCALE);
    draw_text(&mut out, bar_x1 + PAD, bar_y, &hi, white, TEXT_SCALE);
    for x in bar_x0..bar_x1 {
        let c = legend.colormap.map((x - bar_x0) as f32 / (bar_x1 - bar_x0 - 1).max(1) as f32);
        for y in bar_y..bar_y + LINE {
            out.put_pixel(x, y, Rgb(c));
        }
    }
    let summary = format!(
        "min {}  mean {}  max {}",
        fmt_value(legend.min as f64),
        fmt_value(legend.mean),
        fmt_value(legend.max as f64)
    );
    draw_line(&mut out, PAD, bar_y + LINE + PAD, &summary, white, w - 2 * PAD);
    out
}

/// A `w`×`h` image (at least `img`'s size) with `img` at its top left and `background` elsewhere:
/// what `from_pixel` and `imageops::replace` make, rows copied in parallel (at 4K, pixel by pixel
/// on one thread, they were a serial stretch of the frame as long as its image's colouring).
fn below(img: &RgbImage, w: u32, h: u32, background: [u8; 3]) -> RgbImage {
    let (iw, ih) = (img.width() as usize, img.height() as usize);
    let mut buf = vec![0u8; w as usize * h as usize * 3];
    if w > 0 {
        crate::parallel::region(|| {
            buf.par_chunks_mut(w as usize * 3).enumerate().for_each(|(y, row)| {
                let copied = if y < ih { iw * 3 } else { 0 };
                if copied > 0 {
                    row[..copied].copy_from_slice(&img.as_raw()[y * iw * 3..(y + 1) * iw * 3]);
                }
                for px in row[copied..].chunks_exact_mut(3) {
                    px.copy_from_slice(&background);
                }
            })
        });
    }
    RgbImage::from_raw(w, h, buf).expect("the buffer holds w×h pixels")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn legend(subject: &str) -> Legend {
        Legend {
            title: "nodes visited per ray".into(),
            subject: subject.into(),
            note: String::new(),
            colormap: super::super::ColorMap::Viridis,
            range_min: 0.0,
            range_max: 60.0,
            min: 1.0,
            max: 59.0,
            mean: 12.5,
        }
    }

    /// Rows of the strip that have any light pixel (text or bar).
    fn inked_rows(img: &RgbImage, from: u32) -> Vec<u32> {
        (from..img.height()).filter(|&y| (0..img.width()).any(|x| img.get_pixel(x, y).0[0] > 100)).collect()
    }

    /// Any finite range draws, however large its numbers and however small the image (it
    /// used to index past the image's right edge).
    #[test]
    fn any_finite_range_draws_on_any_image() {
        for (lo, hi) in [(-1e8, 1.0), (0.0, 1e20), (-3e38, 3e38), (-f32::MAX, f32::MAX), (1e-30, 2e-30)] {
            for w in [1, 8, 32, 300] {
                let l = Legend { range_min: lo, range_max: hi, min: lo, max: hi, mean: 0.0, ..legend("x") };
                let out = draw_legend(&RgbImage::new(w, 4), &l);
                assert!(out.width() >= w);
            }
        }
        assert_eq!(fmt_value(-1e8), "-1e8");
        assert_eq!(fmt_value(3.4e38), "3.4e38");
        assert_eq!(fmt_value(12.0), "12");
        assert_eq!(fmt_value(2.5), "2.5");
        assert_eq!(fmt_value(0.0025), "2.5e-3");
    }

    /// The parallel copy makes what `from_pixel` and `replace` made.
    #[test]
    fn the_image_above_the_strip_is_copied_whole() {
        let img = RgbImage::from_fn(37, 11, |x, y| Rgb([x as u8, y as u8, (x * y) as u8]));
        for (w, h) in [(37, 11), (37, 30), (50, 11), (64, 40)] {
            let mut want = RgbImage::from_pixel(w, h, Rgb([24, 24, 24]));
            image::imageops::replace(&mut want, &img, 0, 0);
            assert_eq!(below(&img, w, h, [24, 24, 24]), want, "{w}×{h}");
        }
    }

    #[test]
    fn the_strip_names_what_the_image_shows_on_a_line_of_its_own() {
        let img = RgbImage::new(320, 40);
        let plain = draw_legend(&img, &legend(""));
        let named = draw_legend(&img, &legend("bunny.obj, SAH binned, binary"));
        assert_eq!(named.height() - plain.height(), LINE + PAD, "one more line");
        assert_eq!(named.height(), 40 + legend_height(&legend("x")));
        // The subject line has ink between the title and the bar.
        let title_end = 40 + PAD + LINE;
        let subject_rows: Vec<u32> =
            inked_rows(&named, title_end).into_iter().filter(|&y| y < title_end + PAD + LINE).collect();
        assert!(!subject_rows.is_empty(), "the subject is drawn");
        // A subject too long for the strip at the legend's scale is drawn at half size, whole.
        let long = "a-very-long-mesh-name-from-a-scanning-lab.obj, SAH sweep, 4-wide SIMD";
        assert!(text_width(long, TEXT_SCALE) > 600 - 2 * PAD && text_width(long, 1) <= 600 - 2 * PAD);
        let small = draw_legend(&RgbImage::new(600, 10), &legend(long));
        let last_col = (0..small.width())
            .rev()
            .find(|&x| (10 + PAD + LINE..10 + 2 * (PAD + LINE)).any(|y| small.get_pixel(x, y).0[0] > 100));
        assert!(last_col.is_some_and(|x| x < 600 - PAD), "the long subject ends inside the strip: {last_col:?}");
    }
}
