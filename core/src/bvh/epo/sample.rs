//! The terms of the nodes whose exact sums would cost too much, estimated from points on the
//! surface. A node's term is w(n) · P(n), P(n) the share of the surface outside n's subtree that
//! lies in n's box, so the sum of the terms of a set H of nodes is the mean over the surface of
//! g(p) = Σ w(n) over the nodes n of H whose box holds p and whose subtree does not hold p's
//! triangle. Two estimators of that sum, both unbiased:
//!
//! - **Walks**: g at a point is one walk down the tree (a point query, as a ray's end point
//!   makes), so the mean of g over points. Cheap where a point lies in few boxes (a scan, a grid
//!   of scans); where it lies in thousands (long thin crossing triangles) a walk is long and g
//!   varies much from point to point, as all of H is summed at the same point.
//! - **Pairs**: each node of H tests its own points, drawn at random from a pool: the hits over
//!   the tests estimate P(n). A test costs one box test whatever the overlap, and the nodes' errors
//!   are nearly independent, so where boxes overlap much this is far better per unit of work.
//!
//! A pilot of walks measures both variances per unit of work (g's variance for walks; Σ w²·P for
//! pairs, from the same walks' hits) and the estimate takes the better. Points are stratified:
//! R independent replicates, each spreading its points evenly over the surface in leaf order
//! (point i of k falls in the i-th k-th of the running area, at an offset drawn once per
//! replicate, and uniformly across the triangle it lands on). Each point is uniform on its
//! stratum, so each replicate's estimate is unbiased; the spread of the R replicates gives the
//! standard error of their mean, itself unbiased (randomised quasi-Monte Carlo; Owen, "Monte
//! Carlo theory, methods and examples", ch. 17).

use super::clip::holds_point;
use super::exact::{wide, Prepared};
use crate::random::Rng;
use glam::{DVec3, Vec3A};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, AtomicU8, Ordering};

/// `Query::flags`: the node is hard; it or a node below it is.
const HARD: u8 = 1;
const BELOW: u8 = 2;
/// Replicates (the standard error has R − 1 degrees of freedom).
pub(super) const REPLICATES: usize = 16;
/// Points per replicate of walks, at least and at most.
const MIN_POINTS: usize = 16;
const MAX_POINTS: usize = 1 << 20;
/// The pilot's walks: up to this many points, or a twentieth of the budget, at least `MIN_PILOT`.
const PILOT_POINTS: usize = 256;
const MIN_PILOT: usize = 8;
/// Work of making one point of a pool (the search in the running area, the corner weights), and
/// how many tests each point of a pool serves, about.
const POINT_WORK: u64 = 8;
const REUSE: usize = 8;
/// Pairs test at least this share of the nodes in each replicate.
const MIN_SHARE: f64 = 0.25;
/// Points per parallel task, and nodes per parallel task of pairs.
const CHUNK: usize = 256;
/// The seed of the points `measure` takes (the tests try others).
pub(super) const SEED: u64 = 0x4550_4f37; // "EPO7"

/// Which estimator: the better by the pilot, or one (the tests try each).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(test), allow(dead_code))]
pub(super) enum Estimator {
    Best,
    Walks,
    Pairs,
}

/// The estimate of the hard nodes' terms.
pub(super) struct Estimate {
    /// Each hard node's term, in the order of `hard`.
    pub terms: Vec<f64>,
    /// The standard error of their sum.
    pub std_error: f64,
    /// Points walked from, or tests made by pairs.
    pub samples: usize,
    pub work: u64,
}

