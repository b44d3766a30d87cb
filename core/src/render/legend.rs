//! Drawing a heatmap's legend into an image (for PNG export): a colour bar with its end values and
//! the frame's min / mean / max, in the 8×8 bitmap font of the `font8x8` crate.

use crate::render::views::Legend;
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

/// Format a legend number compactly: integers as integers, fractions below 1 to four significant
/// digits (a SIMT efficiency of 1/32 is 0.03125, not 0.0: issue 59), others with one decimal, and
/// very large or very small ones in scientific notation (`-1e8`, `3.4e38`), so that any finite
/// range has labels a few characters long. The app's legend, the PNG's and `render`'s line say
/// a figure by it alike.
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
    } else if v.abs() < 1.0 {
        let digits = (3 - v.abs().log10().floor() as i32).max(1) as usize;
        let s = format!("{v:.digits$}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.1}")
    }
}

/// Height of the strip `draw_legend` appends for `legend`.
pub fn legend_height(legend: &Legend) -> u32 {
    rows_height(one_row_each(legend))
}

/// Space between the rows of one wrapped text: less than between the strip's texts, so a headline
/// broken in two still reads as one.
const WRAP_GAP: u32 = PAD / 2;

/// How many rows each text of a legend strip takes when it is wrapped rather than shrunk
/// (`draw_legend_wrapped`). The frames of one film take the largest of each (`max`), so every
/// frame has the same size (a GIF's frames share one) and its headline the same place.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LegendRows {
    pub title: u32,
    pub subject: u32,
    pub note: u32,
    pub summary: u32,
}

impl LegendRows {
    /// Each text's larger count.
    pub fn max(self, o: LegendRows) -> LegendRows {
        LegendRows {
            title: self.title.max(o.title),
            subject: self.subject.max(o.subject),
            note: self.note.max(o.note),
            summary: self.summary.max(o.summary),
        }
    }
}

/// `draw_legend`'s rows: a line for each text it has (the title always).
fn one_row_each(legend: &Legend) -> LegendRows {
    LegendRows {
        title: 1,
        subject: u32::from(!legend.subject.is_empty()),
        note: u32::from(!legend.note.is_empty()),
        summary: 1,
    }
}

/// The strip's height for `rows`: the texts and the colour bar, `PAD` around each, `WRAP_GAP`
/// between the rows of one text.
fn rows_height(r: LegendRows) -> u32 {
    let blocks = [r.title, r.subject, r.note, 1, r.summary];
    let texts = blocks.iter().filter(|&&n| n > 0).count() as u32;
    let rows: u32 = blocks.iter().sum();
    PAD * (texts + 1) + LINE * rows + WRAP_GAP * (rows - texts)
}

