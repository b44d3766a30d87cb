//! `compare --ray-kind all` (or one secondary kind): every strategy's trees counted and timed on
//! the same rays of each kind, and how well the SAH cost and EPO rank the trees for each kind
//! (`explain::ray_kinds`).

use super::rows::{budgeted_median, PerTree, Tree};
use crate::bvh::{AnyBvh, BuildParams, LinearScan, SahCost, TraceOptions};
use crate::cli::progress;
use crate::cli::rays::RayArgs;
use crate::explain::ray_kinds::{spearman, KindRays, Work};
use crate::explain::timing::ms;
use crate::render::{render, Camera, RayKind, RenderSettings};
use std::fmt::Write;
use std::time::Duration;

/// The most secondary rays of one kind each tree is counted and timed on: a frame's ao rays on a
/// dense mesh are millions, each dearer than a camera ray, and fourteen trees times four kinds of
/// them would take many minutes; an evenly spread quarter million ranks the trees as well, and
/// the table says when it is a sample.
const MAX_SECONDARY_RAYS: usize = 1 << 18;

/// What a cell says in place of figures when a secondary kind has no rays: they leave the camera
/// rays' hits, and there are none.
const NO_RAYS: &str = "no rays: the camera sees no surface";

/// One strategy × kind: the work per ray and the speed.
#[derive(Clone, Debug, serde::Serialize)]
pub struct KindCell {
    pub row: String,
    pub kind: &'static str,
    pub rays: u64,
    pub hits: u64,
    pub nodes_per_ray: f64,
    pub tri_tests_per_ray: f64,
    /// The SAH cost model's combined cost per ray (traversal × nodes + intersection × tests).
    pub cost_per_ray: f64,
    /// Single rays on the trace timing's threads (one unless `--threads`); for the linear scan,
    /// over the rays it was timed on. `None` for a kind with no rays (no camera ray hit): a rate
    /// of nothing timed would be the clock's noise.
    pub mrays_per_s: Option<f64>,
    pub speedup_over_linear: Option<f64>,
    /// The linear scan's rays timed and counted, when fewer than the list's.
    pub sampled_rays: Option<usize>,
}

/// The rays of each kind, and the cells measured so far.
pub struct KindsTable {
    lists: Vec<KindRays>,
    described: Vec<String>,
    trace: TraceOptions,
    cost: SahCost,
    pub cells: Vec<KindCell>,
    /// (row name, SAH cost, EPO) of the first layout's rows: what the correlations rank.
    ranked: Vec<(String, f64, f64)>,
}

impl KindsTable {
    /// The rays of `args`' kinds (primary always first, as the yardstick) for `camera`: the
    /// secondary rays leave the hits of a frame traced through `mesh`'s default tree.
    pub fn new(mesh: &crate::mesh::Mesh, camera: &Camera, args: &RayArgs, trace: TraceOptions, cost: SahCost) -> Self {
        let mut kinds = args.kinds();
        if kinds.first() != Some(&RayKind::Primary) {
            kinds.retain(|&k| k != RayKind::Primary);
            kinds.insert(0, RayKind::Primary);
        }
        let hits = progress::with_spinner("finding the camera rays' hits", || {
            let tree = AnyBvh::build(mesh, &BuildParams::default());
            render(&tree, mesh, camera, &RenderSettings { trace, ..Default::default() })
        });
        let (lists, described) = kinds
            .into_iter()
            .map(|kind| match args.secondary(kind, &mesh.bounds(), camera) {
                None => (KindRays::primary(camera), "the camera's rays, one per pixel (closest hit)".to_string()),
                Some(sec) => {
                    // Only the kept rays are made (a frame's are hundreds of millions at 256 per pixel).
                    let kept = sec.frame_rays(&hits, camera, MAX_SECONDARY_RAYS);
                    let note = match kept.rays.len() as u64 {
                        0 => format!(" ({NO_RAYS})"),
                        n if n < kept.of => format!(" (an evenly spread {n} of the frame's {})", kept.of),
                        _ => String::new(),
                    };
                    (KindRays { kind, rays: kept.rays }, format!("{}{note}", sec.spec.describe()))
                }
            })
            .unzip();
        Self { lists, described, trace, cost, cells: Vec::new(), ranked: Vec::new() }
    }

