//! The EPO measure of a tree: exact where the budget allows, sampled past it, with its error.

use crate::bvh::epo::exact::{wide, Prepared};
use crate::bvh::epo::sample::Estimator;
use crate::bvh::hierarchy::Hierarchy;
use crate::bvh::node::Bvh;
use crate::parallel::Disjoint;
use rayon::prelude::*;

/// Units of work (a node visited or a triangle's box tested; a clip is `exact::CLIP_WORK` more)
/// per triangle and level of the tree (log₂ of the triangles): the budget of `measure`, which
/// costs about the SAH build's time on the meshes of BENCHMARKS.md ("EPO (issue 37)").
pub const BUDGET_PER_TRIANGLE_LEVEL: f64 = 0.5;

/// Meshes of up to `SMALL` triangles get at least `SMALL_BUDGET`, in which they are measured
/// exactly (a few milliseconds).
pub const SMALL: usize = 4096;

pub const SMALL_BUDGET: u64 = 1 << 21;

/// The share of the budget the exact walks may take; the estimate has the rest, or all that
/// they leave.
pub(super) const EXACT_SHARE: f64 = 0.75;

/// Nodes the pilot walks, at most, and the share of the walks' budget it may take (1/this).
pub(super) const PILOT_NODES: usize = 1024;

pub(super) const PILOT_SHARE: u64 = 16;

/// The walks' caps, at least and at most.
pub(super) const MIN_CAP: u64 = 64;

pub(super) const MAX_CAP: u64 = 1 << 20;

/// The walks run only where the pilot says that at least this share of them would finish.
pub(super) const MIN_FINISHED: f64 = 0.5;

/// Nodes walked between two looks at the work done.
pub(super) const WALK_BLOCK: usize = 1 << 14;

/// The largest cap at which `count` walks cost at most `left` by the pilot's `priced` walks (0
/// where none does, or where it would finish fewer than `MIN_FINISHED` of them): a walk costs
/// what it cost the pilot, at most the cap; one the pilot did not finish, the cap.
pub(super) fn cap_within(priced: &[(Option<f64>, u64)], count: usize, left: u64) -> u64 {
    let mut costs: Vec<u64> = priced.iter().filter(|d| d.0.is_some()).map(|d| d.1).collect();
    costs.sort_unstable();
    let (all, mut below) = (priced.len() as f64, 0f64);
    let mut best = 0;
    for (i, &c) in costs.iter().enumerate() {
        // Walks up to this one cost what they did; the others, c each.
        let mean = (below + c as f64 * (all - i as f64)) / all;
        if mean * count as f64 > left as f64 {
            break;
        }
        best = c;
        below += c as f64;
    }
    // Walks that would finish too few nodes spend what the estimate does better with.
    let finished = costs.iter().filter(|&&c| c <= best).count();
    if (finished as f64) < MIN_FINISHED * all {
        0
    } else {
        best
    }
}

/// The end-point overlap of a tree, and how it was found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Epo {
    /// The tree's EPO: the sum of `terms`.
    pub value: f64,
    /// The standard error of `value`: 0 where every node's term is exact.
    pub std_error: f64,
    /// Each node's term (its share of `value`): exact, or estimated where its walk would have
    /// passed the budget.
    pub terms: Vec<f64>,
    /// Nodes whose terms are exact (of `terms.len()`).
    pub exact_nodes: usize,
    /// The estimate's samples: points walked from, or tests of a point against a node's box (0
    /// where all is exact).
    pub samples: usize,
    /// Units of work done, and the budget.
    pub work: u64,
    pub budget: u64,
}

impl Epo {
    /// Whether every node's term is exact.
    pub fn is_exact(&self) -> bool {
        self.exact_nodes == self.terms.len()
    }

    /// "2.205" where exact, "7664 ± 43" where estimated: ± two standard errors (about 95%).
    pub fn text(&self) -> String {
        figure(self.value, self.error())
    }

