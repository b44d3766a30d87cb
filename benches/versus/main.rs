//! `cargo bench -p bvhscope-versus --bench versus`: bvhscope against obvhs and the bvh crate on the same meshes and
//! the same rays. Prints one markdown table per mesh and closing ratio lines. Every time is the
//! median of several runs; hit counts are printed so nobody wins by missing.
//! `BENCH_QUICK=1` runs a reduced set (under two minutes on 2 cores). For iterating on one thing:
//! `BENCH_ONLY=sah,medium` keeps contenders whose names contain a word, `BENCH_MESH=bunny` one mesh,
//! `BENCH_APP=1` prints only the app figures, `BENCH_OVERHEAD=1` only the counting overhead,
//! `BENCH_COUNTS=1` only the work per ray (nodes, triangle tests) of our strategies' trees,
//! `BENCH_KERNELS=1` only our SIMD kernels (four lanes, AVX2, AVX-512) raced on one tree, alternated
//! with Embree (`BENCH_KERNEL_LEAVES=16:10,…` adds trees of larger leaves: leaf size : traversal cost).
//! `BENCH_THREADS=1,2,4,8,16` only the scaling tables (`scaling.rs`): per phase (OBJ load, each
//! strategy's build and Embree's, EPO, a counted and a packet 4K frame) the median time on each
//! thread count, the speed-up over one thread, and the serial fraction measured on this machine with
//! its Amdahl projection for 16 threads; counts above the machine's cores run, flagged
//! oversubscribed. `BENCH_SCALING_MESH=path.obj` times another mesh than the bunny,
//! `BENCH_SCALING_REPS=n` runs per thread count (3), `BENCH_SCALING_ONLY=frame,…` some phases.
//! Tuning: `BENCH_TRAVERSAL_COST=c` and `BENCH_MAX_LEAF=n` build our trees with that SAH traversal
//! cost and leaf size; `BENCH_EMBREE_ISA=avx2` asks Embree for its kernels of another CPU,
//! `BENCH_EMBREE_ROBUST=1` for its robust mode.
//! Embree 3 is raced when `build.rs` found it (Debian: libembree-dev); tinybvh's BVH8_CPU (the
//! `tinybvh-rs` crate) when the bench is built with AVX2 enabled: `RUSTFLAGS="-C target-cpu=native"
//! CARGO_TARGET_DIR=target/native cargo bench -p bvhscope-versus --bench versus`.

mod contenders;
mod counts;
mod embree;
mod kernels;
mod ratios;
mod rays;
mod scaling;
mod scenes;
mod tinybvh;

use bvhscope::bvh::Layout;
use bvhscope::mesh::Mesh;
use contenders::{Contender, Family, Tracer};
use rayon::prelude::*;
use rayon::{ThreadPool, ThreadPoolBuilder};
use rays::RaySpec;
use std::fmt::Write;
use std::time::{Duration, Instant};

struct Settings {
    quick: bool,
    primary_size: u32,
    incoherent: usize,
    /// Runs of each trace (the median is kept).
    reps: usize,
    /// Runs of each build below a million triangles.
    build_reps: usize,
}