    fn cell(&self, row: &str, list: &KindRays, work: Work, seconds_per_ray: f64, sampled: Option<usize>) -> KindCell {
        let (nodes, tris, cost) = work.per_ray(self.cost);
        KindCell {
            row: row.to_string(),
            kind: list.kind.name(),
            rays: list.rays.len() as u64,
            hits: work.hits,
            nodes_per_ray: nodes,
            tri_tests_per_ray: tris,
            cost_per_ray: cost,
            mrays_per_s: (!list.rays.is_empty()).then(|| 1e-6 / seconds_per_ray.max(1e-15)),
            speedup_over_linear: None,
            sampled_rays: sampled,
        }
    }

    /// Per kind: Spearman's rank correlation of the measured cost per ray with the SAH cost and
    /// with the EPO, over the ranked rows.
    pub fn correlations(&self) -> Vec<(&'static str, Option<f64>, Option<f64>)> {
        let sah: Vec<f64> = self.ranked.iter().map(|r| r.1).collect();
        let epo: Vec<f64> = self.ranked.iter().map(|r| r.2).collect();
        self.lists
            .iter()
            .map(|list| {
                let measured: Vec<f64> = self
                    .ranked
                    .iter()
                    .map(|(name, ..)| {
                        let c = self.cells.iter().find(|c| &c.row == name && c.kind == list.kind.name());
                        c.map_or(f64::NAN, |c| c.cost_per_ray)
                    })
                    .collect();
                match list.rays.is_empty() {
                    // Nothing measured: no ranking (each tree's zero cost would tie).
                    true => (list.kind.name(), None, None),
                    false => (list.kind.name(), spearman(&sah, &measured), spearman(&epo, &measured)),
                }
            })
            .collect()
    }

    /// The markdown table: a row per tree, a column per kind, each cell "nodes / tri tests per ray,
    /// MRays/s, speed-up over the linear scan"; the kinds and the correlations under it.
    pub fn markdown(&self, trace_threads: usize) -> String {
        let mut o = String::new();
        let kinds: Vec<&str> = self.lists.iter().map(|l| l.kind.name()).collect();
        let _ = writeln!(o, "| strategy | {} |", kinds.join(" | "));
        let _ = writeln!(o, "|---|{}", "---:|".repeat(kinds.len()));
        let mut rows: Vec<&str> = Vec::new();
        for c in &self.cells {
            if !rows.contains(&c.row.as_str()) {
                rows.push(&c.row);
            }
        }
        for row in rows {
            let cells: Vec<String> = kinds
                .iter()
                .map(|k| {
                    let c = self.cells.iter().find(|c| c.row == row && c.kind == *k).expect("every row has every kind");
                    let (Some(rate), Some(speedup)) = (c.mrays_per_s, c.speedup_over_linear) else {
                        return NO_RAYS.to_string();
                    };
                    let star = if c.sampled_rays.is_some() { "*" } else { "" };
                    format!(
                        "{:.1} / {:.1} · {}{star} · {speedup:.0}×",
                        c.nodes_per_ray,
                        c.tri_tests_per_ray,
                        three_figures(rate),
                    )
                })
                .collect();
            let _ = writeln!(o, "| {row} | {} |", cells.join(" | "));
        }
        let _ = writeln!(o);
        let _ = writeln!(
            o,
            "Each cell: nodes visited / triangle tests per ray (every ray of the kind; camera rays that miss the mesh count too) · MRays/s (single rays, {trace_threads} thread(s)) · speed-up over the linear scan. The rays:"
        );
        for (list, d) in self.lists.iter().zip(&self.described) {
            let _ = writeln!(o, "- {}: {} rays, {d}", list.kind.name(), list.rays.len());
        }
        if let Some(n) = self.cells.iter().find_map(|c| c.sampled_rays) {
            let _ = writeln!(o, "* the linear scan timed and counted on an evenly spread sample (e.g. {n} rays).");
        }
        let fmt = |r: Option<f64>| r.map_or("—".to_string(), |r| format!("{r:+.2}"));
        let _ = writeln!(
            o,
            "\nSpearman rank correlation, over the {} trees {}, of the measured cost per ray (the SAH's own cost model) with:",
            self.ranked.len(),
            self.ranked.first().map_or(String::new(), |(n, ..)| format!("laid out as {}", layout_of(n)))
        );
        for ((kind, sah, epo), list) in self.correlations().into_iter().zip(&self.lists) {
            let _ = match list.rays.is_empty() {
                true => writeln!(o, "- {kind}: {NO_RAYS}"),
                false => writeln!(o, "- {kind}: SAH cost {}, EPO {}", fmt(sah), fmt(epo)),
            };
        }
        o
    }
}