/// Estimate the terms of the nodes `hard` with about `budget` units of work (a node a walk
/// visits, a point a pair tests; at least `REPLICATES · MIN_POINTS` walks or a test per node and
/// replicate, whatever the budget), the points drawn from `seed`.
pub(super) fn estimate(p: &Prepared, hard: &[u32], budget: u64, seed: u64, by: Estimator) -> Estimate {
    let n = p.bvh.nodes.len();
    // Per node, one byte: whether it is hard, and whether it or one below it is (the walks skip
    // the rest): from each hard node up its parents until one already marked, in parallel where
    // there are many (the marks, not their order, make the flags).
    let marks: Vec<AtomicU8> =
        crate::parallel::region_if(wide(n), || (0..n).into_par_iter().map(|_| AtomicU8::new(0)).collect());
    crate::parallel::region_if(wide(hard.len()), || {
        hard.par_iter().for_each(|&m| {
            marks[m as usize].fetch_or(HARD, Ordering::Relaxed);
            let mut up = m;
            while let Some(f) = marks.get(up as usize) {
                if f.fetch_or(BELOW, Ordering::Relaxed) & BELOW != 0 {
                    break;
                }
                up = p.h.parent[up as usize];
            }
        })
    });
    let flags: Vec<u8> =
        crate::parallel::region_if(wide(n), || marks.into_par_iter().map(AtomicU8::into_inner).collect());
    let q = Query { p, seed, hard, flags: &flags };

    // The pilot walks double as a price list.
    let mut pilot = Walked::default();
    let mut points = 0;
    while points < PILOT_POINTS && (points < MIN_PILOT || pilot.work < budget / 20) {
        let more = points.max(MIN_PILOT);
        let w = q.walks(u64::MAX - points as u64, more, None);
        (pilot.sum, pilot.squares, pilot.weighted_hits, pilot.work) =
            (pilot.sum + w.sum, pilot.squares + w.squares, pilot.weighted_hits + w.weighted_hits, pilot.work + w.work);
        points += more;
    }
    let np = points as f64;
    let per_point = (pilot.work as f64 / np).max(1.0);
    let mean = pilot.sum / np;
    let g_variance = (pilot.squares / np - mean * mean).max(0.0);
    // Variance of each estimator times its work (the smaller, the better): walks, Var(g) per
    // point; pairs, Σ w²·P(1 − P) ≤ Σ w²·P per test per node, |H| tests.
    let walk_cost = g_variance * per_point;
    let pair_cost = pilot.weighted_hits / np * hard.len() as f64;
    let left = budget.saturating_sub(pilot.work) as f64 / REPLICATES as f64;
    let mut estimates = Vec::with_capacity(REPLICATES);
    let mut work = pilot.work;
    let (tests, terms, found);
    let pairs = match by {
        Estimator::Best => pair_cost < walk_cost,
        Estimator::Walks => false,
        Estimator::Pairs => true,
    };
    if pairs {
        // Each node tests `k` points of a pool `REUSE` times smaller than all the tests of a
        // replicate (a point costs more to make than to test); where the budget has less than a
        // test per node and replicate, each node is tested in a replicate with probability
        // `share`, and its hits count 1/`share` times (Horvitz & Thompson 1952).
        let per_test = 1.0 + POINT_WORK as f64 / REUSE as f64;
        let per_replicate = left / (per_test * hard.len() as f64);
        let (k, share) = ((per_replicate as usize).max(1), per_replicate.clamp(MIN_SHARE, 1.0));
        let pool = ((k * hard.len()) as f64 * share / REUSE as f64) as usize;
        let pool = pool.clamp(CHUNK, 1 << 20);
        let mut counts = vec![0f64; hard.len()];
        let mut hits = 0;
        // Small pools are made all at once, side by side (one at a time, each is a few tasks);
        // big ones one by one, each in parallel (all at once they would take much memory).
        let small = pool.div_ceil(CHUNK) < 16;
        let mut pools: Vec<Vec<(u32, Vec3A)>> = match small {
            true => {
                crate::parallel::region(|| (0..REPLICATES as u64).into_par_iter().map(|r| q.pool(r, pool)).collect())
            }
            false => Vec::new(),
        };
        for r in 0..REPLICATES as u64 {
            let points = match small {
                true => std::mem::take(&mut pools[r as usize]),
                false => q.pool(r, pool),
            };
            let (sum, h, w) = q.pairs(r, &points, k, share, &mut counts);
            estimates.push(sum / k as f64);
            (hits, work) = (hits + h, work + w);
        }
        found = hits;
        tests = ((REPLICATES * k * hard.len()) as f64 * share) as usize;
        terms = crate::parallel::region_if(wide(hard.len()), || {
            counts.par_iter().zip(hard).map(|(&c, &m)| p.weight(m as usize) * c / (REPLICATES * k) as f64).collect()
        });
    } else {
        // Counted by node (the walks find nodes, not places in `hard`).
        let hits: Vec<AtomicU32> =
            crate::parallel::region_if(wide(n), || (0..n).into_par_iter().map(|_| AtomicU32::new(0)).collect());
        let k = ((left / per_point) as usize).clamp(MIN_POINTS, MAX_POINTS);
        // The replicates side by side (each a few chunks on a small mesh: one at a time left 16
        // threads idle); each one's sums are its own, so the figures do not depend on the order.
        let walked: Vec<Walked> = crate::parallel::region(|| {
            (0..REPLICATES as u64).into_par_iter().map(|r| q.walks(r, k, Some(&hits))).collect()
        });
        for w in walked {
            estimates.push(w.sum / k as f64);
            work += w.work;
        }
        tests = REPLICATES * k;
        (terms, found) = crate::parallel::region_if(wide(hard.len()), || {
            let hits = |&m: &u32| hits[m as usize].load(Ordering::Relaxed);
            let terms = hard.par_iter().map(|m| p.weight(*m as usize) * hits(m) as f64 / tests as f64).collect();
            (terms, hard.par_iter().map(|m| hits(m) as u64).sum())
        });
    }
    let mean = estimates.iter().sum::<f64>() / REPLICATES as f64;
    let var = estimates.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (REPLICATES * (REPLICATES - 1)) as f64;
    // The replicates' spread says little where hits are rare (all replicates may miss a box
    // that holds much): the error is then at least a count's, 1/√(hits + 1) of the estimate.
    let std_error = var.sqrt().max(mean / (found as f64 + 1.0).sqrt());
    Estimate { terms, std_error, samples: tests, work }
}

