//! Every implementation under test, behind one trait: build (timed) and trace one ray.

use crate::rays::RaySpec;
use bvhscope::bvh::packet::PACKET;
use bvhscope::bvh::{
    Accelerator, AnyBvh, BuildParams, Layout, NoStats, RayCounters, Strategy, TraceOptions, TreeStats,
};
use bvhscope::cpu::Simd;
use bvhscope::geometry::{intersect_triangle, Ray, TriangleTest};
use bvhscope::mesh::Mesh;
use glam::{Vec3, Vec3A};
use std::hint::black_box;
use std::time::{Duration, Instant};

/// Closest-hit tracing of one ray; true when something was hit.
pub trait Tracer: Sync + Send {
    fn trace(&self, r: &RaySpec) -> bool;

    /// Trace consecutive rays (a chunk of the ray list, a multiple of 4 long); returns the hits.
    fn trace_chunk(&self, rays: &[RaySpec]) -> usize {
        rays.iter().filter(|r| self.trace(r)).count()
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    Ours,
    ObvhsBvh2,
    ObvhsCwbvh,
    BvhCrate,
    /// Embree with single rays (`rtcIntersect1`).
    Embree,
    /// Embree with packets or streams (built only where Embree is found).
    #[cfg_attr(not(embree), allow(dead_code))]
    EmbreePackets,
    /// tinybvh's BVH8_CPU with single rays (built only where AVX2 was enabled at compile time).
    #[cfg_attr(not(target_feature = "avx2"), allow(dead_code))]
    TinyBvh,
}

pub struct Built {
    pub tracer: Box<dyn Tracer>,
    pub sah_cost: Option<f64>,
    /// Bytes per triangle of what the traversal reads: nodes, indices, triangle leaves.
    pub bytes_per_tri: Option<f64>,
}

/// Builds a tracer and says how long the build proper took.
pub type BuildFn = Box<dyn Fn(&Mesh) -> (Built, Duration) + Sync>;

/// A named way to build a tracer; `build` returns the structure and the time of the build proper
/// (input conversion to the library's own types is not timed).
pub struct Contender {
    pub name: String,
    pub family: Family,
    pub build: BuildFn,
    /// Slow builds are skipped on big meshes in quick mode.
    pub slow_build: bool,
}

// ---------------------------------------------------------------- ours

struct Ours<A, S> {
    accel: A,
    opts: TraceOptions,
    _stats: std::marker::PhantomData<S>,
}

impl<A: Accelerator + Send, S: bvhscope::bvh::TraversalStats + Default + Sync + Send> Tracer for Ours<A, S> {
    #[inline]
    fn trace(&self, r: &RaySpec) -> bool {
        let mut ray = Ray::new(r.origin, r.dir);
        let mut stats = S::default();
        let hit = self.accel.closest_hit(&mut ray, self.opts, &mut stats).is_some();
        black_box(&stats);
        hit
    }
}

/// Our BVH traced in packets of up to 64 consecutive rays (`Accelerator::closest_hits`): an 8×8
/// pixel tile of the primary frame; 64 unrelated rays of the incoherent set.
struct OursPackets {
    bvh: AnyBvh,
}

impl Tracer for OursPackets {
    fn trace(&self, r: &RaySpec) -> bool {
        let mut ray = Ray::new(r.origin, r.dir);
        self.bvh.closest_hit(&mut ray, TraceOptions::default(), &mut NoStats).is_some()
    }

    fn trace_chunk(&self, rays: &[RaySpec]) -> usize {
        let mut hits = 0;
        let mut packet = Vec::with_capacity(PACKET);
        let mut out = [None; PACKET];
        for c in rays.chunks(PACKET) {
            packet.clear();
            packet.extend(c.iter().map(|r| Ray::new(r.origin, r.dir)));
            let out = &mut out[..c.len()];
            self.bvh.closest_hits(&mut packet, out, TraceOptions::default());
            hits += out.iter().flatten().count();
        }
        hits
    }
}

fn tracer<S: bvhscope::bvh::TraversalStats + Default + Sync + Send + 'static>(
    bvh: AnyBvh,
    opts: TraceOptions,
) -> Box<dyn Tracer> {
    match bvh {
        AnyBvh::Binary(accel) => Box::new(Ours::<_, S> { accel, opts, _stats: Default::default() }),
        AnyBvh::Wide(accel) => Box::new(Ours::<_, S> { accel, opts, _stats: Default::default() }),
        AnyBvh::Wide8(accel) => Box::new(Ours::<_, S> { accel, opts, _stats: Default::default() }),
    }
}

