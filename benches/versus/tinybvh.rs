//! tinybvh (Jacco Bikker's single-header library, 1.6.8 as the `tinybvh-rs` crate bundles it) as
//! a contender: its BVH8_CPU, the 8-wide CPU layout of Fuetterling et al., "Accelerated Single Ray
//! Tracing for Wide Vector Units" (HPG 2017), with leaves of exactly four triangles in SoA form.
//!
//! What is raced: tinybvh's binned-SAH build (`Build`) and its spatial-split build (`BuildHQ`),
//! each split to leaves of at most four, collapsed to its MBVH<8> and converted to BVH8_CPU (the
//! whole chain is the timed build, as tinybvh's own speed test does), traced one ray at a time
//! with `BVH8_CPU::Intersect`. The crate compiles that walk only when AVX2 is enabled at compile
//! time, so it is raced only in a bench built with `RUSTFLAGS="-C target-cpu=native"` (in a target
//! folder of its own, so the tests' build is not invalidated); elsewhere `notice()` says why not.
//! Its builds are single-threaded: the NT build column repeats the 1T one.
//!
//! No SAH cost is printed: tinybvh's `SAHCost` uses its own constants, and ours would be computed
//! over a different tree than the one traced (its leaves split to four after the build).
//! Memory is what BVH8_CPU's conversion allocates, computed from its layout (256-byte nodes,
//! 192-byte four-triangle leaves: `BVH8_CPU::ConvertFrom`), without the MBVH it keeps a copy of.

use crate::contenders::Contender;
use bvhscope::mesh::Mesh;

/// A line for the report when tinybvh is not in the race.
pub fn notice() -> Option<&'static str> {
    if cfg!(target_feature = "avx2") {
        None
    } else {
        Some(
            "tinybvh's BVH8_CPU walk is compiled only with AVX2 enabled: raced without it \
             (RUSTFLAGS=\"-C target-cpu=native\" CARGO_TARGET_DIR=target/native cargo bench -p bvhscope-versus --bench versus).",
        )
    }
}

/// The triangles as tinybvh takes them: three `[x, y, z, 0]` vertices per triangle, in the mesh's order.
fn positions(mesh: &Mesh) -> Vec<[f32; 4]> {
    (0..mesh.triangle_count() as u32).flat_map(|i| mesh.triangle(i).map(|v| [v.x, v.y, v.z, 0.0])).collect()
}

/// The nodes of tinybvh's 8-wide BVH in use (the root and every interior node below it) and its leaves.
#[cfg_attr(not(target_feature = "avx2"), allow(dead_code))]
fn mbvh_counts(mbvh: &tinybvh_rs::mbvh::BVH) -> (usize, usize) {
    let nodes = mbvh.nodes();
    let (mut interior, mut leaves) = (0, 0);
    let mut stack = vec![0u32];
    while let Some(i) = stack.pop() {
        let n = &nodes[i as usize];
        if n.is_leaf() {
            leaves += 1;
        } else {
            interior += 1;
            stack.extend(n.child[..n.child_count as usize].iter().copied().filter(|&c| c != 0));
        }
    }
    (interior, leaves)
}

/// tinybvh's CWBVH node count for the mesh (its binned-SAH tree, leaves of at most three, as
/// its CWBVH conversion asks), printed beside ours in the closing lines.
pub fn cwbvh_nodes(mesh: &Mesh) -> usize {
    let tris = positions(mesh);
    let Ok(mut bvh) = tinybvh_rs::bvh::BVH::new(tris.as_slice().into()) else { return 0 };
    bvh.split_leaves(3);
    let mbvh = tinybvh_rs::mbvh::BVH::new(&bvh);
    tinybvh_rs::cwbvh::BVH::new(&mbvh).map(|c| c.nodes().len()).unwrap_or(0)
}

#[cfg(not(target_feature = "avx2"))]
pub fn all() -> Vec<Contender> {
    Vec::new()
}

#[cfg(target_feature = "avx2")]
pub fn all() -> Vec<Contender> {
    vec![linked::contender(false), linked::contender(true)]
}

#[cfg(target_feature = "avx2")]
mod linked {
    use super::{mbvh_counts, positions, Contender};
    use crate::contenders::{Built, Family, Tracer};
    use crate::rays::RaySpec;
    use std::time::Instant;
    use tinybvh_rs::{bvh, bvh8_cpu, mbvh, Intersector, Ray, INFINITE};

    struct Bvh8Cpu(bvh8_cpu::BVH);

    // SAFETY: `BVH8_CPU::Intersect` is a const method that reads the node and leaf blocks the
    // conversion wrote and writes only the ray it is given; nothing is changed after the build.
    unsafe impl Send for Bvh8Cpu {}
    unsafe impl Sync for Bvh8Cpu {}

    impl Tracer for Bvh8Cpu {
        #[inline]
        fn trace(&self, r: &RaySpec) -> bool {
            let mut ray = Aligned(Ray::new(r.origin.to_array(), r.dir.to_array()));
            self.0.intersect(&mut ray.0);
            ray.0.hit.t < INFINITE
        }
    }

    /// tinybvh's C++ `Ray` is 64-byte aligned and its AVX2 walk loads it as such; the crate's
    /// Rust `Ray` is aligned to 16 only, and a ray on the stack at an address 16 past a cache line
    /// made the walk fault. Held in this, every ray sits where the C++ code expects it.
    #[repr(C, align(64))]
    struct Aligned(Ray);

    pub fn contender(hq: bool) -> Contender {
        Contender {
            name: format!("tinybvh {} (BVH8_CPU)", if hq { "BuildHQ" } else { "Build" }),
            family: Family::TinyBvh,
            slow_build: hq,
            build: Box::new(move |mesh| {
                let tris = positions(mesh);
                let t = Instant::now();
                let built =
                    if hq { bvh::BVH::new_hq(tris.as_slice().into()) } else { bvh::BVH::new(tris.as_slice().into()) };
                let mut wald = built.expect("three vertices per triangle");
                wald.split_leaves(4);
                let wide = mbvh::BVH::new(&wald);
                let cpu = bvh8_cpu::BVH::new(&wide).expect("leaves of at most four");
                let took = t.elapsed();
                let (interior, leaves) = mbvh_counts(&wide);
                let bytes = (interior * 256 + leaves * 192) as f64 / mesh.triangle_count() as f64;
                let built = Built { tracer: Box::new(Bvh8Cpu(cpu)), sah_cost: None, bytes_per_tri: Some(bytes) };
                (built, took)
            }),
        }
    }
}

/// The closing line comparing compressed wide BVHs: our CWBVH (the GPU's encoder, over the
/// default SAH tree, leaves of up to four) and tinybvh's (its binned SAH, leaves of up to three).
pub fn cwbvh_line(mesh: &Mesh) -> String {
    use bvhscope::bvh::{BuildParams, Bvh, Layout};
    let name = mesh.name.split_whitespace().next().unwrap_or("mesh").to_lowercase();
    let ours = Bvh::build(mesh, &BuildParams { layout: Layout::Binary, ..BuildParams::default() });
    let ours = bvhscope_gpu::Cwbvh::from_bvh(&ours).map(|c| c.nodes.len()).unwrap_or(0);
    format!("CWBVH nodes {name}: bvhscope {ours} (leaves ≤ 4), tinybvh {} (leaves ≤ 3)\n", cwbvh_nodes(mesh))
}
