//! The jobs themselves: each starts its work on a thread of its own (`Jobs::spawn`) and reports
//! over the channel; starting one cancels the running one of its kind.

use super::*;

impl Jobs {
    /// Load an OBJ in the background. A newer load supersedes an older one: the older one cannot be
    /// stopped inside the parser, but its result is dropped (`poll` keeps only the current job's).
    pub fn load(&mut self, path: PathBuf) {
        let job = self.start(format!("Loading {}", path.display()));
        let send = self.sender(job.id);
        let primary = Other::new(&self.primary);
        self.spawn_uncounted(&job, move || {
            let _primary = primary;
            let result = Scene::open(&path).map(Arc::new).map_err(|e| e.to_string());
            send(JobEvent::Loaded(result));
        });
        self.load = Some(job);
    }

    /// Build a BVH (or two levels) over `scene` in the background; a running build is cancelled,
    /// and so are the render, the comparison, the visit count and the wrong pixels (they are of
    /// the BVH being replaced). The build starts its clock once every other job has ended.
    /// With `gpu`, lbvh and ploc are built on it (`GpuJobs::build`).
    pub fn build(&mut self, scene: Arc<Scene>, params: SceneBuild, scene_id: u64, gpu: Option<Arc<bvhscope_gpu::Gpu>>) {
        if let Some(old) = self.build.take() {
            old.control.cancel();
        }
        let others =
            [self.render.take(), self.compare.take(), self.visits.take(), self.wrong.take(), self.speedup.take()];
        for old in others.into_iter().flatten() {
            old.control.cancel();
        }
        // The cancelled render is redrawn once the build is done (or for the BVH kept, if not).
        self.last_render = None;
        self.last_compare = None;
        let label = match params.top {
            Some(top) => format!("Building two levels ({} over {})", top.strategy.label(), params.bvh.strategy.label()),
            None => format!("Building ({})", params.bvh.strategy.label()),
        };
        let label = if gpu.is_some() { format!("{label} on the GPU") } else { label };
        let job = self.start(label);
        let (send, control, others) = (self.sender(job.id), job.control.clone(), self.others.clone());
        let gpu_jobs = self.gpu.clone();
        self.gpu.last_build_on_gpu = gpu.is_some();
        let primary = Other::new(&self.primary);
        self.spawn_uncounted(&job, move || {
            let _primary = primary;
            while others.load(std::sync::atomic::Ordering::SeqCst) > 0 && !control.is_cancelled() {
                std::thread::sleep(Duration::from_millis(1));
            }
            match gpu_jobs.build(&scene, &params, &control, gpu.as_deref()) {
                Ok(result) => send(JobEvent::Built { scene_id, params, result }),
                Err(why) => {
                    send(JobEvent::GpuFailed(why));
                    send(JobEvent::NotBuilt);
                }
            }
        });
        self.build = Some(job);
        self.last_build = Some((params, scene_id));
    }

    /// Cancel the running build, if any (its result will be ignored).
    pub fn cancel_build(&mut self) {
        if let Some(old) = self.build.take() {
            old.control.cancel();
            self.last_build = None;
        }
    }

