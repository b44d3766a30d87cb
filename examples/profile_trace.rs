//! A profiling driver: traces the bunny's primary and incoherent rays with the wide SAH BVH on
//! one thread, many times over, for `perf record` / `valgrind --tool=callgrind`.
//! `cargo run --release --example profile_trace -- [binary|wide4|wide8] [primary|incoherent|build|frame]`
//! (`PRESET=fastest`: the `fastest` preset's tree and trace options instead; `TEST=name`: that
//! triangle test, e.g. `moller-trumbore-stored`)
//! (`TIME=n`: also the plain closest-hit traversal of all rays, n times, with its median)
//! (`frame` with `PARTS=1` also splits the app's frame into counting, passes and snapshots, with
//! `ONLY=counted` times only the counted frame;
//! `primary` with `PACKET=1` also times 8×8 packets, with `PACKET=only` nothing else).

use bvhscope::bvh::{Accelerator, AnyBvh, BuildParams, Layout, NoStats, TraceOptions};
use bvhscope::geometry::Ray;
use bvhscope::mesh::{load_obj, Mesh};
use bvhscope::random::Rng;
use bvhscope::render::Camera;
use glam::Vec3;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let layout = match args.get(1).map(|a| a.as_str()) {
        Some("binary") => Layout::Binary,
        Some("wide8") => Layout::Wide8,
        _ => Layout::Wide4,
    };
    let what = args.get(2).map_or("primary", |s| s.as_str());
    let path = args.get(3).map_or("../shared/models/stanford-bunny.obj", |s| s.as_str());
    let (mesh, _) = load_obj(path).unwrap_or_else(|e| panic!("{e}"));
    let (params, opts) = params_from_env(layout);
    if what == "build" {
        return time_builds(&mesh, &params);
    }
    let bvh = AnyBvh::build(&mesh, &params);
    if what == "frame" {
        return time_frames(&bvh, &mesh, layout);
    }
    let rays = rays_of(&mesh, what);
    if let Some(n) = std::env::var("TIME").ok().and_then(|n| n.parse::<usize>().ok()) {
        time_rays(&bvh, &rays, opts, n, layout, what);
    }
    print_work(&bvh, &rays, opts);
    if std::env::var("PACKET").is_ok() && what == "primary" {
        time_packets(&bvh, &rays, opts, layout, what);
        if std::env::var("PACKET").is_ok_and(|p| p == "only") {
            return;
        }
    }
    let t = Instant::now();
    let mut hits = 0;
    for _ in 0..5 {
        for r in &rays {
            let mut r = *r;
            hits += bvh.closest_hit(&mut r, opts, &mut NoStats).is_some() as usize;
        }
    }
    let secs = t.elapsed().as_secs_f64();
    println!("{what} {layout:?}: {:.2} MRays/s, {hits} hits", 5.0 * rays.len() as f64 / secs / 1e6);
}

/// The tree and trace options: the default build in `layout`, or `PRESET=fastest`'s (the layout
/// argument ignored), with `STRATEGY`, `COST`, `BINS`, `SWEEP` and `LEAF` over them.
fn params_from_env(layout: Layout) -> (BuildParams, TraceOptions) {
    // `PRESET=fastest`: the `fastest` preset's build and trace options (the layout argument is ignored).
    let fastest = std::env::var("PRESET").is_ok_and(|p| p == "fastest");
    let mut params =
        if fastest { bvhscope::bvh::Preset::Fastest.build() } else { BuildParams { layout, ..BuildParams::default() } };
    let mut opts = if fastest { bvhscope::bvh::Preset::Fastest.trace_options() } else { TraceOptions::default() };
    if let Ok(t) = std::env::var("TEST") {
        opts.test = bvhscope::geometry::TriangleTest::from_name(&t).expect("TEST is a triangle test's name");
    }
    if let Ok(c) = std::env::var("COST") {
        params.cost.traversal = c.parse().expect("COST is a number");
    }
    if let Ok(b) = std::env::var("BINS") {
        params.sah_bins = b.parse().expect("BINS is a number");
    }
    if let Ok(k) = std::env::var("STRATEGY") {
        params.strategy = bvhscope::bvh::Strategy::from_name(&k).expect("STRATEGY is a strategy's name");
    }
    if std::env::var("SWEEP").is_ok() {
        params.strategy = bvhscope::bvh::Strategy::SahSweep;
    }
    if let Ok(l) = std::env::var("LEAF") {
        params.max_leaf_size = l.parse().expect("LEAF is a number");
    }
    (params, opts)
}

