//! Progressive ray casting: pass 1 traces every 8th pixel in x and y, then every 4th, 2nd, and
//! finally the rest, each pass tracing only pixels no earlier pass traced, so the full frame costs
//! one ray per pixel in total. Work is split into bands of 16 rows, cut into pieces of 128 columns
//! (traced in 16-pixel-square tiles) run on rayon; the cancel flag is read before each piece, and
//! the caller sees the frame after each pass. Without counters, an accelerator that traces packets
//! (both BVH layouts, `bvh::packet`; not the linear scan) gets each pass in packets of up to 8×8
//! pixels of the pass's grid; with counters on (the heatmaps) every ray is traced alone. The app's
//! normal and depth views take both: the image from packets, then its counts for the hover
//! read-out and the Statistics panel (`render_passes_counts_after`).

use super::secondary::SecondaryRays;
use crate::bvh::packet::{packet_position, PACKET, PACKET_SIDE};
use crate::bvh::{Accelerator, NoStats, RayCounters, TraceOptions, TraversalStats};
use crate::mesh::Surface;
use crate::render::camera::Camera;
use crate::render::frame::{Frame, FramePool};
use crate::render::sample::PixelSample;
use crate::work::{Cancelled, WorkControl};
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Pixel strides of the passes, coarse to fine.
pub const PASS_STRIDES: [u32; 4] = [8, 4, 2, 1];
const TILE: u32 = 16;
const _: () = assert!(TILE as usize <= crate::render::camera::ROW_RAYS, "a tile's row is made in one call");

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderSettings {
    pub trace: TraceOptions,
    /// Record per-pixel traversal counters (for heatmaps). Off, the plain traversal runs.
    pub count: bool,
    /// Coarse passes first; off, a single full-resolution pass.
    pub progressive: bool,
    /// Secondary rays traced from every hit (`render::secondary`), resolved for the scene and the
    /// camera; the counters are then theirs. `None`: primary rays only.
    pub secondary: Option<SecondaryRays>,
}

/// Reported after each finished pass.
#[derive(Clone, Copy, Debug)]
pub struct PassInfo {
    pub stride: u32,
    /// Rays traced in this pass.
    pub rays: u64,
    pub pass_time: Duration,
    /// Since the render started.
    pub elapsed: Duration,
    /// The pass only adds counters to a frame already handed on whole and uncounted
    /// (`render_passes_counts_after`): its samples, and so its image, are the previous pass's.
    pub counts_only: bool,
    /// The frame is whole but uncounted, and a `counts_only` pass follows.
    pub counts_follow: bool,
}

/// Render a full frame in one pass (no cancellation, no progress).
pub fn render<A: Accelerator, M: Surface + ?Sized>(
    accel: &A,
    mesh: &M,
    camera: &Camera,
    settings: &RenderSettings,
) -> Frame {
    let settings = RenderSettings { progressive: false, ..*settings };
    match render_progressive(accel, mesh, camera, &settings, &FramePool::default(), &WorkControl::new(), |_, _| {}) {
        Ok(frame) => frame,
        Err(Cancelled) => unreachable!("nobody else holds this control"),
    }
}

/// Render pass by pass, into a frame from `frames` (a job that renders again and again keeps one
/// pool). The control's total is set to the pixel count and its done counter advanced as bands
/// finish; `on_pass` sees the frame after each pass. Returns the finished frame, or `Cancelled`
/// once the control is cancelled (checked before each band).
pub fn render_progressive<A: Accelerator, M: Surface + ?Sized>(
    accel: &A,
    mesh: &M,
    camera: &Camera,
    settings: &RenderSettings,
    frames: &FramePool,
    control: &WorkControl,
    mut on_pass: impl FnMut(&Frame, &PassInfo),
) -> Result<Frame, Cancelled> {
    let start = Instant::now();
    control.set_total(camera.width as u64 * camera.height as u64);
    let mut frame = Frame::new_in(frames, camera.width, camera.height, settings.count);
    if let Some(sec) = &settings.secondary {
        frame.set_secondary(&sec.spec);
    }
    let strides: &[u32] = if settings.progressive { &PASS_STRIDES } else { &[1] };
    let mut previous = 0u32;
    for &stride in strides {
        let t = Instant::now();
        let secondary = settings.secondary.filter(|s| s.spec.kind.is_secondary());
        let pass = Pass { accel, mesh, camera, trace: settings.trace, secondary, stride, previous, control };
        let rays = if settings.count {
            pass.trace::<RayCounters>(&mut frame)
        } else if accel.traces_packets() && secondary.is_none() {
            pass.trace_packets(&mut frame)
        } else {
            pass.trace::<NoStats>(&mut frame)
        };
        control.check()?;
        frame.stride = stride;
        previous = stride;
        on_pass(
            &frame,
            &PassInfo {
                stride,
                rays,
                pass_time: t.elapsed(),
                elapsed: start.elapsed(),
                counts_only: false,
                counts_follow: false,
            },
        );
    }
    Ok(frame)
}

