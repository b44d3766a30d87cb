//! What the app and the CLI trace: one BVH over one mesh (an OBJ, or a scene flattened), or the
//! two-level BVH over the scene's mesh placements, each with the meshes it was built over, so it
//! shades its own hits (`Surface`). Both give the same triangle ids (a two-level hit's id is the
//! one the flattened scene gives the same triangle).

use super::imported::Imported;
use super::tree::TreeView;
use crate::bvh::accel::{Accelerator, Hit, TraceOptions};
use crate::bvh::any::AnyBvh;
use crate::bvh::counters::TraversalStats;
use crate::bvh::params::BuildParams;
use crate::bvh::two_level::TwoLevelBvh;
use crate::geometry::{Ray, TriangleHit, TriangleIntersector};
use crate::mesh::{Mesh, Surface};
use crate::work::{Cancelled, WorkControl};
use glam::{Affine3A, Vec3};
use std::sync::Arc;

/// How to build a scene's acceleration structure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneBuild {
    /// The single BVH's parameters, or the bottom level's (each mesh's BVH).
    pub bvh: BuildParams,
    /// Some: build two levels, with these parameters for the top level.
    pub top: Option<BuildParams>,
}

impl SceneBuild {
    /// "SAH binned, wide4", or "top SAH binned / Midpoint, binary" for two levels: the strategy and
    /// layout, as the statistics columns and exported images name a build.
    pub fn label(&self) -> String {
        let one = format!("{}, {}", self.bvh.strategy.label(), self.bvh.layout.name());
        match self.top {
            Some(top) => format!("top {} / {one}", top.strategy.label()),
            None => one,
        }
    }
}

#[derive(Clone, Debug)]
pub enum SceneBvh {
    /// `imported`: the tree was read from a dump (`bvh::imported`), not built.
    Single {
        bvh: AnyBvh,
        mesh: Arc<Mesh>,
        imported: Option<Arc<Imported>>,
    },
    TwoLevel {
        bvh: TwoLevelBvh,
        meshes: Vec<Arc<Mesh>>,
    },
}

impl SceneBvh {
    /// One BVH over `mesh`.
    pub fn build_single(mesh: Arc<Mesh>, params: &BuildParams, control: &WorkControl) -> Result<SceneBvh, Cancelled> {
        Ok(SceneBvh::Single { bvh: AnyBvh::build_controlled(&mesh, params, control)?, mesh, imported: None })
    }

    /// A tree imported from a dump over `mesh` (`dump::import`).
    pub fn imported(bvh: AnyBvh, mesh: Arc<Mesh>, imported: Imported) -> SceneBvh {
        SceneBvh::Single { bvh, mesh, imported: Some(Arc::new(imported)) }
    }

    /// The box an imported tree is measured against (its SAH cost, the rays that enter it): the
    /// mesh's, so it compares with a built tree on one yardstick (`TreeStats::against`,
    /// `Frame::ray_summary_in`) even where its root box is larger. `None` for a built tree, whose
    /// root box is the mesh's, and for two levels.
    pub fn yardstick(&self) -> Option<crate::geometry::Aabb> {
        match self {
            SceneBvh::Single { mesh, imported: Some(_), .. } => Some(mesh.bounds()),
            _ => None,
        }
    }

    /// Where the tree came from when it was imported, not built.
    pub fn import(&self) -> Option<&Imported> {
        match self {
            SceneBvh::Single { imported, .. } => imported.as_deref(),
            SceneBvh::TwoLevel { .. } => None,
        }
    }