/// `s` broken into lines of at most `chars` characters: after a comma where the phrases fit
/// ("nodes visited: 0/2296 splits," above "SAH 4096.0", not "SAH" above its number), else at
/// spaces; a word longer than a line is broken inside it (a path stays whole, not cut off).
fn wrap(s: &str, chars: usize) -> Vec<String> {
    let chars = chars.max(1);
    // A text that fits is kept as it is (the summary's double spaces).
    if !s.is_empty() && s.chars().count() <= chars {
        return vec![s.to_string()];
    }
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for phrase in s.split_inclusive(", ").map(str::trim).filter(|p| !p.is_empty()) {
        let (len, n) = (line.chars().count(), phrase.chars().count());
        if len > 0 && n <= chars && len + 1 + n > chars {
            lines.push(std::mem::take(&mut line));
        }
        for word in phrase.split(' ').filter(|w| !w.is_empty()) {
            add_word(&mut lines, &mut line, word, chars);
        }
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

/// `word` after `line` when it fits there, else on lines of its own (`chars` letters at a time).
fn add_word(lines: &mut Vec<String>, line: &mut String, word: &str, chars: usize) {
    let (len, n) = (line.chars().count(), word.chars().count());
    if len > 0 && len + 1 + n <= chars {
        line.push(' ');
        line.push_str(word);
        return;
    }
    if len > 0 {
        lines.push(std::mem::take(line));
    }
    let letters: Vec<char> = word.chars().collect();
    let mut pieces = letters.chunks(chars).map(|c| c.iter().collect::<String>()).peekable();
    while let Some(piece) = pieces.next() {
        if pieces.peek().is_some() {
            lines.push(piece);
        } else {
            *line = piece;
        }
    }
}

/// Characters of the legend's text size that fit on a line of a strip `w` wide.
fn chars_per_line(w: u32) -> usize {
    (w.saturating_sub(2 * PAD) / text_width("x", TEXT_SCALE)).max(1) as usize
}

/// The rows `legend`'s texts take wrapped at the legend's text size, in the strip below an image
/// `width` wide (the title keeps its row even when empty, as in `draw_legend`).
pub fn legend_rows(width: u32, legend: &Legend) -> LegendRows {
    let chars = chars_per_line(strip_width(width, legend));
    let rows = |s: &str| wrap(s, chars).len() as u32;
    LegendRows {
        title: rows(&legend.title).max(1),
        subject: rows(&legend.subject),
        note: rows(&legend.note),
        summary: rows(&summary(legend)).max(1),
    }
}

/// The frame's min / mean / max, as the strip's last line says them.
fn summary(legend: &Legend) -> String {
    format!(
        "min {}  mean {}  max {}",
        fmt_value(legend.min as f64),
        fmt_value(legend.mean),
        fmt_value(legend.max as f64)
    )
}

/// The strip's width below an image `width` wide: wide enough for both range labels and a bar
/// between them, whatever the image's width.
fn strip_width(width: u32, legend: &Legend) -> u32 {
    let lo = fmt_value(legend.range_min as f64);
    let hi = fmt_value(legend.range_max as f64);
    let labels = PAD + text_width(&lo, TEXT_SCALE) + PAD + 4 * LINE + PAD + text_width(&hi, TEXT_SCALE) + PAD;
    width.max(2 * PAD + 10 * LINE).max(labels)
}

/// The image with a legend strip appended below it: the title, what the image is of (mesh,
/// strategy, layout), the colour bar with its range, and the frame's min / mean / max. A text
/// too long for the strip is drawn at half size.
pub fn draw_legend(img: &RgbImage, legend: &Legend) -> RgbImage {
    strip(img, legend, one_row_each(legend), false)
}

/// `draw_legend` with every text at the legend's size, wrapped onto more rows where it is too
/// long (never shrunk), in at least `rows` rows each: a film's frames, given the `max` of their
/// `legend_rows`, share one size and one headline size whatever each frame's numbers.
pub fn draw_legend_wrapped(img: &RgbImage, legend: &Legend, rows: LegendRows) -> RgbImage {
    strip(img, legend, rows.max(legend_rows(img.width(), legend)), true)
}

/// The strip below `img` with `rows` rows for each text; `wrapped` breaks a long text onto its
/// rows, else it is drawn on one at the size that fits.
fn strip(img: &RgbImage, legend: &Legend, rows: LegendRows, wrapped: bool) -> RgbImage {
    let lo = fmt_value(legend.range_min as f64);
    let hi = fmt_value(legend.range_max as f64);
    let (w, h) = (strip_width(img.width(), legend), img.height());
    let mut out = below(img, w, h + rows_height(rows), [24, 24, 24]);
    let white = Rgb([235, 235, 235]);
    let grey = Rgb([170, 170, 170]);
    let chars = chars_per_line(w);
    // A text in its `n` rows from `y`; the `y` below them and their gap.
    let text = |out: &mut RgbImage, y: u32, s: &str, color: Rgb<u8>, n: u32| -> u32 {
        if n == 0 {
            return y;
        }
        if wrapped {
            for (i, line) in wrap(s, chars).iter().enumerate() {
                draw_text(out, PAD, y + i as u32 * (LINE + WRAP_GAP), line, color, TEXT_SCALE);
            }
        } else {
            draw_line(out, PAD, y, s, color, w - 2 * PAD);
        }
        y + n * LINE + (n - 1) * WRAP_GAP + PAD
    };
    let y = text(&mut out, h + PAD, &legend.title, white, rows.title);
    let y = text(&mut out, y, &legend.subject, grey, rows.subject);
    // Colour bar between the two range labels.
    let bar_y = text(&mut out, y, &legend.note, grey, rows.note);
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
    text(&mut out, bar_y + LINE + PAD, &summary(legend), white, rows.summary);
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
        assert_eq!(fmt_value(0.03125), "0.03125");
        assert_eq!(fmt_value(0.69334), "0.6933");
        assert_eq!(fmt_value(-0.5), "-0.5");
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

    /// Phrases, then words, stay whole where they fit; a word longer than a line is broken, not cut off.
    #[test]
    fn wrap_breaks_after_commas_then_at_spaces_and_inside_only_words_too_long() {
        assert_eq!(
            wrap("nodes visited: 183/21880 splits, SAH 1078.7", 24),
            ["nodes visited: 183/21880", "splits, SAH 1078.7"]
        );
        assert_eq!(
            wrap("nodes visited: 0/2296 splits, SAH 4096.0", 39),
            ["nodes visited: 0/2296 splits,", "SAH 4096.0"]
        );
        assert_eq!(wrap("knot.obj, SAH binned, log scale", 20), ["knot.obj,", "SAH binned,", "log scale"]);
        assert_eq!(wrap("a bunny-from-the-lab.obj x", 8), ["a", "bunny-fr", "om-the-l", "ab.obj x"]);
        assert_eq!(wrap("fits", 4), ["fits"]);
        assert!(wrap("", 10).is_empty());
    }

    /// Wrapped strips for titles of different lengths, given the larger rows, have one size; with
    /// one row each they are `draw_legend`'s strips, pixel for pixel.
    #[test]
    fn wrapped_strips_share_one_size() {
        // 400 pixels: 24 characters a line, the summary's length.
        let img = RgbImage::new(400, 40);
        let short = Legend { title: "visits".into(), ..legend("x") };
        let long = Legend { title: "nodes visited: 183/21880 splits, SAH 1078.7".into(), ..legend("x") };
        let rows = legend_rows(400, &short).max(legend_rows(400, &long));
        assert_eq!(legend_rows(400, &short), one_row_each(&short), "a short title fits on one row");
        assert_eq!(rows, LegendRows { title: 2, subject: 1, note: 0, summary: 1 });
        let (a, b) = (draw_legend_wrapped(&img, &short, rows), draw_legend_wrapped(&img, &long, rows));
        assert_eq!((a.width(), a.height()), (b.width(), b.height()));
        assert_eq!(a.height(), 40 + legend_height(&short) + LINE + WRAP_GAP);
        let wide = RgbImage::new(800, 40);
        assert!(draw_legend_wrapped(&wide, &long, legend_rows(800, &long)) == draw_legend(&wide, &long));
    }
}
