//! Background work for the app: loading, building and rendering each run on their own thread
//! and report over one channel; the UI thread only polls. Starting a job of a kind cancels the
//! running one of that kind, and results of superseded jobs are dropped by id.

use crate::app::views::compare::CompareB;
use crate::app::views::import::{ImportedTree, WrongPixels, CHECK_RAYS};
use crate::app::views::node::{Explained, FrameVisits};
use crate::bvh::{SceneBuild, SceneBvh, TraceOptions};
use crate::render::{
    render_passes, render_passes_counts_after, view_image, Camera, Frame, FramePool, PassInfo, RenderSettings,
};
use crate::scene::Scene;
use crate::work::WorkControl;
use std::path::PathBuf;
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::Arc;
use std::time::{Duration, Instant};

mod gpu;
pub mod messages;
mod work;

pub use gpu::Probe;
pub use messages::*;

/// A job in flight.
pub struct Running {
    pub id: u64,
    pub control: Arc<WorkControl>,
    pub started: Instant,
    pub label: String,
}

pub struct Jobs {
    tx: Sender<(u64, JobEvent)>,
    rx: Receiver<(u64, JobEvent)>,
    ctx: egui::Context,
    next_id: u64,
    pub load: Option<Running>,
    pub build: Option<Running>,
    pub render: Option<Running>,
    /// The node explainer's background work (`views::node`): preparing the tree, counting the
    /// frame's visits, inspecting the selected node. Each started only when nothing above runs.
    pub explain: Option<Running>,
    pub visits: Option<Running>,
    pub inspect: Option<(Running, u32)>,
    /// B of the side-by-side view: built if needed, then traced on A's camera.
    pub compare: Option<Running>,
    /// Reading and checking a dump; finding the frame's wrong pixels of an imported tree.
    pub import: Option<Running>,
    pub wrong: Option<Running>,
    /// Timing the BVH against the linear scan (the statistics panel's speed-up).
    pub speedup: Option<Running>,
    /// Writing the build replay's animation (the Replay window's export).
    pub film: Option<Running>,
    /// Reading a grade report.
    pub grade: Option<Running>,
    /// What the last compare job was asked for.
    pub last_compare: Option<(SceneBuild, u64, Camera, TraceOptions, Option<crate::render::SecondaryRays>)>,
    pub picking: Option<Pick>,
    /// The last render started (to tell whether a new one is needed).
    pub last_render: Option<RenderRequest>,
    /// The last build started: its parameters and scene.
    pub last_build: Option<(SceneBuild, u64)>,
    /// The render jobs' frame storage, reused from one render to the next (`FramePool`).
    frames: FramePool,
    /// Jobs other than builds and loads running now: a build waits for them to end before it
    /// starts its clock, so its time is the build's alone (as `bvhscope stats` measures it), not
    /// the build's and a render's sharing the cores.
    others: Arc<std::sync::atomic::AtomicUsize>,
    /// The scene's own work running now (loads, builds, renders) and the scene of the last full
    /// frame shown: an import's check waits for them (`import`), so a slow but correct dump never
    /// keeps the mesh's own build and first image waiting.
    primary: Arc<std::sync::atomic::AtomicUsize>,
    pub shown_scene: Arc<std::sync::atomic::AtomicU64>,
    /// The GPU the render and build jobs may use, and what they keep on it (`jobs::gpu`).
    pub gpu: gpu::GpuJobs,
}

/// Counts a job among `Jobs::others` while it lives.
struct Other(Arc<std::sync::atomic::AtomicUsize>);

impl Other {
    fn new(count: &Arc<std::sync::atomic::AtomicUsize>) -> Self {
        count.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        Other(count.clone())
    }
}

impl Drop for Other {
    fn drop(&mut self) {
        self.0.fetch_sub(1, std::sync::atomic::Ordering::SeqCst);
    }
}

impl Jobs {
    pub fn new(ctx: egui::Context) -> Self {
        let (tx, rx) = channel();
        Self {
            tx,
            rx,
            ctx,
            next_id: 1,
            load: None,
            build: None,
            render: None,
            explain: None,
            visits: None,
            inspect: None,
            compare: None,
            import: None,
            wrong: None,
            speedup: None,
            film: None,
            grade: None,
            last_compare: None,
            picking: None,
            last_render: None,
            last_build: None,
            frames: FramePool::default(),
            others: Default::default(),
            primary: Default::default(),
            shown_scene: Default::default(),
            gpu: Default::default(),
        }
    }