    /// Render progressively in the background; a running render is cancelled.
    pub fn render(&mut self, req: RenderRequest) {
        if let Some(old) = self.render.take() {
            old.control.cancel();
        }
        let label = if req.gpu.is_some() && req.partial.is_none() { "Rendering on the GPU" } else { "Rendering" };
        let job = self.start(label.to_string());
        let (send, control) = (self.sender(job.id), job.control.clone());
        let (r, frames, gpu_jobs) = (req.clone(), self.frames.clone(), self.gpu.clone());
        let primary = Other::new(&self.primary);
        self.spawn(&job, move || {
            let _primary = primary;
            if let (Some(g), None) = (&r.gpu, &r.partial) {
                match gpu_jobs.render(&r, g, &control) {
                    Ok(Some(pass)) => send(JobEvent::Pass(pass)),
                    Ok(None) => {}
                    Err(why) => send(JobEvent::GpuFailed(format!("Tracing on the GPU failed: {why}"))),
                }
                return;
            }
            // Always count: the heatmaps, the hover read-out and the Statistics panel need the
            // counters. A heatmap is drawn from them; the normal and depth views are drawn from
            // uncounted packets first, and their counts follow in one more pass.
            let settings =
                RenderSettings { trace: r.trace, count: true, progressive: r.progressive, secondary: r.secondary };
            let on_pass = |frame: Frame, info: PassInfo| {
                let (img, legend) = view_image(&frame, r.style.view, r.style.colormap, r.style.range, r.style.cost);
                let image = egui::ColorImage::from_rgb([img.width() as usize, img.height() as usize], img.as_raw());
                let (bvh, camera, style, trace, partial) =
                    (r.bvh.clone(), r.camera, r.style, r.trace, r.partial.clone());
                let (frame, gpu) = (Arc::new(frame), None);
                let pass =
                    PassOutput { bvh, frame, image, legend, info, camera, trace, style, partial, gpu, cpu_finished: 0 };
                send(JobEvent::Pass(pass));
            };
            // A replay's partial tree traces in place of the BVH it is part of; the mesh shades.
            let _ = match (&r.partial, &*r.bvh) {
                (Some(p), SceneBvh::Single { mesh, .. }) => {
                    render_passes(&**p, &**mesh, &r.camera, &settings, &frames, &control, on_pass)
                }
                _ if r.style.view.is_heatmap() => {
                    render_passes(&*r.bvh, &*r.bvh, &r.camera, &settings, &frames, &control, on_pass)
                }
                _ => render_passes_counts_after(&*r.bvh, &*r.bvh, &r.camera, &settings, &frames, &control, on_pass),
            };
        });
        self.render = Some(job);
        self.last_render = Some(req);
    }

    /// Prepare the binary tree behind `bvh` (a single BVH) for the Tree and Node windows.
    pub fn explain(&mut self, bvh: Arc<SceneBvh>) {
        let job = self.start("Preparing the tree view".to_string());
        let send = self.sender(job.id);
        self.spawn(&job, move || {
            if let Some(tree) = bvh.binary_tree() {
                let tree = Arc::new(tree.into_owned());
                send(JobEvent::Explained(Arc::new(Explained::new(bvh.clone(), tree))));
            }
        });
        self.explain = Some(job);
    }

    /// Build B (unless `have` is already B's build) and trace it on `camera`, counting; a running
    /// compare job is cancelled.
    #[allow(clippy::too_many_arguments)]
    pub fn compare(
        &mut self,
        scene: Arc<Scene>,
        scene_id: u64,
        build: SceneBuild,
        have: Option<Arc<SceneBvh>>,
        camera: Camera,
        trace: TraceOptions,
        secondary: Option<crate::render::SecondaryRays>,
    ) {
        if let Some(old) = self.compare.take() {
            old.control.cancel();
        }
        let job = self.start(format!("Building and tracing B ({})", build.bvh.strategy.label()));
        let (send, control, frames) = (self.sender(job.id), job.control.clone(), self.frames.clone());
        self.spawn(&job, move || {
            let bvh = match have.filter(|b| b.build_params() == build) {
                Some(b) => b,
                None => match scene.build(&build, &control) {
                    Ok(b) => Arc::new(b),
                    Err(_) => return,
                },
            };
            let settings = RenderSettings { trace, count: true, progressive: false, secondary };
            let mut last = None;
            let _ = render_passes(&*bvh, &*bvh, &camera, &settings, &frames, &control, |frame, _| last = Some(frame));
            if let Some(frame) = last.filter(|f| f.is_complete()) {
                // B's end-point overlap, of its binary tree as A's is (the statistics' EPO row).
                let epo = bvh.binary_tree().map(|t| crate::bvh::epo::measure(&t, &crate::bvh::Hierarchy::of(&t)));
                let (epo, epo_error) = (epo.as_ref().map(|e| e.value), epo.as_ref().and_then(|e| e.error()));
                let stats = crate::bvh::TreeStats { epo, epo_error, ..crate::bvh::TreeStats::of(bvh.tree()) };
                let summary = frame.ray_summary();
                let frame = Arc::new(frame);
                let b = CompareB { scene_id, build, bvh, stats, frame, camera, trace, secondary, summary };
                send(JobEvent::Compared(Box::new(b)));
            }
        });
        self.compare = Some(job);
        self.last_compare = Some((build, scene_id, camera, trace, secondary));
    }