/// `render_progressive` for a caller that keeps each pass's frame (the app shows them while it
/// refines): a coarse pass is handed on as a snapshot of its traced pixels (1/stride² of the frame),
/// the last pass as the frame itself, uncopied.
pub fn render_passes<A: Accelerator, M: Surface + ?Sized>(
    accel: &A,
    mesh: &M,
    camera: &Camera,
    settings: &RenderSettings,
    frames: &FramePool,
    control: &WorkControl,
    mut on_pass: impl FnMut(Frame, PassInfo),
) -> Result<(), Cancelled> {
    let mut last = None;
    let frame = render_progressive(accel, mesh, camera, settings, frames, control, |frame, info| {
        if frame.is_complete() {
            last = Some(*info);
        } else {
            on_pass(frame.snapshot(), *info);
        }
    })?;
    on_pass(frame, last.expect("the last pass is complete"));
    Ok(())
}

/// `render_passes` for a view drawn without counters (the normal and depth views) in a program
/// that still reads them (the app's hover read-out and Statistics panel): the passes uncounted, in
/// 8×8 packets (the counted walk goes ray by ray, because a heatmap's count is that of the ray's own
/// walk, and takes about twice as long: BENCHMARKS.md, "Packets in groups of eight on AVX2"), then
/// the frame once more ray by ray with counters, handed on as one more full pass marked
/// `counts_only`. Where packets would not be traced (a tree without them, secondary rays) or
/// `settings.count` is off, this is `render_passes`.
pub fn render_passes_counts_after<A: Accelerator, M: Surface + ?Sized>(
    accel: &A,
    mesh: &M,
    camera: &Camera,
    settings: &RenderSettings,
    frames: &FramePool,
    control: &WorkControl,
    mut on_pass: impl FnMut(Frame, PassInfo),
) -> Result<(), Cancelled> {
    let secondary = settings.secondary.is_some_and(|s| s.spec.kind.is_secondary());
    if !settings.count || secondary || !accel.traces_packets() {
        return render_passes(accel, mesh, camera, settings, frames, control, on_pass);
    }
    let start = Instant::now();
    let image = RenderSettings { count: false, ..*settings };
    render_passes(accel, mesh, camera, &image, frames, control, |frame, info| {
        let counts_follow = frame.is_complete();
        on_pass(frame, PassInfo { counts_follow, ..info })
    })?;
    control.restart();
    let counted = RenderSettings { progressive: false, ..*settings };
    render_passes(accel, mesh, camera, &counted, frames, control, |frame, info| {
        on_pass(frame, PassInfo { elapsed: start.elapsed(), counts_only: true, ..info })
    })
}

/// One pass: the pixels on the `stride` grid that the `previous` grid (0: none) did not cover.
struct Pass<'a, A, M: ?Sized> {
    accel: &'a A,
    mesh: &'a M,
    camera: &'a Camera,
    trace: TraceOptions,
    secondary: Option<SecondaryRays>,
    stride: u32,
    previous: u32,
    control: &'a WorkControl,
}

