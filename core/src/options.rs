//! Every option a user sets, described once: its name on the command line and in scene files, its
//! label in the app, its help (the CLI's `--help` and the app's tooltips), and for numbers the
//! limits and the default. The CLI, the build panel and the scene-file reader all read these
//! tables, so none of them can accept a value the others refuse.

use crate::bvh::{Layout, Preset, Strategy, TraversalOrder};
use crate::geometry::TriangleTest;
use crate::render::warp::WarpSize;
use crate::render::{ColorMap, PairView, RayKind, UpAxis, View};

mod numbers;
pub use numbers::{Number, ParamOption, BUILD_PARAMS, TOP_MAX_LEAF_SIZE};

/// One value of a choice: what it is called where.
#[derive(Clone, Copy, Debug)]
pub struct Named<T> {
    pub value: T,
    /// Kebab-case: the command line and scene files.
    pub name: &'static str,
    /// The app.
    pub label: &'static str,
    /// One line for `--help` and tooltips.
    pub help: &'static str,
}

/// A choice among named values (strategy, layout, view…), with its table.
pub trait Choice: Copy + PartialEq + Send + Sync + 'static {
    const TABLE: &'static [Named<Self>];

    fn named(self) -> &'static Named<Self> {
        Self::TABLE.iter().find(|n| n.value == self).expect("every value is in its table")
    }
    fn from_name(name: &str) -> Option<Self> {
        Self::TABLE.iter().find(|n| n.name == name).map(|n| n.value)
    }
    /// The names, for messages that list what is accepted.
    fn names() -> String {
        Self::TABLE.iter().map(|n| n.name).collect::<Vec<_>>().join(", ")
    }
}

/// The values of a table in its order (the choices' `ALL` constants).
/// A table's values in its order (the `ALL` of `choice!`).
pub const fn values<T: Copy, const N: usize>(table: &[Named<T>; N]) -> [T; N] {
    let mut out = [table[0].value; N];
    let mut i = 0;
    while i < N {
        out[i] = table[i].value;
        i += 1;
    }
    out
}

/// `ALL`, `name`, `label`, `help` and `from_name` of a choice, read from its table.
#[macro_export]
macro_rules! choice {
    ($ty:ty, $table:ident, $n:literal) => {
        impl $crate::options::Choice for $ty {
            const TABLE: &'static [$crate::options::Named<Self>] = &$table;
        }
        impl $ty {
            pub const ALL: [$ty; $n] = $crate::options::values(&$table);

            pub fn name(self) -> &'static str {
                $crate::options::Choice::named(self).name
            }
            pub fn label(self) -> &'static str {
                $crate::options::Choice::named(self).label
            }
            pub fn help(self) -> &'static str {
                $crate::options::Choice::named(self).help
            }
            pub fn from_name(name: &str) -> Option<Self> {
                <Self as $crate::options::Choice>::from_name(name)
            }
        }
    };
}

const STRATEGIES: [Named<Strategy>; 7] = [
    Named {
        value: Strategy::Midpoint,
        name: "midpoint",
        label: "Midpoint",
        help: "split the widest axis of the centroid bounds in the middle; fast, poor on uneven meshes",
    },
    Named {
        value: Strategy::EqualCount,
        name: "equal-count",
        label: "Equal count",
        help: "split at the median centroid of the widest axis; balanced tree, ignores box sizes",
    },
    Named {
        value: Strategy::SahBinned,
        name: "sah",
        label: "SAH binned",
        help: "surface area heuristic over bins on all axes; near-best trees, fast to build",
    },
    Named {
        value: Strategy::SahSweep,
        name: "sah-sweep",
        label: "SAH sweep",
        help: "surface area heuristic tried between every pair of centroids; exact, slowest to build",
    },
    Named {
        value: Strategy::Lbvh,
        name: "lbvh",
        label: "LBVH (Morton)",
        help: "linear BVH: centroids sorted by Morton code, split where the code's top differing bit flips; fastest to build, blocky trees",
    },
    Named {
        value: Strategy::Ploc,
        name: "ploc",
        label: "PLOC",
        help: "bottom-up: clusters in Morton order merge with their nearest neighbour (smallest joint box) within a search radius; SAH-like trees, fast parallel build",
    },
    Named {
        value: Strategy::Sbvh,
        name: "sbvh",
        label: "SBVH (spatial splits)",
        help: "binned SAH that may also cut triangles at a plane (Stich et al. 2009): less overlap, fewer tests per ray, more references and a slower build",
    },
];
choice!(Strategy, STRATEGIES, 7);