    /// Two standard errors where the figure is estimated (about a 95% interval).
    pub fn error(&self) -> Option<f64> {
        (!self.is_exact()).then_some(2.0 * self.std_error)
    }

    /// How it was found, for a note beside the figure.
    pub fn method(&self) -> String {
        if self.is_exact() {
            "exact".into()
        } else {
            format!(
                "{} of {} nodes exact, the rest estimated from {} samples of the surface; ± two standard errors",
                self.exact_nodes,
                self.terms.len(),
                self.samples
            )
        }
    }
}

/// An EPO figure as `Epo::text` writes it: three decimals, or "value ± error" with as many
/// decimals as the error leaves meaningful (at most three).
pub fn figure(value: f64, error: Option<f64>) -> String {
    match error {
        None => format!("{value:.3}"),
        Some(e) => {
            let d = if e > 0.0 { (-(e.log10().floor()) as i32 + 1).clamp(0, 3) as usize } else { 3 };
            format!("{value:.d$} ± {e:.d$}")
        }
    }
}

/// The budget of `measure` for a tree of `slots` triangles (`BUDGET_PER_TRIANGLE_LEVEL`).
pub fn budget(slots: usize) -> u64 {
    let levels = (slots.max(2) as f64).log2().ceil();
    let budget = (BUDGET_PER_TRIANGLE_LEVEL * slots as f64 * levels) as u64;
    if slots <= SMALL {
        budget.max(SMALL_BUDGET)
    } else {
        budget
    }
}

/// The tree's EPO and each node's term, within `budget(triangles)` units of work.
pub fn measure(bvh: &Bvh, h: &Hierarchy) -> Epo {
    measure_within(bvh, h, budget(bvh.tris.len()))
}

/// `measure` with a given budget (the tests give small ones to exercise the estimate).
pub fn measure_within(bvh: &Bvh, h: &Hierarchy, budget: u64) -> Epo {
    measure_with(bvh, h, budget, crate::bvh::epo::sample::SEED, Estimator::Best)
}