impl PerTree for KindsTable {
    /// Count `bvh` on every list (on the frames' pool) and time it (median of up to `runs`, on
    /// the traces' pool). `first_layout`: its row joins the ranking.
    fn tree(&mut self, t: Tree<'_>) {
        let Tree { bvh, row, first_layout, runs, pools } = t;
        for list in &self.lists {
            let n = list.rays.len();
            if n == 0 {
                // Nothing to count or time (a kind without rays: no camera ray hit).
                let cell = self.cell(&row.name, list, Work::default(), 0.0, None);
                self.cells.push(cell);
                continue;
            }
            let work = pools.0.install(|| list.count(bvh, self.trace, n));
            let t = pools.1.install(|| budgeted_median(runs, || ms(list.time(bvh, self.trace, n))));
            let cell = self.cell(&row.name, list, work, t / 1e3 / n.max(1) as f64, None);
            self.cells.push(cell);
        }
        if let (true, Some(sah), Some(epo)) = (first_layout, row.sah_cost, row.epo) {
            self.ranked.push((row.name.clone(), sah, epo));
        }
    }

    /// The linear scan's cells, each list timed and counted within `budget` in all, then every
    /// cell's speed-up over it.
    fn done(&mut self, mesh: &crate::mesh::Mesh, budget: Duration, traces: &rayon::ThreadPool) {
        let linear = LinearScan::new(mesh);
        let each = budget / self.lists.len().max(1) as u32;
        let mut linear_cells = Vec::new();
        for list in &self.lists {
            if list.rays.is_empty() {
                linear_cells.push(self.cell("Linear scan", list, Work::default(), 0.0, None));
                continue;
            }
            let (per_ray, n) =
                progress::with_spinner(&format!("timing the linear scan on {} rays", list.kind.name()), || {
                    traces.install(|| list.time_per_ray_within(&linear, self.trace, each))
                });
            let work = list.count(&linear, self.trace, n);
            let sampled = (n < list.rays.len()).then_some(n);
            linear_cells.push(self.cell("Linear scan", list, work, per_ray, sampled));
        }
        for c in &mut self.cells {
            let l = linear_cells.iter().find(|l| l.kind == c.kind).expect("every kind has its linear cell");
            c.speedup_over_linear = c.mrays_per_s.zip(l.mrays_per_s).map(|(tree, linear)| tree / linear.max(1e-12));
        }
        for l in &mut linear_cells {
            l.speedup_over_linear = l.mrays_per_s.map(|_| 1.0);
        }
        self.cells.extend(linear_cells);
    }
}

/// `v` to three significant figures (a linear scan's 0.000612 MRays/s as much as a tree's 3.41).
fn three_figures(v: f64) -> String {
    let places = if v > 0.0 { (2 - v.log10().floor() as i32).clamp(0, 9) } else { 2 } as usize;
    format!("{v:.places$}")
}

/// The layout in a row's name, "SAH (binned) (binary)" → "binary".
fn layout_of(name: &str) -> &str {
    name.rsplit_once('(').map_or(name, |(_, l)| l.trim_end_matches(')'))
}
