//! What a GPU warp pays: rays run in groups of 32 lanes (64 on some GPUs) that step together, so a
//! group takes as long as its longest ray while lanes whose ray has finished sit idle (SIMT
//! execution; Aila & Laine, "Understanding the Efficiency of Ray Traversal on GPUs", HPG 2009).
//! From per-ray counts (the GPU's or the CPU's, which are equal) this computes each group's cost,
//! the most work of its rays, and its SIMT efficiency, mean over max.
//!
//! Groups are the lanes the GPU crate's trace kernels give a warp: for a frame, blocks of 8×4
//! pixels (32) or 8×8 (64), as the 8×8 workgroups of `trace_camera` are split into warps; for a
//! ray list, runs of consecutive rays. Pixels past the frame's edge are no lanes of their group.
//!
//! It lives in core, not in the GPU crate that first needed it, because it needs no GPU: the
//! heatmap views `warp-cost` and `simt-efficiency` compute it from any frame's counts, so they
//! work on the CPU path too (`bvhscope-gpu` re-exports it).

use crate::bvh::RayCounters;

/// Lanes per group.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum WarpSize {
    /// NVIDIA's warp, and most GPUs'.
    #[default]
    W32,
    /// AMD's wave64.
    W64,
}

impl WarpSize {
    pub const ALL: [WarpSize; 2] = [WarpSize::W32, WarpSize::W64];

    /// The size of `lanes` lanes (32 or 64), for a command line's `--warp`.
    pub fn from_lanes(lanes: u32) -> Option<WarpSize> {
        WarpSize::ALL.into_iter().find(|w| w.lanes() == lanes)
    }

    pub fn lanes(self) -> u32 {
        match self {
            WarpSize::W32 => 32,
            WarpSize::W64 => 64,
        }
    }

    /// The pixel block of a group: 8 wide, 4 or 8 tall.
    pub fn block(self) -> (u32, u32) {
        (8, self.lanes() / 8)
    }
}

/// Which count is a ray's work.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum WarpWork {
    /// Steps of the walk's loop: nodes visited plus triangle tests.
    #[default]
    Steps,
    NodesVisited,
    BoxTests,
    TriangleTests,
}

impl WarpWork {
    pub fn of(self, c: &RayCounters) -> u32 {
        match self {
            WarpWork::Steps => c.nodes_visited + c.triangle_tests,
            WarpWork::NodesVisited => c.nodes_visited,
            WarpWork::BoxTests => c.box_tests,
            WarpWork::TriangleTests => c.triangle_tests,
        }
    }
}

/// One group: its lanes, their work summed, and the most work of one lane (the group's cost).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WarpGroup {
    pub lanes: u32,
    pub total: u64,
    pub max: u32,
}

impl WarpGroup {
    /// Mean work over the most work: 1 when every lane works as long as the longest (or none works).
    pub fn efficiency(&self) -> f64 {
        if self.max == 0 {
            1.0
        } else {
            self.total as f64 / (self.lanes as f64 * self.max as f64)
        }
    }
}

/// The groups of a frame or a ray list.
#[derive(Clone, Debug, PartialEq)]
pub struct WarpView {
    pub size: WarpSize,
    pub work: WarpWork,
    /// Groups per row of blocks (a frame) or 1 (a list, whose groups form one column).
    pub columns: u32,
    /// Frame size in pixels, (rays, 1) for a list.
    pub width: u32,
    pub height: u32,
    /// Row by row of blocks, or in ray order.
    pub groups: Vec<WarpGroup>,
}

/// The figures `stats` prints.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct WarpSummary {
    /// Σ work over Σ (lanes × group cost): the share of lane-steps that do work.
    pub simt_efficiency: f64,
    /// The mean of the groups' efficiencies.
    pub mean_group_efficiency: f64,
    /// Σ group cost: what the groups take, one after another, in steps.
    pub total_cost: u64,
    /// The mean group cost.
    pub mean_cost: f64,
    pub max_cost: u32,
}

impl WarpSummary {
    /// The figures as `stats --warp` prints them and the app's statistics show them, one text
    /// for both (issue 59: the app never showed the headline efficiency).
    pub fn text(&self) -> String {
        format!(
            "SIMT efficiency {:.4} (mean of groups {:.4}), group cost mean {:.2}, max {}, total {} steps",
            self.simt_efficiency, self.mean_group_efficiency, self.mean_cost, self.max_cost, self.total_cost
        )
    }
}

impl WarpView {
    /// The groups of a `width`×`height` frame's per-pixel counts (row by row from the top).
    pub fn frame(width: u32, height: u32, counters: &[RayCounters], size: WarpSize, work: WarpWork) -> WarpView {
        assert_eq!(counters.len(), width as usize * height as usize, "one count per pixel");
        let (bw, bh) = size.block();
        let columns = width.div_ceil(bw);
        let mut groups = vec![WarpGroup::default(); (columns * height.div_ceil(bh)) as usize];
        for y in 0..height {
            for x in 0..width {
                let g = &mut groups[((y / bh) * columns + x / bw) as usize];
                let w = work.of(&counters[(y * width + x) as usize]);
                g.lanes += 1;
                g.total += w as u64;
                g.max = g.max.max(w);
            }
        }
        WarpView { size, work, columns, width, height, groups }
    }

