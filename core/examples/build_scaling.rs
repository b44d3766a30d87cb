//! Times the OBJ load and every strategy's build on one and more threads (issue 37, "Builds that
//! scale"), median of a few runs each, in this process:
//!
//! `cargo run --release -p bvhscope-core --example build_scaling -- grid /tmp/grid4m.obj ../shared/models/stanford-bunny.obj 58`
//! writes 58 bunnies on a square grid (4,028,158 triangles);
//! `cargo run --release -p bvhscope-core --example build_scaling -- time /tmp/grid4m.obj 1,2 3 [STRATEGY,…]`
//! times loading it and building it with each strategy (binary layout) on 1 and 2 threads, 3 runs each,
//! with the time each spends outside parallel regions (`bvhscope_core::parallel::serial`), and
//! projects the speed-up on 16 threads from it with Amdahl's law.
use bvhscope_core::bvh::{BuildParams, Bvh, Layout, Strategy};
use bvhscope_core::mesh::{load_obj, write_obj};
use bvhscope_core::parallel::measure_serial;
use std::time::{Duration, Instant};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize| args.get(i).map(String::as_str);
    match arg(0) {
        Some("grid") => {
            let (one, _) = load_obj(arg(2).expect("the mesh to repeat")).expect("reading the mesh");
            let mesh = bvhscope_core::mesh::generate::grid_of(&one, arg(3).map_or(58, |c| c.parse().expect("a count")));
            let path = arg(1).expect("the output path");
            let mut f = std::io::BufWriter::new(std::fs::File::create(path).expect("create"));
            write_obj(&mesh, &mut f).expect("write");
            println!("wrote {path}: {} triangles", mesh.triangle_count());
        }
        Some("time") => {
            let path = arg(1).expect("the OBJ to time");
            let threads: Vec<usize> =
                arg(2).unwrap_or("1,2").split(',').map(|t| t.parse().expect("a thread count")).collect();
            let runs: usize = arg(3).map_or(3, |r| r.parse().expect("a run count"));
            let strategies: Vec<Strategy> = match arg(4) {
                Some(list) => list.split(',').map(|s| Strategy::from_name(s).expect("a strategy")).collect(),
                None => Strategy::ALL.to_vec(),
            };
            time(path, &threads, runs, &strategies);
        }
        _ => panic!("usage: build_scaling grid OUT MESH [COPIES] | time OBJ [THREADS [RUNS [STRATEGIES]]]"),
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Amdahl's law: the speed-up on `p` threads of work whose fraction `f` is serial.
fn amdahl(f: f64, p: f64) -> f64 {
    1.0 / (f + (1.0 - f) / p)
}

/// Per work: (thread count, median wall ms, median serial ms).
type Rows = Vec<(String, Vec<(usize, f64, f64)>)>;

/// The process's CPU time (user and system, all threads) from /proc/self/stat, in clock ticks of
/// 10 ms: on a machine shared with other work, wall times on two threads suffer from it, so the
/// CPU time a run used is printed beside its wall time.
fn cpu_time() -> Duration {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat.rsplit_once(')').map_or("", |x| x.1).split_whitespace().collect();
    let ticks: u64 = fields.get(11..13).map_or(0, |f| f.iter().filter_map(|x| x.parse::<u64>().ok()).sum());
    Duration::from_millis(ticks * 10)
}

fn time(path: &str, threads: &[usize], runs: usize, strategies: &[Strategy]) {
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    println!("machine: {cores} hardware threads; {runs} runs each, medians");
    let mut rows: Rows = Vec::new();
    let mut record = |name: &str, t: usize, times: Vec<(Duration, Duration, Duration)>| {
        let wall = median(times.iter().map(|x| ms(x.0)).collect());
        let serial = median(times.iter().map(|x| ms(x.1)).collect());
        let cpu = median(times.iter().map(|x| ms(x.2)).collect());
        let all: Vec<String> = times.iter().map(|x| format!("{:.0}", ms(x.0))).collect();
        println!(
            "{t} threads: {name:<11} {wall:>8.0} ms (runs {}), serial {serial:>6.1} ms, cpu {cpu:>6.0} ms",
            all.join("/")
        );
        match rows.iter_mut().find(|r| r.0 == name) {
            Some(r) => r.1.push((t, wall, serial)),
            None => rows.push((name.to_owned(), vec![(t, wall, serial)])),
        }
    };
    for &t in threads {
        // `f` times its work and then frees what it made, untimed. One thread: run by
        // `measure_serial`, which also gives the time outside parallel regions (on its own pool
        // of one thread; the freeing, outside `f`'s time, is taken off that). More: on a pool.
        let timed = |f: &(dyn Fn() -> Duration + Sync)| -> (Duration, Duration, Duration) {
            let cpu = cpu_time();
            let (d, serial) = if t == 1 {
                let (d, total, serial) = measure_serial(f);
                (d, serial.saturating_sub(total.saturating_sub(d)))
            } else {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build().expect("a pool");
                (pool.install(f), Duration::ZERO)
            };
            (d, serial, cpu_time().saturating_sub(cpu))
        };
        let load = || {
            let t0 = Instant::now();
            let mesh = load_obj(path).expect("loading");
            let d = t0.elapsed();
            drop(mesh);
            d
        };
        let loads = (0..runs).map(|_| timed(&load)).collect();
        record("load", t, loads);
        let (mesh, _) = load_obj(path).expect("loading");
        for &s in strategies {
            let params = BuildParams { strategy: s, layout: Layout::Binary, ..Default::default() };
            // (The tree is dropped inside: freeing it is not part of the build.)
            let build = || {
                let t0 = Instant::now();
                let bvh = Bvh::build(&mesh, &params);
                let d = t0.elapsed();
                drop(bvh);
                d
            };
            let builds = (0..runs).map(|_| timed(&build)).collect();
            record(s.name(), t, builds);
        }
    }
    // The serial fraction f is measured on one thread; Amdahl's law projects the speed-up on p
    // threads as 1 / (f + (1 - f) / p), assuming the rest scales perfectly (a projection).
    println!("\n| work | 1T ms | 2T ms | 2T speed-up | serial ms (1T) | f | Amdahl 2T | Amdahl 16T (projection) |");
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for (name, r) in &rows {
        let at = |t: usize| r.iter().find(|x| x.0 == t);
        let (Some(one), two) = (at(1), at(2)) else { continue };
        let f = one.2 / one.1;
        let two_ms = two.map_or("—".to_owned(), |x| format!("{:.0}", x.1));
        let speed = two.map_or("—".to_owned(), |x| format!("{:.2}×", one.1 / x.1));
        println!(
            "| {name} | {:.0} | {two_ms} | {speed} | {:.1} | {:.2} % | {:.2}× | {:.1}× |",
            one.1,
            one.2,
            100.0 * f,
            amdahl(f, 2.0),
            amdahl(f, 16.0)
        );
    }
}
