//! The real app's clipboard, under Xvfb: a Ctrl+click pins a ray, Ctrl+Shift+C copies its
//! `bvhscope trace` command, and the X clipboard gives that command back (eframe is built with its
//! `clipboard` feature; without it the copy did nothing). Needs Xvfb and xdotool (`.ci/run`
//! installs them); without them the test says so and passes, except under `CI=true`.
#![cfg(feature = "gui")]

#[path = "../core/tests/common/scratch.rs"]
mod scratch;

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn has(tool: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Kills the process when dropped (a failed assertion must not leave Xvfb or the app running).
struct Killed(Child);
impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn xdotool(display: &str, args: &[&str]) -> String {
    let out = Command::new("xdotool").args(args).env("DISPLAY", display).output().expect("xdotool runs");
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

/// Start Xvfb on a free display (it writes the number it took to the pipe given by -displayfd).
fn xvfb() -> (Killed, String) {
    use std::io::Read;
    let mut child = Command::new("Xvfb")
        .args(["-displayfd", "1", "-screen", "0", "1600x1000x24", "-nolisten", "tcp"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("Xvfb starts");
    let mut out = child.stdout.take().unwrap();
    let mut number = String::new();
    let mut byte = [0u8; 1];
    while out.read(&mut byte).is_ok_and(|n| n == 1) && byte[0] != b'\n' {
        number.push(byte[0] as char);
    }
    assert!(!number.is_empty(), "Xvfb said which display it took");
    (Killed(child), format!(":{}", number.trim()))
}

#[test]
fn copy_trace_command_puts_the_command_on_the_x_clipboard() {
    if !(has("Xvfb") && has("xdotool")) {
        assert!(std::env::var("CI").as_deref() != Ok("true"), "CI=true needs Xvfb and xdotool (.ci/run installs them)");
        eprintln!("skipped: the clipboard test needs Xvfb and xdotool");
        return;
    }
    let (_xvfb, display) = xvfb();
    let torus = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/torus.obj");
    let home = scratch::shared("clipboard");
    let (data, runtime) = (home.join("data"), home.join("runtime"));
    std::fs::create_dir_all(&data).unwrap();
    std::fs::create_dir_all(&runtime).unwrap();
    let _app = Killed(
        Command::new(env!("CARGO_BIN_EXE_bvhscope"))
            .arg(&torus)
            .env("DISPLAY", &display)
            .env("XDG_DATA_HOME", &data)
            .env("XDG_RUNTIME_DIR", &runtime)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("the app starts"),
    );
    let window = xdotool(&display, &["search", "--sync", "--name", "bvhscope"]);
    let window = window.lines().next().expect("the app's window").to_string();
    // std's environment is the process's: the clipboard below reads this display.
    std::env::set_var("DISPLAY", &display);
    let mut clipboard = arboard::Clipboard::new().expect("a clipboard on the Xvfb display");
    let start = Instant::now();
    let mut copied = String::new();
    // Until the mesh is loaded and shown a click pins nothing: try again until it does.
    while !copied.starts_with("bvhscope trace") {
        assert!(start.elapsed() < Duration::from_secs(300), "no trace command on the clipboard (last: {copied:?})");
        std::thread::sleep(Duration::from_secs(2));
        let _ = xdotool(&display, &["windowfocus", "--sync", &window]);
        // The middle of the image (the window is 1400×860, the image between the two side panels).
        let _ = xdotool(&display, &["mousemove", "--window", &window, "700", "430"]);
        for step in [&["keydown", "ctrl"][..], &["mousedown", "1"], &["mouseup", "1"], &["keyup", "ctrl"]] {
            std::thread::sleep(Duration::from_millis(200));
            let _ = xdotool(&display, step);
        }
        std::thread::sleep(Duration::from_millis(500));
        let _ = xdotool(&display, &["key", "ctrl+shift+c"]);
        std::thread::sleep(Duration::from_millis(500));
        copied = clipboard.get_text().unwrap_or_default();
    }
    assert!(copied.contains("torus.obj") && copied.contains("--ray "), "{copied}");
    // What was copied is a command the CLI accepts.
    let words = shell_words(&copied);
    assert!(bvhscope::cli::Cli::from_words(&words).is_ok(), "{copied}");
}

/// The copied command's words (it quotes a path with spaces in single quotes).
fn shell_words(s: &str) -> Vec<String> {
    let (mut words, mut word, mut quoted) = (Vec::new(), String::new(), false);
    for c in s.chars() {
        match c {
            '\'' => quoted = !quoted,
            ' ' if !quoted => {
                if !word.is_empty() {
                    words.push(std::mem::take(&mut word));
                }
            }
            c => word.push(c),
        }
    }
    words.push(word);
    words
}
