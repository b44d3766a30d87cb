//! What a build is asked for and what it reports: the strategy and its numbers, the SAH's
//! constants, the layout, and the report of the phases. The builder owns each number's limits and
//! default (`Param`); `crate::options` gives them their names, labels and help for users.

use std::time::Duration;

/// A number's limits (inclusive) and default, as the builder accepts it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits<T> {
    pub min: T,
    pub max: T,
    pub default: T,
}

impl<T: PartialOrd + Copy> Limits<T> {
    pub fn contains(&self, v: T) -> bool {
        self.min <= v && v <= self.max
    }

    /// `v` within the limits (a NaN, which is in no order with them, gives the default).
    pub fn clamp(&self, v: T) -> T {
        if v.partial_cmp(&self.min).is_none() {
            self.default
        } else if v < self.min {
            self.min
        } else if v > self.max {
            self.max
        } else {
            v
        }
    }

    /// The limits, for messages: "1..=255".
    pub fn range_text(&self) -> String
    where
        T: std::fmt::Display,
    {
        format!("{}..={}", self.min, self.max)
    }
}

/// A number of a build that users set. Which strategies read which is the strategy's to say
/// (`Strategy::reads`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Param {
    /// Most triangles in a leaf (the node format's count field would take 65535; trees with leaves
    /// that big are not worth building).
    MaxLeafSize,
    /// Bins per axis of the binned SAH (`split::sah_binned`).
    SahBins,
    /// PLOC's neighbour search radius (`ploc`).
    PlocRadius,
    /// Stich et al.'s α: where the SBVH prices spatial splits (`sbvh`).
    SbvhAlpha,
    /// The SBVH's reference budget, in percent of the triangles.
    SbvhGrowth,
    /// Passes of reinsertion after any build (`reinsert`).
    ReinsertPasses,
    /// The SAH's cost of a traversal step against a triangle test's.
    TraversalCost,
}

/// A parameter's value: a whole number or a real one, as its limits are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamValue {
    Whole(u32),
    Real(f32),
}

impl std::fmt::Display for ParamValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ParamValue::Whole(v) => write!(f, "{v}"),
            ParamValue::Real(v) => write!(f, "{v}"),
        }
    }
}

/// A parameter's limits, whole or real.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamLimits {
    Whole(Limits<u32>),
    Real(Limits<f32>),
}

impl ParamLimits {
    pub fn default_value(&self) -> ParamValue {
        match self {
            ParamLimits::Whole(l) => ParamValue::Whole(l.default),
            ParamLimits::Real(l) => ParamValue::Real(l.default),
        }
    }

    pub fn range_text(&self) -> String {
        match self {
            ParamLimits::Whole(l) => l.range_text(),
            ParamLimits::Real(l) => l.range_text(),
        }
    }

    /// `v` within the limits, of the limits' kind (a real number for a whole one is rounded; a
    /// NaN gives the default).
    pub fn clamp(&self, v: ParamValue) -> ParamValue {
        match (self, v) {
            (ParamLimits::Whole(l), ParamValue::Whole(x)) => ParamValue::Whole(l.clamp(x)),
            (ParamLimits::Whole(l), ParamValue::Real(x)) if x.is_nan() => ParamValue::Whole(l.default),
            (ParamLimits::Whole(l), ParamValue::Real(x)) => ParamValue::Whole(l.clamp(x.round().max(0.0) as u32)),
            (ParamLimits::Real(l), v) => ParamValue::Real(l.clamp(v.real())),
        }
    }
}

impl ParamValue {
    /// As a whole number (a real one rounded).
    pub fn whole(self) -> u32 {
        match self {
            ParamValue::Whole(x) => x,
            ParamValue::Real(x) => x.round().max(0.0) as u32,
        }
    }

    pub fn real(self) -> f32 {
        match self {
            ParamValue::Whole(x) => x as f32,
            ParamValue::Real(x) => x,
        }
    }
}

pub const MAX_LEAF_SIZE: Limits<u32> = Limits { min: 1, max: 255, default: 4 };
pub const SAH_BINS: Limits<u32> = Limits { min: 2, max: super::split::sah_binned_max_bins() as u32, default: 16 };
pub const PLOC_RADIUS: Limits<u32> = Limits { min: 1, max: 64, default: 16 };
pub const SBVH_ALPHA: Limits<f32> = Limits { min: 0.0, max: 1.0, default: 1e-5 };
pub const SBVH_GROWTH: Limits<u32> = Limits { min: 0, max: 300, default: 30 };
pub const REINSERT_PASSES: Limits<u32> = Limits { min: 0, max: 32, default: 0 };
pub const TRAVERSAL_COST: Limits<f32> = Limits { min: 0.01, max: 100.0, default: 1.0 };
/// Placements in a leaf of a two-level BVH's top level (one: each placement's box tested alone).
pub const TOP_MAX_LEAF_SIZE: Limits<u32> = Limits { min: 1, max: 255, default: 1 };

