//! What each of our strategies' trees costs a ray in work rather than time: nodes visited and
//! triangles tested per ray on the bench's own rays, with references per triangle (the SBVH
//! duplicates cut triangles) and the SAH cost. Counted by the traversal that renders, through its
//! `RayCounters` sink, on the binary layout (the tree as built).

use crate::rays::RaySpec;
use bvhscope::bvh::{Accelerator, BuildParams, Bvh, Layout, RayCounters, Strategy, TraceOptions, TreeStats};
use bvhscope::geometry::Ray;
use bvhscope::mesh::Mesh;
use rayon::prelude::*;
use std::fmt::Write;

/// Per ray: nodes visited, triangle tests.
fn per_ray(bvh: &Bvh, rays: &[RaySpec]) -> (f64, f64) {
    let (nodes, tris) = rays
        .par_iter()
        .map(|r| {
            let mut c = RayCounters::default();
            let mut ray = Ray::new(r.origin, r.dir);
            bvh.closest_hit(&mut ray, TraceOptions::default(), &mut c);
            (c.nodes_visited as u64, c.triangle_tests as u64)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    let n = rays.len().max(1) as f64;
    (nodes as f64 / n, tris as f64 / n)
}

pub fn table(mesh: &Mesh, primary: &[RaySpec], incoherent: &[RaySpec]) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "\n#### Work per ray, {} (binary layout, `RayCounters`)\n", mesh.name);
    let _ = writeln!(o, "| strategy | references / triangle | SAH cost | primary nodes | primary tri tests | primary nodes + tri tests | incoherent nodes | incoherent tri tests | incoherent nodes + tri tests |");
    let _ = writeln!(o, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for strategy in Strategy::ALL {
        let params = BuildParams { strategy, layout: Layout::Binary, ..BuildParams::default() };
        let bvh = Bvh::build(mesh, &params);
        let stats = TreeStats::of(&bvh);
        let ((pn, pt), (inn, it)) = (per_ray(&bvh, primary), per_ray(&bvh, incoherent));
        let _ = writeln!(
            o,
            "| {} | {:.3} | {:.2} | {pn:.2} | {pt:.2} | {:.2} | {inn:.2} | {it:.2} | {:.2} |",
            strategy.name(),
            bvh.prim_ids.len() as f64 / mesh.triangle_count().max(1) as f64,
            stats.sah_cost,
            pn + pt,
            inn + it
        );
    }
    o
}
