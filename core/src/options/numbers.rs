//! The numbers a user sets, described once: each build parameter's names, label and help (its
//! limits and default are the builder's), and the numbers that are no build parameter. The CLI's
//! options, the scene file's keys and the build panel's fields are read from here.

use crate::bvh::{Limits, Param, ParamLimits, ParamValue};

/// A build parameter as users see it: its names, label and help. Its limits and default are the
/// builder's (`Param::limits`); which strategies read it is the strategy's (`Strategy::reads`).
#[derive(Clone, Copy, Debug)]
pub struct ParamOption {
    pub param: Param,
    /// Kebab-case: the command line (`--max-leaf-size`).
    pub name: &'static str,
    /// Snake-case: the scene file's `bvh` object.
    pub key: &'static str,
    pub label: &'static str,
    pub help: &'static str,
    /// Set on a log scale in the app (its useful values span orders of magnitude).
    pub log: bool,
}

/// Every build parameter, in the order the build panel shows them; the command line's options,
/// the scene file's keys and the panel's fields are read from here.
pub const BUILD_PARAMS: [ParamOption; 7] = [
    ParamOption {
        param: Param::MaxLeafSize,
        name: "max-leaf-size",
        key: "max_leaf_size",
        label: "Max leaf size",
        help: "Most triangles in a leaf. The SAH strategies may stop earlier when a leaf is cheaper than a split.",
        log: true,
    },
    ParamOption {
        param: Param::SahBins,
        name: "bins",
        key: "bins",
        label: "SAH bins",
        help: "Bins per axis of the binned SAH: more bins, closer to the exact sweep, slower build. Nodes of fewer than three triangles per bin use a third of their count, at least 4 (never more than asked for).",
        log: true,
    },
    ParamOption {
        param: Param::PlocRadius,
        name: "ploc-radius",
        key: "ploc_radius",
        label: "PLOC radius",
        help: "Clusters PLOC searches on each side (in Morton order) for a cluster's nearest neighbour: larger, better trees, slower build.",
        log: true,
    },
    ParamOption {
        param: Param::SbvhAlpha,
        name: "sbvh-alpha",
        key: "sbvh_alpha",
        label: "SBVH α",
        help: "SBVH: spatial splits are tried only where an object split's two boxes share more than this fraction of the root's surface area (Stich et al.'s α; 0: everywhere, 1: nowhere).",
        log: true,
    },
    ParamOption {
        param: Param::SbvhGrowth,
        name: "sbvh-growth",
        key: "sbvh_growth",
        label: "SBVH growth %",
        help: "SBVH: spatial splits may add at most this many percent more triangle references than there are triangles.",
        log: false,
    },
    ParamOption {
        param: Param::ReinsertPasses,
        name: "reinsert-passes",
        key: "reinsert_passes",
        label: "Reinsertion passes",
        help: "After the build, move nodes to where they cost least under the SAH (Bittner, Hapala & Havran 2013), largest boxes first, for up to this many passes over the tree (0: off). Works on any strategy's binary tree.",
        log: false,
    },
    ParamOption {
        param: Param::TraversalCost,
        name: "traversal-cost",
        key: "traversal_cost",
        label: "SAH traversal cost",
        help: "SAH cost of one traversal step relative to one triangle test (1 = equal).",
        log: true,
    },
];

impl ParamOption {
    pub fn limits(&self) -> ParamLimits {
        self.param.limits()
    }

    /// The help with the limits and the default, for `--help` and tooltips.
    pub fn help_line(&self) -> String {
        let l = self.limits();
        format!("{} ({}) [default: {}]", self.help, l.range_text(), l.default_value())
    }

    /// A value a user typed (the command line), within the limits.
    pub fn parse(&self, s: &str) -> Result<ParamValue, String> {
        let t = s.trim();
        match self.limits() {
            ParamLimits::Whole(l) => match t.parse::<u32>() {
                Ok(v) if l.contains(v) => Ok(ParamValue::Whole(v)),
                _ => Err(format!("'{s}' is not a whole number {}", l.range_text())),
            },
            ParamLimits::Real(l) => match t.parse::<f32>() {
                Ok(v) if l.contains(v) => Ok(ParamValue::Real(v)),
                _ => Err(format!("'{s}' is not a number {}", l.range_text())),
            },
        }
    }

    /// A scene file's value, within the limits.
    pub fn from_json(&self, v: &serde_json::Value) -> Result<ParamValue, String> {
        match self.limits() {
            ParamLimits::Whole(l) => match v.as_u64() {
                Some(x) if x <= u32::MAX as u64 && l.contains(x as u32) => Ok(ParamValue::Whole(x as u32)),
                _ => Err(format!("expected a whole number {}", l.range_text())),
            },
            ParamLimits::Real(l) => match v.as_f64() {
                Some(x) if l.contains(x as f32) => Ok(ParamValue::Real(x as f32)),
                _ => Err(format!("expected a number {}", l.range_text())),
            },
        }
    }

    /// The value as a scene file writes it.
    pub fn to_json(v: ParamValue) -> serde_json::Value {
        match v {
            ParamValue::Whole(x) => x.into(),
            ParamValue::Real(x) => x.into(),
        }
    }
}

impl Param {
    /// How users see it.
    pub fn option(self) -> &'static ParamOption {
        BUILD_PARAMS.iter().find(|o| o.param == self).expect("every parameter is in BUILD_PARAMS")
    }
}

/// A number a user sets that is no build parameter: its names, help, and its owner's limits.
#[derive(Clone, Copy, Debug)]
pub struct Number<T> {
    /// Kebab-case: the command line.
    pub name: &'static str,
    pub label: &'static str,
    pub help: &'static str,
    pub limits: Limits<T>,
}

pub const TOP_MAX_LEAF_SIZE: Number<u32> = Number {
    name: "top-max-leaf-size",
    label: "Placements per leaf",
    help: "Most placements in a leaf of the top level (two levels).",
    limits: crate::bvh::params::TOP_MAX_LEAF_SIZE,
};