impl Param {
    pub const ALL: [Param; 7] = [
        Param::MaxLeafSize,
        Param::SahBins,
        Param::PlocRadius,
        Param::SbvhAlpha,
        Param::SbvhGrowth,
        Param::ReinsertPasses,
        Param::TraversalCost,
    ];

    pub fn limits(self) -> ParamLimits {
        match self {
            Param::MaxLeafSize => ParamLimits::Whole(MAX_LEAF_SIZE),
            Param::SahBins => ParamLimits::Whole(SAH_BINS),
            Param::PlocRadius => ParamLimits::Whole(PLOC_RADIUS),
            Param::SbvhAlpha => ParamLimits::Real(SBVH_ALPHA),
            Param::SbvhGrowth => ParamLimits::Whole(SBVH_GROWTH),
            Param::ReinsertPasses => ParamLimits::Whole(REINSERT_PASSES),
            Param::TraversalCost => ParamLimits::Real(TRAVERSAL_COST),
        }
    }

    /// Its value in `p`.
    pub fn get(self, p: &BuildParams) -> ParamValue {
        match self {
            Param::MaxLeafSize => ParamValue::Whole(p.max_leaf_size),
            Param::SahBins => ParamValue::Whole(p.sah_bins),
            Param::PlocRadius => ParamValue::Whole(p.ploc_radius),
            Param::SbvhAlpha => ParamValue::Real(p.sbvh_alpha),
            Param::SbvhGrowth => ParamValue::Whole(p.sbvh_growth),
            Param::ReinsertPasses => ParamValue::Whole(p.reinsert_passes),
            Param::TraversalCost => ParamValue::Real(p.cost.traversal),
        }
    }

    /// Set it in `p` (as given: `BuildParams::clamped` brings it within the limits).
    pub fn set(self, p: &mut BuildParams, v: ParamValue) {
        match self {
            Param::MaxLeafSize => p.max_leaf_size = v.whole(),
            Param::SahBins => p.sah_bins = v.whole(),
            Param::PlocRadius => p.ploc_radius = v.whole(),
            Param::SbvhAlpha => p.sbvh_alpha = v.real(),
            Param::SbvhGrowth => p.sbvh_growth = v.whole(),
            Param::ReinsertPasses => p.reinsert_passes = v.whole(),
            Param::TraversalCost => p.cost.traversal = v.real(),
        }
    }
}

/// Cost constants of the surface area heuristic (Goldsmith & Salmon 1987; MacDonald & Booth 1990).
/// The defaults, 1 and 1, make the normalised SAH cost of a tree read as "expected traversal steps
/// plus triangle tests per ray that hits the root box". They are parameters because the right
/// ratio depends on the traversal code; the builder and the statistics use the same values.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SahCost {
    /// Cost of visiting an interior node (one step: two child box tests).
    pub traversal: f32,
    /// Cost of one ray–triangle test.
    pub intersection: f32,
}

impl SahCost {
    /// Bottom-up leaf gathering (PLOC's layout, reinsertion's collapse): a subtree over `count`
    /// triangles in a box of `area`, whose two children cost `children` (their SAH costs summed,
    /// in area units), costs the cheaper of a leaf (C_isect·n·A, only when `count` fits a leaf of
    /// `max_leaf`) and a split (C_trav·A + children). Returns the cost and whether it is a leaf.
    pub fn leaf_or_split(&self, area: f64, count: u32, children: f64, max_leaf: u32) -> (f64, bool) {
        let split = self.traversal as f64 * area + children;
        let as_leaf = self.intersection as f64 * count as f64 * area;
        if count <= max_leaf && as_leaf <= split {
            (as_leaf, true)
        } else {
            (split, false)
        }
    }
}

impl Default for SahCost {
    fn default() -> Self {
        Self { traversal: TRAVERSAL_COST.default, intersection: 1.0 }
    }
}

