use super::*;
use std::path::Path;

const LAB: &str = r#"{
  "title": "Why SAH wins",
  "steps": [
    { "caption": "Midpoint's boxes at depth 3", "scene": "../scenes/knot-on-floor.json",
      "bvh": { "strategy": "midpoint", "max_leaf_size": 2 }, "view": "normals", "boxes": 3 },
    { "caption": "What each ray costs", "view": "visits", "range": [0, 30], "boxes": "off",
      "show": { "ray": { "pixel": [640, 300], "step": 12 } },
      "question": "Why is the floor hot?", "answer": "Its two triangles sit deep in the tree." },
    { "caption": "SAH beside it", "show": { "compare": { "bvh": { "strategy": "sah" }, "mode": "difference" } },
      "rays": { "kind": "ao", "samples": 4, "seed": 7 } },
    { "caption": "The root's cost curve", "bvh": { "layout": "wide4" }, "show": { "node": 0 }, "colormap": "turbo",
      "order": "split-axis", "test": "moller-trumbore",
      "camera": { "position": [0, 6, 11], "look_at": [0, 1, 0], "size": [800, 600] } },
    { "caption": "The build, split by split", "scene": "../scenes/monkey.json", "show": { "replay": { "splits": 40 } }, "range": "auto" }
  ]
}"#;

fn lab() -> Lesson {
    parse_lesson(Path::new("lessons/lab.json"), LAB).unwrap()
}

#[test]
fn a_step_changes_only_what_it_names_and_the_rest_carries_over() {
    let states = lab().states();
    assert_eq!(states.len(), 5);
    let s = &states[1];
    assert_eq!(s.scene, Path::new("lessons/../scenes/knot-on-floor.json"));
    let build = s.build_params(None);
    assert_eq!((build.strategy, build.max_leaf_size), (Strategy::Midpoint, 2), "from step 0");
    assert_eq!(s.view, View::Visits);
    assert_eq!(s.range, HeatRange::Fixed { min: 0.0, max: 30.0 });
    assert_eq!(s.boxes, None);
    assert_eq!(states[0].boxes, Some(3));
    assert_eq!(s.show, Show::Ray { pixel: (640, 300), step: Some(12) });
    let s = &states[2];
    assert_eq!(s.rays.kind, RayKind::Ao);
    assert_eq!((s.rays.samples, s.rays.seed), (4, 7));
    assert_eq!(s.range, HeatRange::Fixed { min: 0.0, max: 30.0 }, "kept");
    let Show::Compare { b, mode } = &s.show else { panic!("{:?}", s.show) };
    assert_eq!(*mode, PairView::Difference);
    assert_eq!(b.apply(&s.build_params(None)).strategy, Strategy::SahBinned);
    assert_eq!(b.apply(&s.build_params(None)).max_leaf_size, 2, "B is A with its strategy changed");
    let s = &states[3];
    let build = s.build_params(None);
    assert_eq!((build.strategy, build.layout), (Strategy::Midpoint, Layout::Wide4));
    // Options a step leaves unnamed are the scene's own, as `render` takes them.
    let scene = BuildParams { strategy: Strategy::EqualCount, max_leaf_size: 8, sah_bins: 7, ..Default::default() };
    let over = s.build_params(Some(&scene));
    assert_eq!((over.strategy, over.max_leaf_size, over.sah_bins), (Strategy::Midpoint, 2, 7));
    assert_eq!((s.trace.order, s.trace.test), (TraversalOrder::SplitAxisSign, TriangleTest::MollerTrumbore));
    assert_eq!(s.camera.map(|c| (c.width, c.height)), Some((800, 600)));
    assert_eq!(s.rays.kind, RayKind::Ao, "kept");
    // Another scene: its own camera, the image alone until the step names a view.
    let s = &states[4];
    assert_eq!(s.camera, None);
    assert_eq!(s.show, Show::Replay { splits: 40 });
    assert_eq!(s.range, HeatRange::Auto);
    assert_eq!(s.colormap, ColorMap::Turbo);
}

