//! `BENCH_KERNELS=1`: the fastest preset's tree walked with each SIMD kernel this CPU has from four
//! lanes up (`cpu::Simd`, forced with `with_simd`), and with `BENCH_KERNEL_LEAVES=8:5,16:8` trees of
//! larger leaves (leaf size : SAH traversal cost) with AVX2 and AVX-512; single rays and 8×8
//! packets, primary and incoherent, on one thread; Embree (where found) and tinybvh (in an AVX2 build) beside them. The kernels
//! take turns on every slice of 16384 rays (the order rotating from slice to slice), their times
//! summed over the ray set; the median of several such passes is kept. Rows of the main table are
//! timed minutes apart, and this shared machine drifts by ±15% over minutes: two turns on a slice
//! are milliseconds apart, so the ratios between kernels hold where the absolute figures do not.
//! Each turn is timed by the thread's CPU time (`CLOCK_THREAD_CPUTIME_ID`), not the clock:
//! with other work on the machine the clock also counts the time the thread waited for a core,
//! which moved one binary's packet rate from 24 to 17 MRays/s between two runs a minute apart.

use crate::contenders::{ours_with_kernels, Built, Tracer, Tracing};
use crate::embree;
use crate::rays::{self, RaySpec};
use crate::tinybvh;
use crate::{median, Settings};
use bvhscope::bvh::Preset;
use bvhscope::cpu::Simd;
use bvhscope::geometry::TriangleTest;
use bvhscope::mesh::Mesh;
use rayon::ThreadPool;
use std::fmt::Write;

const SLICE: usize = 16384;
const WATERTIGHT: TriangleTest = TriangleTest::Watertight;

/// One column: a kernel and the tree's leaf size and SAH traversal cost.
#[derive(Clone, Copy)]
struct Setup {
    simd: Simd,
    leaf: u32,
    cost: f32,
    test: TriangleTest,
}

/// The columns: every kernel on the fastest preset's tree, then AVX2 and AVX-512 on the trees of
/// `BENCH_KERNEL_LEAVES=leaf:cost,…` (larger leaves, which one AVX-512 pass tests at once).
fn setups() -> Vec<Setup> {
    let fastest = Preset::Fastest.build();
    let mut v: Vec<Setup> = Simd::ALL
        .into_iter()
        .filter(|&k| k >= Simd::Simd4 && k <= Simd::detected())
        .map(|simd| Setup { simd, leaf: fastest.max_leaf_size, cost: fastest.cost.traversal, test: WATERTIGHT })
        .collect();
    // The other triangle tests on the same tree, with AVX2 and (where the CPU has it) AVX-512:
    // Möller–Trumbore from the same vertex loads (`triangle8`; four lanes a pass with AVX-512),
    // and on the stored edges and normal (`stored_triangle`: eight lanes, or sixteen with
    // AVX-512): what the watertight test costs, and what the stored form buys.
    for simd in [Simd::Avx2, Simd::Avx512].into_iter().filter(|&k| k <= Simd::detected()) {
        for test in TriangleTest::ALL.into_iter().filter(|&t| t != WATERTIGHT) {
            v.push(Setup { simd, leaf: fastest.max_leaf_size, cost: fastest.cost.traversal, test });
        }
    }
    let extra = std::env::var("BENCH_KERNEL_LEAVES").unwrap_or_default();
    for pair in extra.split(',').filter(|p| !p.trim().is_empty()) {
        let (leaf, cost) = pair.split_once(':').expect("BENCH_KERNEL_LEAVES=leaf:cost,…");
        let (leaf, cost) = (leaf.trim().parse().expect("a leaf size"), cost.trim().parse().expect("a cost"));
        for simd in [Simd::Avx2, Simd::Avx512].into_iter().filter(|&k| k <= Simd::detected()) {
            v.push(Setup { simd, leaf, cost, test: WATERTIGHT });
        }
    }
    v
}

