//! What the app's UI tests share: the app in a harness, stepping it until its background work is
//! done, files to open. Each test binary uses some of it.
#![allow(dead_code)]

use bvhscope::app::{AppOptions, BvhscopeApp};
use egui_kittest::Harness;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Where the UI tests write their files (removed when the test process exits).
#[path = "../../core/tests/common/scratch.rs"]
pub mod scratch;

/// Make this test process end, when the test harness exits, with the harness's own exit status
/// but without the C libraries' teardown. Twice a UI test binary whose every test had passed
/// aborted in that teardown ("malloc_consolidate(): unaligned fastbin chunk detected" in
/// November, "double free or corruption (fasttop)" in December, one run in a few each), which
/// stops `cargo test` before the binaries after it: a heap fault that safe Rust cannot make, in
/// the exit of the libraries wgpu loads for the snapshots (Mesa's software Vulkan and the LLVM in
/// it). Exit handlers run last registered first, and a library loaded later registers its own,
/// so this registers again on every call (`run_until` calls it after the app's harness, and its
/// devices, exist): a few hundred small entries a process. The scratch folder is removed first.
pub fn end_without_teardown() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        extern "C" {
            // glibc's on_exit(3): like atexit, and the handler is given the exit status.
            fn on_exit(f: extern "C" fn(libc::c_int, *mut libc::c_void), arg: *mut libc::c_void) -> libc::c_int;
        }
        extern "C" fn end(status: libc::c_int, _: *mut libc::c_void) {
            use std::io::Write;
            let _ = std::io::stdout().flush();
            let _ = std::io::stderr().flush();
            scratch::remove_unless_kept();
            // SAFETY: _exit(2) ends the process at once with the status exit(3) was given.
            unsafe { libc::_exit(status) }
        }
        // SAFETY: the handler has the signature on_exit(3) expects and ignores its argument.
        unsafe {
            on_exit(end, std::ptr::null_mut());
        }
    }
}

pub fn harness() -> Harness<'static, BvhscopeApp> {
    Harness::builder()
        .with_size(egui::vec2(1400.0, 860.0))
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()))
}

/// Step the app until `done` holds (background jobs report asynchronously).
pub fn run_until(h: &mut Harness<'_, BvhscopeApp>, what: &str, done: impl Fn(&BvhscopeApp) -> bool) {
    end_without_teardown();
    let start = Instant::now();
    let mut told = Instant::now();
    while !done(h.state()) {
        if told.elapsed() > Duration::from_secs(30) {
            told = Instant::now();
            eprintln!("still waiting for {what}: {}", state_line(h.state()));
        }
        // A guard against a hang, not a timing: CI's 2 cores under a parallel test run took over
        // two minutes for an import's check (debug build) when the app was not stuck.
        assert!(start.elapsed() < Duration::from_secs(600), "timed out waiting for {what}");
        h.step();
        std::thread::sleep(Duration::from_millis(5));
    }
    h.step();
    h.step();
    assert_legend_apart(h);
}

/// The heatmap legend (its title, its histogram) never over the image: checked each time a test
/// has waited for something, so in every layout the tests open (issue 59: floating over the image
/// it hid half of it when presenting).
pub fn assert_legend_apart(h: &Harness<'_, BvhscopeApp>) {
    use egui_kittest::kittest::Queryable;
    let image = h.state().image_rect;
    let legend = h.query_all_by_label_contains("Legend: ").chain(h.query_all_by_label("Histogram of the heatmap"));
    for node in legend {
        let r = node.rect();
        let both = r.intersect(image);
        assert!(
            both.width() <= 0.5 || both.height() <= 0.5,
            "the legend's part at {r:?} overlaps the image at {image:?}"
        );
    }
}

/// What a long wait is waiting on: the jobs running, the image's size, the frames' cameras.
fn state_line(a: &BvhscopeApp) -> String {
    let j = &a.jobs;
    let running = [
        ("load", j.load.is_some()),
        ("build", j.build.is_some()),
        ("render", j.render.is_some()),
        ("compare", j.compare.is_some()),
        ("import", j.import.is_some()),
        ("wrong", j.wrong.is_some()),
    ];
    let running: Vec<&str> = running.iter().filter(|r| r.1).map(|r| r.0).collect();
    let shown = a.shown.as_ref().map(|s| (s.camera.width, s.camera.height, s.frame.is_complete()));
    let b = a.compare.b.as_ref().map(|b| (b.camera.width, b.camera.height));
    format!(
        "jobs {running:?}, viewport {:?}, shown {shown:?}, B {b:?}, pending {}",
        a.viewport_pixels(),
        a.grade.pending.is_some()
    )
}

pub fn idle(app: &BvhscopeApp) -> bool {
    app.current_bvh().is_some() && !app.jobs.is_busy() && app.shown.as_ref().is_some_and(|s| s.frame.is_complete())
}

/// Click the widget labelled `label` wherever its tile has scrolled it (a view's tile scrolls, and
/// a simulated pointer lands where the widget is drawn): by the accessibility action, as a screen
/// reader clicks.
pub fn click_label(h: &mut Harness<'_, BvhscopeApp>, label: &str) {
    use egui_kittest::kittest::Queryable;
    h.get_by_label(label).click_accesskit();
    h.run_steps(2);
}

