//! The renderer's output: one sample per pixel, refined pass by pass, and the traversal counters
//! beside it when the render counted.
//!
//! Samples and counters live in two arrays, and the counters only when asked for: the plain
//! view's frame stays small (20 bytes a pixel, 18 MB at 1280×720). One array of 48-byte samples
//! (44 MB at 1280×720, past the 32 MiB up to which glibc's malloc reuses freed memory) was freshly
//! mapped, faulted in and unmapped on every frame, a cost the app's frame rate showed
//! (BENCHMARKS.md, "The frame regression, located"); larger views pass that limit whatever the
//! layout, so the render job keeps dropped frames' storage for its next frame.

use super::sample::PixelSample;
use super::secondary::{RayKind, SecondarySpec};
use crate::bvh::RayCounters;
use rayon::prelude::*;

/// A frame being refined. Until the last pass, only every `stride`-th pixel in x and y has been
/// traced; `sample` returns the traced pixel covering a given one, so a coarse frame can be shown.
///
/// The renderer's working frame stores a slot for every pixel (later passes fill the gaps); a
/// `snapshot` of a coarse pass stores only the traced pixels, so handing it on costs 1/stride² of
/// the full frame.
///
/// The fields are private: the indexing depends on them together (`step` divides `stride`).
#[derive(Clone, Debug)]
pub struct Frame {
    width: u32,
    height: u32,
    /// 1 when every pixel was traced; 8, 4 or 2 after a coarse pass; 0 before any pass. Set by
    /// the renderer after each pass.
    pub(super) stride: u32,
    /// Pixel spacing of the stored samples: 1, or `stride` in a snapshot.
    step: u32,
    /// Row by row over the stored grid.
    samples: Vec<PixelSample>,
    /// One per stored sample when the render counted, else empty. In a frame of secondary rays,
    /// the sum over the pixel's secondary rays (none where the primary ray missed).
    counters: Vec<RayCounters>,
    /// What the counters are of: `Primary`, or the secondary rays traced from each hit.
    kind: RayKind,
    /// Secondary rays traced from each pixel whose primary ray hit (0 in a primary frame).
    per_hit: u32,
    /// In a counted frame of secondary rays, the primary rays' own counters; else empty.
    primary: Vec<RayCounters>,
    /// The secondary rays' whole spec (seed, light, length), `None` in a primary frame: figures
    /// of another seed are of other rays, which the kind alone does not tell (issue 59).
    spec: Option<SecondarySpec>,
    /// Where the storage goes when the frame is dropped.
    pool: FramePool,
}

impl Frame {
    /// An untraced full-resolution frame, with counters if `counted`, on fresh storage that is
    /// freed when it is dropped.
    pub fn new(width: u32, height: u32, counted: bool) -> Self {
        Self::new_in(&FramePool::default(), width, height, counted)
    }

    /// `new`, on a dropped frame's storage from `pool` when one large enough was kept, else fresh;
    /// filled in parallel either way. The frame, and its snapshots, return their storage to
    /// `pool` when dropped.
    pub fn new_in(pool: &FramePool, width: u32, height: u32, counted: bool) -> Self {
        let n = width as usize * height as usize;
        let (mut samples, mut counters) = pool.take(n, counted);
        // In parallel: a 4K counted frame is 400 MB, whose pages are faulted in by this fill.
        crate::parallel::region(|| {
            samples.par_extend(rayon::iter::repeat_n(PixelSample::MISS, n));
            if counted {
                counters.par_extend(rayon::iter::repeat_n(RayCounters::ZERO, n));
            }
        });
        Self {
            width,
            height,
            stride: 0,
            step: 1,
            samples,
            counters,
            kind: RayKind::Primary,
            per_hit: 0,
            primary: Vec::new(),
            spec: None,
            pool: pool.clone(),
        }
    }

    /// The frame as one of `spec`'s secondary rays (set by the renderer before it traces; a
    /// counted one gets room for the primary rays' own counters).
    pub(super) fn set_secondary(&mut self, spec: &SecondarySpec) {
        self.kind = spec.kind;
        self.per_hit = spec.rays_per_hit();
        self.spec = spec.kind.is_secondary().then_some(*spec);
        if self.counted() && spec.kind.is_secondary() {
            self.primary = vec![RayCounters::ZERO; self.counters.len()];
        }
    }