const LAYOUTS: [Named<Layout>; 3] = [
    Named {
        value: Layout::Binary,
        name: "binary",
        label: "binary",
        help: "the binary BVH as built (two children per node), as in the handout",
    },
    Named {
        value: Layout::Wide4,
        name: "wide4",
        label: "4-wide SIMD",
        help: "collapsed into 4-wide nodes whose boxes are tested together with SIMD: faster",
    },
    Named {
        value: Layout::Wide8,
        name: "wide8",
        label: "8-wide SIMD",
        help: "collapsed into 8-wide nodes: eight boxes in one AVX2 or AVX-512 pass where the CPU has it (chosen at run time), half as many levels again",
    },
];
choice!(Layout, LAYOUTS, 3);

const ORDERS: [Named<TraversalOrder>; 2] = [
    Named {
        value: TraversalOrder::SplitAxisSign,
        name: "split-axis",
        label: "split-axis sign",
        help: "the handout's rule: the ray's sign on the node's split axis picks the near child",
    },
    Named {
        value: TraversalOrder::EntryDistance,
        name: "entry-distance",
        label: "entry distance",
        help: "visit the child whose box the ray enters first",
    },
];
choice!(TraversalOrder, ORDERS, 2);

const TESTS: [Named<TriangleTest>; 3] = [
    Named {
        value: TriangleTest::Watertight,
        name: "watertight",
        label: "watertight",
        help: "Woop, Benthin & Wald 2013: no cracks along shared edges",
    },
    Named {
        value: TriangleTest::MollerTrumbore,
        name: "moller-trumbore",
        label: "Möller–Trumbore",
        help: "Möller & Trumbore 1997: the classic; may miss rays exactly through edges",
    },
    Named {
        value: TriangleTest::MollerTrumboreStored,
        name: "moller-trumbore-stored",
        label: "Möller–Trumbore, stored edges",
        help: "Embree's form: each triangle's edges and normal kept (48 more bytes), less work a ray; may miss rays through edges",
    },
];
choice!(TriangleTest, TESTS, 3);

const VIEWS: [Named<View>; 12] = [
    Named {
        value: View::Normals,
        name: "normals",
        label: "Normals",
        help: "the surface normal as colour (n·0.5 + 0.5), as the handout's normal integrator draws it",
    },
    Named {
        value: View::Depth,
        name: "depth",
        label: "Depth",
        help: "distance from the camera to the hit, near bright, far dim; misses black",
    },
    Named {
        value: View::Visits,
        name: "visits",
        label: "Nodes visited",
        help: "heatmap of the nodes each primary ray visited (taken from the stack and processed, interior and leaf)",
    },
    Named {
        value: View::TriTests,
        name: "tri-tests",
        label: "Triangle tests",
        help: "heatmap of the ray–triangle tests each primary ray made",
    },
    Named {
        value: View::Cost,
        name: "cost",
        label: "Combined cost",
        help: "heatmap of C_trav × nodes visited + C_isect × triangle tests, with the build's SAH constants",
    },
    Named {
        value: View::WarpCost(WarpSize::W32),
        name: "warp-cost",
        label: "Warp cost (32 lanes)",
        help: "heatmap of what each GPU warp of 32 rays (an 8×4 pixel block) pays: the most nodes visited + triangle tests of its rays, as its lanes step together",
    },
    Named {
        value: View::SimtEfficiency(WarpSize::W32),
        name: "simt-efficiency",
        label: "SIMT efficiency (32 lanes)",
        help: "heatmap of each 8×4 block's SIMT efficiency: its rays' mean work over the most work (1: no lane of the warp sits idle)",
    },
    Named {
        value: View::WarpCost(WarpSize::W64),
        name: "warp-cost-64",
        label: "Warp cost (64 lanes)",
        help: "warp cost for GPUs that run 64 rays together (AMD's wave64): the most work in each 8×8 pixel block",
    },
    Named {
        value: View::SimtEfficiency(WarpSize::W64),
        name: "simt-efficiency-64",
        label: "SIMT efficiency (64 lanes)",
        help: "SIMT efficiency of 64-lane groups (8×8 pixel blocks): mean work over the most work",
    },
    Named {
        value: View::TopVisits,
        name: "top-visits",
        label: "Top-level nodes visited",
        help: "nodes of the top level (over the placements) visited per ray",
    },
    Named {
        value: View::BottomVisits,
        name: "bottom-visits",
        label: "Bottom-level nodes visited",
        help: "nodes of the meshes' own BVHs visited per ray",
    },
    Named {
        value: View::Instances,
        name: "instances",
        label: "Instances entered",
        help: "placements whose mesh BVH the ray entered (moved into object space)",
    },
];
choice!(View, VIEWS, 12);

