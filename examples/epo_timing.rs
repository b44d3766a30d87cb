//! The EPO's cost against the SAH build's, in one process (BENCHMARKS.md, "EPO (issue 37)"):
//! `cargo run --release --example epo_timing -- MESH.obj [RUNS [SCALE]]` loads the mesh, then
//! builds the binary SAH tree and measures its EPO `RUNS` times (default 3) on rayon's threads
//! (`RAYON_NUM_THREADS` sets them), and prints the medians, their ratio and how the EPO was found.
//! `SCALE` multiplies the EPO's budget of work (default 1: `epo::measure`'s).
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