    /// Count, per node, the visits of `camera`'s primary rays (a running count is cancelled).
    pub fn visits(&mut self, explained: Arc<Explained>, camera: Camera, trace: TraceOptions) {
        if let Some(old) = self.visits.take() {
            old.control.cancel();
        }
        let job = self.start("Counting visits per node".to_string());
        let (send, control) = (self.sender(job.id), job.control.clone());
        self.spawn(&job, move || {
            if let Ok(v) = crate::explain::visits::frame_visits(&explained.tree, &camera, trace, &control) {
                send(JobEvent::Visits(FrameVisits { explained, camera, trace, counts: v.counts }));
            }
        });
        self.visits = Some(job);
    }

    /// Read the dump at `path` for `scene`'s mesh and check it as `bvhscope check` does, with
    /// `CHECK_RAYS` random rays and `camera`'s primary rays. The check waits for the scene's own
    /// load, build and first full frame (`primary`, `shown_scene`) and is not among the jobs a
    /// build waits for: a dump whose check takes minutes (every box the root's) never holds the
    /// mesh's image back, nor any build or frame asked for while it runs (its own thread pool).
    pub fn import(&mut self, path: PathBuf, scene: Arc<Scene>, scene_id: u64, camera: Camera, trace: TraceOptions) {
        let job = self.start(format!("Checking {}", path.display()));
        let (send, control) = (self.sender(job.id), job.control.clone());
        let (primary, shown) = (self.primary.clone(), self.shown_scene.clone());
        self.spawn_uncounted(&job, move || {
            use std::sync::atomic::Ordering::SeqCst;
            // The scene's own work first: while any runs, or until its first full frame (or two
            // seconds with nothing running: a scene that shows no frame).
            let mut idle_since: Option<Instant> = None;
            while !control.is_cancelled() {
                let busy = primary.load(SeqCst) > 0;
                if !busy && shown.load(SeqCst) == scene_id {
                    break;
                }
                let idle = *idle_since.get_or_insert_with(Instant::now);
                if busy {
                    idle_since = None;
                } else if idle.elapsed() > Duration::from_secs(2) {
                    break;
                }
                std::thread::sleep(Duration::from_millis(20));
            }
            // On a pool of its own, half the cores: in rayon's shared pool a check of minutes
            // would keep every worker busy and starve a build or frame asked for meanwhile.
            let threads = std::thread::available_parallelism().map_or(1, |n| (n.get() / 2).max(1));
            let tree = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
                Ok(pool) => pool.install(|| import_tree(path, &scene, scene_id, &camera, trace, &control)),
                Err(_) => import_tree(path, &scene, scene_id, &camera, trace, &control),
            };
            send(JobEvent::Imported(tree.map(Box::new)));
        });
        self.import = Some(job);
    }

    /// Read the grade report at `path` (its grade.json, or its folder), its mesh and dumps looked
    /// for (`explain::grade::GradeReport::read`); a newer report replaces one being read.
    pub fn grade_report(&mut self, path: PathBuf) {
        let job = self.start(format!("Reading {}", path.display()));
        let send = self.sender(job.id);
        self.spawn(&job, move || {
            let read = crate::explain::grade::GradeReport::read(&path).map(Box::new).map_err(|e| e.to_string());
            send(JobEvent::GradeReport(read));
        });
        self.grade = Some(job);
    }

    /// Time `bvh` (a single BVH) against the linear scan on `camera`'s frame, single rays on one
    /// thread (`explain::timing`, as `compare`'s trace column); a running timing is cancelled.
    pub fn speedup(&mut self, bvh: Arc<SceneBvh>, camera: Camera, trace: TraceOptions) {
        if let Some(old) = self.speedup.take() {
            old.control.cancel();
        }
        let job = self.start("Timing against the linear scan".to_string());
        let (send, control) = (self.sender(job.id), job.control.clone());
        self.spawn(&job, move || {
            let SceneBvh::Single { mesh, .. } = &*bvh else { return };
            let linear = crate::bvh::LinearScan::new(mesh);
            let budget = LINEAR_BUDGET;
            // Timed as `compare` times its rows: the tree's median of as many runs (issue 59).
            let runs = crate::explain::timing::RUNS;
            if let Ok(s) =
                crate::explain::timing::speedup_one_thread(&*bvh, &linear, &camera, trace, runs, budget, &control)
            {
                send(JobEvent::Speedup(Box::new(Timed { bvh, camera, trace, speedup: s })));
            }
        });
        self.speedup = Some(job);
    }

    /// Write the replay's animation to `path` (`bvhscope replay`'s film, the same frames and
    /// file), with progress; a newer export replaces a running one.
    pub fn film(&mut self, r: FilmRequest, path: PathBuf) {
        if let Some(old) = self.film.take() {
            old.control.cancel();
        }
        let job = self.start("Writing the replay".to_string());
        let (send, control) = (self.sender(job.id), job.control.clone());
        let steps = crate::explain::replay_film::steps(r.replay.splits(), r.settings.frames).len();
        control.set_total(steps as u64);
        self.spawn(&job, move || {
            use crate::explain::replay_film::film;
            let Ok(f) = film(&r.replay, &r.mesh, &r.camera, &r.settings, &r.subject, &control) else {
                return send(JobEvent::Filmed(Err("Writing the replay was cancelled".into())));
            };
            let delay = FILM_DELAY_MS;
            let result = crate::render::animation::write_animation(&path, &f.images, delay)
                .map(|()| {
                    let fewer = if f.images.len() < r.settings.frames as usize {
                        format!(": the tree has {} splits, so one frame per step", r.replay.splits())
                    } else {
                        String::new()
                    };
                    format!("Saved {} ({} frames{fewer})", path.display(), f.images.len())
                })
                .map_err(|e| e.to_string());
            send(JobEvent::Filmed(result));
        });
        self.film = Some(job);
    }

    /// Stop the speed-up's timing.
    pub fn cancel_speedup(&mut self) {
        if let Some(old) = self.speedup.take() {
            old.control.cancel();
        }
    }

    /// The pixels of `camera`'s frame whose hit through `bvh` (an imported tree) differs from the
    /// linear scan's.
    pub fn wrong(
        &mut self,
        bvh: Arc<SceneBvh>,
        reference: Arc<crate::explain::check::Reference>,
        camera: Camera,
        trace: TraceOptions,
    ) {
        let job = self.start("Finding wrong pixels".to_string());
        let (send, control) = (self.sender(job.id), job.control.clone());
        self.spawn(&job, move || {
            let SceneBvh::Single { mesh, .. } = &*bvh else { return };
            let rays = crate::explain::check::RaySet::new(mesh, &camera, 0);
            let Ok(wrong) = crate::explain::check::wrong_rays(&*bvh, mesh, &reference, &rays, trace, &control) else {
                return;
            };
            send(JobEvent::Wrong(WrongPixels { bvh, camera, trace, pixels: wrong.pixels }));
        });
        self.wrong = Some(job);
    }

    /// Inspect `node` of the prepared tree.
    pub fn inspect(&mut self, explained: Arc<Explained>, node: u32) {
        let job = self.start(format!("Inspecting node {node}"));
        let send = self.sender(job.id);
        self.spawn(&job, move || {
            if let Some(ins) = crate::explain::inspect::inspect(&explained.tree, &explained.hierarchy, node) {
                send(JobEvent::Inspected { node, explained, inspection: Arc::new(ins) });
            }
        });
        self.inspect = Some((job, node));
    }

    /// Ask for a file with the system dialog, off the UI thread (rfd's async dialog blocks its
    /// thread until answered where a portal or zenity exists, and returns None at once where not).
    pub fn pick_file(&mut self, pick: Pick, suggested_name: &str) {
        if self.picking.is_some() {
            return;
        }
        self.picking = Some(pick);
        let send = self.sender(0);
        let name = suggested_name.to_string();
        std::thread::spawn(move || {
            let start = Instant::now();
            let dialog = rfd::AsyncFileDialog::new();
            let fut = async move {
                match pick {
                    Pick::Open => {
                        let mut kinds: Vec<String> = crate::mesh::MeshFormat::EXTENSIONS
                            .iter()
                            .flat_map(|e| [e.to_string(), e.to_uppercase()])
                            .collect();
                        kinds.push("json".into());
                        dialog.add_filter("Meshes (OBJ, PLY, OFF, STL, glTF) and scenes", &kinds).pick_file().await
                    }
                    Pick::SaveScene => {
                        dialog.add_filter("bvhscope scene", &["json"]).set_file_name(&name).save_file().await
                    }
                    Pick::SavePng => dialog.add_filter("PNG image", &["png"]).set_file_name(&name).save_file().await,
                    Pick::SaveStatsCsv => dialog.add_filter("CSV", &["csv"]).set_file_name(&name).save_file().await,
                    Pick::SaveStatsJson => dialog.add_filter("JSON", &["json"]).set_file_name(&name).save_file().await,
                    Pick::SaveCounts => dialog.add_filter("CSV", &["csv"]).set_file_name(&name).save_file().await,
                    Pick::OpenBvh => dialog.add_filter("bvhscope-bvh dumps", &["json", "gz", "txt"]).pick_file().await,
                    Pick::OpenGradeReport => dialog.add_filter("grade report", &["json"]).pick_file().await,
                    Pick::OpenLesson => dialog.add_filter("lesson", &["json"]).pick_file().await,
                    Pick::SaveLesson => dialog.add_filter("lesson", &["json"]).set_file_name(&name).save_file().await,
                    Pick::SaveAnimation => {
                        let filters = dialog.add_filter("GIF", &["gif"]).add_filter("animated PNG", &["png"]);
                        filters.set_file_name(&name).save_file().await
                    }
                    Pick::SaveBvh => {
                        let filters =
                            dialog.add_filter("bvhscope-bvh JSON", &["json"]).add_filter("text form", &["txt"]);
                        filters.set_file_name(&name).save_file().await
                    }
                }
            };
            let path = pollster::block_on(fut).map(|h| h.path().to_path_buf());
            send(JobEvent::Picked { pick, path, took: start.elapsed() });
        });
    }
}

