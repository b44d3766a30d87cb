//! The BVH built over the scene on screen (the scene itself is the core's `scene::Scene`), with the
//! statistics the panels show.

use crate::bvh::{SceneBuild, SceneBvh, TreeStats};
use std::collections::VecDeque;
use std::sync::Arc;

/// The BVH of the current scene.
pub struct BuiltBvh {
    pub bvh: Arc<SceneBvh>,
    /// What the statistics rows describe: the single BVH; for two levels the top level, or the
    /// mesh's BVH when the scene places one mesh once (its top level is one node, nothing to
    /// describe).
    pub stats: TreeStats,
    /// Two levels: the top level's statistics.
    pub top_stats: Option<TreeStats>,
    /// Two levels: each mesh's name and its BVH's statistics.
    pub bottom: Vec<(String, TreeStats)>,
    pub scene_id: u64,
}

impl BuiltBvh {
    /// Statistics of a finished build; `names` are the scene's mesh names (two levels).
    pub fn new(bvh: Arc<SceneBvh>, names: &[String], scene_id: u64) -> Self {
        let (stats, top_stats, bottom) = match bvh.two_level() {
            Some(t) => {
                let top = TreeStats::of(&t.top);
                let bottom: Vec<(String, TreeStats)> = t
                    .bottom
                    .iter()
                    .enumerate()
                    .map(|(k, b)| (names.get(k).cloned().unwrap_or_else(|| format!("mesh {k}")), TreeStats::of(b)))
                    .collect();
                let rows = match (&t.instances[..], &bottom[..]) {
                    ([_], [(_, mesh)]) => mesh.clone(),
                    _ => top.clone(),
                };
                (rows, Some(top), bottom)
            }
            None => match bvh.yardstick() {
                // An imported tree: on the mesh's box, as the tree it is compared with.
                Some(y) => (TreeStats::against(bvh.tree(), &y), None, Vec::new()),
                None => (TreeStats::of(bvh.tree()), None, Vec::new()),
            },
        };
        Self { bvh, stats, top_stats, bottom, scene_id }
    }

    /// Whether the statistics rows describe the mesh's BVH of a two-level build of one placement.
    pub fn rows_are_the_mesh(&self) -> bool {
        self.bvh.two_level().is_some_and(|t| t.instances.len() == 1 && t.bottom.len() == 1)
    }

    /// Deepest level of the bottom BVHs (or of the single BVH): the box depth slider's end.
    pub fn bottom_max_depth(&self) -> u32 {
        match self.bvh.two_level() {
            Some(_) => self.bottom.iter().map(|(_, s)| s.max_depth).max().unwrap_or(0),
            None => self.stats.max_depth,
        }
    }
}

/// The last few trees built for the scene on screen, by their options: a lesson stepping back
/// and forth between two builds (or a user between two strategies) gets each again at once
/// instead of rebuilding it. Imported trees are not kept (they are the import's).
#[derive(Default)]
pub struct BuildCache(VecDeque<(u64, SceneBuild, Arc<SceneBvh>)>);

impl BuildCache {
    /// How many trees are kept: a lesson's few builds, without holding many big trees in memory.
    pub const KEEP: usize = 4;
    /// Over this many triangles only the tree on screen is kept (four trees of a scan of tens of
    /// millions of triangles would take gigabytes).
    pub const KEEP_ONE_OVER: usize = 2_000_000;

    /// The tree built for scene `scene_id` with `build`, if kept.
    pub fn get(&self, scene_id: u64, build: &SceneBuild) -> Option<Arc<SceneBvh>> {
        self.0.iter().find(|(id, b, _)| *id == scene_id && b == build).map(|(_, _, t)| t.clone())
    }

    /// Keep `bvh`, built for scene `scene_id` of `triangles` triangles (trees of other scenes
    /// go: their scene is gone).
    pub fn keep(&mut self, scene_id: u64, triangles: usize, bvh: &Arc<SceneBvh>) {
        if bvh.import().is_some() {
            return;
        }
        let build = bvh.build_params();
        self.0.retain(|(id, b, _)| *id == scene_id && *b != build);
        self.0.push_front((scene_id, build, bvh.clone()));
        self.0.truncate(if triangles > Self::KEEP_ONE_OVER { 1 } else { Self::KEEP });
    }

    pub fn len(&self) -> usize {
        self.0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}