const COLOR_MAPS: [Named<ColorMap>; 5] = [
    Named { value: ColorMap::Viridis, name: "viridis", label: "viridis", help: "perceptually uniform, blue to yellow" },
    Named {
        value: ColorMap::Inferno,
        name: "inferno",
        label: "inferno",
        help: "perceptually uniform, black to yellow",
    },
    Named { value: ColorMap::Magma, name: "magma", label: "magma", help: "perceptually uniform, black to white" },
    Named { value: ColorMap::Turbo, name: "turbo", label: "turbo", help: "rainbow-like, more contrast, not uniform" },
    Named {
        value: ColorMap::Diverging,
        name: "blue-red",
        label: "blue-red",
        help: "diverging, white in the middle: made for differences (render --against uses it)",
    },
];
choice!(ColorMap, COLOR_MAPS, 5);

const UP_AXES: [Named<UpAxis>; 2] = [
    Named { value: UpAxis::Y, name: "y", label: "Y up", help: "+y is up (most formats, the handout)" },
    Named {
        value: UpAxis::Z,
        name: "z",
        label: "Z up",
        help: "+z is up (CAD, Blender coordinates, many scans); the default camera looks along +y",
    },
];
choice!(UpAxis, UP_AXES, 2);

const PRESETS: [Named<Preset>; 2] = [
    Named {
        value: Preset::Handout,
        name: "handout",
        label: "Handout mode",
        help: "the lab's BVH: midpoint split, binary layout, split-axis-sign order, Möller–Trumbore test, max leaf size 4 (the handout leaves it to you), one level",
    },
    Named {
        value: Preset::Fastest,
        name: "fastest",
        label: "Fastest traversal",
        help: "bvhscope's fastest tree: binned SAH, 8-wide layout, leaves as large as one SIMD pass tests (16 triangles and traversal cost 10 where the CPU has AVX-512, 8 and cost 5 with AVX2, else 4 and cost 3), entry-distance order, watertight test, one level",
    },
];
choice!(Preset, PRESETS, 2);

const PAIR_VIEWS: [Named<PairView>; 3] = [
    Named {
        value: PairView::Halves,
        name: "halves",
        label: "Halves",
        help: "A's heatmap on the left half, B's on the right, on one colour scale",
    },
    Named {
        value: PairView::Wipe,
        name: "wipe",
        label: "Wipe",
        help: "A left of a line, B right of it (the app's line is dragged; the command line's is --wipe)",
    },
    Named {
        value: PairView::Difference,
        name: "difference",
        label: "Difference B - A",
        help: "B's count minus A's per pixel: blue where B does less work, red where it does more",
    },
];
choice!(PairView, PAIR_VIEWS, 3);

const RAY_KINDS: [Named<RayKind>; 4] = [
    Named {
        value: RayKind::Primary,
        name: "primary",
        label: "Primary",
        help: "the camera's rays, closest hit: the most coherent rays there are",
    },
    Named {
        value: RayKind::Shadow,
        name: "shadow",
        label: "Shadow",
        help: "from each hit to a point light (above the camera unless given), any hit",
    },
    Named {
        value: RayKind::Ao,
        name: "ao",
        label: "Ambient occlusion",
        help: "cosine-weighted hemisphere rays from each hit, 10% of the scene's diagonal long unless given, any hit",
    },
    Named {
        value: RayKind::Bounce,
        name: "bounce",
        label: "Diffuse bounce",
        help: "one cosine-weighted diffuse bounce from each hit, closest hit: the most incoherent",
    },
];
choice!(RayKind, RAY_KINDS, 4);

#[cfg(test)]
#[path = "options_tests.rs"]
mod tests;