impl<A: Accelerator, M: Surface + ?Sized> Pass<'_, A, M> {
    /// Trace the pass ray by ray, counting into `S`; returns the rays traced.
    fn trace<S: TraversalStats + Default + Into<RayCounters>>(&self, frame: &mut Frame) -> u64 {
        let Pass { accel, mesh, camera, trace, secondary, stride, previous, control } = *self;
        let gen = camera.ray_gen();
        let width = camera.width as u64;
        for_each_piece(frame, control, |piece| {
            let mut traced = 0u64;
            let Piece { y0, x0, x1, mut samples, mut counters, mut primary } = piece;
            let (mut xs, mut rays) = ([0u32; TILE as usize], [gen.pixel_ray(0, 0); TILE as usize]);
            // Tile by tile across the piece: neighbouring rays walk the same nodes.
            for t0 in (x0..x1).step_by(TILE as usize) {
                for dy in (0..samples.len() as u32).filter(|dy| (y0 + dy).is_multiple_of(stride)) {
                    let y = y0 + dy;
                    // The row's rays made first, together (`RayGen::row_rays`), then traced: made
                    // one by one between walks, each ray's square root and divisions waited on the
                    // one before (10 % of a counted frame on AVX2, BENCHMARKS.md).
                    let mut n = 0;
                    for x in (t0..(t0 + TILE).min(x1)).step_by(stride as usize) {
                        if previous == 0 || !x.is_multiple_of(previous) || !y.is_multiple_of(previous) {
                            xs[n] = x;
                            n += 1;
                        }
                    }
                    gen.row_rays(y, &xs[..n], &mut rays[..n]);
                    for (&x, &(mut ray)) in xs.iter().zip(&rays[..n]) {
                        let mut stats = S::default();
                        let hit = accel.closest_hit(&mut ray, trace, &mut stats);
                        let i = (x - x0) as usize;
                        let s = PixelSample::of(mesh, &ray, hit);
                        samples[dy as usize][i] = s;
                        let mut counted: RayCounters = stats.into();
                        if let Some(sec) = secondary.as_ref() {
                            if let Some(p) = primary.get_mut(dy as usize) {
                                p[i] = counted;
                            }
                            // A missed pixel has no secondary rays: its value is marked, not zero.
                            counted = RayCounters::default();
                            if s.is_hit() {
                                // The hit point: the primary ray's direction is unit length.
                                let point = ray.origin() + ray.dir() * s.t;
                                let pixel = y as u64 * width + x as u64;
                                counted = sec.trace::<A, S>(accel, trace, pixel, point, s.normal, ray.dir()).0;
                            }
                        }
                        if let Some(c) = counters.get_mut(dy as usize) {
                            c[i] = counted;
                        }
                        traced += 1;
                    }
                }
            }
            traced
        })
    }
}

/// Columns of a piece: a multiple of every pass's packet span (`PACKET_SIDE` × the largest
/// stride, 64), so the packets of a pass are those of the whole band, and pieces small enough
/// (2,048 pixels) that 16 threads share a 4K frame's 4,000 of them evenly where the mesh makes
/// some rows far costlier than others (the band alone, 135 of them, left threads idle at the end).
const PIECE_COLUMNS: u32 = 128;

/// A piece of a band for one task: `TILE` rows (fewer at the bottom) from row `y0`, columns
/// `x0..x1`; its slots row by row, each row's from `x0`, and its counters likewise (no rows when the
/// frame does not count).
struct Piece<'a> {
    y0: u32,
    x0: u32,
    x1: u32,
    samples: Vec<&'a mut [PixelSample]>,
    counters: Vec<&'a mut [RayCounters]>,
    /// The primary rays' own counters in a counted frame of secondary rays (else no rows).
    primary: Vec<&'a mut [RayCounters]>,
}