/// `click_label` for the widget whose label contains `part`.
pub fn click_label_containing(h: &mut Harness<'_, BvhscopeApp>, part: &str) {
    use egui_kittest::kittest::Queryable;
    h.get_by_label_contains(part).click_accesskit();
    h.run_steps(2);
}

/// Give the text field labelled `label` the keyboard, wherever its tile has scrolled it.
pub fn focus_label(h: &mut Harness<'_, BvhscopeApp>, label: &str) {
    use egui_kittest::kittest::Queryable;
    h.get_by_label(label).focus();
    h.run_steps(2);
}

/// Compare's pair on screen: B traced on A's camera, both frames complete, nothing running.
pub fn pair_shown(a: &BvhscopeApp) -> bool {
    idle(a) && a.compare.b.as_ref().is_some_and(|b| a.shown.as_ref().is_some_and(|s| s.camera == b.camera))
}

pub fn temp_file(name: &str, text: &str) -> PathBuf {
    let p = scratch::shared("ui").join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[derive(Debug)]
pub struct Dropped(pub PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &Path {
        &self.0
    }
    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

/// Type `text` key by key, as a person would (each character its key and its text).
pub fn type_keys(h: &mut Harness<'_, BvhscopeApp>, text: &str) {
    for c in text.chars() {
        let key = egui::Key::from_name(&c.to_uppercase().to_string());
        if let Some(key) = key {
            h.key_down(key);
        }
        h.event(egui::Event::Text(c.to_string()));
        if let Some(key) = key {
            h.key_up(key);
        }
        h.step();
    }
}

pub fn words(args: &[String]) -> bvhscope::cli::Command {
    let mut all = vec!["bvhscope".to_string()];
    all.extend(args.iter().cloned());
    bvhscope::cli::Cli::from_words(&all).unwrap().command.unwrap()
}

pub fn s(x: impl ToString) -> String {
    x.to_string()
}

/// `--camera … --fov … --size …`: the camera of the image on screen, for the command line.
pub fn camera_words(c: &bvhscope::render::Camera) -> Vec<String> {
    let v3 = |v: glam::Vec3| format!("{},{},{}", v.x, v.y, v.z);
    vec![
        s("--camera"),
        format!("{}:{}:{}", v3(c.position), v3(c.look_at), v3(c.up)),
        s("--fov"),
        s(c.vfov_deg),
        s("--size"),
        format!("{}x{}", c.width, c.height),
    ]
}

/// The checkout (scenes/, assets/).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Open `file` as File ▸ Open does, once the first frame is done, and wait for its frame.
pub fn open(h: &mut Harness<'_, BvhscopeApp>, file: &Path) {
    run_until(h, "the first frame", idle);
    h.state_mut().act(bvhscope::app::Action::Picked(bvhscope::app::Pick::Open, file.to_path_buf()));
    let f = file.to_path_buf();
    run_until(h, "the file", move |a| a.scene.source == bvhscope::app::SceneSource::File(f.clone()) && idle(a));
}

/// Switch the build panel's strategy to `s`.
pub fn with_strategy(h: &mut Harness<'_, BvhscopeApp>, s: bvhscope::bvh::Strategy) {
    let mut settings = h.state().settings.clone();
    settings.build.strategy = s;
    h.state_mut().act(bvhscope::app::Action::Edit(Box::new(settings)));
}

/// Midpoint's tree on screen as a heatmap (with its legend), nothing running.
pub fn midpoint_heatmap_shown(a: &BvhscopeApp) -> bool {
    idle(a)
        && a.shown.as_ref().is_some_and(|s| {
            s.legend.is_some() && s.bvh.build_params().bvh.strategy == bvhscope::bvh::Strategy::Midpoint
        })
}

/// The built-in scene's midpoint tree (A) against SAH binned (B), side by side on the nodes-visited
/// heatmap, both frames there.
pub fn midpoint_against_sah() -> Harness<'static, BvhscopeApp> {
    use bvhscope::app::Action;
    use bvhscope::bvh::Strategy;
    use egui_kittest::kittest::Queryable;
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    let mut s = h.state().settings.clone();
    s.build.strategy = Strategy::Midpoint;
    h.state_mut().act(Action::Edit(Box::new(s)));
    h.state_mut().act(Action::View(2));
    run_until(&mut h, "midpoint's heatmap", midpoint_heatmap_shown);
    h.get_by_role_and_label(egui::accesskit::Role::Button, "View").click();
    h.run_steps(2);
    h.get_by_label("Compare side by side…").click();
    run_until(&mut h, "B", pair_shown);
    h
}

/// Pin the ray of the frame's first hit pixel on its middle row (as a click on the image does);
/// its pixel.
pub fn pin_first_hit(h: &mut Harness<'_, BvhscopeApp>) -> (u32, u32) {
    let (x, y) = {
        let f = &h.state().shown.as_ref().unwrap().frame;
        let y = f.height() / 2;
        (0..f.width()).map(|x| (x, y)).find(|&(x, y)| f.sample(x, y).is_hit()).expect("the mesh is in view")
    };
    h.state_mut().act(bvhscope::app::Action::PinPixel(x, y));
    h.run_steps(2);
    (x, y)
}