/// How the built tree is laid out for traversal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Layout {
    /// The binary BVH as built: two children per node, the handout's structure.
    Binary,
    /// The binary BVH collapsed into 4-wide nodes traversed with SIMD box tests (`bvh::wide`).
    #[default]
    Wide4,
    /// Collapsed into 8-wide nodes: eight child boxes in one AVX2 pass where the CPU has it
    /// (`crate::cpu`), two passes of four elsewhere.
    Wide8,
}

/// How a tree is built: top down by a splitter (midpoint, equal count, SAH binned or swept), or
/// by a builder of its own (LBVH, PLOC, SBVH). Its row of `REGISTRY` says which.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Strategy {
    /// Middle of the centroid bounds on the widest axis.
    Midpoint,
    /// Median centroid on the widest axis: equally many triangles on each side.
    EqualCount,
    /// Surface area heuristic, evaluated at bin boundaries on all three axes.
    #[default]
    SahBinned,
    /// Surface area heuristic, evaluated between every pair of neighbouring centroids.
    SahSweep,
    /// A builder of its own (`builders::lbvh`): the hierarchy of the
    /// centroids' sorted Morton codes.
    Lbvh,
    /// A bottom-up builder of its own (`builders::ploc`): clusters merged with their nearest
    /// neighbours in Morton order.
    Ploc,
    /// The binned SAH with spatial splits (`builders::sbvh`): triangles cut where that beats
    /// sorting them to one side, so a triangle may be referenced by several leaves.
    Sbvh,
}

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct BuildParams {
    pub strategy: Strategy,
    /// Most triangles in a leaf (default 4). The SAH strategies may stop earlier when a leaf is
    /// cheaper than a split; no strategy makes a larger leaf.
    pub max_leaf_size: u32,
    /// Bins per axis for `SahBinned` (default 16); nodes of fewer than three triangles per bin
    /// use n/3 bins (at least 4, never more than asked for).
    pub sah_bins: u32,
    pub cost: SahCost,
    pub layout: Layout,
    /// PLOC's neighbour search: clusters each side in Morton order (default 16).
    pub ploc_radius: u32,
    /// Passes of reinsertion after the build (`bvh::reinsert`; 0, the default: none).
    pub reinsert_passes: u32,
    /// SBVH: spatial splits are priced where the object split's children share more than this
    /// fraction of the root's surface area (Stich et al.'s α; default 1e-5).
    pub sbvh_alpha: f32,
    /// SBVH: at most this many percent more references than triangles (default 30).
    pub sbvh_growth: u32,
}

impl Default for BuildParams {
    fn default() -> Self {
        Self {
            strategy: Strategy::SahBinned,
            max_leaf_size: MAX_LEAF_SIZE.default,
            sah_bins: SAH_BINS.default,
            cost: SahCost::default(),
            layout: Layout::default(),
            ploc_radius: PLOC_RADIUS.default,
            reinsert_passes: REINSERT_PASSES.default,
            sbvh_alpha: SBVH_ALPHA.default,
            sbvh_growth: SBVH_GROWTH.default,
        }
    }
}

impl BuildParams {
    pub fn with_strategy(strategy: Strategy) -> Self {
        Self { strategy, ..Self::default() }
    }
}

/// What the build did and how long each phase took.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct BuildReport {
    /// Triangle bounds and centroids.
    pub setup_time: Duration,
    /// The top-down splitting.
    pub split_time: Duration,
    /// Copying triangles into leaf order.
    pub reorder_time: Duration,
    /// Collapsing the binary tree into wide nodes (wide layout only).
    pub collapse_time: Duration,
    /// Nodes where the strategy found no useful split (midpoint with an empty side, SAH with
    /// coincident centroids) and an equal-count split was used instead.
    pub fallback_splits: u32,
    /// Nodes split by equal count because they were deeper than `HEURISTIC_DEPTH_LIMIT`.
    pub depth_limited_splits: u32,
    /// SBVH: nodes split by a spatial split (the others by object splits).
    pub spatial_splits: u32,
    /// The reinsertion pass after the build, when asked for (`BuildParams::reinsert_passes`).
    pub reinsertion: Option<super::reinsert::Reinsertion>,
}

impl BuildReport {
    pub fn total_time(&self) -> Duration {
        let optimise = self.reinsertion.map_or(Duration::ZERO, |r| r.time);
        self.setup_time + self.split_time + self.reorder_time + self.collapse_time + optimise
    }
}

impl BuildParams {
    /// The parameters with every number within the limits the builder accepts.
    pub fn clamped(&self) -> BuildParams {
        let mut p = *self;
        for param in Param::ALL {
            param.set(&mut p, param.limits().clamp(param.get(self)));
        }
        p
    }
}