/// The plain and the counting traversal of one SAH tree (built twice: the build is deterministic),
/// for the alternated overhead measurement in `main.rs`.
pub fn plain_and_counting(mesh: &Mesh, layout: Layout) -> [Box<dyn Tracer>; 2] {
    let params = BuildParams { layout, ..BuildParams::with_strategy(Strategy::SahBinned) };
    let opts = TraceOptions::default();
    [tracer::<NoStats>(AnyBvh::build(mesh, &params), opts), tracer::<RayCounters>(AnyBvh::build(mesh, &params), opts)]
}

/// How our rows trace: plain single rays, single rays with the heatmap counters on, or packets of 64.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Tracing {
    Plain,
    Counting,
    Packets,
}

/// Our BVH with one strategy and layout (default parameters), traced as `tracing` says.
pub fn ours(strategy: Strategy, layout: Layout, tracing: Tracing) -> Contender {
    let params = BuildParams { layout, ..BuildParams::with_strategy(strategy) };
    ours_with(strategy.name(), params, tracing)
}

/// Our BVH built with `params` (named `label` in the table), traced as `tracing` says.
pub fn ours_with(label: &str, params: BuildParams, tracing: Tracing) -> Contender {
    ours_with_kernels(label, params, tracing, None, TriangleTest::Watertight)
}

/// `ours_with`, walked with the kernels of `simd` instead of the best this CPU has (`with_simd`):
/// the same tree raced with AVX2 and with AVX-512 in one run (named "…, avx2").
pub fn ours_with_kernels(
    label: &str,
    params: BuildParams,
    tracing: Tracing,
    simd: Option<Simd>,
    test: TriangleTest,
) -> Contender {
    let label = match simd {
        Some(s) => format!("{label}, {}", s.name()),
        None => label.to_string(),
    };
    let label = if test == TriangleTest::Watertight { label } else { format!("{label}, {}", test.label()) };
    let layout_name = match params.layout {
        Layout::Binary => "BVH2",
        Layout::Wide4 => "BVH4",
        Layout::Wide8 => "BVH8",
    };
    let name = match tracing {
        Tracing::Plain => format!("bvhscope {label} ({layout_name})"),
        Tracing::Counting => format!("bvhscope {label} ({layout_name}), counting"),
        Tracing::Packets => format!("bvhscope {label} ({layout_name}, 8×8 packets)"),
    };
    Contender {
        name,
        family: Family::Ours,
        slow_build: params.strategy == Strategy::SahSweep,
        build: Box::new(move |mesh| {
            let t = Instant::now();
            let mut params = params;
            // BENCH_TRAVERSAL_COST=c: the SAH's traversal cost (for tuning; default 1).
            if let Some(c) = std::env::var("BENCH_TRAVERSAL_COST").ok().and_then(|c| c.parse().ok()) {
                params.cost.traversal = c;
            }
            if let Some(l) = std::env::var("BENCH_MAX_LEAF").ok().and_then(|c| c.parse().ok()) {
                params.max_leaf_size = l;
            }
            let bvh = match (AnyBvh::build(mesh, &params), simd) {
                (AnyBvh::Wide(w), Some(s)) => AnyBvh::Wide(w.with_simd(s)),
                (AnyBvh::Wide8(w), Some(s)) => AnyBvh::Wide8(w.with_simd(s)),
                (bvh, _) => bvh,
            };
            let took = t.elapsed();
            let opts = TraceOptions { test, ..TraceOptions::default() };
            // The stored leaves made now (not timed by the first walk) and counted.
            let bytes = bvh.bytes_for(opts);
            let stats = TreeStats::of(&bvh);
            let built = Built {
                sah_cost: Some(stats.sah_cost),
                bytes_per_tri: Some(bytes as f64 / mesh.triangle_count() as f64),
                tracer: match tracing {
                    Tracing::Plain => tracer::<NoStats>(bvh, opts),
                    Tracing::Counting => tracer::<RayCounters>(bvh, opts),
                    Tracing::Packets => Box::new(OursPackets { bvh }),
                },
            };
            (built, took)
        }),
    }
}

// ---------------------------------------------------------------- obvhs

