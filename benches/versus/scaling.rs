//! `BENCH_THREADS=1,2,4,8,16`: how each phase scales with the thread count (issue 37). Per phase —
//! the OBJ load, each strategy's build, EPO of the SAH tree, a counted frame (the visits heatmap:
//! single rays with counters) and a packet frame (normals: 8×8 packets), both 3840×2160 with their
//! image made, without PNG encoding, which has rows of its own — the median time on a rayon pool
//! of each thread count and the speed-up over one thread, with Embree's builds beside ours where it
//! was found. Counts above this machine's cores still run, flagged as oversubscribed.
//!
//! A machine with few cores cannot show 16 threads, so each phase's serial fraction f is measured
//! as well (`parallel::measure_serial`: the time outside the stretches marked parallel, on one
//! thread) and the speed-up on 16 threads projected from it with Amdahl's law, 1 / (f + (1 − f)/16)
//! (Amdahl, "Validity of the single processor approach…", AFIPS 1967), as
//! `core/examples/build_scaling.rs` does for the builds. Embree's serial part cannot be seen.
//!
//! The mesh: the bunny of `../shared/models`, or `BENCH_SCALING_MESH=path.obj`;
//! `BENCH_SCALING_REPS=n` runs per phase and thread count (default 3, the thread counts taking
//! turns so that the machine's drift falls on all of them); `BENCH_SCALING_ONLY=frame,png` keeps
//! the phases whose names contain a word.

use bvhscope::bvh::{epo, AnyBvh, BuildParams, Bvh, Hierarchy, Layout, Strategy};
use bvhscope::mesh::{load_obj, Mesh};
use bvhscope::render::{draw_legend, render, view_image, Camera, ColorMap, HeatRange, RenderSettings, View};
use bvhscope_core::parallel::measure_serial;
use rayon::ThreadPool;
use std::fmt::Write;
use std::path::PathBuf;
use std::time::{Duration, Instant};

const FRAME: (u32, u32) = (3840, 2160);

/// A phase's work: it times what counts and returns that time; what it made is dropped after the
/// clock stops (freeing is not the phase's work).
type Work<'a> = Box<dyn Fn() -> Duration + Sync + 'a>;

struct Phase<'a> {
    name: String,
    work: Work<'a>,
    /// Whether its serial part can be measured (not Embree's: its threads are its own).
    measured: bool,
}

/// Per phase: the median time per thread count (in the order given), and on one thread the
/// median time outside parallel regions and the median of its share of each run.
struct Row {
    name: String,
    times: Vec<f64>,
    serial: Option<(f64, f64)>,
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Amdahl's law: the speed-up on `p` threads of work whose fraction `f` is serial.
fn amdahl(f: f64, p: f64) -> f64 {
    1.0 / (f + (1.0 - f) / p)
}

/// The thread counts of `BENCH_THREADS`, 1 first (the speed-ups and the serial fraction are of it).
pub fn thread_counts(list: &str) -> Vec<usize> {
    let mut v: Vec<usize> =
        list.split(',').map(|t| t.trim().parse().expect("BENCH_THREADS=1,2,4,…: thread counts")).collect();
    v.retain(|&t| t > 1);
    v.insert(0, 1);
    v.dedup();
    v
}

fn mesh_path() -> PathBuf {
    match std::env::var("BENCH_SCALING_MESH") {
        Ok(p) => PathBuf::from(p),
        Err(_) => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/models/stanford-bunny.obj"),
    }
}

/// Time `f` and drop what it made, untimed.
fn timed<T>(f: impl FnOnce() -> T) -> Duration {
    let t0 = Instant::now();
    let made = f();
    let d = t0.elapsed();
    drop(made);
    d
}

/// The phases over `mesh` (loaded from `path`) and its trees.
fn phases<'a>(path: &'a PathBuf, mesh: &'a Mesh, sah: &'a Bvh, frame_bvh: &'a AnyBvh) -> Vec<Phase<'a>> {
    let phase = |name: &str, work: Work<'a>| Phase { name: name.into(), work, measured: true };
    let mut v = vec![phase("OBJ load", Box::new(move || timed(|| load_obj(path).expect("loading the mesh"))))];
    for s in Strategy::ALL {
        let params = BuildParams { strategy: s, layout: Layout::Binary, ..Default::default() };
        v.push(phase(&format!("build {}", s.name()), Box::new(move || timed(|| Bvh::build(mesh, &params)))));
    }
    for c in crate::embree::all().into_iter().filter(|c| c.family == crate::contenders::Family::Embree) {
        let build = c.build;
        // "embree medium (rtcIntersect1)": the build is the scene's, whatever traces it.
        let name = c.name.split(" (").next().unwrap_or(&c.name).to_owned();
        v.push(Phase { name: format!("build {name}"), work: Box::new(move || build(mesh).1), measured: false });
    }
    v.push(phase("EPO of the SAH tree", Box::new(move || timed(|| epo::measure(sah, &Hierarchy::of(sah))))));
    let camera = Camera::framing(&mesh.bounds(), FRAME.0, FRAME.1);
    let (w, h) = FRAME;
    let frame = move |view: View| {
        let count = view.is_heatmap();
        let settings = RenderSettings { count, ..Default::default() };
        let f = render(frame_bvh, mesh, &camera, &settings);
        let (img, legend) = view_image(&f, view, ColorMap::Viridis, HeatRange::Auto, BuildParams::default().cost);
        // As `render` draws it: the heatmap's legend below the image.
        let img = match legend {
            Some(l) => draw_legend(&img, &l),
            None => img,
        };
        (f, img)
    };
    v.push(phase(&format!("counted frame {w}×{h}"), Box::new(move || timed(|| frame(View::Visits)))));
    v.push(phase(&format!("packet frame {w}×{h}"), Box::new(move || timed(|| frame(View::Normals)))));
    // PNG encoding, on one thread whatever the pool (the `png` crate's deflate is serial): what
    // `render` does after the frame, for both images.
    for (what, view) in [("counted", View::Visits), ("packet", View::Normals)] {
        let (_, image) = frame(view);
        v.push(phase(
            &format!("PNG encoding, {what} frame's image"),
            Box::new(move || {
                timed(|| {
                    let mut bytes = Vec::new();
                    image.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).expect("encoding");
                    bytes
                })
            }),
        ));
    }
    v
}