    /// What the counters are of, and the secondary rays per hit pixel (0 for primary rays).
    pub fn ray_kind(&self) -> (RayKind, u32) {
        (self.kind, self.per_hit)
    }

    /// The secondary rays the frame traced from its hits (`None`: the camera's rays).
    pub fn secondary(&self) -> Option<&SecondarySpec> {
        self.spec.as_ref()
    }

    /// A heatmap's value at a traced pixel: the metric of its ray, or in a frame of secondary
    /// rays the mean over the pixel's secondary rays; `None` where a frame of secondary rays
    /// has none (the primary ray missed), which the views mark as such, never as zero.
    #[inline]
    pub fn value(&self, view: super::View, s: &PixelSample, c: &RayCounters, cost: crate::bvh::SahCost) -> Option<f32> {
        match self.per_hit {
            0 => Some(view.metric(c, cost)),
            _ if !s.is_hit() => None,
            n => Some(view.metric(c, cost) / n as f32),
        }
    }

    /// The primary ray's own counters behind `sample(x, y)` in a counted frame of secondary
    /// rays; in a primary frame, `counters(x, y)`.
    pub fn primary_counters(&self, x: u32, y: u32) -> RayCounters {
        if self.primary.is_empty() {
            return self.counters(x, y);
        }
        let s = self.stride.max(1);
        self.primary.get(self.grid_index(x / s, y / s)).copied().unwrap_or(RayCounters::ZERO)
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// 1 when every pixel was traced; 8, 4 or 2 after a coarse pass; 0 before any pass.
    pub fn stride(&self) -> u32 {
        self.stride
    }

    pub fn is_complete(&self) -> bool {
        self.stride == 1
    }

    /// Whether the traversal counters were recorded.
    pub fn counted(&self) -> bool {
        !self.counters.is_empty()
    }

    /// Columns and rows of the traced grid (the full size once complete).
    pub fn grid_size(&self) -> (u32, u32) {
        let s = self.stride.max(1);
        (self.width.div_ceil(s), self.height.div_ceil(s))
    }

    /// Stored slots from one traced pixel to the next in a row (1 in a snapshot).
    #[inline]
    fn slots_per_grid_step(&self) -> usize {
        debug_assert!(self.stride.max(1).is_multiple_of(self.step), "step divides stride");
        (self.stride.max(1) / self.step) as usize
    }

    /// Index of the stored slot of traced grid point (gx, gy).
    #[inline]
    fn grid_index(&self, gx: u32, gy: u32) -> usize {
        let per_step = self.slots_per_grid_step();
        let cols = self.width.div_ceil(self.step) as usize;
        gy as usize * per_step * cols + gx as usize * per_step
    }

    /// The traced sample at grid point (gx, gy), i.e. pixel (gx·stride, gy·stride).
    #[inline]
    pub fn grid_sample(&self, gx: u32, gy: u32) -> &PixelSample {
        &self.samples[self.grid_index(gx, gy)]
    }

    /// Its counters (zero when the render did not count).
    #[inline]
    pub fn grid_counters(&self, gx: u32, gy: u32) -> RayCounters {
        self.counters.get(self.grid_index(gx, gy)).copied().unwrap_or(RayCounters::ZERO)
    }

    /// The sample shown at pixel (x, y): the nearest traced pixel above-left of it.
    #[inline]
    pub fn sample(&self, x: u32, y: u32) -> &PixelSample {
        let s = self.stride.max(1);
        self.grid_sample(x / s, y / s)
    }

    /// The counters of the ray behind `sample(x, y)`.
    pub fn counters(&self, x: u32, y: u32) -> RayCounters {
        let s = self.stride.max(1);
        self.grid_counters(x / s, y / s)
    }

    /// Row `gy` of the traced grid: each traced sample with its counters (zero when uncounted).
    pub fn grid_row(&self, gy: u32) -> impl Iterator<Item = (&PixelSample, RayCounters)> + '_ {
        let (cols, _) = self.grid_size();
        let per = self.slots_per_grid_step();
        let start = self.grid_index(0, gy);
        let counters = self.counters.get(start..).unwrap_or_default().iter().step_by(per).copied();
        let samples = self.samples[start..].iter().step_by(per).take(cols as usize);
        samples.zip(counters.chain(std::iter::repeat(RayCounters::ZERO)))
    }

