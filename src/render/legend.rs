//! Drawing a heatmap's legend into an image (for PNG export): a colour bar with its end values and
//! the frame's min / mean / max, in the 8×8 bitmap font of the `font8x8` crate.

use super::Legend;
use font8x8::UnicodeFonts;
use image::{Rgb, RgbImage};

const PAD: u32 = 8;
const TEXT_SCALE: u32 = 2;
const LINE: u32 = 8 * TEXT_SCALE;

fn text_width(s: &str) -> u32 {
    s.chars().count() as u32 * LINE
}

fn draw_text(img: &mut RgbImage, x: u32, y: u32, s: &str, color: Rgb<u8>) {
    for (i, ch) in s.chars().enumerate() {
        let glyph = font8x8::BASIC_FONTS.get(ch).or_else(|| font8x8::LATIN_FONTS.get(ch)).unwrap_or([0; 8]);
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8u32 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                for dy in 0..TEXT_SCALE {
                    for dx in 0..TEXT_SCALE {
                        let px = x + i as u32 * LINE + col * TEXT_SCALE + dx;
                        let py = y + row as u32 * TEXT_SCALE + dy;
                        if px < img.width() && py < img.height() {
                            img.put_pixel(px, py, color);
                        }
                    }
                }
            }
        }
    }
}

/// Format a legend number compactly: integers as integers, others with one decimal.
pub fn fmt_value(v: f64) -> String {
    if (v - v.round()).abs() < 1e-9 && v.abs() < 1e9 {
        format!("{}", v.round() as i64)
    } else {
        format!("{v:.1}")
    }
}

/// The image with a legend strip appended below it.
pub fn draw_legend(img: &RgbImage, legend: &Legend) -> RgbImage {
    let strip = PAD * 4 + LINE * 3;
    let (w, h) = (img.width().max(2 * PAD + 10 * LINE), img.height());
    let mut out = RgbImage::from_pixel(w, h + strip, Rgb([24, 24, 24]));
    image::imageops::replace(&mut out, img, 0, 0);
    let white = Rgb([235, 235, 235]);
    let y0 = h + PAD;
    draw_text(&mut out, PAD, y0, &legend.title, white);
    // Colour bar between the two range labels.
    let lo = fmt_value(legend.range_min as f64);
    let hi = fmt_value(legend.range_max as f64);
    let bar_y = y0 + LINE + PAD;
    let bar_x0 = PAD + text_width(&lo) + PAD;
    let bar_x1 = w.saturating_sub(PAD + text_width(&hi) + PAD).max(bar_x0 + 1);
    draw_text(&mut out, PAD, bar_y, &lo, white);
    draw_text(&mut out, bar_x1 + PAD, bar_y, &hi, white);
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
    draw_text(&mut out, PAD, bar_y + LINE + PAD, &summary, white);
    out
}
