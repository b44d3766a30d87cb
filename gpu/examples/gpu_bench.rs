//! GPU throughput, for a run on a real GPU (lavapipe runs it too, but a software adapter's figures
//! say nothing about a GPU): MRays/s of primary and incoherent rays per node format (binary,
//! CWBVH), counted and plain, exact and fused arithmetic; the warp view's SIMT efficiency; the
//! GPU LBVH's and PLOC's build phases against core's on this machine's CPU. The adapter is named first.
//!
//! ```sh
//! cargo run --release -p bvhscope-gpu --example gpu_bench -- [MESH.obj ...] [--size 1920x1080]
//!     [--rays 1000000] [--reps 5]
//! ```
//! Without a mesh: ../shared/models/stanford-bunny.obj, else core's built-in scene. Primary rays:
//! one per pixel of the default view (`Camera::framing`). Incoherent rays: from random points on
//! random triangles in random directions, a hair off the surface (core's `incoherent_rays`, as
//! benches/versus traces them, seed 1). Each figure is the best of `reps` runs of submit-to-completion time;
//! read-backs are not timed.

use bvhscope_core::bvh::{BuildParams, Bvh, Layout, Strategy};
use bvhscope_core::mesh::{generate, load_obj, Mesh};
use bvhscope_core::render::{incoherent_rays, Camera};
use bvhscope_gpu::{
    Cwbvh, Gpu, GpuBinaryBvh, GpuCwbvh, GpuLbvh, GpuPloc, GpuTrace, GpuTraceOptions, Rays, WarpSize, WarpView, WarpWork,
};
use std::time::{Duration, Instant};

struct Args {
    meshes: Vec<String>,
    width: u32,
    height: u32,
    rays: usize,
    reps: u32,
}

fn args() -> Result<Args, String> {
    let mut a = Args { meshes: vec![], width: 1920, height: 1080, rays: 1_000_000, reps: 5 };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().ok_or(format!("{arg} needs a value"));
        match arg.as_str() {
            "--size" => {
                let v = value()?;
                let (w, h) = v.split_once('x').ok_or("--size WxH")?;
                (a.width, a.height) = (w.parse().map_err(|e| format!("{e}"))?, h.parse().map_err(|e| format!("{e}"))?);
            }
            "--rays" => a.rays = value()?.parse().map_err(|e| format!("--rays: {e}"))?,
            "--reps" => a.reps = value()?.parse::<u32>().map_err(|e| format!("--reps: {e}"))?.max(1),
            s if s.starts_with("--") => return Err(format!("unknown option {s}")),
            path => a.meshes.push(path.to_string()),
        }
    }
    Ok(a)
}

