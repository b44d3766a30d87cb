//! The command line's explaining commands as a user runs them: `trace` (a ray's steps, and its
//! counts against `render --counts`), `inspect` (a node's curves), `render --against` (two builds'
//! difference) and `replay` (a build step by step).

mod cli_support;

use cli_support::{bvhscope, render_small_visits, tent, tmp};
use std::path::PathBuf;

/// `trace` and `render --counts` tell the same story for the same pixel: the counts file's row is
/// the trace's totals and hit, pixel for pixel over a whole small image, in both layouts.
#[test]
fn trace_and_the_counts_file_agree_for_every_pixel() {
    let mesh = tent();
    let (w, h) = (24, 16);
    for layout in ["binary", "wide4"] {
        let csv = tmp(&format!("counts-{layout}.csv"));
        let png = tmp(&format!("counts-{layout}.png"));
        let size = format!("{w}x{h}");
        let out = bvhscope(&[
            "render",
            mesh.to_str().unwrap(),
            "--view",
            "visits",
            "--size",
            &size,
            "--layout",
            layout,
            "--counts",
            csv.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let text = std::fs::read_to_string(&csv).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("x,y,nodes_visited,box_tests,leaves_visited,triangle_tests,hit_triangle"));
        let rows: Vec<Vec<i64>> = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
        assert_eq!(rows.len(), w * h);
        assert!(rows.iter().any(|r| r[6] >= 0) && rows.iter().any(|r| r[6] == -1), "hits and misses");
        // Every 7th pixel, traced alone, gives its row.
        for r in rows.iter().step_by(7) {
            let pixel = format!("{},{}", r[0], r[1]);
            let out = bvhscope(&[
                "trace",
                mesh.to_str().unwrap(),
                "--pixel",
                &pixel,
                "--size",
                &size,
                "--layout",
                layout,
                "--format",
                "json",
            ]);
            assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
            let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
            let c = &v["counts"];
            let got = [&c["nodes_visited"], &c["box_tests"], &c["leaves_visited"], &c["triangle_tests"]]
                .map(|x| x.as_i64().unwrap());
            assert_eq!(got[..], r[2..6], "pixel {pixel} ({layout})");
            let hit = v["hit"]["triangle"].as_i64().unwrap_or(-1);
            assert_eq!(hit, r[6], "pixel {pixel} ({layout})");
            assert_eq!(v["steps"].as_array().unwrap().iter().filter(|s| s["step"] == "enter").count() as i64, got[0]);
        }
    }
}

#[test]
fn trace_prints_the_steps_and_refuses_a_pixel_outside_the_image() {
    let mesh = tent();
    let out = bvhscope(&["trace", mesh.to_str().unwrap(), "--ray", "0,0.5,5:0,0,-1", "--layout", "binary"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    for needle in
        ["box of node 0: hit", "enter node 0", "closest hit so far: triangle", "counts          nodes visited"]
    {
        assert!(text.contains(needle), "{needle}: {text}");
    }
    let out = bvhscope(&["trace", mesh.to_str().unwrap(), "--pixel", "40,3", "--size", "40x30"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("outside the 40x30 image"), "{err}");
}

/// `inspect` explains a node: in JSON the sweep SAH's marker is its curves' minimum, midpoint's
/// sits at the middle of the centroid bounds on their widest axis, and the figures are there; the
/// CSV parses with the documented columns; a node past the tree is refused in one line.
#[test]
fn inspect_prints_a_nodes_curves_and_each_strategys_plane() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let out = bvhscope(&["inspect", torus, "--node", "1", "--strategy", "midpoint", "--format", "json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["node"], 1);
    assert_eq!(v["path"], serde_json::json!([0, 1]));
    assert!(v["triangles"].as_u64().unwrap() > 100);
    let sweep_min = ["x", "y", "z"]
        .iter()
        .flat_map(|a| v["curves"][a]["sweep"].as_array().unwrap().iter().map(|p| p["cost"].as_f64().unwrap()))
        .fold(f64::INFINITY, f64::min);
    assert_eq!(v["markers"]["sah-sweep"]["cost"].as_f64().unwrap(), sweep_min);
    let (lo, hi) = (&v["centroid_bounds"]["min"], &v["centroid_bounds"]["max"]);
    let extent: Vec<f64> = (0..3).map(|k| hi[k].as_f64().unwrap() - lo[k].as_f64().unwrap()).collect();
    let widest = (0..3).max_by(|&a, &b| extent[a].total_cmp(&extent[b])).unwrap();
    let m = &v["markers"]["midpoint"];
    assert_eq!(m["axis"], ["x", "y", "z"][widest]);
    let middle = (lo[widest].as_f64().unwrap() as f32 + hi[widest].as_f64().unwrap() as f32) * 0.5;
    assert_eq!(m["position"].as_f64().unwrap() as f32, middle);
    assert_eq!(v["split_axis"], m["axis"], "the midpoint tree split this node where midpoint's marker says");

    // In the (default) 4-wide layout, the wide node it is collapsed into.
    let out = bvhscope(&["inspect", torus, "--node", "1", "--format", "json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["wide_node"]["top"], 0, "node 1 is swallowed by the root's wide node: {}", v["wide_node"]);
    assert!(v["wide_node"]["collapsed"].as_array().unwrap().contains(&serde_json::json!(1)));

    let out = bvhscope(&["inspect", torus, "--node", "1", "--format", "csv"]);
    let mut reader = csv::Reader::from_reader(&out.stdout[..]);
    assert_eq!(
        reader.headers().unwrap(),
        vec![
            "axis",
            "position",
            "left_count",
            "right_count",
            "area_left_ratio",
            "area_right_ratio",
            "left_term",
            "right_term",
            "cost"
        ]
    );
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    let cost = |r: &csv::StringRecord, i: usize| r[i].parse::<f32>().unwrap();
    assert!(rows.len() > 100 && rows.iter().all(|r| cost(r, 8) > 1.0));
    // The cost is the traversal step plus the two terms the columns name.
    assert!(rows.iter().all(|r| (cost(r, 8) - (1.0 + cost(r, 6) + cost(r, 7))).abs() < 1e-3 * cost(r, 8)));

    let out = bvhscope(&["inspect", torus, "--node", "999999"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--node 999999: the tree has"));
    let out = bvhscope(&["inspect", torus, "--node", "0"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("where each strategy splits") && text.contains("EPO share"), "{text}");
}

/// `stats` prints the tree's end-point overlap, and `compare` has it as a column.
#[test]
fn stats_and_compare_show_the_end_point_overlap() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let out = bvhscope(&["stats", torus, "--no-rays", "--format", "json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["stats"]["epo"].as_f64().unwrap() > 0.0);
    let out = bvhscope(&["stats", torus, "--no-rays"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("EPO "));
}

/// `render --against`: the difference of two identical builds is zero everywhere, and B − A is,
/// pixel by pixel, the difference of the two builds' `--counts` files.
#[test]
fn render_against_writes_the_per_pixel_difference_of_two_builds() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let (a_csv, b_csv, d_csv, png) =
        (tmp("against-a.csv"), tmp("against-b.csv"), tmp("against-d.csv"), tmp("against.png"));
    let run = |extra: &[&str]| render_small_visits(torus, extra);
    let p = |path: &PathBuf| path.to_str().unwrap().to_string();
    let err = run(&["--strategy", "midpoint", "--against", "midpoint", "-o", &p(&png)]);
    assert!(err.contains("less work at 0 pixels, the same at 1536, more at 0"), "{err}");
    run(&["--strategy", "midpoint", "--counts", &p(&a_csv), "-o", &p(&png)]);
    run(&["--strategy", "sah", "--counts", &p(&b_csv), "-o", &p(&png)]);
    run(&["--strategy", "midpoint", "--against", "sah", "--difference", &p(&d_csv), "-o", &p(&png)]);
    let rows = |path: &PathBuf| -> Vec<csv::StringRecord> {
        csv::Reader::from_path(path).unwrap().records().map(|r| r.unwrap()).collect()
    };
    let (a, b, d) = (rows(&a_csv), rows(&b_csv), rows(&d_csv));
    assert_eq!((a.len(), b.len(), d.len()), (1536, 1536, 1536));
    let mut differ = 0;
    for ((a, b), d) in a.iter().zip(&b).zip(&d) {
        assert_eq!((&a[0], &a[1]), (&d[0], &d[1]), "the same pixel");
        let (na, nb): (f32, f32) = (a[2].parse().unwrap(), b[2].parse().unwrap());
        assert_eq!(d[4].parse::<f32>().unwrap(), nb - na, "pixel {},{}", &d[0], &d[1]);
        differ += (nb != na) as usize;
    }
    assert!(differ > 0, "midpoint and SAH differ somewhere");
    let img = image::open(&png).unwrap().to_rgb8();
    assert!(img.width() >= 48 && img.height() > 32, "the image with its legend strip below");
    let out = bvhscope(&["render", torus, "--against", "sah", "--view", "normals", "-o", &p(&png)]);
    assert_eq!(out.status.code(), Some(2), "only heatmaps have a difference");
}

/// `replay` writes the build as an animated PNG, a frame per step from the root alone to the
/// finished tree, and prints each step's SAH cost: the first is one leaf of every triangle, the
/// last the finished binary tree's (as `stats` prints it).
#[test]
fn replay_writes_an_animated_png_and_the_sah_cost_per_step() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let apng = tmp("replay.png");
    let out = bvhscope(&[
        "replay",
        torus,
        "--strategy",
        "midpoint",
        "--size",
        "48x32",
        "--frames",
        "6",
        "-o",
        apng.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let table = String::from_utf8_lossy(&out.stdout);
    let rows: Vec<Vec<f64>> =
        table.lines().skip(1).map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect()).collect();
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&apng).unwrap()));
    let reader = decoder.read_info().unwrap();
    let frames = reader.info().animation_control.expect("an animated PNG").num_frames;
    assert_eq!(frames as usize, rows.len(), "a frame per step");
    assert!(rows.len() >= 5);
    let triangles = rows[0][1];
    assert_eq!(rows[0][0], 0.0);
    assert!(triangles > 100.0, "the root alone costs a test of every triangle");
    assert!(rows.windows(2).all(|w| w[1][0] > w[0][0]), "k grows");
    assert!(rows.last().unwrap()[1] < triangles / 5.0, "the finished tree costs far less than one leaf");
    let stats = bvhscope(&["stats", torus, "--strategy", "midpoint", "--layout", "binary", "--no-rays"]);
    let text = String::from_utf8_lossy(&stats.stdout);
    let sah = text.lines().find(|l| l.starts_with("SAH cost")).unwrap().split_whitespace().nth(2).unwrap().to_string();
    assert_eq!(format!("{:.3}", rows.last().unwrap()[1]), sah, "the last step is the finished tree");
    assert_eq!(rows.len(), 6, "the frames asked for");

    // A .gif is a real GIF (slide software plays it), with the frames asked for; another name is
    // refused before anything is rendered, and nothing is written.
    for frames in ["20", "24"] {
        let gif = tmp(&format!("replay-{frames}.gif"));
        let args = [
            "replay",
            torus,
            "--strategy",
            "midpoint",
            "--size",
            "48x32",
            "--frames",
            frames,
            "-o",
            gif.to_str().unwrap(),
        ];
        let out = bvhscope(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let table = String::from_utf8_lossy(&out.stdout);
        assert_eq!(table.lines().skip(1).count(), frames.parse::<usize>().unwrap(), "{table}");
        let bytes = std::fs::read(&gif).unwrap();
        assert!(bytes.starts_with(b"GIF89a"), "a GIF, not a PNG under a .gif name");
        let mut d = gif::DecodeOptions::new().read_info(&bytes[..]).unwrap();
        let mut n = 0;
        while d.read_next_frame().unwrap().is_some() {
            n += 1;
        }
        assert_eq!(n.to_string(), frames);
    }
    let mp4 = tmp("replay.mp4");
    let out = bvhscope(&["replay", torus, "--size", "48x32", "-o", mp4.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("must end in .gif or .png"));
    assert!(!mp4.exists());
}

/// A replay GIF's headline ("nodes visited: 0/2296 splits, SAH 4096.0") too long for its frame is
/// wrapped at the body text's size on every frame, never shrunk to half of it (issue 59: 7-pixel
/// headlines in some frames, their size jumping between frames).
#[test]
fn a_replay_gif_keeps_its_headline_size_on_every_frame() {
    let knot = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/knot.obj");
    let gif = tmp("replay-headline.gif");
    let args = ["replay", knot, "--view", "visits", "--size", "480x24", "--frames", "6", "-o", gif.to_str().unwrap()];
    let out = bvhscope(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(&gif).unwrap();
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut d = opts.read_info(&bytes[..]).unwrap();
    let w = d.width() as usize;
    let mut runs = Vec::new();
    while let Some(f) = d.read_next_frame().unwrap() {
        // Rows below the image with white text (the headline first, the min / mean / max last).
        let white = |y: usize| (0..w).any(|x| f.buffer[(y * w + x) * 4..][..3].iter().all(|&c| c > 200));
        let rows: Vec<usize> = (24..f.height as usize).filter(|&y| white(y)).collect();
        let first_run = rows.windows(2).take_while(|p| p[1] == p[0] + 1).count() + 1;
        runs.push((rows[0], first_run));
    }
    assert_eq!(runs.len(), 6);
    // Glyphs 14 pixels high (16 with a descender) at the body's size, 8 at most at half of it.
    assert!(runs.iter().all(|&r| r.0 == runs[0].0), "one place for the headline: {runs:?}");
    assert!(runs.iter().all(|&r| r.1 >= 12), "the headline at the body's size, not half of it: {runs:?}");
}