/// `measure_within`, the estimate's points drawn from `seed`, by `by`.
pub(super) fn measure_with(bvh: &Bvh, h: &Hierarchy, budget: u64, seed: u64, by: Estimator) -> Epo {
    let n = bvh.nodes.len();
    let p = Prepared::new(bvh, h);
    let total = p.total();
    if n == 0 || !(total > 0.0) {
        return Epo { terms: vec![0.0; n], exact_nodes: n, budget, ..Epo::default() };
    }
    // Zeroed; each node's term is written once, by the task that finds it (`Disjoint`).
    let mut terms = vec![0.0; n];
    let out = Disjoint::new(&mut terms);
    let exact_budget = (budget as f64 * EXACT_SHARE) as u64;
    let walk = |nodes: &[u32], cap: u64| -> Vec<(Option<f64>, u64)> {
        crate::parallel::region_if(nodes.len() >= 16, || {
            nodes.par_iter().map_init(Vec::new, |stack, &m| p.walk(m as usize, cap, stack)).collect()
        })
    };
    let mut spent = 0u64;
    let mut hard = Vec::new();
    // The finished walks' terms written; the others added, in order, to `hard`; the work done.
    let keep = |nodes: &[u32], done: &[(Option<f64>, u64)], hard: &mut Vec<u32>| {
        crate::parallel::region_if(wide(nodes.len()), || {
            let unfinished: Vec<u32> = nodes
                .par_iter()
                .zip(done)
                .filter_map(|(&m, (sum, _))| match sum {
                    Some(s) => {
                        // SAFETY: each node is walked once, in one of the lists `keep` is given.
                        unsafe { out.set(m as usize, p.weight(m as usize) * s / total) };
                        None
                    }
                    None => Some(m),
                })
                .collect();
            hard.extend(unfinished);
            done.par_iter().map(|d| d.1).sum::<u64>()
        })
    };
    // A pilot of nodes spread over the array, with a `PILOT_SHARE`th of the walks' share, prices the
    // walks: the cap for the rest is the largest at which, by the pilot, they fit what is left.
    let stride = n.div_ceil(PILOT_NODES);
    let pilot: Vec<u32> = (0..n).step_by(stride).map(|m| m as u32).collect();
    // (All of the share where the pilot is every node, half of it for a small mesh, which is
    // most likely to be measured exactly.)
    let share = if pilot.len() == n {
        1
    } else if bvh.tris.len() <= SMALL {
        2
    } else {
        PILOT_SHARE
    };
    let pilot_cap = (exact_budget / (share * pilot.len() as u64)).clamp(MIN_CAP, MAX_CAP);
    let priced = walk(&pilot, pilot_cap);
    spent += keep(&pilot, &priced, &mut hard);
    let mut todo: Vec<u32> = crate::parallel::region_if(wide(n), || {
        (0..n as u32).into_par_iter().filter(|&m| !(m as usize).is_multiple_of(stride)).collect()
    });
    let mut cap = cap_within(&priced, todo.len(), exact_budget.saturating_sub(spent));
    // In blocks, so the walks stop where the pilot was wrong by much (the same place whatever
    // the threads); then again for those left, while what remains gives each twice the cap.
    while cap > 0 {
        let mut left = Vec::new();
        for (k, block) in todo.chunks(WALK_BLOCK).enumerate() {
            if spent > exact_budget + exact_budget / 4 {
                left.extend(todo[k * WALK_BLOCK..].iter().copied());
                break;
            }
            let done = walk(block, cap);
            spent += keep(block, &done, &mut left);
        }
        todo = std::mem::take(&mut hard);
        todo.extend(left);
        // (The pilot's walks left here were tried at its cap.)
        let tried = cap.max(pilot_cap);
        let next = exact_budget.saturating_sub(spent) / todo.len().max(1) as u64;
        if todo.is_empty() || next < 2 * tried || tried >= MAX_CAP {
            break;
        }
        cap = next.min(MAX_CAP);
    }
    let pending = crate::parallel::region_if(wide(todo.len()), || crate::parallel::concat(vec![hard, todo], 0));
    let mut epo = Epo { exact_nodes: n - pending.len(), work: spent, budget, ..Epo::default() };
    if !pending.is_empty() {
        let e = crate::bvh::epo::sample::estimate(&p, &pending, budget.saturating_sub(spent), seed, by);
        crate::parallel::region_if(wide(pending.len()), || {
            // SAFETY: the pending nodes are those no walk finished, each once.
            pending.par_iter().zip(&e.terms).for_each(|(&m, &t)| unsafe { out.set(m as usize, t) })
        });
        (epo.std_error, epo.samples) = (e.std_error, e.samples);
        epo.work += e.work;
    }
    epo.value = crate::parallel::region_if(wide(n), || crate::parallel::sum(&terms));
    epo.terms = terms;
    epo
}

/// Each node's term of the EPO sum (its share of the total; they add up to `of`): `measure`'s.
pub fn node_terms(bvh: &Bvh, h: &Hierarchy) -> Vec<f64> {
    measure(bvh, h).terms
}

/// One node's term, exactly (the node inspector's "EPO share"): one walk, which costs at most a
/// box test per node and a clip per triangle.
pub fn node_term(bvh: &Bvh, h: &Hierarchy, node: usize) -> f64 {
    let p = Prepared::new(bvh, h);
    let total = p.total();
    if !(total > 0.0) {
        return 0.0;
    }
    let sum = p.walk(node, u64::MAX, &mut Vec::new()).0.unwrap_or(0.0);
    p.weight(node) * sum / total
}

/// The tree's EPO (`measure`'s value).
pub fn of(bvh: &Bvh) -> f64 {
    measure(bvh, &Hierarchy::of(bvh)).value
}