/// The best of `reps` runs of `f`, and the last run's result.
fn best(
    reps: u32,
    mut f: impl FnMut() -> Result<GpuTrace, bvhscope_gpu::GpuError>,
) -> Result<(Duration, GpuTrace), String> {
    let mut best = Duration::MAX;
    let mut last = GpuTrace::default();
    for _ in 0..reps {
        last = f().map_err(|e| e.to_string())?;
        best = best.min(last.gpu_time);
    }
    Ok((best, last))
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let a = args()?;
    let gpu = Gpu::new().map_err(|e| e.to_string())?;
    println!("adapter: {}", gpu.name());
    if gpu.is_software() {
        println!("note: a software adapter: these figures are for checking the benchmark runs, not for comparing");
    }
    let mut meshes: Vec<(String, Mesh)> = Vec::new();
    for path in &a.meshes {
        meshes.push((path.clone(), load_obj(path).map_err(|e| format!("{path}: {e}"))?.0));
    }
    if meshes.is_empty() {
        let bunny = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/models/stanford-bunny.obj");
        match load_obj(&bunny) {
            Ok((m, _)) => meshes.push(("stanford-bunny.obj".into(), m)),
            Err(_) => meshes.push(("built-in scene".into(), generate::builtin_scene())),
        }
    }
    println!(
        "| mesh | triangles | format | rays | counted | arithmetic | MRays/s | nodes/ray | tris/ray | SIMT eff. (32) |"
    );
    println!("| --- | ---: | --- | --- | --- | --- | ---: | ---: | ---: | ---: |");
    for (name, mesh) in &meshes {
        let bvh = Bvh::build(mesh, &BuildParams { layout: Layout::Binary, ..BuildParams::default() });
        let binary = GpuBinaryBvh::upload(&gpu, &bvh).map_err(|e| e.to_string())?;
        let cw = Cwbvh::from_bvh(&bvh).map_err(|e| e.to_string())?;
        let cwbvh = GpuCwbvh::upload(&gpu, &cw).map_err(|e| e.to_string())?;
        let cam = Camera::framing(&mesh.bounds(), a.width, a.height);
        let list = incoherent_rays(mesh, a.rays, 1);
        for (kind, rays) in [("primary", Rays::Camera(&cam)), ("incoherent", Rays::List(&list))] {
            for format in ["binary", "cwbvh"] {
                for (counted, exact) in [(true, true), (false, true), (false, false)] {
                    let opts = GpuTraceOptions { counted, exact, ..GpuTraceOptions::default() };
                    let trace = || match format {
                        "binary" => binary.trace(&gpu, rays, opts),
                        _ => cwbvh.trace(&gpu, rays, opts),
                    };
                    // One run first: compiling the kernel is not timed.
                    trace().map_err(|e| e.to_string())?;
                    let (time, t) = best(a.reps, trace)?;
                    let n = rays.len() as f64;
                    let (nodes, tris, simt) = if counted {
                        let c = &t.counters;
                        let view = match rays {
                            Rays::Camera(_) => WarpView::frame(a.width, a.height, c, WarpSize::W32, WarpWork::Steps),
                            Rays::List(_) => WarpView::list(c, WarpSize::W32, WarpWork::Steps),
                        };
                        let sum = |f: fn(&bvhscope_core::bvh::RayCounters) -> u32| {
                            c.iter().map(|x| f(x) as f64).sum::<f64>() / n
                        };
                        (
                            format!("{:.1}", sum(|x| x.nodes_visited)),
                            format!("{:.1}", sum(|x| x.triangle_tests)),
                            format!("{:.3}", view.summary().simt_efficiency),
                        )
                    } else {
                        ("".into(), "".into(), "".into())
                    };
                    println!(
                        "| {name} | {} | {format} | {kind} | {} | {} | {:.1} | {nodes} | {tris} | {simt} |",
                        mesh.triangle_count(),
                        if counted { "counted" } else { "plain" },
                        if exact { "exact" } else { "fused" },
                        n / time.as_secs_f64() / 1e6,
                    );
                }
            }
        }
        let lbvh = GpuLbvh::new(&gpu).map_err(|e| e.to_string())?;
        let params = BuildParams { strategy: Strategy::Lbvh, layout: Layout::Binary, ..BuildParams::default() };
        lbvh.build(&gpu, mesh, &params).map_err(|e| e.to_string())?;
        let mut t = lbvh.build(&gpu, mesh, &params).map_err(|e| e.to_string())?.1;
        for _ in 1..a.reps {
            let u = lbvh.build(&gpu, mesh, &params).map_err(|e| e.to_string())?.1;
            if u.total() < t.total() {
                t = u;
            }
        }
        let start = Instant::now();
        let cpu = Bvh::build(mesh, &params);
        let cpu_time = start.elapsed();
        println!(
            "GPU LBVH, {name}: {:?} (upload {:?}, codes {:?}, sort {:?}, emission {:?}, boxes {:?}, download {:?}); CPU LBVH on {} threads: {:?} ({} nodes)",
            t.total(),
            t.upload,
            t.codes,
            t.sort,
            t.emission,
            t.boxes,
            t.download,
            std::thread::available_parallelism().map_or(1, |n| n.get()),
            cpu_time,
            cpu.nodes.len()
        );
        let ploc = GpuPloc::new(&gpu).map_err(|e| e.to_string())?;
        let params = BuildParams { strategy: Strategy::Ploc, ..params };
        ploc.build(&gpu, mesh, &params).map_err(|e| e.to_string())?;
        let (g, t) = ploc.build(&gpu, mesh, &params).map_err(|e| e.to_string())?;
        let start = Instant::now();
        let cpu = Bvh::build(mesh, &params);
        let cpu_time = start.elapsed();
        let sah = |b: &Bvh| bvhscope_core::bvh::TreeStats::of(b).sah_cost;
        println!(
            "GPU PLOC, {name}: {:?} (upload {:?}, codes {:?}, sort {:?}, {} clustering rounds {:?}, layout on the host {:?}, download {:?}), SAH {:.3}; CPU PLOC: {:?}, SAH {:.3}",
            t.total(),
            t.upload,
            t.codes,
            t.sort,
            t.rounds,
            t.emission,
            t.boxes,
            t.download,
            sah(&g),
            cpu_time,
            sah(&cpu)
        );
    }
    Ok(())
}
