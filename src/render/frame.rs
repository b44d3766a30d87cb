//! The renderer's output: one sample per pixel, refined pass by pass.

use crate::bvh::RayCounters;
use glam::Vec3;

/// What one primary ray found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelSample {
    /// Hit distance (the ray direction is unit length, so this is the distance to the camera);
    /// `f32::INFINITY` for a miss.
    pub t: f32,
    /// Shading normal at the hit (world space), zero for a miss.
    pub normal: Vec3,
    /// The mesh's triangle index, `u32::MAX` for a miss.
    pub prim: u32,
    /// The traversal's work (zero unless the render counted).
    pub counters: RayCounters,
}

impl PixelSample {
    pub const MISS: PixelSample =
        PixelSample { t: f32::INFINITY, normal: Vec3::ZERO, prim: u32::MAX, counters: RayCounters::ZERO };

    pub fn is_hit(&self) -> bool {
        self.prim != u32::MAX
    }
}

/// A frame being refined. Until the last pass, only every `stride`-th pixel in x and y has been
/// traced; `sample` returns the traced pixel covering a given one, so a coarse frame can be shown.
#[derive(Clone, Debug)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    pub samples: Vec<PixelSample>,
    /// 1 when every pixel was traced; 8, 4 or 2 after a coarse pass; 0 before any pass.
    pub stride: u32,
    /// Whether the counters were recorded.
    pub counted: bool,
}

impl Frame {
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            samples: vec![PixelSample::MISS; width as usize * height as usize],
            stride: 0,
            counted: false,
        }
    }

    pub fn is_complete(&self) -> bool {
        self.stride == 1
    }

    /// The sample shown at pixel (x, y): the nearest traced pixel above-left of it.
    #[inline]
    pub fn sample(&self, x: u32, y: u32) -> &PixelSample {
        let s = self.stride.max(1);
        let (x, y) = (x - x % s, y - y % s);
        &self.samples[(y * self.width + x) as usize]
    }

    /// Iterate the samples actually traced so far (one per `stride`×`stride` block).
    pub fn traced(&self) -> impl Iterator<Item = &PixelSample> + '_ {
        let s = self.stride.max(1) as usize;
        let w = self.width as usize;
        let rows = if self.stride == 0 { 0 } else { self.height as usize };
        (0..rows).step_by(s).flat_map(move |y| (0..w).step_by(s).map(move |x| &self.samples[y * w + x]))
    }

    /// Hit mask, row by row (true = hit), at full resolution.
    pub fn hit_mask(&self) -> Vec<bool> {
        (0..self.height)
            .flat_map(|y| (0..self.width).map(move |x| (x, y)))
            .map(|(x, y)| self.sample(x, y).is_hit())
            .collect()
    }
}

/// Per-ray work over the traced rays of a frame (hit and missed).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct RaySummary {
    pub rays: u64,
    pub hits: u64,
    pub mean_nodes_visited: f64,
    pub max_nodes_visited: u32,
    pub mean_box_tests: f64,
    pub mean_triangle_tests: f64,
    pub max_triangle_tests: u32,
    /// Two-level BVH: top-level nodes visited and instances entered per ray (0 for one BVH).
    pub mean_top_nodes_visited: f64,
    pub mean_instances_entered: f64,
}

impl Frame {
    pub fn ray_summary(&self) -> RaySummary {
        let mut s = RaySummary::default();
        let (mut nodes, mut boxes, mut tris, mut top, mut inst) = (0u64, 0u64, 0u64, 0u64, 0u64);
        for p in self.traced() {
            s.rays += 1;
            s.hits += p.is_hit() as u64;
            nodes += p.counters.nodes_visited as u64;
            boxes += p.counters.box_tests as u64;
            tris += p.counters.triangle_tests as u64;
            top += p.counters.top_nodes_visited as u64;
            inst += p.counters.instances_entered as u64;
            s.max_nodes_visited = s.max_nodes_visited.max(p.counters.nodes_visited);
            s.max_triangle_tests = s.max_triangle_tests.max(p.counters.triangle_tests);
        }
        let n = s.rays.max(1) as f64;
        s.mean_nodes_visited = nodes as f64 / n;
        s.mean_box_tests = boxes as f64 / n;
        s.mean_triangle_tests = tris as f64 / n;
        s.mean_top_nodes_visited = top as f64 / n;
        s.mean_instances_entered = inst as f64 / n;
        s
    }
}