    /// The samples traced so far (one per `stride`×`stride` block) with their counters, row by row.
    pub fn traced(&self) -> impl Iterator<Item = (&PixelSample, RayCounters)> + '_ {
        let rows = if self.stride == 0 { 0 } else { self.grid_size().1 };
        (0..rows).flat_map(move |gy| self.grid_row(gy))
    }

    /// How many traced pixels hit something: rows in parallel (at 4K, the serial count was as
    /// long as a 16-thread frame's whole image).
    pub fn hit_count(&self) -> usize {
        let rows = if self.stride == 0 { 0 } else { self.grid_size().1 };
        crate::parallel::region(|| {
            (0..rows).into_par_iter().map(|gy| self.grid_row(gy).filter(|(s, _)| s.is_hit()).count()).sum()
        })
    }

    /// Every pixel's sample, row by row, of a complete frame (`None` before the last pass).
    pub fn full_samples(&self) -> Option<&[PixelSample]> {
        (self.is_complete() && self.step == 1).then_some(&self.samples[..])
    }

    /// A copy of what has been traced: the whole frame once complete, else only the traced pixels.
    pub fn snapshot(&self) -> Frame {
        if self.step == self.stride.max(1) {
            return self.clone();
        }
        let (cols, rows) = self.grid_size();
        let n = cols as usize * rows as usize;
        let (mut samples, mut counters) = self.pool.take(n, self.counted());
        self.gather(&mut samples, PixelSample::MISS, |(s, _)| *s);
        if self.counted() {
            self.gather(&mut counters, RayCounters::ZERO, |(_, c)| c);
        }
        // The primary rays' counters of the traced pixels, in the snapshot's order (small: only
        // frames of secondary rays have them).
        let primary = match self.primary.is_empty() {
            true => Vec::new(),
            false => (0..rows)
                .flat_map(|gy| (0..cols).map(move |gx| (gx, gy)))
                .map(|(gx, gy)| self.primary[self.grid_index(gx, gy)])
                .collect(),
        };
        let pool = self.pool.clone();
        Frame {
            width: self.width,
            height: self.height,
            stride: self.stride,
            step: self.stride,
            samples,
            counters,
            kind: self.kind,
            per_hit: self.per_hit,
            primary,
            spec: self.spec,
            pool,
        }
    }

    /// Fill the empty `out` with `pick` of each traced pixel, row by row of the grid; rows in
    /// parallel, as the gather is memory-bound (`fill` only sizes the vector first).
    fn gather<T: Copy + Send + Sync>(
        &self,
        out: &mut Vec<T>,
        fill: T,
        pick: impl Fn((&PixelSample, RayCounters)) -> T + Sync,
    ) {
        let (cols, rows) = self.grid_size();
        out.par_extend(rayon::iter::repeat_n(fill, cols as usize * rows as usize));
        if cols == 0 {
            return;
        }
        out.par_chunks_mut(cols as usize).enumerate().for_each(|(gy, row)| {
            for (to, from) in row.iter_mut().zip(self.grid_row(gy as u32)) {
                *to = pick(from);
            }
        });
    }

    /// The full-resolution frame's storage, for the renderer to fill: samples and counters
    /// (empty when not counting), row by row.
    pub(super) fn slots_mut(&mut self) -> (&mut [PixelSample], &mut [RayCounters]) {
        debug_assert_eq!(self.step, 1, "only the working frame is traced into");
        (&mut self.samples, &mut self.counters)
    }

    /// `slots_mut` with the primary rays' counters of a counted frame of secondary rays (empty
    /// otherwise).
    pub(super) fn slots_with_primary_mut(&mut self) -> (&mut [PixelSample], &mut [RayCounters], &mut [RayCounters]) {
        debug_assert_eq!(self.step, 1, "only the working frame is traced into");
        (&mut self.samples, &mut self.counters, &mut self.primary)
    }

    /// The counts behind the heatmaps, as CSV: a header, then one row per pixel, row by row:
    /// `x,y,nodes_visited,box_tests,leaves_visited,triangle_tests,hit_triangle` (pixels 0-based
    /// from the top left, `-1` for a miss). In a frame of secondary rays (`secondary_counts_csv`)
    /// the counts are of the pixel's secondary rays. `None` unless the frame is complete and counted.
    pub fn counts_csv(&self) -> Option<String> {
        use std::fmt::Write;
        if !self.counted() || self.full_samples().is_none() {
            return None;
        }
        if self.kind.is_secondary() {
            return Some(self.secondary_counts_csv());
        }
        let mut o = String::from("x,y,nodes_visited,box_tests,leaves_visited,triangle_tests,hit_triangle\n");
        for y in 0..self.height {
            for x in 0..self.width {
                let (s, c) = (self.sample(x, y), self.counters(x, y));
                let hit = if s.is_hit() { s.prim as i64 } else { -1 };
                let (n, b, l, t) = (c.nodes_visited, c.box_tests, c.leaves_visited, c.triangle_tests);
                let _ = writeln!(o, "{x},{y},{n},{b},{l},{t},{hit}");
            }
        }
        Some(o)
    }

    /// `counts_csv` of a frame of secondary rays: `x,y,rays,nodes_visited,box_tests,
    /// leaves_visited,triangle_tests,hits,hit_triangle,primary_nodes_visited,primary_triangle_tests`:
    /// the pixel's secondary rays (0 where the primary ray missed), the sums of their counts,
    /// then the primary ray's triangle and own counts. Sums, not means: exact in integers.
    fn secondary_counts_csv(&self) -> String {
        use std::fmt::Write;
        let mut o = String::from("x,y,rays,nodes_visited,box_tests,leaves_visited,triangle_tests,hit_triangle,primary_nodes_visited,primary_triangle_tests\n");
        for y in 0..self.height {
            for x in 0..self.width {
                let (s, c, p) = (self.sample(x, y), self.counters(x, y), self.primary_counters(x, y));
                let (hit, rays) = if s.is_hit() { (s.prim as i64, self.per_hit) } else { (-1, 0) };
                let (n, b, l, t) = (c.nodes_visited, c.box_tests, c.leaves_visited, c.triangle_tests);
                let _ = writeln!(o, "{x},{y},{rays},{n},{b},{l},{t},{hit},{},{}", p.nodes_visited, p.triangle_tests);
            }
        }
        o
    }

    /// Hit mask, row by row (true = hit), at full resolution.
    pub fn hit_mask(&self) -> Vec<bool> {
        (0..self.height)
            .flat_map(|y| (0..self.width).map(move |x| (x, y)))
            .map(|(x, y)| self.sample(x, y).is_hit())
            .collect()
    }
}