    /// The groups of a ray list's counts: consecutive rays, as the list kernel's lanes take them.
    pub fn list(counters: &[RayCounters], size: WarpSize, work: WarpWork) -> WarpView {
        let groups = counters
            .chunks(size.lanes() as usize)
            .map(|c| {
                let w: Vec<u32> = c.iter().map(|c| work.of(c)).collect();
                WarpGroup {
                    lanes: w.len() as u32,
                    total: w.iter().map(|&x| x as u64).sum(),
                    max: w.iter().copied().max().unwrap_or(0),
                }
            })
            .collect();
        WarpView { size, work, columns: 1, width: counters.len() as u32, height: 1, groups }
    }

    pub fn summary(&self) -> WarpSummary {
        let total: u64 = self.groups.iter().map(|g| g.total).sum();
        let lane_steps: u64 = self.groups.iter().map(|g| g.lanes as u64 * g.max as u64).sum();
        let total_cost: u64 = self.groups.iter().map(|g| g.max as u64).sum();
        let n = self.groups.len().max(1) as f64;
        WarpSummary {
            simt_efficiency: if lane_steps == 0 { 1.0 } else { total as f64 / lane_steps as f64 },
            mean_group_efficiency: self.groups.iter().map(|g| g.efficiency()).sum::<f64>() / n,
            total_cost,
            mean_cost: total_cost as f64 / n,
            max_cost: self.groups.iter().map(|g| g.max).max().unwrap_or(0),
        }
    }

    /// The group of a frame's pixel.
    pub fn group_of(&self, x: u32, y: u32) -> &WarpGroup {
        let (bw, bh) = self.size.block();
        &self.groups[((y / bh) * self.columns + x / bw) as usize]
    }

    /// Per pixel of a frame, its group's cost: the heatmap of what each warp pays.
    pub fn cost_image(&self) -> Vec<f32> {
        self.per_pixel(|g| g.max as f32)
    }

    /// Per pixel of a frame, its group's SIMT efficiency (0..1].
    pub fn efficiency_image(&self) -> Vec<f32> {
        self.per_pixel(|g| g.efficiency() as f32)
    }

    fn per_pixel(&self, f: impl Fn(&WarpGroup) -> f32) -> Vec<f32> {
        (0..self.height)
            .flat_map(|y| (0..self.width).map(move |x| (x, y)))
            .map(|(x, y)| f(self.group_of(x, y)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steps(n: u32) -> RayCounters {
        RayCounters { nodes_visited: n, triangle_tests: 1, ..RayCounters::ZERO }
    }

    /// A 10×5 frame in 8×4 blocks: four groups, the right ones 2 pixels wide, the lower ones 1 tall.
    #[test]
    fn a_frame_is_grouped_in_eight_by_four_blocks_with_partial_edges() {
        let (w, h) = (10, 5);
        let counters: Vec<RayCounters> = (0..w * h).map(|i| steps(i % w + 10 * (i / w >= 4) as u32)).collect();
        let v = WarpView::frame(w, h, &counters, WarpSize::W32, WarpWork::Steps);
        assert_eq!((v.columns, v.groups.len()), (2, 4));
        let lanes: Vec<u32> = v.groups.iter().map(|g| g.lanes).collect();
        assert_eq!(lanes, [32, 8, 8, 2]);
        // Top left: x = 0..8 on four rows, work x + 1: max 8, mean 4.5.
        assert_eq!(v.groups[0].max, 8);
        assert_eq!(v.groups[0].efficiency(), 4.5 / 8.0);
        // Bottom right: x = 8, 9 on the last row, work x + 11.
        assert_eq!((v.groups[3].max, v.groups[3].total), (20, 39));
        assert_eq!(v.group_of(9, 4), &v.groups[3]);
        assert_eq!(v.cost_image()[(4 * w + 9) as usize], 20.0);
        let s = v.summary();
        assert_eq!(s.total_cost, 8 + 10 + 18 + 20);
        let work: u64 = counters.iter().map(|c| WarpWork::Steps.of(c) as u64).sum();
        assert_eq!(s.simt_efficiency, work as f64 / (32.0 * 8.0 + 8.0 * 10.0 + 8.0 * 18.0 + 2.0 * 20.0));
        let v64 = WarpView::frame(w, h, &counters, WarpSize::W64, WarpWork::Steps);
        assert_eq!(v64.groups.iter().map(|g| g.lanes).collect::<Vec<_>>(), [40, 10]);
    }

    #[test]
    fn lists_group_consecutive_rays_and_idle_groups_are_efficient() {
        let counters: Vec<RayCounters> = (0..70).map(|i| steps(if i < 64 { 0 } else { i })).collect();
        let v = WarpView::list(&counters, WarpSize::W32, WarpWork::NodesVisited);
        assert_eq!(v.groups.iter().map(|g| g.lanes).collect::<Vec<_>>(), [32, 32, 6]);
        assert_eq!(v.groups[0].efficiency(), 1.0, "no work at all");
        assert_eq!(v.groups[2].max, 69);
        assert_eq!(WarpWork::TriangleTests.of(&counters[0]), 1);
    }
}