/// The tables for `mesh`, single rays then 8×8 packets: per column, median MRays/s and the ratio
/// to the fastest preset's AVX2 column. Where Embree was found, its medium build races in the same
/// alternation: `rtcIntersect1` (and the high-quality build) beside single rays, `rtcIntersect8`
/// and the coherent stream of 64 beside packets; tinybvh's BVH8_CPU (both builds) beside single rays
/// where the bench was built with AVX2 (`tinybvh::notice`).
pub fn table(mesh: &Mesh, s: &Settings, one: &ThreadPool) -> String {
    let setups = setups();
    let passes = if s.quick { 3 } else { 7 };
    let mut o = String::new();
    let primary = rays::primary(mesh, s.primary_size);
    let incoherent = rays::incoherent(mesh, s.incoherent, 0x5EED);
    let base = setups.iter().position(|c| c.simd == Simd::Avx2);
    for tracing in [Tracing::Plain, Tracing::Packets] {
        let mut columns: Vec<(String, Built)> = setups
            .iter()
            // Packets trace with the watertight test only.
            .filter(|c| tracing == Tracing::Plain || c.test == WATERTIGHT)
            .map(|c| {
                let mut params = Preset::Fastest.build();
                (params.max_leaf_size, params.cost.traversal) = (c.leaf, c.cost);
                let b = (ours_with_kernels("fastest", params, tracing, Some(c.simd), c.test).build)(mesh).0;
                let test = if c.test == WATERTIGHT { String::new() } else { format!(" {}", c.test.label()) };
                let name = format!(
                    "{}{test} leaf {} cost {} ({:.1} B/tri)",
                    c.simd.name(),
                    c.leaf,
                    c.cost,
                    b.bytes_per_tri.unwrap_or(0.0)
                );
                (name, b)
            })
            .collect();
        let theirs: &[&str] = match tracing {
            Tracing::Plain => &["embree medium (rtcIntersect1)", "embree high (rtcIntersect1)"],
            _ => &["embree medium (rtcIntersect8)", "embree medium (stream of 64)"],
        };
        let tiny = if tracing == Tracing::Plain { tinybvh::all() } else { Vec::new() };
        let anchors = embree::all().into_iter().filter(|c| theirs.contains(&c.name.as_str())).chain(tiny);
        for c in anchors {
            let b = (c.build)(mesh).0;
            columns.push((format!("{} ({:.1} B/tri)", c.name, b.bytes_per_tri.unwrap_or(0.0)), b));
        }
        let what =
            if tracing == Tracing::Plain { "single rays" } else { "8×8 packets (Embree: its packets, streams)" };
        let _ = writeln!(
            o,
            "\n### {what} on {} (one thread's CPU time, alternated per {SLICE} rays, median of {passes} passes)\n",
            mesh.name
        );
        let head: Vec<&str> = columns.iter().map(|c| c.0.as_str()).collect();
        let _ = writeln!(o, "| rays | {} | hits |", head.join(" | "));
        let _ = writeln!(o, "|---|{}---:|", "---:|".repeat(columns.len()));
        let tracers: Vec<&dyn Tracer> = columns.iter().map(|c| c.1.tracer.as_ref()).collect();
        for (label, rays) in [("primary", &primary), ("incoherent", &incoherent)] {
            let (rates, hits) = alternated(&tracers, rays, passes, one);
            let cells: Vec<String> = rates
                .iter()
                .map(|&r| match base {
                    Some(b) => format!("{r:.2} ({:.2}×)", r / rates[b]),
                    None => format!("{r:.2}"),
                })
                .collect();
            let _ = writeln!(o, "| {label} | {} | {hits} |", cells.join(" | "));
        }
    }
    o
}

/// Median MRays/s of each tracer over `passes` alternated passes, and the hit count (a range where
/// the tracers differ).
fn alternated(tracers: &[&dyn Tracer], rays: &[RaySpec], passes: usize, one: &ThreadPool) -> (Vec<f64>, String) {
    let n = tracers.len();
    let mut per_pass: Vec<Vec<f64>> = vec![Vec::new(); n];
    let mut hits = String::new();
    for pass in 0..passes {
        let mut secs = vec![0.0; n];
        let mut pass_hits = vec![0; n];
        for (j, slice) in rays.chunks(SLICE).enumerate() {
            for turn in 0..n {
                let k = (turn + j + pass) % n;
                let (d, h) = cpu_timed(one, slice, tracers[k]);
                secs[k] += d;
                pass_hits[k] += h;
            }
        }
        // Our kernels find the same hits (the tests say bit for bit); Embree may differ by a few.
        let (lo, hi) = (pass_hits.iter().min().copied().unwrap_or(0), pass_hits.iter().max().copied().unwrap_or(0));
        hits = if lo == hi { format!("{lo}") } else { format!("{lo}..{hi}") };
        for k in 0..n {
            per_pass[k].push(rays.len() as f64 / secs[k] / 1e6);
        }
    }
    (per_pass.into_iter().map(median).collect(), hits)
}

/// Trace `rays` on the one-thread pool; the seconds of CPU time its thread spent, and the hits.
fn cpu_timed(one: &ThreadPool, rays: &[RaySpec], t: &dyn Tracer) -> (f64, usize) {
    one.install(|| {
        let start = thread_cpu_ns();
        let hits = rays.chunks(1024).map(|c| t.trace_chunk(c)).sum();
        ((thread_cpu_ns() - start) as f64 * 1e-9, hits)
    })
}

/// This thread's time on a CPU so far, in nanoseconds (POSIX `clock_gettime` of
/// `CLOCK_THREAD_CPUTIME_ID`, which Linux brings up to date when asked; the schedstat file's figure
/// lags by up to a scheduler tick, longer than a turn). Elsewhere, the clock.
fn thread_cpu_ns() -> u64 {
    #[cfg(target_os = "linux")]
    {
        #[repr(C)]
        struct Timespec {
            sec: i64,
            nsec: i64,
        }
        extern "C" {
            fn clock_gettime(clock: i32, ts: *mut Timespec) -> i32;
        }
        const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
        let mut ts = Timespec { sec: 0, nsec: 0 };
        // SAFETY: `ts` is a valid timespec (64-bit Linux layout) for the call to fill.
        let rc = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) };
        assert_eq!(rc, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID)");
        ts.sec as u64 * 1_000_000_000 + ts.nsec as u64
    }
    #[cfg(not(target_os = "linux"))]
    {
        static START: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
        START.get_or_init(std::time::Instant::now).elapsed().as_nanos() as u64
    }
}