    /// The binary tree the tree view, the node inspector and the replay show for a single BVH:
    /// the tree itself, the binary tree a built 4-wide tree was collapsed from (built again), or an
    /// imported 4-wide tree binarised (`Imported::binary`). `None` for two levels.
    pub fn binary_tree(&self) -> Option<std::borrow::Cow<'_, super::Bvh>> {
        use std::borrow::Cow;
        match self {
            SceneBvh::Single { bvh, imported: Some(i), .. } => match (&i.binary, bvh) {
                (Some((b, _)), _) => Some(Cow::Borrowed(&**b)),
                (None, AnyBvh::Binary(b)) => Some(Cow::Borrowed(b)),
                (None, AnyBvh::Wide(_) | AnyBvh::Wide8(_)) => None,
            },
            SceneBvh::Single { bvh, mesh, imported: None } => Some(bvh.binary_tree(mesh)),
            SceneBvh::TwoLevel { .. } => None,
        }
    }

    /// How captions, tables and the strategy list name the tree: "SAH binned, wide4" (the build's
    /// label) or "imported: FILE, binary".
    pub fn label(&self) -> String {
        match self.import() {
            Some(i) => format!("{}, {}", i.label(), self.build_params().bvh.layout.name()),
            None => self.build_params().label(),
        }
    }

    /// Two levels: a BVH per mesh of `meshes` with `bottom`, and the top level over `placements`
    /// (mesh index, object-to-world transform) with `top`.
    pub fn build_two_level(
        meshes: Vec<Arc<Mesh>>,
        placements: &[(u32, Affine3A)],
        top: &BuildParams,
        bottom: &BuildParams,
        control: &WorkControl,
    ) -> Result<SceneBvh, Cancelled> {
        let refs: Vec<&Mesh> = meshes.iter().map(|m| &**m).collect();
        let bvh = TwoLevelBvh::build(&refs, placements, top, bottom, control)?;
        Ok(SceneBvh::TwoLevel { bvh, meshes })
    }

    /// What this was built with.
    pub fn build_params(&self) -> SceneBuild {
        match self {
            SceneBvh::Single { bvh: b, .. } => SceneBuild { bvh: *b.params(), top: None },
            SceneBvh::TwoLevel { bvh: t, .. } => SceneBuild { bvh: t.bottom_params, top: Some(t.top.params) },
        }
    }

    /// What a walk with `opts` keeps beside the trees (`AnyBvh::walk_bytes`; for two levels,
    /// the meshes' BVHs').
    pub fn walk_bytes(&self, opts: crate::bvh::TraceOptions) -> usize {
        match self {
            SceneBvh::Single { bvh: b, .. } => b.walk_bytes(opts),
            SceneBvh::TwoLevel { bvh: t, .. } => t.bottom.iter().map(|b| b.walk_bytes(opts)).sum(),
        }
    }

    /// The single BVH, or the top level of two.
    pub fn tree(&self) -> &dyn TreeView {
        match self {
            SceneBvh::Single { bvh: b, .. } => b,
            SceneBvh::TwoLevel { bvh: t, .. } => &t.top,
        }
    }

    pub fn two_level(&self) -> Option<&TwoLevelBvh> {
        match self {
            SceneBvh::TwoLevel { bvh: t, .. } => Some(t),
            SceneBvh::Single { .. } => None,
        }
    }

    /// Bytes of every node and index array (each mesh BVH once).
    pub fn memory_bytes(&self) -> usize {
        match self {
            SceneBvh::Single { bvh: b, .. } => b.memory_bytes(),
            SceneBvh::TwoLevel { bvh: t, .. } => t.memory_bytes(),
        }
    }

    /// Total build time.
    pub fn build_time(&self) -> std::time::Duration {
        match self {
            SceneBvh::Single { bvh: b, .. } => b.report().total_time(),
            SceneBvh::TwoLevel { bvh: t, .. } => t.bottom_time + t.top_time,
        }
    }
}

impl Accelerator for SceneBvh {
    #[inline]
    fn trace<T: TriangleIntersector, const BY_DISTANCE: bool, const ANY: bool, S: TraversalStats>(
        &self,
        ray: &mut Ray,
        stats: &mut S,
    ) -> Option<Hit> {
        match self {
            SceneBvh::Single { bvh: b, .. } => b.trace::<T, BY_DISTANCE, ANY, S>(ray, stats),
            SceneBvh::TwoLevel { bvh: t, .. } => t.trace::<T, BY_DISTANCE, ANY, S>(ray, stats),
        }
    }

    fn traces_packets(&self) -> bool {
        matches!(self, SceneBvh::Single { bvh, .. } if bvh.traces_packets())
    }

    #[inline]
    fn closest_hits(&self, rays: &mut [Ray], hits: &mut [Option<Hit>], opts: TraceOptions) {
        match self {
            SceneBvh::Single { bvh: b, .. } => b.closest_hits(rays, hits, opts),
            SceneBvh::TwoLevel { bvh: t, .. } => t.closest_hits(rays, hits, opts),
        }
    }

