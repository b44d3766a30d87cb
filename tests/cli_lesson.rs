//! `bvhscope lesson`: the shipped lessons check clean and render to a handout whose pictures are
//! `render`'s own, byte for byte, for each step's words; broken lessons are named by step and
//! field; the handout's folder replaces only what a handout wrote.

mod cli_support;
mod common;

use bvhscope::lesson::{caption_html, explain_words, folded, read_lesson, render_words};
use cli_support::{bvhscope, tmp};
use std::path::{Path, PathBuf};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn shipped(name: &str) -> PathBuf {
    Path::new(ROOT).join("lessons").join(name)
}

fn fresh(name: &str) -> PathBuf {
    let d = tmp(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn text(o: &std::process::Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// The lessons `lessons/` ships: the knot always, the lab when the shared meshes are there.
fn lessons() -> Vec<PathBuf> {
    let mut out = vec![shipped("why-sah-wins.json")];
    if common::shared_models().is_some() {
        out.push(shipped("course-lab.json"));
    }
    out
}

#[test]
fn the_shipped_lessons_check_clean() {
    for l in lessons() {
        let o = bvhscope(&["lesson", l.to_str().unwrap(), "--check"]);
        assert!(o.status.success(), "{}: {}", l.display(), text(&o));
        assert!(String::from_utf8_lossy(&o.stdout).contains("no problems"), "{}", text(&o));
    }
}

/// Each step's picture in the handout is what `render` writes for that step's words, run as a
/// user runs it; the page holds every caption and the command under each picture.
#[test]
fn each_handout_picture_is_renders_own_output_byte_for_byte() {
    for l in lessons() {
        let stem = l.file_stem().unwrap().to_string_lossy().into_owned();
        let dir = fresh(&format!("handout-{stem}"));
        let o = bvhscope(&["lesson", l.to_str().unwrap(), "-o", dir.to_str().unwrap()]);
        assert!(o.status.success(), "{}", text(&o));
        let lesson = read_lesson(&l).unwrap();
        let page = std::fs::read_to_string(dir.join("index.html")).unwrap();
        assert!(page.contains(&format!("<h1>{}</h1>", caption_html(&lesson.title))), "{stem}");
        for (i, state) in lesson.states().iter().enumerate() {
            let png = dir.join(format!("steps/step-{:02}.png", i + 1));
            let mine = tmp(&format!("{stem}-render-{i}.png"));
            let words = render_words(state, &folded(&state.scene), &mine);
            let r = bvhscope(&words.iter().map(String::as_str).collect::<Vec<_>>());
            assert!(r.status.success(), "step {}: {words:?}: {}", i + 1, text(&r));
            let (a, b) = (std::fs::read(&png).unwrap(), std::fs::read(&mine).unwrap());
            assert!(a == b, "{stem} step {}: the handout's picture is not render's ({words:?})", i + 1);
            // The explain view's twin is a command that runs: trace and inspect here, replay
            // (a minute of frames) parsed.
            if let Some(mut twin) = explain_words(state, &folded(&state.scene)) {
                if twin[0] == "replay" {
                    let words = std::iter::once("bvhscope".to_string()).chain(twin.iter().cloned());
                    assert!(bvhscope::cli::Cli::from_words(words).is_ok(), "{twin:?}");
                } else {
                    twin.push("--max-steps".into());
                    twin.push("10".into());
                    if twin[0] == "inspect" {
                        twin.truncate(twin.len() - 2);
                    }
                    let r = bvhscope(&twin.iter().map(String::as_str).collect::<Vec<_>>());
                    assert!(r.status.success(), "step {}: {twin:?}: {}", i + 1, text(&r));
                }
            }
            let caption = format!("<p class=\"caption\">{}</p>", caption_html(&lesson.steps[i].caption));
            assert!(page.contains(&caption), "{stem} step {}: {caption}", i + 1);
            let command = format!("-o step-{:02}.png</code>", i + 1);
            assert!(page.contains(&command), "{stem} step {}: the command under the picture", i + 1);
        }
        assert_eq!(page.matches("data:image/png;base64,").count(), lesson.steps.len(), "every picture inline");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// One broken lesson per kind of target: each problem on its own line naming the step and field;
/// exit 1. An unreadable lesson: exit 2, one line.
#[test]
fn a_broken_lesson_is_named_by_step_and_field() {
    let dir = fresh("broken-lesson");
    std::fs::create_dir_all(&dir).unwrap();
    let torus = Path::new(ROOT).join("assets/torus.obj");
    let l = dir.join("broken.json");
    let lesson = format!(
        r#"{{ "steps": [
          {{ "caption": "a", "scene": "{t}", "bvh": {{ "strategy": "sah", "layout": "binary" }},
             "camera": {{ "position": [0, 1, 4], "look_at": [0, 0, 0], "size": [64, 48] }} }},
          {{ "caption": "b", "show": {{ "node": 100000 }} }},
          {{ "caption": "c", "show": {{ "ray": {{ "pixel": [32, 24], "step": 100000 }} }} }},
          {{ "caption": "d", "show": {{ "replay": {{ "splits": 100000 }} }} }},
          {{ "caption": "e", "show": {{ "tree": 3 }} }},
          {{ "caption": "f", "scene": "nowhere.obj" }} ] }}"#,
        t = torus.display()
    );
    std::fs::write(&l, lesson).unwrap();
    let o = bvhscope(&["lesson", l.to_str().unwrap(), "--check"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    let lines: Vec<&str> = out.lines().collect();
    let want = [
        "steps[1].show.node: node 100000 is past the tree's last",
        "steps[2].show.ray.step: step 100000, past the end of the ray's walk of",
        "steps[3].show.replay.splits: 100000 splits, more than the build's",
        "steps[5].scene:",
    ];
    assert_eq!(lines.len(), want.len(), "{out}");
    for (line, w) in lines.iter().zip(want) {
        assert!(line.starts_with(&format!("{}: ", l.display())) && line.contains(w), "{line}\nwanted {w}");
    }
    assert!(lines[3].contains("nowhere.obj"), "{}", lines[3]);
    // Unreadable: one line, exit 2.
    std::fs::write(&l, r#"{ "steps": [ { "caption": "a", "scene": "x.obj", "view": "heat" } ] }"#).unwrap();
    let o = bvhscope(&["lesson", l.to_str().unwrap(), "--check"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("steps[0].view: expected one of normals") && err.lines().count() == 1, "{err}");
    // Neither -o nor --check: says what to name.
    let o = bvhscope(&["lesson", l.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("-o DIR"));
}

/// The handout's folder: written again over an earlier handout; a folder holding someone's own
/// file is refused, naming it, and the file kept.
#[test]
fn a_handout_replaces_only_what_a_handout_wrote() {
    let torus = Path::new(ROOT).join("assets/torus.obj");
    let dir = fresh("lesson-folder");
    std::fs::create_dir_all(&dir).unwrap();
    let l = dir.join("small.json");
    std::fs::write(
        &l,
        format!(
            r#"{{ "title": "Small", "steps": [
              {{ "caption": "The *torus*", "scene": "{}", "camera": {{ "position": [0, 2, 4], "look_at": [0, 0, 0], "size": [48, 32] }} }},
              {{ "caption": "Its `visits`", "view": "visits", "question": "Where is it hot?", "answer": "At the rim." }} ] }}"#,
            torus.display()
        ),
    )
    .unwrap();
    let out = dir.join("handout");
    for _ in 0..2 {
        let o = bvhscope(&["lesson", l.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        assert!(o.status.success(), "{}", text(&o));
    }
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(page.contains("The <em>torus</em>") && page.contains("Its <code>visits</code>"), "{page}");
    assert!(page.contains("<details><summary>Answer</summary><p>At the rim.</p></details>"));
    assert!(page.contains("bvhscope render ") && page.contains("--view visits"), "{page}");
    let mine = out.join("steps/notes.txt");
    std::fs::write(&mine, "mine").unwrap();
    let o = bvhscope(&["lesson", l.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(String::from_utf8_lossy(&o.stderr).contains("steps/notes.txt"), "{}", text(&o));
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "mine", "kept");
    // A folder of someone's own, holding an index.html and no list: refused, kept.
    let site = dir.join("site");
    std::fs::create_dir_all(&site).unwrap();
    std::fs::write(site.join("index.html"), "<p>my page</p>").unwrap();
    let o = bvhscope(&["lesson", l.to_str().unwrap(), "-o", site.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("holds index.html but no handout-files.txt") && err.contains("named alike"), "{err}");
    assert_eq!(std::fs::read_to_string(site.join("index.html")).unwrap(), "<p>my page</p>");
    let _ = std::fs::remove_dir_all(&dir);
}