fn obvhs_tris(mesh: &Mesh) -> Vec<obvhs::triangle::Triangle> {
    (0..mesh.triangle_count() as u32)
        .map(|i| {
            let [a, b, c] = mesh.triangle(i);
            obvhs::triangle::Triangle { v0: a.into(), v1: b.into(), v2: c.into() }
        })
        .collect()
}

fn obvhs_ray(r: &RaySpec) -> obvhs::ray::Ray {
    obvhs::ray::Ray::new_inf(Vec3A::from(r.origin), Vec3A::from(r.dir))
}

struct ObvhsBvh2 {
    bvh: obvhs::bvh2::Bvh2,
    tris: Vec<obvhs::triangle::Triangle>,
}

impl Tracer for ObvhsBvh2 {
    #[inline]
    fn trace(&self, r: &RaySpec) -> bool {
        let mut hit = obvhs::ray::RayHit::none();
        self.bvh.ray_traverse(obvhs_ray(r), &mut hit, |ray, id| self.tris[id].intersect(ray))
    }
}

struct ObvhsCw {
    bvh: obvhs::cwbvh::CwBvh,
    tris: Vec<obvhs::triangle::Triangle>,
}

impl Tracer for ObvhsCw {
    #[inline]
    fn trace(&self, r: &RaySpec) -> bool {
        let mut hit = obvhs::ray::RayHit::none();
        self.bvh.ray_traverse(obvhs_ray(r), &mut hit, |ray, id| self.tris[id].intersect(ray))
    }
}

/// SAH cost of a binary tree given as (bounds, children or None for a leaf with `n` prims).
fn sah_of<N>(root: usize, node: impl Fn(usize) -> (bvhscope::geometry::Aabb, Option<(usize, usize)>, u32)) -> f64 {
    let root_area = node(root).0.area() as f64;
    let mut cost = 0.0;
    let mut stack = vec![root];
    while let Some(i) = stack.pop() {
        let (b, children, n) = node(i);
        let rel = b.area() as f64 / root_area;
        match children {
            Some((l, r)) => {
                cost += rel; // C_trav = 1
                stack.push(l);
                stack.push(r);
            }
            None => cost += n as f64 * rel, // C_isect = 1
        }
    }
    let _ = std::marker::PhantomData::<N>;
    cost
}

fn obvhs_presets() -> Vec<(&'static str, obvhs::BvhBuildParams)> {
    use obvhs::BvhBuildParams as P;
    vec![
        ("fastest", P::fastest_build()),
        ("very fast", P::very_fast_build()),
        ("fast", P::fast_build()),
        ("medium", P::medium_build()),
        ("slow", P::slow_build()),
    ]
}

pub fn obvhs_all() -> Vec<Contender> {
    let mut v = Vec::new();
    for (name, params) in obvhs_presets() {
        v.push(Contender {
            name: format!("obvhs {name} (BVH2)"),
            family: Family::ObvhsBvh2,
            slow_build: name == "slow",
            build: Box::new(move |mesh| {
                let tris = obvhs_tris(mesh);
                let t = Instant::now();
                let bvh = obvhs::bvh2::builder::build_bvh2_from_tris(&tris, params, &mut Duration::default());
                let tris: Vec<_> = bvh.primitive_indices.iter().map(|&i| tris[i as usize]).collect();
                let took = t.elapsed();
                let node = |i: usize| {
                    let n = &bvh.nodes[i];
                    let b = bvhscope::geometry::Aabb::new(Vec3::from(n.aabb.min), Vec3::from(n.aabb.max));
                    let children = (n.prim_count == 0).then(|| (n.first_index as usize, n.first_index as usize + 1));
                    (b, children, n.prim_count)
                };
                let sah = sah_of::<()>(0, node);
                let bytes = (bvh.nodes.len() * std::mem::size_of::<obvhs::bvh2::node::Bvh2Node>()
                    + bvh.primitive_indices.len() * 4) as f64
                    / mesh.triangle_count() as f64;
                (
                    Built {
                        tracer: Box::new(ObvhsBvh2 { bvh, tris }),
                        sah_cost: Some(sah),
                        bytes_per_tri: Some(bytes),
                    },
                    took,
                )
            }),
        });
    }
    for (name, params) in obvhs_presets().into_iter().skip(1) {
        v.push(Contender {
            name: format!("obvhs {name} (CWBVH)"),
            family: Family::ObvhsCwbvh,
            slow_build: name == "slow",
            build: Box::new(move |mesh| {
                let tris = obvhs_tris(mesh);
                let t = Instant::now();
                let bvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(&tris, params, &mut Duration::default());
                let tris: Vec<_> = bvh.primitive_indices.iter().map(|&i| tris[i as usize]).collect();
                let took = t.elapsed();
                let bytes = (bvh.nodes.len() * std::mem::size_of::<obvhs::cwbvh::node::CwBvhNode>()
                    + bvh.primitive_indices.len() * 4) as f64
                    / mesh.triangle_count() as f64;
                (Built { tracer: Box::new(ObvhsCw { bvh, tris }), sah_cost: None, bytes_per_tri: Some(bytes) }, took)
            }),
        });
    }
    v
}