/// A dump read and checked (`explain::check::check`) for `scene`, as the Imported BVH window shows it,
/// or one line naming the file and why it cannot be read.
fn import_tree(
    path: PathBuf,
    scene: &Scene,
    scene_id: u64,
    camera: &Camera,
    trace: TraceOptions,
    control: &WorkControl,
) -> Result<ImportedTree, String> {
    use crate::explain::check::{check, Group, Subject};
    let mesh = scene.flat_mesh().map_err(|e| format!("{}: {e}", scene.title()))?;
    let limit = crate::dump::max_bytes(mesh.file_triangle_count());
    let dump = crate::dump::BvhDump::read(&path, limit).map_err(|e| e.to_string())?;
    let mesh_path = match &scene.source {
        crate::scene::SceneSource::File(p) => p.clone(),
        crate::scene::SceneSource::Builtin => PathBuf::from(scene.title()),
    };
    let subject = Subject { dump: &dump, dump_path: &path, mesh: &mesh, mesh_path: &mesh_path };
    let checked =
        check(&subject, camera, CHECK_RAYS, trace, control).map_err(|_| "the check was cancelled".to_string())?;
    let (findings, traced, reference) = (checked.findings, checked.tree, checked.reference.map(Arc::new));
    let bvh = match traced {
        Some((bvh, names)) => Ok(Arc::new(SceneBvh::imported(bvh, mesh, names))),
        None => Err(findings
            .iter()
            .find(|f| f.group == Group::Rays || f.group == Group::Structure)
            .map_or("it cannot be traced".into(), |f| f.line(crate::explain::check::LISTED))),
    };
    Ok(ImportedTree { path, scene_id, bvh, findings, rays: CHECK_RAYS, reference })
}