/// Median of 31 builds, and of each phase (the machine is noisy).
fn time_builds(mesh: &Mesh, params: &BuildParams) {
    let mut runs: Vec<[f64; 4]> = (0..31)
        .map(|_| {
            let t = Instant::now();
            let bvh = std::hint::black_box(bvhscope::bvh::Bvh::build(mesh, params));
            let total = t.elapsed().as_secs_f64() * 1e3;
            let r = &bvh.report;
            let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
            [total, ms(r.setup_time), ms(r.split_time), ms(r.reorder_time)]
        })
        .collect();
    let mut median = |k: usize| {
        runs.sort_by(|a, b| a[k].total_cmp(&b[k]));
        runs[runs.len() / 2][k]
    };
    let (total, setup, split, reorder) = (median(0), median(1), median(2), median(3));
    println!("binary build: median {total:.2} ms (setup {setup:.2}, split {split:.2}, reorder {reorder:.2})");
}

/// 1280×720, all threads: the renderer's plain frame (shading included), and the app's (counted,
/// progressive, each pass's image built as the render job builds it).
fn time_frames(bvh: &AnyBvh, mesh: &Mesh, layout: Layout) {
    use bvhscope::render::{render, render_passes, render_passes_counts_after, view_image, RenderSettings, View};
    let cam = Camera::framing(&mesh.bounds(), 1280, 720);
    let median = |f: &dyn Fn()| {
        let mut t: Vec<f64> = (0..20)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        t.sort_by(f64::total_cmp);
        t[10]
    };
    if std::env::var("ONLY").is_ok_and(|o| o == "counted") {
        // Only the counted single-pass frame, for a profile of it.
        let counted = RenderSettings { count: true, ..RenderSettings::default() };
        let ms = median(&|| drop(std::hint::black_box(render(bvh, mesh, &cam, &counted))));
        return println!("counted frame {layout:?}: median {ms:.1} ms of 20");
    }
    let plain = RenderSettings::default();
    let plain_ms = median(&|| drop(std::hint::black_box(render(bvh, mesh, &cam, &plain))));
    println!("frame {layout:?}, plain: median {plain_ms:.1} ms of 20");
    let app = RenderSettings { count: true, progressive: true, ..RenderSettings::default() };
    let frames = bvhscope::render::FramePool::default();
    let app_ms = median(&|| {
        let control = bvhscope::work::WorkControl::new();
        let _ = render_passes(bvh, mesh, &cam, &app, &frames, &control, |f, _| {
            let style = (View::Normals, Default::default(), Default::default(), Default::default());
            std::hint::black_box(view_image(&f, style.0, style.1, style.2, style.3));
        });
    });
    println!("frame {layout:?}, as the app renders a heatmap: median {app_ms:.1} ms of 20");
    // The app's normal and depth views: the image from uncounted packets, then the counts.
    let image_ms = std::cell::Cell::new(0.0);
    let counts_ms = median(&|| {
        let (control, t) = (bvhscope::work::WorkControl::new(), Instant::now());
        let _ = render_passes_counts_after(bvh, mesh, &cam, &app, &frames, &control, |f, p| {
            if f.is_complete() && !p.counts_only {
                image_ms.set(image_ms.get() + t.elapsed().as_secs_f64() * 1e3 / 20.0);
            }
            let style = (View::Normals, Default::default(), Default::default(), Default::default());
            std::hint::black_box(view_image(&f, style.0, style.1, style.2, style.3));
        });
    });
    println!(
        "frame {layout:?}, as the app renders the normal view: image after {:.1} ms (mean of 20), counts after {counts_ms:.1} (median)",
        image_ms.get()
    );
    if std::env::var("PARTS").is_ok() {
        // Where the app's frame goes beyond the plain one: counting, passes, snapshots.
        let counted = RenderSettings { count: true, ..RenderSettings::default() };
        let c_ms = median(&|| drop(std::hint::black_box(render(bvh, mesh, &cam, &counted))));
        let control = bvhscope::work::WorkControl::new();
        let p_ms =
            median(&|| drop(bvhscope::render::render_progressive(bvh, mesh, &cam, &app, &frames, &control, |_, _| {})));
        let s_ms = median(&|| {
            let _ = render_passes(bvh, mesh, &cam, &app, &frames, &control, |f, _| drop(std::hint::black_box(f)));
        });
        println!("counted {c_ms:.1}, progressive {p_ms:.1}, with snapshots {s_ms:.1}");
    }
}