#[test]
fn a_written_lesson_reads_back_as_the_same_steps() {
    let lesson = lab();
    let path = Path::new("lessons/lab.json");
    let text = write_lesson(&lesson, path);
    let again = parse_lesson(path, &text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(again.states(), lesson.states(), "{text}");
    let without_scenes = |l: &Lesson| l.steps.iter().map(|s| Step { scene: None, ..s.clone() }).collect::<Vec<_>>();
    assert_eq!(without_scenes(&again), without_scenes(&lesson), "captions, questions, edits, views");
    assert!(text.contains("\"scene\": \"../scenes/knot-on-floor.json\""), "{text}");
    // Elsewhere: the same states from the same scene files.
    let moved = Path::new("/tmp/elsewhere/lab.json");
    let text = write_lesson(&lesson, moved);
    let again = parse_lesson(moved, &text).unwrap();
    let scene = |l: &Lesson| write::normal(l.steps[0].scene.as_deref().unwrap());
    assert_eq!(scene(&again), scene(&lesson), "the same file, named by its absolute path");
    assert!(again.steps[0].scene.as_ref().unwrap().is_absolute());
}

/// Each broken lesson's one-line error names the file, the step and the field.
#[test]
fn a_broken_lesson_names_the_step_and_the_field() {
    let step0 = r#"{ "caption": "a", "scene": "x.obj" }"#;
    let cases: &[(String, &str)] = &[
        (r#"{ "steps": [] }"#.into(), "steps: a lesson needs at least one step"),
        (r#"{ "steps": [ { "caption": "a" } ] }"#.into(), "steps[0].scene: missing"),
        (format!(r#"{{ "steps": [ {step0}, {{ "scene": "y.obj" }} ] }}"#), "steps[1].caption: missing"),
        (
            format!(r#"{{ "steps": [ {step0}, {{ "caption": "b", "bvh": {{ "strategy": "best" }} }} ] }}"#),
            "steps[1].bvh.strategy: expected one of midpoint",
        ),
        (
            format!(r#"{{ "steps": [ {step0}, {{ "caption": "b", "bvh": {{ "max_leaf_size": 0 }} }} ] }}"#),
            "steps[1].bvh.max_leaf_size: expected a whole number",
        ),
        (
            format!(r#"{{ "steps": [ {step0}, {{ "caption": "b", "view": "heat" }} ] }}"#),
            "steps[1].view: expected one of normals",
        ),
        (
            format!(r#"{{ "steps": [ {step0}, {{ "caption": "b", "range": [3, 1] }} ] }}"#),
            "steps[1].range: min 3 is not below max 1",
        ),
        (
            format!(r#"{{ "steps": [ {step0}, {{ "caption": "b", "boxes": -1 }} ] }}"#),
            "steps[1].boxes: expected a depth",
        ),
        (
            format!(r#"{{ "steps": [ {step0}, {{ "caption": "b", "show": {{ "ray": {{ "pixel": [1] }} }} }} ] }}"#),
            "steps[1].show.ray.pixel: expected [x, y]",
        ),
        (
            format!(r#"{{ "steps": [ {step0}, {{ "caption": "b", "show": {{ "node": 1, "tree": 2 }} }} ] }}"#),
            "steps[1].show: expected one of ray",
        ),
        (
            format!(r#"{{ "steps": [ {step0}, {{ "caption": "b", "show": "nothing" }} ] }}"#),
            "steps[1].show: expected \"image\"",
        ),
        (
            format!(r#"{{ "steps": [ {step0}, {{ "caption": "b", "rays": {{ "kind": "ao", "samples": 0 }} }} ] }}"#),
            "steps[1].rays.samples: expected a whole number from 1 to 256",
        ),
        (
            format!(r#"{{ "steps": [ {step0}, {{ "caption": "b", "answer": "4" }} ] }}"#),
            "steps[1].answer: an answer needs its question",
        ),
        (
            format!(r#"{{ "steps": [ {step0}, {{ "caption": "b", "colour": "red" }} ] }}"#),
            "steps[1].colour: unknown field",
        ),
        (
            format!(
                r#"{{ "steps": [ {step0}, {{ "caption": "b", "camera": {{ "position": [0,0,1], "look_at": [0,0,0], "size": [64, 48] }}, "show": {{ "ray": {{ "pixel": [64, 0] }} }} }} ] }}"#
            ),
            "steps[1].show.ray.pixel: (64, 0) is outside the step's 64×48 image",
        ),
        (r#"{ "steps": [ { "caption": "a", "scene": "x.obj", "caption": "b" } ] }"#.into(), "line 1"),
    ];
    for (text, want) in cases {
        let e = parse_lesson(Path::new("l.json"), text).expect_err(text).to_string();
        assert!(e.starts_with("l.json: ") && e.contains(want), "{text}\n→ {e}\nwanted {want}");
        assert!(!e.contains('\n'), "one line: {e}");
    }
}

#[test]
fn a_huge_or_binary_lesson_file_is_refused_before_it_is_parsed() {
    let dir = crate::scratch::shared("lesson");
    let big = dir.join("big.json");
    std::fs::write(&big, vec![b' '; (read::MAX_LESSON_BYTES + 1) as usize]).unwrap();
    let e = read_lesson(&big).unwrap_err().to_string();
    assert!(e.contains("more than the 4 MB"), "{e}");
    let binary = dir.join("bin.json");
    std::fs::write(&binary, [0xff, 0xfe, b'{']).unwrap();
    assert!(read_lesson(&binary).unwrap_err().to_string().contains("not UTF-8"));
    assert!(read_lesson(&dir).unwrap_err().to_string().contains("directory"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The lesson reader's fuzzer: the shipped lessons mutated (bytes flipped, cut short, spans
/// doubled or dropped, hostile values put in) never panic; a lesson read back has states and
/// writes back to text that reads again; a refusal is one line naming the file.
#[test]
fn mutated_lessons_never_panic_and_refusals_are_one_line() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../lessons");
    let seeds: Vec<String> = ["why-sah-wins.json", "course-lab.json"]
        .iter()
        .map(|n| std::fs::read_to_string(root.join(n)).unwrap())
        .chain([LAB.to_string()])
        .collect();
    let hostile: [&[u8]; 10] = [
        b"1e400",
        b"-1",
        b"18446744073709551616",
        b"\"\\u0000\"",
        b"[[[[[[[[",
        b"null",
        b"\"../../../../etc/passwd\"",
        b"{\"ray\":{\"pixel\":[4294967295,0],\"step\":4294967295}}",
        b"\"\\u202e\"",
        b"NaN",
    ];
    let path = Path::new("fuzz/l.json");
    let mut rng = crate::random::Rng::new(0x001E_550F);
    let (mut read, mut refused) = (0, 0);
    for case in 0..3000u32 {
        let mut b = seeds[case as usize % seeds.len()].clone().into_bytes();
        for _ in 0..1 + rng.next_u64() % 4 {
            let at = (rng.next_u64() as usize) % b.len().max(1);
            match rng.next_u64() % 5 {
                0 => b[at] = rng.next_u64() as u8,
                1 => b.truncate(at),
                2 => {
                    let end = (at + 1 + (rng.next_u64() as usize % 64)).min(b.len());
                    let span = b[at..end].to_vec();
                    b.splice(at..at, span);
                }
                3 => {
                    let end = (at + 1 + (rng.next_u64() as usize % 64)).min(b.len());
                    b.drain(at..end);
                }
                _ => {
                    let h = hostile[rng.next_u64() as usize % hostile.len()];
                    let end = (at + (rng.next_u64() as usize % 12)).min(b.len());
                    b.splice(at..end, h.iter().copied());
                }
            }
        }
        let Ok(text) = String::from_utf8(b) else { continue };
        match parse_lesson(path, &text) {
            Ok(l) => {
                read += 1;
                assert_eq!(l.states().len(), l.steps.len());
                let again = write_lesson(&l, path);
                let back = parse_lesson(path, &again).unwrap_or_else(|e| panic!("case {case}: {e}\n{again}"));
                assert_eq!(back.steps.len(), l.steps.len(), "case {case}");
            }
            Err(e) => {
                refused += 1;
                let e = e.to_string();
                assert!(e.starts_with("fuzz/l.json: ") && !e.contains('\n'), "case {case}: {e}");
            }
        }
    }
    assert!(read > 100 && refused > 1000, "{read} read, {refused} refused: the mutations reach both sides");
}
