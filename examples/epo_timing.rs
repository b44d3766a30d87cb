//! The EPO's cost against the SAH build's, in one process (BENCHMARKS.md, "EPO (issue 37)"):
//! `cargo run --release --example epo_timing -- MESH.obj [RUNS [SCALE]]` loads the mesh, then
//! builds the binary SAH tree and measures its EPO `RUNS` times (default 3) on rayon's threads
//! (`RAYON_NUM_THREADS` sets them), and prints the medians, their ratio and how the EPO was found.
//! `SCALE` multiplies the EPO's budget of work (default 1: `epo::measure`'s). Last, the serial
//! part of the node-to-parent table and of the EPO (`parallel::measure_serial`, on one thread) and
//! Amdahl's projection of both on 16 threads beside the build's.
use bvhscope::bvh::{epo, BuildParams, Bvh, Hierarchy, Layout};
use std::time::Instant;

fn main() {
    let path = std::env::args().nth(1).expect("usage: epo_timing MESH.obj [RUNS [SCALE]]");
    let runs: usize = std::env::args().nth(2).map_or(3, |r| r.parse().expect("a count"));
    let scale: f64 = std::env::args().nth(3).map_or(1.0, |r| r.parse().expect("a number"));
    let (mesh, _) = bvhscope::mesh::load_obj(&path).expect("reading the mesh");
    let params = BuildParams { layout: Layout::Binary, ..BuildParams::default() };
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (mut builds, mut epos, mut hierarchies) = (Vec::new(), Vec::new(), Vec::new());
    let mut last = None;
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        let bvh = Bvh::build(&mesh, &params);
        builds.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        let h = Hierarchy::of(&bvh);
        hierarchies.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        let e = epo::measure_within(&bvh, &h, (epo::budget(bvh.tris.len()) as f64 * scale) as u64);
        epos.push(t.elapsed().as_secs_f64() * 1e3);
        last = Some((e, bvh.nodes.len()));
    }
    let (e, nodes) = last.expect("one run");
    // Serial parts, on one thread: the build's, the hierarchy's and the EPO's.
    let serial = |f: &(dyn Fn() + Sync)| {
        let (_, total, serial) = bvhscope_core::parallel::measure_serial(f);
        (total.as_secs_f64() * 1e3, serial.as_secs_f64() * 1e3)
    };
    let bvh = Bvh::build(&mesh, &params);
    let h = Hierarchy::of(&bvh);
    let b1 = serial(&|| drop(Bvh::build(&mesh, &params)));
    let h1 = serial(&|| drop(Hierarchy::of(&bvh)));
    let e1 = serial(&|| drop(epo::measure_within(&bvh, &h, (epo::budget(bvh.tris.len()) as f64 * scale) as u64)));
    let amdahl16 = |(t, s): (f64, f64)| s + (t - s) / 16.0;
    println!(
        "one thread: build {:.1} ms (serial {:.1}), hierarchy {:.1} ms (serial {:.1}), EPO {:.1} ms (serial {:.1}); \
         Amdahl 16T: build {:.1} ms, hierarchy + EPO {:.1} ms ({:.2} of the build)",
        b1.0,
        b1.1,
        h1.0,
        h1.1,
        e1.0,
        e1.1,
        amdahl16(b1),
        amdahl16(h1) + amdahl16(e1),
        (amdahl16(h1) + amdahl16(e1)) / amdahl16(b1)
    );
    let (b, h, m) = (median(builds), median(hierarchies), median(epos));
    println!(
        "{path}: {} triangles, {nodes} nodes, {} threads; SAH build {b:.1} ms, hierarchy {h:.1} ms, EPO {m:.1} ms \
         (EPO with hierarchy / build {:.2}); EPO {} ({}; work {} of budget {})",
        mesh.triangle_count(),
        rayon::current_num_threads(),
        (m + h) / b,
        e.text(),
        e.method(),
        e.work,
        e.budget
    );
}