/// Run `trace_piece` on each piece of each band of `TILE` rows in parallel (rayon: the bands, and
/// in each band its pieces, split on the worker that takes the band), skipping pieces once the
/// control is cancelled. The closure returns the rays it traced, which are added to the control's
/// progress and summed.
fn for_each_piece(frame: &mut Frame, control: &WorkControl, trace_piece: impl Fn(Piece) -> u64 + Sync) -> u64 {
    let w = frame.width() as usize;
    let band = w * TILE as usize;
    let (samples, counters, primary) = frame.slots_with_primary_mut();
    if w == 0 {
        return 0;
    }
    let bands = samples.len().div_ceil(band);
    fn bands_of(c: &mut [RayCounters], bands: usize, band: usize) -> Vec<&mut [RayCounters]> {
        if c.is_empty() {
            (0..bands).map(|_| Default::default()).collect()
        } else {
            c.chunks_mut(band).collect()
        }
    }
    let counter_bands = bands_of(counters, bands, band).into_iter().zip(bands_of(primary, bands, band));
    // Each row cut at the pieces' columns, the cuts dealt to the pieces.
    fn cut<T>(band: &mut [T], w: usize) -> Vec<Vec<&mut [T]>> {
        let mut pieces: Vec<Vec<&mut [T]>> = Vec::new();
        for row in band.chunks_mut(w) {
            for (k, part) in row.chunks_mut(PIECE_COLUMNS as usize).enumerate() {
                match pieces.get_mut(k) {
                    Some(p) => p.push(part),
                    None => pieces.push(vec![part]),
                }
            }
        }
        pieces
    }
    crate::parallel::region(|| {
        samples
            .par_chunks_mut(band)
            .zip(counter_bands.collect::<Vec<_>>())
            .enumerate()
            .map(|(b, (samples, (counters, primary)))| {
                let mut counters = cut(counters, w).into_iter();
                let mut primary = cut(primary, w).into_iter();
                let pieces: Vec<Piece> = (cut(samples, w).into_iter().enumerate())
                    .map(|(k, samples)| {
                        let x0 = k as u32 * PIECE_COLUMNS;
                        let x1 = (x0 + PIECE_COLUMNS).min(w as u32);
                        let counters = counters.next().unwrap_or_default();
                        let primary = primary.next().unwrap_or_default();
                        Piece { y0: b as u32 * TILE, x0, x1, samples, counters, primary }
                    })
                    .collect();
                pieces
                    .into_par_iter()
                    .map(|piece| {
                        if control.is_cancelled() {
                            return 0;
                        }
                        let traced = trace_piece(piece);
                        control.add_done(traced);
                        traced
                    })
                    .sum::<u64>()
            })
            .sum()
    })
}

impl<A: Accelerator, M: Surface + ?Sized> Pass<'_, A, M> {
    /// `trace` without counters, in packets: the pass's pixels grouped in blocks of 8×8 pixels of
    /// its grid (fewer rows where the band is shorter), listed in `packet_position` order, leaving
    /// out the pixels an earlier pass traced.
    fn trace_packets(&self, frame: &mut Frame) -> u64 {
        let Pass { accel, mesh, camera, trace, stride, previous, control, .. } = *self;
        let gen = camera.ray_gen();
        let span = PACKET_SIDE * stride;
        for_each_piece(frame, control, |piece| {
            let Piece { y0, x0, x1, mut samples, .. } = piece;
            let rows = samples.len() as u32;
            let mut traced = 0u64;
            let mut rays = Vec::with_capacity(PACKET);
            let mut pixels = Vec::with_capacity(PACKET);
            let mut hits = [None; PACKET];
            // Bands start on a multiple of TILE, which every stride divides: row 0 is on the grid;
            // pieces on a multiple of `PIECE_COLUMNS`, which every span divides.
            for by in (0..rows).step_by(span as usize) {
                for bx in (x0..x1).step_by(span as usize) {
                    rays.clear();
                    pixels.clear();
                    for k in 0..PACKET as u32 {
                        let (gx, gy) = packet_position(k);
                        let (x, dy) = (bx + gx * stride, by + gy * stride);
                        let done_before =
                            previous != 0 && x.is_multiple_of(previous) && (y0 + dy).is_multiple_of(previous);
                        if x < x1 && dy < rows && !done_before {
                            rays.push(gen.pixel_ray(x, y0 + dy));
                            pixels.push((dy as usize, (x - x0) as usize));
                        }
                    }
                    let hits = &mut hits[..rays.len()];
                    accel.closest_hits(&mut rays, hits, trace);
                    for ((ray, hit), &(dy, i)) in rays.iter().zip(hits.iter()).zip(&pixels) {
                        samples[dy][i] = PixelSample::of(mesh, ray, *hit);
                    }
                    traced += rays.len() as u64;
                }
            }
            traced
        })
    }
}

impl From<NoStats> for RayCounters {
    fn from(_: NoStats) -> Self {
        RayCounters::default()
    }
}

#[cfg(test)]
#[path = "raycast_tests.rs"]
mod tests;