// ---------------------------------------------------------------- the bvh crate

#[derive(Clone)]
struct BTri {
    v: [Vec3; 3],
    node: usize,
}

impl bvh::aabb::Bounded<f32, 3> for BTri {
    fn aabb(&self) -> bvh::aabb::Aabb<f32, 3> {
        let lo = self.v[0].min(self.v[1]).min(self.v[2]);
        let hi = self.v[0].max(self.v[1]).max(self.v[2]);
        bvh::aabb::Aabb::with_bounds(nalgebra::Point3::new(lo.x, lo.y, lo.z), nalgebra::Point3::new(hi.x, hi.y, hi.z))
    }
}

impl bvh::bounding_hierarchy::BHShape<f32, 3> for BTri {
    fn set_bh_node_index(&mut self, i: usize) {
        self.node = i;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

struct BvhCrate {
    bvh: bvh::bvh::Bvh<f32, 3>,
    shapes: Vec<BTri>,
}

impl Tracer for BvhCrate {
    #[inline]
    fn trace(&self, r: &RaySpec) -> bool {
        let ray = bvh::ray::Ray::new(
            nalgebra::Point3::new(r.origin.x, r.origin.y, r.origin.z),
            nalgebra::Vector3::new(r.dir.x, r.dir.y, r.dir.z),
        );
        // Its own triangle test culls back faces; ours does not, and hit counts must agree, so the
        // closest-hit loop over its candidates uses our watertight test.
        let mut ours = Ray::new(r.origin, r.dir);
        let mut hit = false;
        for s in self.bvh.traverse_iterator(&ray, &self.shapes) {
            if let Some(h) = intersect_triangle(TriangleTest::Watertight, &ours, &s.v) {
                ours.t_max = h.t;
                hit = true;
            }
        }
        hit
    }
}

fn aabb_of(a: &bvh::aabb::Aabb<f32, 3>) -> bvhscope::geometry::Aabb {
    bvhscope::geometry::Aabb::new(Vec3::new(a.min.x, a.min.y, a.min.z), Vec3::new(a.max.x, a.max.y, a.max.z))
}

fn par_executor(l: bvh::bvh::BvhNodeBuildArgs<'_, BTri, f32, 3>, r: bvh::bvh::BvhNodeBuildArgs<'_, BTri, f32, 3>) {
    if l.node_count() + r.node_count() < 4096 {
        l.build();
        r.build();
    } else {
        rayon::join(|| l.build_with_executor(par_executor), || r.build_with_executor(par_executor));
    }
}

pub fn bvh_crate() -> Contender {
    Contender {
        name: "bvh crate SAH".into(),
        family: Family::BvhCrate,
        slow_build: false,
        build: Box::new(|mesh| {
            let mut shapes: Vec<BTri> =
                (0..mesh.triangle_count() as u32).map(|i| BTri { v: mesh.triangle(i), node: 0 }).collect();
            let t = Instant::now();
            let bvh = if rayon::current_num_threads() > 1 {
                bvh::bvh::Bvh::build_with_executor(&mut shapes, par_executor)
            } else {
                bvh::bvh::Bvh::build(&mut shapes)
            };
            let took = t.elapsed();
            // SAH over its binary tree: node boxes are stored in the parent (one shape per leaf).
            let nodes = &bvh.nodes;
            let root_box = match &nodes[0] {
                bvh::bvh::BvhNode::Node { child_l_aabb, child_r_aabb, .. } => {
                    aabb_of(child_l_aabb).union(aabb_of(child_r_aabb))
                }
                bvh::bvh::BvhNode::Leaf { shape_index, .. } => {
                    aabb_of(&bvh::aabb::Bounded::aabb(&shapes[*shape_index]))
                }
            };
            let mut boxes = vec![bvhscope::geometry::Aabb::EMPTY; nodes.len()];
            boxes[0] = root_box;
            for n in nodes {
                if let bvh::bvh::BvhNode::Node { child_l_index, child_l_aabb, child_r_index, child_r_aabb, .. } = n {
                    boxes[*child_l_index] = aabb_of(child_l_aabb);
                    boxes[*child_r_index] = aabb_of(child_r_aabb);
                }
            }
            let sah = sah_of::<()>(0, |i| match &nodes[i] {
                bvh::bvh::BvhNode::Node { child_l_index, child_r_index, .. } => {
                    (boxes[i], Some((*child_l_index, *child_r_index)), 0)
                }
                bvh::bvh::BvhNode::Leaf { .. } => (boxes[i], None, 1),
            });
            let bytes =
                (nodes.len() * std::mem::size_of::<bvh::bvh::BvhNode<f32, 3>>()) as f64 / mesh.triangle_count() as f64;
            (
                Built { tracer: Box::new(BvhCrate { bvh, shapes }), sah_cost: Some(sah), bytes_per_tri: Some(bytes) },
                took,
            )
        }),
    }
}

/// Every contender: each of our strategies in each layout, packets and counting walks, the
/// `fastest` preset (and on an AVX-512 CPU the AVX2 family's), obvhs, the bvh crate, Embree and
/// tinybvh where found.
pub fn all() -> Vec<Contender> {
    let mut contenders = vec![];
    use bvhscope::bvh::Strategy;
    for layout in Layout::ALL {
        for strategy in Strategy::ALL {
            contenders.push(ours(strategy, layout, Tracing::Plain));
        }
    }
    contenders.push(ours(Strategy::SahBinned, Layout::Binary, Tracing::Packets));
    contenders.push(ours(Strategy::SahBinned, Layout::Wide4, Tracing::Packets));
    contenders.push(ours(Strategy::SahBinned, Layout::Wide8, Tracing::Packets));
    // The fastest preset (8-wide; leaves of up to 16 with AVX-512, else 4), as the app's and CLI's
    // `--preset fastest` on this CPU.
    let fastest = bvhscope::bvh::Preset::Fastest.build();
    contenders.push(ours_with("fastest", fastest, Tracing::Plain));
    contenders.push(ours_with("fastest", fastest, Tracing::Packets));
    contenders.push(ours_with("fastest", fastest, Tracing::Counting));
    // Where the CPU has AVX-512, the AVX2 family in the same run: the preset's tree on an AVX2
    // machine (leaves of eight) walked with the AVX2 kernels forced; and the tree of leaves ≤ 32
    // (BENCHMARKS.md, "The fastest preset by kernel family").
    if bvhscope::cpu::Simd::detected() > bvhscope::cpu::Simd::Avx2 {
        let avx2 = Some(bvhscope::cpu::Simd::Avx2);
        let (leaf, cost) = bvhscope::bvh::Preset::fastest_leaves(bvhscope::cpu::Simd::Avx2);
        let cost = bvhscope::bvh::SahCost { traversal: cost, ..fastest.cost };
        let tree = bvhscope::bvh::BuildParams { max_leaf_size: leaf, cost, ..fastest };
        for tracing in [Tracing::Plain, Tracing::Packets] {
            let wt = TriangleTest::Watertight;
            contenders.push(ours_with_kernels("fastest for AVX2", tree, tracing, avx2, wt));
        }
        let others = [(32, 12.0)];
        for (leaf, cost) in others {
            let cost = bvhscope::bvh::SahCost { traversal: cost, ..fastest.cost };
            let p = bvhscope::bvh::BuildParams { max_leaf_size: leaf, cost, ..fastest };
            let label = format!("fastest, leaves {leaf}");
            contenders.push(ours_with(&label, p, Tracing::Plain));
            contenders.push(ours_with(&label, p, Tracing::Packets));
        }
    }
    contenders.push(ours(Strategy::SahBinned, Layout::Binary, Tracing::Counting));
    contenders.push(ours(Strategy::SahBinned, Layout::Wide4, Tracing::Counting));
    contenders.push(ours(Strategy::SahBinned, Layout::Wide8, Tracing::Counting));
    contenders.extend(obvhs_all());
    contenders.push(bvh_crate());
    contenders.extend(crate::embree::all());
    contenders.extend(crate::tinybvh::all());
    for n in [crate::embree::notice(), crate::tinybvh::notice()].into_iter().flatten() {
        eprintln!("notice: {n}");
    }
    contenders
}
