//! Frames of one size written as an animation that loops, in the format the file's name says: a
//! GIF for `.gif` (what slide software plays), an animated PNG for `.png` (every colour exact);
//! any other name is refused before anything is rendered (`ANIMATION.check`).
//!
//! A GIF holds 256 colours: one palette for all frames, learnt from all of them by NeuQuant
//! (Dekker, "Kohonen neural networks for optimal colour quantization", Network 1994), so a
//! colour means the same value in every frame; frames with 256 colours or fewer keep them exactly.

use crate::files::{write_bytes, FileError, OutputKind};
use image::RgbImage;
use std::collections::HashMap;
use std::path::Path;

pub const ANIMATION: OutputKind =
    OutputKind { what: "an animation (.gif: a GIF; .png: an animated PNG)", extensions: &["gif", "png"] };

/// Write `frames` (one size, at least one) shown `delay_ms` each, looping, to `path`.
pub fn write_animation(path: &Path, frames: &[RgbImage], delay_ms: u16) -> Result<(), FileError> {
    ANIMATION.check(path)?;
    let gif = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gif"));
    let err = |e: String| FileError::Write { path: path.into(), source: std::io::Error::other(e) };
    let bytes = if gif { encode_gif(frames, delay_ms) } else { encode_apng(frames, delay_ms) }.map_err(err)?;
    write_bytes(path, &bytes)
}

/// An animated PNG of `frames`.
pub fn encode_apng(frames: &[RgbImage], delay_ms: u16) -> Result<Vec<u8>, String> {
    let e = |e: png::EncodingError| e.to_string();
    let mut out = Vec::new();
    let (w, h) = frames[0].dimensions();
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_animated(frames.len() as u32, 0).map_err(e)?;
    let mut writer = enc.write_header().map_err(e)?;
    for f in frames {
        writer.set_frame_delay(delay_ms, 1000).map_err(e)?;
        writer.write_image_data(f.as_raw()).map_err(e)?;
    }
    writer.finish().map_err(e)?;
    Ok(out)
}

/// One palette of at most 256 colours for all `frames`, and each colour's index in it.
fn palette(frames: &[RgbImage]) -> (Vec<u8>, HashMap<[u8; 3], u8>) {
    // The colours themselves, while there are 256 or fewer.
    let mut seen: HashMap<[u8; 3], u8> = HashMap::new();
    let mut exact = Vec::new();
    for p in frames.iter().flat_map(|f| f.pixels()) {
        if !seen.contains_key(&p.0) {
            if seen.len() == 256 {
                seen.clear();
                break;
            }
            seen.insert(p.0, seen.len() as u8);
            exact.extend_from_slice(&p.0);
        }
    }
    if !seen.is_empty() {
        return (exact, seen);
    }
    // Learn the palette from a sample of every frame (a few hundred thousand pixels).
    let total: usize = frames.iter().map(|f| f.pixels().len()).sum();
    let step = (total / 400_000).max(1);
    let mut sample = Vec::new();
    for (i, p) in frames.iter().flat_map(|f| f.pixels()).enumerate() {
        if i % step == 0 {
            sample.extend_from_slice(&[p.0[0], p.0[1], p.0[2], 255]);
        }
    }
    let nq = color_quant::NeuQuant::new(10, 256, &sample);
    let map: Vec<u8> = nq.color_map_rgb();
    let mut index = HashMap::new();
    for p in frames.iter().flat_map(|f| f.pixels()) {
        index.entry(p.0).or_insert_with(|| nq.index_of(&[p.0[0], p.0[1], p.0[2], 255]) as u8);
    }
    (map, index)
}

/// A looping GIF of `frames` with one global palette.
pub fn encode_gif(frames: &[RgbImage], delay_ms: u16) -> Result<Vec<u8>, String> {
    let (map, index) = palette(frames);
    let (w, h) = frames[0].dimensions();
    let (w16, h16) = (
        u16::try_from(w).map_err(|_| "wider than a GIF's 65,535")?,
        u16::try_from(h).map_err(|_| "taller than a GIF's 65,535")?,
    );
    let mut out = Vec::new();
    {
        let e = |e: gif::EncodingError| e.to_string();
        let mut enc = gif::Encoder::new(&mut out, w16, h16, &map).map_err(e)?;
        enc.set_repeat(gif::Repeat::Infinite).map_err(e)?;
        for f in frames {
            let pixels: Vec<u8> = f.pixels().map(|p| index[&p.0]).collect();
            let mut frame = gif::Frame::from_indexed_pixels(w16, h16, pixels, None);
            // GIF delays are in hundredths of a second.
            frame.delay = (delay_ms as u32).div_ceil(10) as u16;
            enc.write_frame(&frame).map_err(e)?;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(n: usize, colours: u32) -> Vec<RgbImage> {
        (0..n)
            .map(|k| {
                RgbImage::from_fn(40, 30, |x, y| {
                    let c = (x + y * 40 + k as u32 * 7) % colours;
                    image::Rgb([(c * 37 % 256) as u8, (c * 91 % 256) as u8, (c * 13 % 256) as u8])
                })
            })
            .collect()
    }

    /// A .gif is a GIF with every frame (`image` decodes it back), exact when the frames have
    /// few colours; a .png is an animated PNG; any other name is refused.
    #[test]
    fn each_name_gets_its_format_with_every_frame() {
        let dir = crate::scratch::shared("anim");
        let f = frames(5, 100);
        let gif = dir.join("a.gif");
        write_animation(&gif, &f, 400).unwrap();
        let bytes = std::fs::read(&gif).unwrap();
        assert!(bytes.starts_with(b"GIF89a"));
        let mut dec = gif::DecodeOptions::new();
        dec.set_color_output(gif::ColorOutput::RGBA);
        let mut d = dec.read_info(&bytes[..]).unwrap();
        let mut n = 0;
        while let Some(frame) = d.read_next_frame().unwrap() {
            assert_eq!(frame.delay, 40);
            let px = &frame.buffer[..4];
            assert_eq!(px[..3], f[n].get_pixel(0, 0).0, "exact: 100 colours fit a palette");
            n += 1;
        }
        assert_eq!(n, 5);
        let png = dir.join("a.png");
        write_animation(&png, &f, 400).unwrap();
        let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
        let r = dec.read_info().unwrap();
        assert_eq!(r.info().animation_control.map(|a| a.num_frames), Some(5));
        let e = write_animation(&dir.join("a.mp4"), &f, 400).unwrap_err().to_string();
        assert!(e.contains("must end in .gif or .png"), "{e}");
    }

    /// Frames of thousands of colours share one palette of 256 close to them.
    #[test]
    fn many_colours_are_quantised_to_one_close_palette() {
        let f = frames(3, 5000);
        let bytes = encode_gif(&f, 100).unwrap();
        let mut dec = gif::DecodeOptions::new();
        dec.set_color_output(gif::ColorOutput::RGBA);
        let mut d = dec.read_info(&bytes[..]).unwrap();
        let frame = d.read_next_frame().unwrap().unwrap();
        let err: f64 = frame
            .buffer
            .chunks(4)
            .zip(f[0].pixels())
            .map(|(q, p)| (0..3).map(|c| (q[c] as f64 - p.0[c] as f64).abs()).sum::<f64>())
            .sum::<f64>()
            / (40.0 * 30.0 * 3.0);
        assert!(err < 20.0, "mean error per channel {err}");
    }
}