/// The bunny's primary rays (a 1024² frame; `AWAY=1` turned around) or a million incoherent rays
/// from its surface.
fn rays_of(mesh: &Mesh, what: &str) -> Vec<Ray> {
    if what == "primary" {
        let cam = Camera::framing_from(&mesh.bounds(), 1024, 1024, Vec3::new(0.45, 0.35, 1.0), 45.0);
        let g = cam.ray_gen();
        (0..1024 * 1024)
            .map(|i| g.pixel_ray(i % 1024, i / 1024))
            .map(|r| if std::env::var("AWAY").is_ok() { Ray::new(r.origin(), -r.dir()) } else { r })
            .collect()
    } else {
        let mut rng = Rng::new(12345);
        (0..1_000_000)
            .map(|_| {
                let t = mesh.triangle(rng.below(mesh.triangle_count() as u64) as u32);
                let p = (t[0] + t[1] + t[2]) / 3.0;
                let d = Vec3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5).normalize_or(Vec3::X);
                Ray::new(p + d * 1e-4, d)
            })
            .collect()
    }
}

/// The plain closest-hit walk of all rays, `n` times, and the counted one: medians.
fn time_rays(bvh: &AnyBvh, rays: &[Ray], opts: TraceOptions, n: usize, layout: Layout, what: &str) {
    let mut times: Vec<f64> = (0..n)
        .map(|_| {
            let t = Instant::now();
            for r in rays {
                let mut r = *r;
                std::hint::black_box(bvh.closest_hit(&mut r, opts, &mut NoStats));
            }
            rays.len() as f64 / t.elapsed().as_secs_f64() / 1e6
        })
        .collect();
    times.sort_by(f64::total_cmp);
    println!("{layout:?} {what}: median {:.2} MRays/s of {n}", times[n / 2]);
    // The same rays walked with the heatmaps' counters (what the app's frame traces).
    let mut counted: Vec<f64> = (0..n)
        .map(|_| {
            let t = Instant::now();
            for r in rays {
                let (mut r, mut c) = (*r, bvhscope::bvh::RayCounters::default());
                std::hint::black_box(bvh.closest_hit(&mut r, opts, &mut c));
                std::hint::black_box(c);
            }
            rays.len() as f64 / t.elapsed().as_secs_f64() / 1e6
        })
        .collect();
    counted.sort_by(f64::total_cmp);
    println!("{layout:?} {what}, counted: median {:.2} MRays/s of {n}", counted[n / 2]);
}

/// The work per ray: nodes, box tests, leaves, triangle tests.
fn print_work(bvh: &AnyBvh, rays: &[Ray], opts: TraceOptions) {
    let mut c = bvhscope::bvh::RayCounters::default();
    for r in rays {
        let mut r = *r;
        let mut one = bvhscope::bvh::RayCounters::default();
        bvh.closest_hit(&mut r, opts, &mut one);
        c.nodes_visited += one.nodes_visited;
        c.box_tests += one.box_tests;
        c.leaves_visited += one.leaves_visited;
        c.triangle_tests += one.triangle_tests;
    }
    let n = rays.len() as f64;
    println!(
        "per ray: {:.2} nodes, {:.2} box tests, {:.2} leaves, {:.2} triangle tests",
        c.nodes_visited as f64 / n,
        c.box_tests as f64 / n,
        c.leaves_visited as f64 / n,
        c.triangle_tests as f64 / n
    );
}

/// 8×8 pixel blocks of the 1024² frame, each in packet order; results checked against single
/// rays on a first, untimed round.
fn time_packets(bvh: &AnyBvh, rays: &[Ray], opts: TraceOptions, layout: Layout, what: &str) {
    use bvhscope::bvh::packet::{packet_position, PACKET};
    const ROUNDS: usize = 20;
    let mut t = Instant::now();
    let (mut hits, mut differ) = (0, 0);
    let mut out = [None; PACKET];
    let mut packet = Vec::with_capacity(PACKET);
    for round in 0..ROUNDS + 1 {
        if round == 1 {
            (t, hits) = (Instant::now(), 0);
        }
        for by in (0..1024).step_by(8) {
            for bx in (0..1024).step_by(8) {
                let index = |k: u32| {
                    let (x, y) = packet_position(k);
                    (by + y as usize) * 1024 + bx + x as usize
                };
                packet.clear();
                packet.extend((0..PACKET as u32).map(|k| rays[index(k)]));
                bvh.closest_hits(&mut packet, &mut out, opts);
                hits += out.iter().filter(|h| h.is_some()).count();
                if round == 0 {
                    for (k, h) in out.iter().enumerate() {
                        let mut r = rays[index(k as u32)];
                        let want = bvh.closest_hit(&mut r, opts, &mut NoStats);
                        differ += (want.map(|h| h.t) != h.map(|h| h.t)) as usize;
                    }
                }
            }
        }
    }
    let secs = t.elapsed().as_secs_f64();
    let rate = ROUNDS as f64 * rays.len() as f64 / secs / 1e6;
    println!("{what} {layout:?} packets: {rate:.2} MRays/s, {hits} hits, {differ} differ from single rays");
}