/// The tables: times, speed-ups and serial fractions per phase.
pub fn table(threads: &[usize]) -> String {
    let path = mesh_path();
    let reps: usize = std::env::var("BENCH_SCALING_REPS").map_or(3, |r| r.parse().expect("BENCH_SCALING_REPS=n"));
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let pools: Vec<ThreadPool> =
        threads.iter().map(|&t| rayon::ThreadPoolBuilder::new().num_threads(t).build().expect("a pool")).collect();
    eprintln!("scaling: loading {}", path.display());
    let (mesh, _) = load_obj(&path).expect("loading the mesh");
    let all = pools.last().expect("a pool");
    let sah = all.install(|| Bvh::build(&mesh, &BuildParams { layout: Layout::Binary, ..Default::default() }));
    let frame_bvh = all.install(|| AnyBvh::build(&mesh, &BuildParams::default()));
    let mut phases = phases(&path, &mesh, &sah, &frame_bvh);
    if let Ok(only) = std::env::var("BENCH_SCALING_ONLY") {
        let words: Vec<String> = only.split(',').map(|w| w.trim().to_lowercase()).collect();
        phases.retain(|p| words.iter().any(|w| p.name.to_lowercase().contains(w.as_str())));
    }
    let mut rows = Vec::new();
    for p in phases {
        eprintln!("  {} ...", p.name);
        let mut times = vec![Vec::new(); threads.len()];
        let mut serial = Vec::new();
        for _ in 0..reps {
            // The thread counts take turns, so drift on this shared machine falls on all of them.
            for (i, pool) in pools.iter().enumerate() {
                times[i].push(ms(pool.install(|| (p.work)())));
            }
            // On one thread, the time outside parallel regions, less the untimed drop (serial).
            if p.measured {
                let (d, total, outside) = measure_serial(|| (p.work)());
                let outside = ms(outside.saturating_sub(total.saturating_sub(d)));
                serial.push((outside, outside / ms(d)));
                times[0].push(ms(d));
            }
        }
        let times = times.into_iter().map(crate::median).collect();
        let serial = p.measured.then(|| {
            let (ms, f): (Vec<f64>, Vec<f64>) = serial.into_iter().unzip();
            (crate::median(ms), crate::median(f))
        });
        rows.push(Row { name: p.name, times, serial });
    }
    write(&path, &mesh, threads, cores, reps, &rows)
}

fn write(path: &std::path::Path, mesh: &Mesh, threads: &[usize], cores: usize, reps: usize, rows: &[Row]) -> String {
    let mut o = String::new();
    let name = path.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned());
    let _ = writeln!(o, "\n### Scaling: {name} ({} triangles)\n", mesh.triangle_count());
    let _ = writeln!(
        o,
        "{}; medians of {reps} runs per thread count (one thread: {} runs, half of them timing the serial part); \
         frames {}×{}, default tree (SAH, 4-wide), image made, legend drawn, no PNG.\n",
        crate::machine(),
        2 * reps,
        FRAME.0,
        FRAME.1
    );
    let flag = |t: usize| if t > cores { "*" } else { "" };
    let mut head = String::from("| phase |");
    let mut rule = String::from("| --- |");
    for &t in threads {
        let _ = write!(head, " {t}T{} ms |", flag(t));
        rule += " ---: |";
        if t > 1 {
            let _ = write!(head, " {t}T{} × |", flag(t));
            rule += " ---: |";
        }
    }
    head += " serial ms (1T) | f | Amdahl 16T |";
    rule += " ---: | ---: | ---: |";
    let _ = writeln!(o, "{head}\n{rule}");
    for r in rows {
        let _ = write!(o, "| {} |", r.name);
        for (i, &t) in threads.iter().enumerate() {
            let _ = write!(o, " {:.1} |", r.times[i]);
            if t > 1 {
                let _ = write!(o, " {:.2}× |", r.times[0] / r.times[i]);
            }
        }
        match r.serial {
            Some((s, f)) => {
                let _ = writeln!(o, " {s:.1} | {:.2} % | {:.1}× |", 100.0 * f, amdahl(f, 16.0));
            }
            None => {
                let _ = writeln!(o, " — | — | — |");
            }
        }
    }
    if threads.iter().any(|&t| t > cores) {
        let _ = writeln!(o, "\n\\* oversubscribed: more threads than this machine's {cores} hardware threads.");
    }
    let _ = writeln!(
        o,
        "\nf: the share of a one-thread run spent outside parallel regions (`parallel::measure_serial`), median; \
         Amdahl 16T: 1 / (f + (1 − f)/16), what 16 cores would give if the rest scaled perfectly."
    );
    o
}
