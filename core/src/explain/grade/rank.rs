//! The order within the class: the correct submissions ranked by one key (the rubric's
//! `rank_by`), each figure taken over bvhscope's SAH tree of the same layout, lowest first, so a
//! 4-wide dump is held to the 4-wide SAH tree; equal figures share a place (they are listed by
//! name, then by the order given), so the same class ranks the same every time and two students
//! with the same tree rank alike. Incorrect submissions get no rank.

use super::{GradeRow, Verdict, VersusSah};
use serde::Serialize;

/// What ranks the class.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RankBy {
    /// The SAH cost: deterministic, and what the lab's SAH exercise optimises.
    #[default]
    SahCost,
    /// Nodes visited per primary ray.
    NodesPerRay,
    /// Triangle tests per primary ray.
    TriTestsPerRay,
    /// Single-ray trace time: what a renderer sees, but it varies by a few percent from run to
    /// run, so close ranks may swap.
    TraceTime,
}

impl RankBy {
    pub const ALL: [RankBy; 4] = [RankBy::SahCost, RankBy::NodesPerRay, RankBy::TriTestsPerRay, RankBy::TraceTime];

    /// The name in a rubric.
    pub fn name(self) -> &'static str {
        match self {
            RankBy::SahCost => "sah_cost",
            RankBy::NodesPerRay => "nodes_per_ray",
            RankBy::TriTestsPerRay => "tri_tests_per_ray",
            RankBy::TraceTime => "trace_time",
        }
    }

    pub fn from_name(s: &str) -> Option<RankBy> {
        Self::ALL.into_iter().find(|r| r.name() == s)
    }

    /// In words, for the report: "SAH cost over bvhscope's SAH tree's, lowest first".
    pub fn describe(self) -> &'static str {
        match self {
            RankBy::SahCost => "SAH cost relative to bvhscope's SAH tree in the same layout, lowest first",
            RankBy::NodesPerRay => "nodes visited per ray relative to bvhscope's SAH tree in the same layout, fewest first",
            RankBy::TriTestsPerRay => {
                "triangle tests per ray relative to bvhscope's SAH tree in the same layout, fewest first"
            }
            RankBy::TraceTime => {
                "single-ray trace time relative to bvhscope's SAH tree in the same layout, fastest first (varies a few percent between runs)"
            }
        }
    }

    pub fn of(self, v: &VersusSah) -> f64 {
        match self {
            RankBy::SahCost => v.sah_cost,
            RankBy::NodesPerRay => v.nodes_per_ray,
            RankBy::TriTestsPerRay => v.tri_tests_per_ray,
            RankBy::TraceTime => v.trace_time,
        }
    }
}

/// Set `rank` on every correct row that was measured (1 = best), and clear it on the others.
pub fn rank(rows: &mut [GradeRow], by: RankBy) {
    let mut ranked: Vec<(f64, &str, usize, usize)> = rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.verdict == Verdict::Correct)
        .filter_map(|(i, r)| r.versus_sah.as_ref().map(|v| (by.of(v), r.name.as_str(), r.index, i)))
        .collect();
    // total_cmp: a NaN (a reference of zero work) sorts last, never panics the sort.
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0).then_with(|| a.1.cmp(b.1)).then(a.2.cmp(&b.2)));
    // Equal figures share a place (1, 2, 2, 4): two students who handed in the same tree get
    // the same rank, whatever their names.
    let mut places = Vec::with_capacity(ranked.len());
    for (k, &(key, _, _, i)) in ranked.iter().enumerate() {
        let place = if k > 0 && ranked[k - 1].0.total_cmp(&key).is_eq() { places[k - 1] } else { (i, k + 1) };
        places.push((i, place.1));
    }
    for r in rows.iter_mut() {
        r.rank = None;
    }
    for (i, place) in places {
        rows[i].rank = Some(place);
    }
}