/// Why per-pixel results cannot make a frame (`Frame::from_hits`).
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum FromHitsError {
    #[error("{what}: {got} given for a {width}x{height} frame of {pixels} pixels")]
    Length { what: &'static str, got: usize, width: u32, height: u32, pixels: usize },
    #[error("pixel ({x}, {y}) hit triangle {prim}, but the mesh has {triangles} triangles")]
    NoSuchTriangle { x: u32, y: u32, prim: u32, triangles: usize },
    #[error(transparent)]
    Camera(#[from] super::CameraError),
}

impl Frame {
    /// A complete frame of `camera` from hits and counts traced elsewhere (the GPU path): `hits`
    /// per pixel row by row from the top left, and `counters` likewise or empty (then the frame
    /// is uncounted). Each sample is made as the renderer makes it, from the hit and the pixel's
    /// ray (`Camera::ray_gen().pixel_ray`), so every view, legend, histogram and `counts_csv` of
    /// the frame is what a render with these hits and counts gives.
    pub fn from_hits(
        mesh: &crate::mesh::Mesh,
        camera: &super::Camera,
        hits: &[Option<crate::bvh::Hit>],
        counters: &[RayCounters],
    ) -> Result<Frame, FromHitsError> {
        camera.validate()?;
        let (width, height) = (camera.width, camera.height);
        let pixels = width as usize * height as usize;
        let length = |what, got| FromHitsError::Length { what, got, width, height, pixels };
        if hits.len() != pixels {
            return Err(length("hits", hits.len()));
        }
        if !counters.is_empty() && counters.len() != pixels {
            return Err(length("counters", counters.len()));
        }
        let triangles = mesh.triangle_count();
        if let Some(i) = hits.iter().position(|h| h.is_some_and(|h| h.prim as usize >= triangles)) {
            let prim = hits[i].map_or(0, |h| h.prim);
            let (x, y) = ((i % width as usize) as u32, (i / width as usize) as u32);
            return Err(FromHitsError::NoSuchTriangle { x, y, prim, triangles });
        }
        let mut frame = Frame::new(width, height, !counters.is_empty());
        let gen = camera.ray_gen();
        let (samples, slots) = frame.slots_mut();
        samples.par_chunks_mut(width as usize).zip(hits.par_chunks(width as usize)).enumerate().for_each(
            |(y, (row, hits))| {
                for (x, (s, hit)) in row.iter_mut().zip(hits).enumerate() {
                    *s = PixelSample::of(mesh, &gen.pixel_ray(x as u32, y as u32), *hit);
                }
            },
        );
        slots.copy_from_slice(counters);
        frame.stride = 1;
        Ok(frame)
    }
}

impl Drop for Frame {
    fn drop(&mut self) {
        self.pool.keep(std::mem::take(&mut self.samples), std::mem::take(&mut self.counters));
    }
}

/// Storage of a render job's dropped frames, for its new frames and snapshots to reuse. A fresh
/// allocation of a frame's size is mapped anew by the system allocator, its pages faulted in on
/// first touch and unmapped again when freed; on this machine that cost more than tracing the
/// bunny's frame (BENCHMARKS.md, "The frame regression, located"). The app's render job drops a
/// frame and its three coarse snapshots per render, so the last `KEPT` vectors of each kind are
/// kept (first in, first out), at most `MAX_BYTES` of each: at the app's largest view (2560×1440)
/// a counted frame and its snapshots fit, about 230 MB in all. Vectors under `MIN_BYTES` are left
/// to the allocator.
///
/// A frame made in a pool returns its storage to that pool when dropped, wherever it is dropped
/// (the app drops frames on the UI thread); the storage is freed with the pool's last frame or
/// handle. Clones share one pool.
#[derive(Clone, Default)]
pub struct FramePool(std::sync::Arc<std::sync::Mutex<Kept>>);

#[derive(Default)]
struct Kept {
    samples: Vec<Vec<PixelSample>>,
    counters: Vec<Vec<RayCounters>>,
}

impl std::fmt::Debug for FramePool {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("FramePool")
    }
}

impl FramePool {
    const KEPT: usize = 4;
    const MIN_BYTES: usize = 1 << 20;
    const MAX_BYTES: usize = 192 << 20;

    /// Empty vectors able to hold `n` samples, and `n` counters if `counted`: the smallest kept
    /// ones large enough, else fresh.
    fn take(&self, n: usize, counted: bool) -> (Vec<PixelSample>, Vec<RayCounters>) {
        fn smallest_fitting<T>(kept: &mut Vec<Vec<T>>, n: usize) -> Vec<T> {
            let fitting = kept.iter().enumerate().filter(|(_, v)| v.capacity() >= n);
            match fitting.min_by_key(|(_, v)| v.capacity()) {
                Some((i, _)) => kept.remove(i),
                None => Vec::new(),
            }
        }
        let (mut samples, mut counters) = (Vec::new(), Vec::new());
        if let Ok(mut kept) = self.0.lock() {
            samples = smallest_fitting(&mut kept.samples, n);
            if counted {
                counters = smallest_fitting(&mut kept.counters, n);
            }
        }
        samples.clear();
        samples.reserve_exact(n);
        counters.clear();
        counters.reserve_exact(if counted { n } else { 0 });
        (samples, counters)
    }

    /// Keep a dropped frame's vectors; the oldest kept ones beyond `KEPT` are freed, outside the lock.
    fn keep(&self, samples: Vec<PixelSample>, counters: Vec<RayCounters>) {
        fn push<T>(kept: &mut Vec<Vec<T>>, v: Vec<T>, evicted: &mut Vec<Vec<T>>) {
            let bytes = |v: &Vec<T>| v.capacity() * size_of::<T>();
            if bytes(&v) >= FramePool::MIN_BYTES {
                kept.push(v);
                while kept.len() > FramePool::KEPT || kept.iter().map(bytes).sum::<usize>() > FramePool::MAX_BYTES {
                    evicted.push(kept.remove(0));
                }
            }
        }
        let (mut old_samples, mut old_counters) = (Vec::new(), Vec::new());
        if let Ok(mut kept) = self.0.lock() {
            push(&mut kept.samples, samples, &mut old_samples);
            push(&mut kept.counters, counters, &mut old_counters);
        }
    }
}

#[cfg(test)]
#[path = "frame_tests.rs"]
mod tests;
