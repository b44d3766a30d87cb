//! The warp view computed from the GPU's per-ray counts equals the one computed from the CPU's,
//! for both node formats, frames and ray lists, warps of 32 and 64.

mod common;

use bvhscope_core::bvh::{RayCounters, Strategy, TraversalOrder};
use bvhscope_core::geometry::TriangleTest;
use bvhscope_core::render::Camera;
use bvhscope_gpu::{Cwbvh, GpuBinaryBvh, GpuCwbvh, GpuTraceOptions, Rays, WarpSize, WarpView, WarpWork};
use common::*;

#[test]
fn gpu_and_cpu_counts_give_the_same_warp_view() {
    let Some(gpu) = gpu() else { return };
    let mesh = shared_mesh("stanford-bunny.obj").unwrap_or_else(exact_mesh);
    let bvh = build(&mesh, Strategy::SahBinned, 4);
    let cam = Camera::framing(&mesh.bounds(), 80, 60);
    let primary = camera_rays(&cam);
    let incoherent = incoherent_rays(&mesh, 4096, 3);
    let binary = GpuBinaryBvh::upload(&gpu, &bvh).unwrap();
    let wide = Cwbvh::from_bvh(&bvh).unwrap();
    let gwide = GpuCwbvh::upload(&gpu, &wide).unwrap();
    let opts = GpuTraceOptions::default();
    let cpu_wide = |rays: &[bvhscope_core::geometry::Ray]| -> Vec<RayCounters> {
        rays.iter().map(|r| wide.trace_cpu(&mut r.clone(), TriangleTest::Watertight).1).collect()
    };
    let frames = [
        (
            "binary",
            binary.trace(&gpu, Rays::Camera(&cam), opts).unwrap().counters,
            cpu_trace(&bvh, &primary, TraversalOrder::EntryDistance).1,
        ),
        ("cwbvh", gwide.trace(&gpu, Rays::Camera(&cam), opts).unwrap().counters, cpu_wide(&primary)),
    ];
    let lists = [
        (
            "binary",
            binary.trace(&gpu, Rays::List(&incoherent), opts).unwrap().counters,
            cpu_trace(&bvh, &incoherent, TraversalOrder::EntryDistance).1,
        ),
        ("cwbvh", gwide.trace(&gpu, Rays::List(&incoherent), opts).unwrap().counters, cpu_wide(&incoherent)),
    ];
    for size in [WarpSize::W32, WarpSize::W64] {
        for work in [WarpWork::Steps, WarpWork::NodesVisited, WarpWork::BoxTests, WarpWork::TriangleTests] {
            for (format, g, c) in &frames {
                let (a, b) = (WarpView::frame(80, 60, g, size, work), WarpView::frame(80, 60, c, size, work));
                assert_eq!(a, b, "{format} frame {size:?} {work:?}");
                assert_eq!(a.groups.len(), (10 * 60u32.div_ceil(size.block().1)) as usize);
            }
            for (format, g, c) in &lists {
                assert_eq!(
                    WarpView::list(g, size, work),
                    WarpView::list(c, size, work),
                    "{format} list {size:?} {work:?}"
                );
            }
        }
    }
    // The figures a class would compare (printed: the test's point is the agreement above).
    use std::io::Write;
    for (kind, set) in [("primary", &frames), ("incoherent", &lists)] {
        for (format, g, _) in set.iter() {
            let v = if kind == "primary" {
                WarpView::frame(80, 60, g, WarpSize::W32, WarpWork::Steps)
            } else {
                WarpView::list(g, WarpSize::W32, WarpWork::Steps)
            };
            let s = v.summary();
            let _ = writeln!(
                std::io::stderr(),
                "{kind} {format}: SIMT efficiency {:.3}, mean group cost {:.1} steps",
                s.simt_efficiency,
                s.mean_cost
            );
            assert!(s.simt_efficiency > 0.0 && s.simt_efficiency <= 1.0);
        }
    }
}
