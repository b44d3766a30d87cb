//! The reconciler: the one place that compares what the app shows and has built with what its
//! state asks for, and starts the background work (build, render, explanations, the comparison,
//! the imported tree's wrong pixels) that closes the gap.

use crate::app::jobs::RenderRequest;
use crate::app::state::{BvhscopeApp, MessageKind};
use crate::bvh::SceneBvh;
use crate::render::View;
use std::sync::Arc;

impl BvhscopeApp {
    /// Bring the background work in line with the state: settings that depend on the BVH are
    /// kept within it, a build starts when the settings or the scene differ from what was built
    /// or is building, and a render when what the viewport would show differs from the last
    /// render asked for. The one place that decides what to rebuild and re-render.
    pub fn reconcile(&mut self) {
        self.fit_settings_to_bvh();
        self.fit_levels_to_scene();
        self.ensure_build();
        self.ensure_render();
        self.ensure_explained();
        self.ensure_compare();
        self.ensure_wrong();
    }

    /// The red mask's pixels: once an image of the imported tree is done, the frame's primary
    /// rays are traced against the linear scan (unless they were for this camera).
    pub(super) fn ensure_wrong(&mut self) {
        if !self.import.on || self.jobs.is_busy() || self.jobs.wrong.is_some() {
            return;
        }
        let Some(s) = self.shown.as_ref().filter(|s| s.frame.is_complete() && s.partial.is_none()) else { return };
        let Some(reference) = self.import.tree.as_ref().and_then(|t| t.reference.clone()) else { return };
        if s.bvh.import().is_some() && self.import.wrong_for(&s.bvh, &s.camera, &s.trace).is_none() {
            self.jobs.wrong(s.bvh.clone(), reference, s.camera, s.trace);
        }
    }

    /// B of the side-by-side view: once A's image is done, B is built (or kept) and traced on the
    /// same camera and traversal, unless it already was.
    pub(super) fn ensure_compare(&mut self) {
        if !self.compare.on || self.jobs.is_busy() {
            return;
        }
        let Some(shown) = self.shown.as_ref().filter(|s| s.frame.is_complete() && s.partial.is_none()) else { return };
        if !self.current_bvh().is_some_and(|b| Arc::ptr_eq(&b.bvh, &shown.bvh)) {
            return;
        }
        let build = self.compare.build_for(self.wanted_build());
        // B traces A's rays: the same secondary rays from the same hits.
        let secondary = self.secondary_rays(&shown.camera);
        let wanted = (build, self.scene_id, shown.camera, self.compare.trace, secondary);
        let have =
            self.compare.b.as_ref().is_some_and(|b| (b.build, b.scene_id, b.camera, b.trace, b.secondary) == wanted);
        if !have && self.jobs.last_compare != Some(wanted) {
            let keep = self.compare.b.as_ref().filter(|b| b.scene_id == self.scene_id).map(|b| b.bvh.clone());
            let (camera, trace) = (shown.camera, self.compare.trace);
            self.jobs.compare(self.scene.clone(), self.scene_id, build, keep, camera, trace, secondary);
        }
    }

    /// The node explainer's background work, each started only when the image is done (it must
    /// not slow a build or a render): the binary tree behind the current single BVH, the frame's
    /// visits per node while the Tree window is open, and the selected node's inspection.
    pub(super) fn ensure_explained(&mut self) {
        if self.jobs.is_busy() {
            return;
        }
        let Some(bvh) = self.current_bvh().map(|b| b.bvh.clone()) else { return };
        if !matches!(*bvh, SceneBvh::Single { .. }) {
            return;
        }
        let Some(explained) = self.nodes.current(Some(&bvh)).cloned() else {
            if self.jobs.explain.is_none() {
                self.jobs.explain(bvh);
            }
            return;
        };
        if self.replay.window {
            let before = self.replay.partial.clone();
            self.replay.fit(&explained);
            let changed = match (&before, &self.replay.partial) {
                (Some(a), Some(b)) => !Arc::ptr_eq(a, b),
                _ => true,
            };
            if changed {
                self.ensure_render();
            }
        }
        if let Some(node) = self.nodes.selected.filter(|_| self.nodes.inspection.is_none()) {
            if self.jobs.inspect.as_ref().is_none_or(|(_, n)| *n != node) {
                self.jobs.inspect(explained.clone(), node);
            }
        }
        if self.nodes.window && self.jobs.visits.is_none() {
            let Some(shown) = self.shown.as_ref().filter(|s| Arc::ptr_eq(&s.bvh, &bvh)) else { return };
            let fresh = self.nodes.visits.as_ref().is_some_and(|v| {
                Arc::ptr_eq(&v.explained, &explained) && v.camera == shown.camera && v.trace == shown.trace
            });
            if !fresh {
                self.jobs.visits(explained, shown.camera, shown.trace);
            }
        }
    }