    /// Look for a GPU adapter in the background (once, at start).
    pub fn probe_gpu(&self) {
        gpu::probe(self.sender(0));
    }

    fn start(&mut self, label: String) -> Running {
        let id = self.next_id;
        self.next_id += 1;
        Running { id, control: Arc::new(WorkControl::new()), started: Instant::now(), label }
    }

    fn sender(&self, id: u64) -> impl Fn(JobEvent) + Send + 'static {
        let (tx, ctx) = (self.tx.clone(), self.ctx.clone());
        move |e| {
            // The receiver lives as long as the app; if it is gone, nobody needs the result.
            let _ = tx.send((id, e));
            ctx.request_repaint();
        }
    }

    /// Run `work` for `job` on a thread of its own, counted among the jobs a build waits for
    /// (`others`). A panic there (a bug) must not leave the job running forever in the status bar:
    /// it is caught and reported as the job's failure.
    fn spawn(&self, job: &Running, work: impl FnOnce() + Send + 'static) {
        let other = Other::new(&self.others);
        self.spawn_uncounted(job, move || {
            let _counted = other;
            work()
        });
    }

    /// `spawn` for builds and loads, which no build waits for.
    fn spawn_uncounted(&self, job: &Running, work: impl FnOnce() + Send + 'static) {
        let (fail, label) = (self.sender(job.id), job.label.clone());
        std::thread::spawn(move || {
            if let Err(panic) = std::panic::catch_unwind(std::panic::AssertUnwindSafe(work)) {
                let why = panic
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "a panic".into());
                fail(JobEvent::Failed(format!(
                    "{label} failed: {why} (an internal error of bvhscope; please report it)"
                )));
            }
        });
    }

    pub fn is_busy(&self) -> bool {
        self.load.is_some() || self.build.is_some() || self.render.is_some()
    }

    /// Events of current jobs (superseded ones are dropped); finished jobs are cleared.
    pub fn poll(&mut self) -> Vec<JobEvent> {
        let mut out = Vec::new();
        while let Ok((id, event)) = self.rx.try_recv() {
            let current = |slot: &Option<Running>| slot.as_ref().is_some_and(|r| r.id == id);
            if let JobEvent::Failed(_) = &event {
                // Whichever job it was is over.
                for slot in [
                    &mut self.load,
                    &mut self.build,
                    &mut self.render,
                    &mut self.explain,
                    &mut self.visits,
                    &mut self.compare,
                    &mut self.import,
                    &mut self.wrong,
                    &mut self.speedup,
                    &mut self.film,
                    &mut self.grade,
                ] {
                    if slot.as_ref().is_some_and(|r| r.id == id) {
                        *slot = None;
                    }
                }
                if self.inspect.as_ref().is_some_and(|(r, _)| r.id == id) {
                    self.inspect = None;
                }
                out.push(event);
                continue;
            }
            match &event {
                JobEvent::Loaded(_) if current(&self.load) => self.load = None,
                JobEvent::Built { .. } | JobEvent::NotBuilt if current(&self.build) => self.build = None,
                JobEvent::Pass(p) if current(&self.render) => {
                    // The normal and depth views' whole image is followed by its counts.
                    if p.info.counts_follow {
                        if let Some(r) = self.render.as_mut() {
                            r.label = "Counting the rays' work".to_string();
                        }
                    } else if p.info.stride == 1 {
                        self.render = None;
                    }
                }
                JobEvent::Picked { .. } => self.picking = None,
                JobEvent::GpuProbed(_) => {}
                JobEvent::GpuFailed(_) => self.render = None,
                JobEvent::Explained(_) if current(&self.explain) => self.explain = None,
                JobEvent::Compared(_) if current(&self.compare) => self.compare = None,
                JobEvent::Visits(_) if current(&self.visits) => self.visits = None,
                JobEvent::Imported(_) if current(&self.import) => self.import = None,
                JobEvent::Wrong(_) if current(&self.wrong) => self.wrong = None,
                JobEvent::Speedup(_) if current(&self.speedup) => self.speedup = None,
                JobEvent::Filmed(_) if current(&self.film) => self.film = None,
                JobEvent::GradeReport(_) if current(&self.grade) => self.grade = None,
                JobEvent::Inspected { .. } if self.inspect.as_ref().is_some_and(|(r, _)| r.id == id) => {
                    self.inspect = None
                }
                _ => continue,
            }
            out.push(event);
        }
        out
    }
}