#[derive(Default, Clone)]
struct Row {
    name: String,
    family: Option<Family>,
    build_1t: f64,
    build_nt: f64,
    sah: Option<f64>,
    bytes: Option<f64>,
    p1: f64,
    pn: f64,
    p_hits: usize,
    i1: f64,
    i_n: f64,
    i_hits: usize,
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Trace all rays on the pool's threads; returns (time, hits).
fn trace(pool: &ThreadPool, rays: &[RaySpec], t: &dyn Tracer) -> (Duration, usize) {
    pool.install(|| {
        let start = Instant::now();
        let hits = rays.par_chunks(1024).map(|c| t.trace_chunk(c)).sum();
        (start.elapsed(), hits)
    })
}

/// Median MRays/s over `reps` runs, and the hit count.
fn mrays(pool: &ThreadPool, rays: &[RaySpec], t: &dyn Tracer, reps: usize) -> (f64, usize) {
    let mut hits = 0;
    let times: Vec<f64> = (0..reps)
        .map(|_| {
            let (d, h) = trace(pool, rays, t);
            hits = h;
            rays.len() as f64 / d.as_secs_f64() / 1e6
        })
        .collect();
    (median(times), hits)
}

fn run_mesh(mesh: &Mesh, contenders: &[Contender], s: &Settings, one: &ThreadPool, all: &ThreadPool) -> Vec<Row> {
    let primary = rays::primary(mesh, s.primary_size);
    let incoherent = rays::incoherent(mesh, s.incoherent, 0x5EED);
    let mut rows = Vec::new();
    for c in contenders {
        if s.quick && c.slow_build && mesh.triangle_count() > 200_000 {
            continue;
        }
        eprintln!("  {} ...", c.name);
        // Builds of the small meshes take milliseconds, where a scheduler hiccup on this noisy
        // machine moves a median of three by half: eleven runs for them.
        let build_reps = if mesh.triangle_count() > 1_000_000 { 1 } else { s.build_reps };
        let b1 = median((0..build_reps).map(|_| ms(one.install(|| (c.build)(mesh)).1)).collect());
        let mut built = None;
        let bn = median(
            (0..build_reps)
                .map(|_| {
                    let (b, d) = all.install(|| (c.build)(mesh));
                    built = Some(b);
                    ms(d)
                })
                .collect(),
        );
        let Some(built) = built else { continue };
        let t = built.tracer.as_ref();
        // The bvh crate is slow on incoherent rays of big meshes: fewer repetitions there.
        let reps = if c.family == Family::BvhCrate { 1 } else { s.reps };
        let (p1, p_hits) = mrays(one, &primary, t, reps);
        let (pn, _) = mrays(all, &primary, t, reps);
        let (i1, i_hits) = mrays(one, &incoherent, t, reps);
        let (i_n, _) = mrays(all, &incoherent, t, reps);
        rows.push(Row {
            name: c.name.clone(),
            family: Some(c.family),
            build_1t: b1,
            build_nt: bn,
            sah: built.sah_cost,
            bytes: built.bytes_per_tri,
            p1,
            pn,
            p_hits,
            i1,
            i_n,
            i_hits,
        });
    }
    rows
}

fn table(mesh: &Mesh, rows: &[Row], s: &Settings, threads: usize) -> String {
    let n = mesh.triangle_count() as f64;
    let mut o = String::new();
    let _ = writeln!(o, "\n### {} ({} triangles)\n", mesh.name, mesh.triangle_count());
    let _ = writeln!(
        o,
        "primary: {0}×{0} pinhole frame; incoherent: {1} rays from the surface; {2} threads for “NT”.\n",
        s.primary_size, s.incoherent, threads
    );
    let _ = writeln!(o, "| implementation | build 1T ms | build NT ms | Mtri/s NT | SAH cost | B/tri | primary 1T MRays/s | primary NT | primary hits | incoherent 1T MRays/s | incoherent NT | incoherent hits |");
    let _ = writeln!(o, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for r in rows {
        let _ = writeln!(
            o,
            "| {} | {:.1} | {:.1} | {:.2} | {} | {} | {:.2} | {:.2} | {} | {:.2} | {:.2} | {} |",
            r.name,
            r.build_1t,
            r.build_nt,
            n / r.build_nt / 1e3,
            r.sah.map_or("—".into(), |v| format!("{v:.2}")),
            r.bytes.map_or("—".into(), |v| format!("{v:.1}")),
            r.p1,
            r.pn,
            r.p_hits,
            r.i1,
            r.i_n,
            r.i_hits
        );
    }
    // Everyone must hit the same rays (±0.1%).
    for (label, hits) in [
        ("primary", rows.iter().map(|r| r.p_hits).collect::<Vec<_>>()),
        ("incoherent", rows.iter().map(|r| r.i_hits).collect()),
    ] {
        let (lo, hi) = (hits.iter().min().copied().unwrap_or(0), hits.iter().max().copied().unwrap_or(0));
        let spread = (hi - lo) as f64 / hi.max(1) as f64;
        let verdict = if spread <= 1e-3 { "agree" } else { "DISAGREE" };
        let _ = writeln!(o, "\n{label} hit counts {verdict}: {lo}..{hi} ({:.3}% spread)", spread * 100.0);
    }
    o
}

/// The heatmap counters' cost, measured in alternation: on one thread, the plain and the counting
/// traversal of the same tree take turns on every slice of 16384 rays (which goes first alternates
/// from slice to slice), their times are summed over the whole ray set, and the median of `pairs`
/// such passes is kept. Rows of the table are timed minutes apart, and this machine drifts by ±15%
/// over minutes and by several percent over seconds; two turns on a slice are milliseconds apart.
fn counting_overhead(mesh: &Mesh, s: &Settings, one: &ThreadPool) -> String {
    const SLICE: usize = 16384;
    let primary = rays::primary(mesh, s.primary_size);
    let incoherent = rays::incoherent(mesh, s.incoherent, 0x5EED);
    let pairs = if s.quick || mesh.triangle_count() > 1_000_000 { 3 } else { 5 };
    let mut o = String::new();
    for (layout, label) in [(Layout::Binary, "BVH2"), (Layout::Wide4, "BVH4"), (Layout::Wide8, "BVH8")] {
        let [plain, counting] = contenders::plain_and_counting(mesh, layout);
        let overhead = |rays: &[RaySpec]| {
            let ratios = (0..pairs)
                .map(|k| {
                    let (mut plain_s, mut counting_s) = (0.0, 0.0);
                    for (j, slice) in rays.chunks(SLICE).enumerate() {
                        let time = |t: &dyn Tracer| trace(one, slice, t);
                        let ((p, hp), (c, hc)) = if (j + k) % 2 == 0 {
                            let p = time(plain.as_ref());
                            (p, time(counting.as_ref()))
                        } else {
                            let c = time(counting.as_ref());
                            (time(plain.as_ref()), c)
                        };
                        assert_eq!(hp, hc, "the counting traversal must find the same hits");
                        plain_s += p.as_secs_f64();
                        counting_s += c.as_secs_f64();
                    }
                    counting_s / plain_s
                })
                .collect();
            (median(ratios) - 1.0) * 100.0
        };
        let _ = writeln!(
            o,
            "counting overhead {} SAH {label} (alternated per {SLICE} rays, median of {pairs} passes): primary 1T {:+.1}%, incoherent 1T {:+.1}%",
            mesh.name,
            overhead(&primary),
            overhead(&incoherent)
        );
    }
    o
}

/// Median of `n` timed runs of `f`, in milliseconds.
fn median_ms(n: usize, mut f: impl FnMut()) -> f64 {
    median(
        (0..n)
            .map(|_| {
                let t = Instant::now();
                f();
                ms(t.elapsed())
            })
            .collect(),
    )
}

/// The figures the README quotes for the app: a full 1280×720 normal frame of the bunny (the app's
/// default wide layout, all threads), load + SAH build of the 2M-triangle mesh from an OBJ file,
/// and a strategy switch (a rebuild) on it.
fn app_figures(meshes: &[Mesh], all: &ThreadPool) -> String {
    use bvhscope::bvh::{AnyBvh, BuildParams, Strategy};
    use bvhscope::render::{render, render_passes, view_image, Camera, ColorMap, HeatRange, RenderSettings, View};
    let mut o = String::from("\n### App figures (all threads)\n\n");
    if let Some(bunny) = meshes.iter().find(|m| m.name.contains("bunny")) {
        for (layout, what) in [
            (bvhscope::bvh::Layout::Wide4, "wide SAH, the app's default layout, 8×8 packets"),
            (bvhscope::bvh::Layout::Binary, "binary SAH, 8×8 packets"),
        ] {
            let bvh = all.install(|| AnyBvh::build(bunny, &BuildParams { layout, ..BuildParams::default() }));
            let cam = Camera::framing(&bunny.bounds(), 1280, 720);
            let settings = RenderSettings::default();
            let plain =
                median_ms(9, || drop(std::hint::black_box(all.install(|| render(&bvh, bunny, &cam, &settings)))));
            let _ = writeln!(
                o,
                "- full 1280×720 normal frame of the bunny ({what}; shading included): median {plain:.1} ms of 9"
            );
            if layout == bvhscope::bvh::Layout::Wide4 {
                // What the app does per frame: count (for the hover read-out and the statistics),
                // refine in four passes, and build each pass's image.
                let app = RenderSettings { count: true, progressive: true, ..settings };
                let (control, frames) = (bvhscope::work::WorkControl::new(), Default::default());
                let app_ms = median_ms(9, || {
                    all.install(|| {
                        let _ = render_passes(&bvh, bunny, &cam, &app, &frames, &control, |f, _| {
                            let (v, c, r) = (View::Normals, ColorMap::default(), HeatRange::Auto);
                            std::hint::black_box(view_image(&f, v, c, r, Default::default()));
                        });
                    })
                });
                let _ = writeln!(
                    o,
                    "- the same frame as the app renders it (counted, four progressive passes, each pass's image): median {app_ms:.1} ms of 9"
                );
            }
        }
    }
    if let Some(big) = meshes.iter().find(|m| m.triangle_count() > 1_000_000) {
        let mut bare = big.clone();
        bare.normals.clear();
        bare.uvs.clear();
        for (label, m) in [("with normals and uvs", big), ("positions and faces only", &bare)] {
            let path = std::env::temp_dir().join(format!("bvhscope-bench-{}.obj", std::process::id()));
            let mut f = std::io::BufWriter::new(std::fs::File::create(&path).expect("temp file"));
            bvhscope::mesh::write_obj(m, &mut f).expect("write OBJ");
            // Flush to disk first, so the load is not timed against the write-back of the file.
            f.into_inner().expect("flush").sync_all().expect("sync");
            let size = std::fs::metadata(&path).map_or(0, |m| m.len());
            let t = Instant::now();
            let (mesh, _) = all.install(|| bvhscope::mesh::load_obj(&path)).expect("read back");
            let load = ms(t.elapsed());
            let t = Instant::now();
            let bvh = all.install(|| AnyBvh::build(&mesh, &BuildParams::default()));
            let build = ms(t.elapsed());
            let _ = writeln!(
                o,
                "- {} triangles from an OBJ file {label} ({:.0} MB): load {:.0} ms + SAH build (wide) {:.0} ms = {:.2} s",
                mesh.triangle_count(),
                size as f64 / 1e6,
                load,
                build,
                (load + build) / 1e3
            );
            drop(bvh);
            let _ = std::fs::remove_file(&path);
        }
        let mesh = big;
        for s in [Strategy::Midpoint, Strategy::SahBinned] {
            let t = Instant::now();
            std::hint::black_box(all.install(|| AnyBvh::build(mesh, &BuildParams::with_strategy(s))));
            let _ = writeln!(
                o,
                "- strategy switch to {} on it (a full rebuild, wide layout): {:.0} ms",
                s.label(),
                ms(t.elapsed())
            );
        }
    }
    o
}

fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    format!("{cpu}, {} threads available", std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// The meshes raced: the shared ones found, the generated scenes, the 2M-triangle knot (not in a
/// quick run unless for the app figures) and the needle soup (full run, or asked for by name).
fn meshes(quick: bool, app_only: bool) -> Vec<Mesh> {
    let mut meshes: Vec<Mesh> = Vec::new();
    meshes.extend(scenes::shared("stanford-bunny.obj"));
    meshes.extend(scenes::shared("beast.obj"));
    meshes.extend(scenes::shared("spot.obj"));
    meshes.extend(scenes::shared("cow.obj"));
    meshes.push(scenes::knot_field());
    meshes.push(scenes::teapot_in_stadium());
    if !quick || app_only {
        meshes.push(scenes::big_knot());
    }
    // The needle soup's walks visit hundreds of nodes a ray: about a minute per contender, so
    // only in the full run (or asked for by name with BENCH_MESH=needles).
    if !quick || std::env::var("BENCH_MESH").is_ok_and(|m| m.contains("needles")) {
        meshes.push(scenes::needles());
    }
    meshes
}

fn main() {
    // `cargo bench` passes `--bench`; nothing else is accepted.
    let quick = std::env::var("BENCH_QUICK").is_ok_and(|v| v == "1");
    let s = if quick {
        Settings { quick, primary_size: 512, incoherent: 200_000, reps: 1, build_reps: 3 }
    } else {
        Settings { quick, primary_size: 1024, incoherent: 1_000_000, reps: 3, build_reps: 11 }
    };
    let one = ThreadPoolBuilder::new().num_threads(1).build().expect("a one-thread pool");
    let all = ThreadPoolBuilder::new().build().expect("a pool");
    let threads = all.current_num_threads();
    // Wake both pools' threads once, so the first contender's figures do not include their start.
    for pool in [&one, &all] {
        pool.install(|| (0..1 << 20).into_par_iter().map(|i: u64| i * i).sum::<u64>());
    }

    // BENCH_THREADS=1,2,…: only the scaling tables (`scaling.rs`), on pools of their own.
    if let Ok(list) = std::env::var("BENCH_THREADS") {
        print!("{}", scaling::table(&scaling::thread_counts(&list)));
        return;
    }

    let mut contenders = contenders::all();
    // BENCH_ONLY=a,b keeps contenders whose name contains one of the words (for quick iteration).
    if let Ok(only) = std::env::var("BENCH_ONLY") {
        let words: Vec<String> = only.split(',').map(|w| w.trim().to_lowercase()).collect();
        contenders.retain(|c| words.iter().any(|w| c.name.to_lowercase().contains(w.as_str())));
    }

    // BENCH_APP=1: only the app figures (frame time, 2M load + build, strategy switch).
    let app_only = std::env::var("BENCH_APP").is_ok_and(|v| v == "1");
    let mut meshes = meshes(quick, app_only);
    if app_only {
        println!("{}", app_figures(&meshes, &all));
        return;
    }

    // BENCH_MESH=word keeps meshes whose name contains it.
    if let Ok(m) = std::env::var("BENCH_MESH") {
        meshes.retain(|mesh| mesh.name.to_lowercase().contains(&m.to_lowercase()));
    }
    // BENCH_COUNTS=1: only the work per ray of our strategies' trees (no timing).
    if std::env::var("BENCH_COUNTS").is_ok_and(|v| v == "1") {
        for mesh in &meshes {
            let (p, i) = (rays::primary(mesh, s.primary_size), rays::incoherent(mesh, s.incoherent, 0x5EED));
            print!("{}", all.install(|| counts::table(mesh, &p, &i)));
        }
        return;
    }
    // BENCH_KERNELS=1: only our SIMD kernels raced on one tree, alternated (`kernels.rs`).
    if std::env::var("BENCH_KERNELS").is_ok_and(|v| v == "1") {
        for mesh in &meshes {
            print!("{}", kernels::table(mesh, &s, &one));
        }
        return;
    }
    // BENCH_OVERHEAD=1: only the counting overhead.
    if std::env::var("BENCH_OVERHEAD").is_ok_and(|v| v == "1") {
        for mesh in &meshes {
            print!("{}", counting_overhead(mesh, &s, &one));
        }
        return;
    }
    let started = Instant::now();
    let mut out = String::new();
    let _ =
        writeln!(out, "## versus ({})\n\nmachine: {}\n", if quick { "BENCH_QUICK=1" } else { "full run" }, machine());
    let mut closing = String::new();
    for mesh in &meshes {
        eprintln!("{} ({} triangles)", mesh.name, mesh.triangle_count());
        let rows = run_mesh(mesh, &contenders, &s, &one, &all);
        let mut t = table(mesh, &rows, &s, threads);
        let (p, i) = (rays::primary(mesh, s.primary_size), rays::incoherent(mesh, s.incoherent, 0x5EED));
        t += &all.install(|| counts::table(mesh, &p, &i));
        print!("{t}");
        out += &t;
        closing += &ratios::ratios(mesh, &rows);
        closing += &tinybvh::cwbvh_line(mesh);
        closing += &counting_overhead(mesh, &s, &one);
    }
    println!("\n{closing}");
    if !quick {
        println!("{}", app_figures(&meshes, &all));
    }
    println!("total time {:.0} s", started.elapsed().as_secs_f64());
}