/// What some walks found.
#[derive(Default)]
struct Walked {
    /// Σ g, Σ g², Σ over the hits of w².
    sum: f64,
    squares: f64,
    weighted_hits: f64,
    work: u64,
}

struct Query<'a, 'b> {
    p: &'b Prepared<'a>,
    seed: u64,
    hard: &'b [u32],
    /// `HARD` and `BELOW` of each node.
    flags: &'b [u8],
}

impl Query<'_, '_> {
    /// The stratum offset of replicate `r`, and a random stream for its `i`-th draw.
    fn offset(&self, r: u64) -> f64 {
        unit(&mut Rng::at(self.seed, r))
    }

    fn rng(&self, r: u64, i: u64) -> Rng {
        Rng::at(self.seed ^ r.wrapping_mul(0xD1B5_4A32_D192_ED03), i)
    }

    /// Points `range` of `k` spread over the surface with `offset`, in order: each one's slot
    /// and position.
    fn spread(
        &self,
        r: u64,
        offset: f64,
        range: std::ops::Range<usize>,
        k: usize,
    ) -> impl Iterator<Item = (u32, Vec3A)> + '_ {
        let mut slot = 0;
        range.map(move |i| {
            let x = (i as f64 + offset) / k as f64 * self.p.total();
            slot = self.slot_at(x, slot);
            (slot as u32, self.point(slot, x, unit(&mut self.rng(r, i as u64))))
        })
    }

    /// The slot at running area `x`, at or after `from` (the points come in order: a gallop
    /// from the last one's slot instead of a search of the whole leaf order).
    fn slot_at(&self, x: f64, from: usize) -> usize {
        let prefix = &self.p.prefix;
        let slots = prefix.len() - 1;
        let (mut lo, mut step) = (from.min(slots - 1), 1);
        // prefix[lo] <= x (or lo is the first slot); find hi with prefix[hi] > x.
        let mut hi = lo + 1;
        while hi < slots && prefix[hi] <= x {
            lo = hi;
            hi = (hi + step).min(slots);
            step *= 2;
        }
        lo + prefix[lo + 1..hi].partition_point(|&a| a <= x)
    }

    /// Replicate `r`'s `k` walks (a pilot's where `r` is near `u64::MAX`), counting each hard
    /// node's hits into `hits`.
    fn walks(&self, r: u64, k: usize, hits: Option<&[AtomicU32]>) -> Walked {
        let offset = self.offset(r);
        let wide = k.div_ceil(CHUNK) >= 16;
        let chunks: Vec<Walked> = crate::parallel::region_if(wide, || {
            (0..k.div_ceil(CHUNK))
                .into_par_iter()
                .map(|c| {
                    let mut stack = Vec::new();
                    let mut out = Walked::default();
                    for (slot, point) in self.spread(r, offset, c * CHUNK..((c + 1) * CHUNK).min(k), k) {
                        let (g, g2, w) = self.g(slot, point, &mut stack, hits);
                        (out.sum, out.squares, out.weighted_hits, out.work) =
                            (out.sum + g, out.squares + g * g, out.weighted_hits + g2, out.work + w);
                    }
                    out
                })
                .collect()
        });
        chunks.iter().fold(Walked::default(), |a, c| Walked {
            sum: a.sum + c.sum,
            squares: a.squares + c.squares,
            weighted_hits: a.weighted_hits + c.weighted_hits,
            work: a.work + c.work,
        })
    }

    /// Replicate `r`'s pool of pairs: `pool` points spread over the surface.
    fn pool(&self, r: u64, pool: usize) -> Vec<(u32, Vec3A)> {
        let offset = self.offset(r);
        crate::parallel::region_if(pool.div_ceil(CHUNK) >= 16, || {
            (0..pool.div_ceil(CHUNK))
                .into_par_iter()
                .flat_map_iter(|c| self.spread(r, offset, c * CHUNK..((c + 1) * CHUNK).min(pool), pool))
                .collect()
        })
    }

    /// Replicate `r` of pairs: `k` tests of points drawn from its pool `points` by each hard
    /// node (by each with probability `share`), whose hits, over `share`, are added to `counts`;
    /// Σ w·hits/`share`, the hits and the work.
    fn pairs(&self, r: u64, points: &[(u32, Vec3A)], k: usize, share: f64, counts: &mut [f64]) -> (f64, u64, u64) {
        let pool = points.len();
        let (bvh, h) = (self.p.bvh, self.p.h);
        let wide = counts.len().div_ceil(CHUNK) >= 16;
        let done: Vec<(f64, u64, u64)> = crate::parallel::region_if(wide, || {
            counts
                .par_chunks_mut(CHUNK)
                .enumerate()
                .map(|(c, counts)| {
                    let (mut sum, mut hits, mut tests) = (0f64, 0u64, 0u64);
                    for (j, count) in counts.iter_mut().enumerate() {
                        let j = c * CHUNK + j;
                        // Streams apart from the pool's (whose draws are numbered below `pool`).
                        let mut rng = self.rng(r, (1 << 40) + (j as u64) * (k as u64 + 1));
                        if share < 1.0 && unit(&mut rng) >= share {
                            continue;
                        }
                        let m = self.hard[j] as usize;
                        let b = bvh.nodes[m].bounds();
                        let mut found = 0u32;
                        for _ in 0..k {
                            let (slot, point) = points[rng.below(pool as u64) as usize];
                            if holds_point(&b, point) && !h.holds(m, slot) {
                                found += 1;
                            }
                        }
                        (tests, hits) = (tests + k as u64, hits + found as u64);
                        let scaled = found as f64 / share;
                        *count += scaled;
                        sum += self.p.weight(m) * scaled;
                    }
                    (sum, hits, tests)
                })
                .collect()
        });
        let (sum, hits, tests) = done.iter().fold((0.0, 0, 0), |(s, h, t), &(a, b, c)| (s + a, h + b, t + c));
        (sum, hits, pool as u64 * POINT_WORK + tests)
    }

    /// The point at running area `x` of the leaf order, in slot `s`: uniform across the
    /// triangle as `x` and `v` are uniform.
    fn point(&self, s: usize, x: f64, v: f64) -> Vec3A {
        let prefix = &self.p.prefix;
        let area = prefix[s + 1] - prefix[s];
        let u = if area > 0.0 { ((x - prefix[s]) / area).clamp(0.0, 1.0) } else { 0.5 };
        let t = &self.p.bvh.tris[s];
        let su = u.sqrt();
        let (a, b, c) = (t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3());
        let q: DVec3 = a * (1.0 - su) + b * (su * (1.0 - v)) + c * (su * v);
        // Inside the triangle's box: a triangle flat in an axis keeps its coordinate exactly, so
        // one lying on a box's face stays on it (the box is closed).
        let (lo, hi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
        Vec3A::from(q.as_vec3().clamp(lo, hi))
    }

    /// g at `point` of slot `slot`, Σ w² over its hits, and the nodes visited.
    fn g(&self, slot: u32, point: Vec3A, stack: &mut Vec<u32>, hits: Option<&[AtomicU32]>) -> (f64, f64, u64) {
        let (bvh, h) = (self.p.bvh, self.p.h);
        let (mut g, mut g2, mut work) = (0f64, 0f64, 0u64);
        stack.clear();
        stack.push(0);
        while let Some(m) = stack.pop() {
            let m = m as usize;
            work += 1;
            let f = self.flags[m];
            if f & BELOW == 0 || !holds_point(&self.p.cover(m), point) {
                continue;
            }
            let node = &bvh.nodes[m];
            if f & HARD != 0 && holds_point(&node.bounds(), point) && !h.holds(m, slot) {
                let w = self.p.weight(m);
                (g, g2) = (g + w, g2 + w * w);
                if let Some(hits) = hits {
                    hits[m].fetch_add(1, Ordering::Relaxed);
                }
            }
            // Children come after their parents; a malformed array whose links loop back would
            // otherwise be walked for ever (the flags mark every node above a hard one).
            if !node.is_leaf() && node.index as usize > m {
                stack.extend([node.index, node.index + 1]);
            }
        }
        (g, g2, work)
    }
}

/// Uniform in [0, 1), 53 bits.
fn unit(rng: &mut Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}