    #[inline]
    fn any_hits(&self, rays: &[Ray], occluded: &mut [bool], opts: TraceOptions) {
        match self {
            SceneBvh::Single { bvh: b, .. } => b.any_hits(rays, occluded, opts),
            SceneBvh::TwoLevel { bvh: t, .. } => t.any_hits(rays, occluded, opts),
        }
    }
}

impl SceneBvh {
    /// The world-space corners (`Aabb::corners` order) of the box of `node` at `level`, as a
    /// trace names them: a placement's mesh BVH's boxes are placed by its transform.
    pub fn node_corners(&self, level: super::TraceLevel, node: super::NodeId) -> Option<[Vec3; 8]> {
        use crate::bvh::counters::NodeId;
        use crate::bvh::trace::TraceLevel;
        let in_tree = |bvh: &AnyBvh| match (bvh, node) {
            (AnyBvh::Binary(b), NodeId::Node(i)) => b.nodes.get(i as usize).map(|n| n.bounds()),
            (AnyBvh::Wide(w), id) => w.node_box(id),
            (AnyBvh::Wide8(w), id) => w.node_box(id),
            (AnyBvh::Binary(_), NodeId::Leaf { .. }) => None,
        };
        match (self, level) {
            (SceneBvh::Single { bvh, .. }, TraceLevel::Mesh) => in_tree(bvh).map(|b| b.corners()),
            (SceneBvh::TwoLevel { bvh, .. }, TraceLevel::Top) => match node {
                NodeId::Node(i) => bvh.top.nodes.get(i as usize).map(|n| n.bounds().corners()),
                NodeId::Leaf { .. } => None,
            },
            (SceneBvh::TwoLevel { bvh, .. }, TraceLevel::Bottom { instance }) => {
                let inst = bvh.instances.get(instance as usize)?;
                let b = in_tree(&bvh.bottom[inst.mesh as usize])?;
                Some(super::two_level::placed_corners(&b, &inst.to_world))
            }
            _ => None,
        }
    }

    /// The world-space corners of triangle `prim` (a hit's id: the mesh's, or for two levels the
    /// scene's, numbered as the flattened scene numbers them).
    pub fn triangle_corners(&self, prim: u32) -> Option<[Vec3; 3]> {
        match self {
            SceneBvh::Single { mesh, .. } => (prim < mesh.triangle_count() as u32).then(|| mesh.triangle(prim)),
            SceneBvh::TwoLevel { bvh, meshes } => {
                let k = bvh.instances.partition_point(|i| i.first_prim <= prim).checked_sub(1)?;
                let inst = &bvh.instances[k];
                let mesh = &meshes[inst.mesh as usize];
                let local = prim - inst.first_prim;
                (local < mesh.triangle_count() as u32)
                    .then(|| mesh.triangle(local).map(|p| inst.to_world.transform_point3(p)))
            }
        }
    }
}

impl Surface for SceneBvh {
    /// One level: the mesh's own normal. Two levels: the placed mesh's, the ray moved into its
    /// object space as the traversal moved it (so `t` is the same), the normal back into the
    /// world by the inverse transpose of the placement.
    fn shading_normal(&self, ray: &Ray, prim: u32, hit: TriangleHit) -> Vec3 {
        match self {
            SceneBvh::Single { mesh, .. } => mesh.shading_normal(ray, prim, hit),
            SceneBvh::TwoLevel { bvh, meshes } => {
                // Instances number their triangles in placement order: the last one starting at
                // or before `prim` holds it.
                let k = bvh.instances.partition_point(|i| i.first_prim <= prim).saturating_sub(1);
                let inst = &bvh.instances[k];
                let local = Ray::new(
                    inst.to_object.transform_point3(ray.origin()),
                    inst.to_object.transform_vector3(ray.dir()),
                );
                let n = meshes[inst.mesh as usize].shading_normal(&local, prim - inst.first_prim, hit);
                (glam::Mat3::from(inst.to_object.matrix3).transpose() * n).normalize_or_zero()
            }
        }
    }
}