    /// Box depths within the tree's depth (once it is known: until a BVH is built the chosen
    /// depth is kept), and no per-level view for a single BVH, which has no levels to tell apart.
    pub(super) fn fit_settings_to_bvh(&mut self) {
        let Some(built) = self.current_bvh() else { return };
        let (max, top) = (built.bottom_max_depth(), built.top_stats.as_ref().map(|s| s.max_depth));
        let s = &mut self.settings;
        s.box_depth = s.box_depth.min(max);
        match top {
            Some(top) => s.top_box_depth = s.top_box_depth.min(top),
            None if s.view.is_per_level() => s.view = View::Visits,
            None => {}
        }
    }

    /// One level over a scene too large to flatten is not built: the app switches to two levels
    /// and says why (the CLI refuses with the same sentence).
    pub(super) fn fit_levels_to_scene(&mut self) {
        if self.settings.two_level || !self.has_instances() {
            return;
        }
        if let Err(e) = self.scene.check_one_level() {
            self.settings.two_level = true;
            self.message(MessageKind::Warning, format!("{e}. Switched to two levels."));
        }
    }

    /// Start a build when the settings or the scene differ from what was built or is building.
    pub(super) fn ensure_build(&mut self) {
        // The imported tree, when it is chosen, is the current BVH: nothing to build.
        if let Some(bvh) = self.import.shown(self.scene_id).cloned() {
            self.jobs.cancel_build();
            self.jobs.last_build = None;
            if !self.current_bvh().is_some_and(|b| Arc::ptr_eq(&b.bvh, &bvh)) {
                self.set_built(bvh);
            }
            return;
        }
        let build = self.wanted_build();
        let wanted = (build, self.scene_id);
        // Built where it should be too: lbvh and ploc on the GPU when it traces the frames.
        let gpu = self.gpu_for_building(&build);
        let have = self.current_bvh().is_some_and(|b| {
            b.bvh.import().is_none() && b.bvh.build_params() == build && self.built_where_wanted(&b.bvh, &build)
        });
        let kept = self.built_cache.get(self.scene_id, &build).filter(|b| self.built_where_wanted(b, &build));
        if have {
            // Switched back to what is built while another build ran: that build is not wanted.
            self.jobs.cancel_build();
        } else if let Some(bvh) = kept {
            // Built before for this scene (a lesson's step back): shown at once.
            self.jobs.cancel_build();
            self.set_built(bvh);
        } else if self.jobs.last_build != Some(wanted) || self.jobs.gpu.last_build_on_gpu != gpu.is_some() {
            self.jobs.build(self.scene.clone(), build, self.scene_id, gpu);
        }
    }

    /// The secondary rays the settings ask for, on `camera` over the scene's bounds (as the
    /// command line resolves `--ray-kind` over the loaded scene's): `None` for camera rays.
    pub(in crate::app) fn secondary_rays(
        &self,
        camera: &crate::render::Camera,
    ) -> Option<crate::render::SecondaryRays> {
        let spec = self.settings.rays;
        spec.kind.is_secondary().then(|| crate::render::SecondaryRays::new(spec, &self.scene.bounds(), camera))
    }

    /// Start a render when what the viewport would show (camera, image size, BVH, view)
    /// differs from the last render asked for.
    pub(super) fn ensure_render(&mut self) {
        let (w, h) = self.viewport_pixels;
        // Nothing renders while a build runs: it would share the cores with it and lengthen the
        // build time the statistics show; the new BVH is rendered when it is there.
        if self.jobs.build.is_some() {
            return;
        }
        let Some(built) = self.current_bvh().filter(|_| w > 0 && h > 0) else { return };
        let camera = self.orbit.camera(w, h);
        let req = RenderRequest {
            bvh: built.bvh.clone(),
            camera,
            trace: self.settings.trace,
            style: self.view_style(),
            progressive: self.settings.progressive,
            partial: self.replay_partial(),
            gpu: self.gpu_for_frames(),
            secondary: self.secondary_rays(&camera),
        };
        if req.camera.validate().is_ok() && !self.jobs.last_render.as_ref().is_some_and(|last| last.same_as(&req)) {
            self.jobs.render(req);
        }
    }
}
