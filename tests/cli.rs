//! The command line as a user runs it: outputs, formats, and one-line errors with exit code 2.

mod common;

use std::path::PathBuf;
use std::process::Command;

fn bvhscope(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_bvhscope")).args(args).output().expect("runs")
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("bvhscope-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A small mesh of our own: four triangles forming a tent. Each call writes its own file: tests
/// run in parallel, and rewriting one shared file let a test read it half written.
fn tent() -> PathBuf {
    static CALLS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let p = tmp(&format!("tent-{}.obj", CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed)));
    std::fs::write(&p, "o tent\nv -1 0 -1\nv 1 0 -1\nv 0 1 0\nv -1 0 1\nv 1 0 1\nf 1 2 3\nf 3 4 5\nf 1 3 4\nf 2 5 3\n")
        .unwrap();
    p
}

#[test]
fn bad_input_gives_one_line_and_exit_code_2() {
    let missing = tmp("missing.obj");
    let nan = tmp("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let dir = std::env::temp_dir();
    for (args, needle) in [
        (vec!["render", missing.to_str().unwrap()], "no such file"),
        (vec!["stats", nan.to_str().unwrap()], "line 2"),
        (vec!["compare", dir.to_str().unwrap()], "is a directory"),
    ] {
        let out = bvhscope(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
        assert!(err.contains(needle) && err.contains(args[1]), "names the file and problem: {err}");
        assert!(!err.contains("panicked") && !err.contains("backtrace"), "{err}");
    }
    let out = bvhscope(&["render", tent().to_str().unwrap(), "--camera", "0,0,0:0,0,0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--camera"));
}

#[test]
fn strategy_help_lists_every_strategy() {
    let out = bvhscope(&["render", "--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    for name in ["midpoint", "equal-count", "sah", "sah-sweep"] {
        assert!(help.contains(name), "--help lists {name}");
    }
}

#[test]
fn render_writes_a_png_of_the_requested_size_with_legend_for_heatmaps() {
    let out_png = tmp("normals.png");
    let out = bvhscope(&["render", tent().to_str().unwrap(), "--size", "64x48", "-o", out_png.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let img = image::open(&out_png).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (64, 48));
    assert!(img.pixels().any(|p| p.0 != [0, 0, 0]), "the mesh is visible");

    let heat = tmp("visits.png");
    let out = bvhscope(&[
        "render",
        tent().to_str().unwrap(),
        "--size",
        "64x48",
        "--view",
        "visits",
        "--strategy",
        "midpoint",
        "-o",
        heat.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let img = image::open(&heat).unwrap().to_rgb8();
    assert!(img.height() > 48, "legend strip appended below the image");
    // The corner ray misses the root box: 0 nodes visited, the bottom of viridis.
    let low = bvhscope::render::ColorMap::Viridis.map(0.0);
    assert_eq!(img.get_pixel(0, 0).0, low);
    assert!(img.get_pixel(32, 30).0 != low, "the tent's middle costs more than nothing");
}

#[test]
fn stats_and_compare_print_their_tables() {
    let out = bvhscope(&[
        "stats",
        tent().to_str().unwrap(),
        "--strategy",
        "equal-count",
        "--max-leaf-size",
        "1",
        "--layout",
        "binary",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("nodes           7 (3 interior, 4 leaves)"), "{text}");

    let out = bvhscope(&["compare", tent().to_str().unwrap(), "--size", "40x30", "--runs", "1", "--format", "json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    let rows = v["rows"].as_array().unwrap();
    let strategies = bvhscope::bvh::SplitStrategy::ALL.len();
    let layouts = bvhscope::bvh::Layout::ALL.len();
    assert_eq!(rows.len(), layouts * strategies + 1, "every strategy in every layout, and the linear scan");
    assert_eq!(rows[0]["name"], "Midpoint (binary)");
    assert_eq!(rows[1]["name"], "Midpoint (wide4)");
    assert_eq!(rows[2]["name"], "Midpoint (wide8)");
    assert_eq!(rows[4 * layouts]["name"], "LBVH (Morton) (binary)");
    assert_eq!(rows[5 * layouts]["name"], "PLOC (binary)");
    assert_eq!(rows[6 * layouts]["name"], "SBVH (spatial splits) (binary)");
    assert_eq!(rows[layouts * strategies]["name"], "Linear scan");
    assert_eq!(rows[layouts * strategies]["tri_tests_per_ray"], 4.0);

    for r in rows {
        assert!(r["frame_ms"].as_f64().unwrap() > 0.0);
    }

    let out = bvhscope(&[
        "compare",
        tent().to_str().unwrap(),
        "--size",
        "40x30",
        "--runs",
        "1",
        "--format",
        "csv",
        "--layout",
        "wide4",
    ]);
    let csv = String::from_utf8_lossy(&out.stdout);
    let strategies = bvhscope::bvh::SplitStrategy::ALL.len();
    assert_eq!(csv.lines().count(), strategies + 2, "header, every strategy in the chosen layout, linear: {csv}");
    assert!(csv.starts_with("strategy,build_ms"));
}

#[test]
fn a_scene_renders_and_reports_two_levels() {
    // Three placements of the tent: two of the same file moved and turned, one more.
    let mesh = tent();
    let scene = tmp("tents.json");
    std::fs::write(
        &scene,
        format!(
            r#"{{"note": "three tents", "meshes": [
                {{"file": "{0}"}},
                {{"file": "{0}", "transform": {{"translate": [3, 0, 0], "rotate": {{"axis": [0, 1, 0], "degrees": 30}}}}}},
                {{"file": "{0}", "transform": {{"translate": [-3, 0, 0], "scale": 0.5}}}}]}}"#,
            mesh.display()
        ),
    )
    .unwrap();
    let s = scene.to_str().unwrap();
    let out = bvhscope(&["stats", s, "--two-level", "--top-strategy", "midpoint"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("3 placements of 1 meshes: 12 triangles as placed, 4 stored"), "{text}");
    assert!(text.contains("top level       Midpoint"), "{text}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("three tents"), "the scene's note is shown");

    let png = tmp("tents-top.png");
    let out =
        bvhscope(&["render", s, "--two-level", "--view", "top-visits", "--size", "64x48", "-o", png.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("top-level nodes visited per ray"), "{err}");
    assert!(image::open(&png).is_ok());

    let out = bvhscope(&["render", s, "--top-strategy", "sah", "-o", png.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "top-level options need --two-level");
}

#[test]
fn the_handout_preset_sets_the_labs_bvh_and_the_options_given_still_win() {
    let t = tent();
    let out = bvhscope(&["stats", t.to_str().unwrap(), "--preset", "handout", "--size", "40x30"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let leaf = bvhscope::bvh::Preset::HANDOUT_MAX_LEAF_SIZE;
    assert!(text.contains(&format!("Midpoint, binary layout (max leaf size {leaf},")), "{text}");
    assert!(text.contains("split-axis sign order, Möller–Trumbore test"), "{text}");
    let out = bvhscope(&["stats", t.to_str().unwrap(), "--preset", "handout", "--max-leaf-size", "1", "--no-rays"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Midpoint, binary layout (max leaf size 1,"), "{text}");
    assert!(!text.contains("rays "), "no frame traced: {text}");
}

#[test]
fn stats_counts_the_rays_in_the_root_box_as_the_app_does() {
    use bvhscope::bvh::{AnyBvh, BuildParams};
    use bvhscope::render::{render, Camera, RenderSettings};
    let t = tent();
    let out = bvhscope(&["stats", t.to_str().unwrap(), "--size", "64x48", "--format", "json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let r = &v["rays"]["summary"];
    // The same frame traced here through the library, as the app traces it.
    let mesh = bvhscope::mesh::load_obj(&t).unwrap().0;
    let bvh = AnyBvh::build(&mesh, &BuildParams::default());
    let cam = Camera::framing(&mesh.bounds(), 64, 48);
    let s = render(&bvh, &mesh, &cam, &RenderSettings { count: true, ..Default::default() }).ray_summary();
    assert_eq!(r["rays"], 64 * 48);
    assert_eq!(r["root_rays"], s.root_rays);
    assert!(s.root_rays > 0 && s.root_rays < s.rays);
    assert_eq!(r["root_mean_nodes_visited"].as_f64().unwrap(), s.root_mean_nodes_visited);
    assert_eq!(r["mean_triangle_tests"].as_f64().unwrap(), s.mean_triangle_tests);
    assert!(s.root_mean_nodes_visited > s.mean_nodes_visited, "the root-box mean is not diluted by misses");
}

#[test]
fn compare_times_single_rays_and_writes_csv_a_reader_parses() {
    let out = bvhscope(&[
        "compare",
        tent().to_str().unwrap(),
        "--size",
        "40x30",
        "--runs",
        "1",
        "--format",
        "csv",
        "--preset",
        "handout",
        "--threads",
        "1",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut r = csv::Reader::from_reader(&out.stdout[..]);
    let header = r.headers().unwrap().clone();
    let records: Vec<csv::StringRecord> = r.records().map(|r| r.unwrap()).collect();
    let strategies = bvhscope::bvh::SplitStrategy::ALL.len();
    assert_eq!(records.len(), strategies + 1, "every strategy in the preset's binary layout, and the linear scan");
    let col = |name: &str| header.iter().position(|h| h == name).unwrap_or_else(|| panic!("{name} in {header:?}"));
    for rec in &records {
        assert_eq!(rec.len(), header.len());
        assert!(rec[col("trace_ms")].parse::<f64>().unwrap() > 0.0);
        let (all, root) = (&rec[col("tri_tests_per_ray")], &rec[col("root_box_tri_tests_per_ray")]);
        assert!(root.parse::<f64>().unwrap() >= all.parse::<f64>().unwrap());
    }
    assert_eq!(&records[0][0], "Midpoint (binary)");
    assert_eq!(&records[strategies][col("build_ms")], "", "the linear scan has no build");
    assert!(records[..strategies].iter().all(|r| r[col("epo")].parse::<f64>().is_ok()), "each strategy's EPO");
    assert_eq!(&records[strategies][col("epo")], "");

    let out = bvhscope(&["compare", tent().to_str().unwrap(), "--size", "40x30", "--runs", "1", "--layout", "binary"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("| trace ms | frame ms |") && text.contains("enter the root box"), "{text}");
    assert!(text.contains("single rays, closest hit, no shading, 1 thread(s)"), "{text}");
}

#[test]
fn a_heatmap_png_names_its_mesh_strategy_and_layout() {
    use bvhscope::render::{draw_legend, legend_height};
    let t = tent();
    let png = tmp("named-visits.png");
    let out = bvhscope(&[
        "render",
        t.to_str().unwrap(),
        "--size",
        "320x48",
        "--view",
        "visits",
        "--strategy",
        "midpoint",
        "--layout",
        "binary",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let img = image::open(&png).unwrap().to_rgb8();
    let base = image::RgbImage::from_fn(320, 48, |x, y| *img.get_pixel(x, y));
    // Redraw the strip with the caption the file should carry; it must match the file's.
    let mut legend = bvhscope::render::view_image(
        &{
            let mesh = bvhscope::mesh::load_obj(&t).unwrap().0;
            let p = bvhscope::bvh::BuildParams {
                strategy: bvhscope::bvh::SplitStrategy::Midpoint,
                layout: bvhscope::bvh::Layout::Binary,
                ..Default::default()
            };
            let bvh = bvhscope::bvh::AnyBvh::build(&mesh, &p);
            let cam = bvhscope::render::Camera::framing(&mesh.bounds(), 320, 48);
            bvhscope::render::render(
                &bvh,
                &mesh,
                &cam,
                &bvhscope::render::RenderSettings { count: true, ..Default::default() },
            )
        },
        bvhscope::render::View::Visits,
        bvhscope::render::ColorMap::Viridis,
        bvhscope::render::HeatRange::Auto,
        Default::default(),
    )
    .1
    .unwrap();
    legend.subject = format!("{}, Midpoint, binary", t.file_name().unwrap().to_string_lossy());
    assert_eq!(img.height(), 48 + legend_height(&legend));
    assert!(draw_legend(&base, &legend) == img, "the strip names mesh, strategy, layout and view");
}

#[test]
fn a_z_up_copy_of_a_mesh_renders_as_the_y_up_original() {
    // The tent written Z-up: (x, y, z) -> (x, -z, y).
    let zup = tmp("tent-zup.obj");
    std::fs::write(&zup, "v -1 1 0\nv 1 1 0\nv 0 0 1\nv -1 -1 0\nv 1 -1 0\nf 1 2 3\nf 3 4 5\nf 1 3 4\nf 2 5 3\n")
        .unwrap();
    let (a, b) = (tmp("yup-depth.png"), tmp("zup-depth.png"));
    let run = |mesh: &std::path::Path, up: &str, out: &std::path::Path| {
        let o = bvhscope(&[
            "render",
            mesh.to_str().unwrap(),
            "--up",
            up,
            "--view",
            "depth",
            "--size",
            "64x48",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        image::open(out).unwrap().to_rgb8()
    };
    let (y, z) = (run(&tent(), "y", &a), run(&zup, "z", &b));
    let differ =
        y.pixels().zip(z.pixels()).filter(|(p, q)| p.0.iter().zip(q.0).any(|(a, b)| a.abs_diff(b) > 2)).count();
    assert!(differ <= 3, "{differ} of {} pixels differ", 64 * 48);
    assert!(y.pixels().filter(|p| p.0 != [0, 0, 0]).count() > 200, "the tent is in view");
}

/// One level over a scene past the flattening budget is refused in one line that says to use two
/// levels, before anything is allocated; two levels of the same scene work.
#[test]
fn one_level_over_too_many_placements_is_refused_and_two_levels_build() {
    let dir = tmp("many");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = common::many_placements(&dir, 21_000);
    let out = bvhscope(&["stats", scene.to_str().unwrap(), "--no-rays"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(
        err.contains("many-21000.json") && err.contains("21000000 triangles") && err.contains("--two-level"),
        "{err}"
    );
    let out = bvhscope(&["stats", scene.to_str().unwrap(), "--no-rays", "--two-level", "--format", "json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["instances"], 21_000, "{v}");
}

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
    assert_eq!(reader.headers().unwrap(), vec!["axis", "position", "left_count", "right_count", "cost"]);
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    assert!(rows.len() > 100 && rows.iter().all(|r| r[4].parse::<f32>().unwrap() > 1.0));

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

/// `render MESH` of a small binary-layout visits heatmap with `extra` options; its stderr.
fn render_small_visits(mesh: &str, extra: &[&str]) -> String {
    let mut args = vec!["render", mesh, "--size", "48x32", "--view", "visits", "--layout", "binary"];
    args.extend(extra);
    let out = bvhscope(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stderr).into_owned()
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
}

/// `export-bvh` writes a built-in tree; `check` passes it (exit 0, the imported row equal to the
/// strategy's), finds a shrunken leaf box (exit 1, naming the node and the triangle, with wrong
/// rays), and refuses an unreadable dump in one line (exit 2).
#[test]
fn check_passes_an_exported_tree_and_names_what_is_wrong_with_a_broken_one() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let (good, bad, junk) = (tmp("good-bvh.txt"), tmp("bad-bvh.txt"), tmp("junk-bvh.json"));
    let p = |x: &PathBuf| x.to_str().unwrap().to_string();
    let out = bvhscope(&["export-bvh", torus, "--strategy", "midpoint", "-o", &p(&good)]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let check = |file: &PathBuf| bvhscope(&["check", torus, "--bvh", &p(file), "--rays", "20000", "--size", "64x48"]);
    let out = check(&good);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("0 defects"), "{text}");
    let row = |name: &str| {
        text.lines()
            .find(|l| l.starts_with(name))
            .unwrap()
            .split_whitespace()
            .skip(2) // "imported: FILE", "Midpoint, binary"
            .collect::<Vec<_>>()
    };
    assert_eq!(row("imported:"), row("Midpoint"), "the same nodes, depth, SAH, EPO and work per ray");

    // Shrink the first leaf's box to half its width in x.
    let dump = std::fs::read_to_string(&good).unwrap();
    let mut leaf = None;
    let lines: Vec<String> = dump
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let w: Vec<&str> = l.split_whitespace().collect();
            if leaf.is_none() && w.first() == Some(&"node") && w.get(7) == Some(&"leaf") {
                let node = dump.lines().take(i).filter(|x| x.starts_with("node ")).count();
                leaf = Some(node);
                let (lo, hi): (f32, f32) = (w[1].parse().unwrap(), w[4].parse().unwrap());
                let mut w: Vec<String> = w.iter().map(|s| s.to_string()).collect();
                w[4] = ((lo + hi) / 2.0).to_string();
                return w.join(" ");
            }
            l.to_string()
        })
        .collect();
    std::fs::write(&bad, lines.join("\n")).unwrap();
    let leaf = leaf.unwrap();
    let out = check(&bad);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains(&format!("(in leaf node {leaf}) sticks out of its leaf's box, node {leaf}")), "{text}");
    assert!(text.lines().any(|l| l.starts_with("bounds (")), "grouped: {text}");
    // The example ray, traced through the imported tree, misses what the linear scan hits.
    let example = text.lines().find(|l| l.contains("hit differently")).expect("wrong rays");
    let (flag, value) = match example.split("--pixel ").nth(1) {
        Some(rest) => ("--pixel", rest.split([' ', ')']).next().unwrap().to_string()),
        None => ("--ray", example.split("--ray ").nth(1).unwrap().split([' ', ')']).next().unwrap().to_string()),
    };
    let want: u32 =
        example.split("the linear scan hits triangle ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    let out = bvhscope(&["trace", torus, "--bvh", &p(&bad), flag, &value, "--size", "64x48", "--format", "json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["build"].as_str().unwrap().starts_with("imported:"));
    assert_ne!(v["hit"]["triangle"].as_u64(), Some(want as u64), "{example}");

    std::fs::write(&junk, r#"{"format": "bvhscope-bvh", "version": 7, "primitives": [], "nodes": []}"#).unwrap();
    let out = check(&junk);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("junk-bvh.json") && err.contains("version 7"), "{err}");
}

/// `check` of a small mesh: a few rays and a small frame.
fn check_small(mesh: &std::path::Path, dump: &std::path::Path) -> std::process::Output {
    let (m, d) = (mesh.to_str().unwrap(), dump.to_str().unwrap());
    bvhscope(&["check", m, "--bvh", d, "--rays", "2000", "--size", "32x24"])
}

/// Primitives are the file's triangle numbers, zero-area ones included (the loader drops those):
/// an exported dump of a mesh with a zero-area face skips its number, and the checker warns that
/// it is in no leaf without calling it a defect.
#[test]
fn dumps_number_triangles_as_the_file_does() {
    let obj = tmp("with-degenerate.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 2 1 0\nv 4 0 0\nv 5 0 0\nv 4 1 0\n\
         f 1 2 3\nf 1 2 2\nf 4 5 6\nf 7 8 9\n",
    )
    .unwrap();
    let dump = tmp("with-degenerate.json");
    let out = bvhscope(&["export-bvh", obj.to_str().unwrap(), "-o", dump.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&dump).unwrap()).unwrap();
    let mut prims: Vec<u64> = v["primitives"].as_array().unwrap().iter().map(|p| p.as_u64().unwrap()).collect();
    prims.sort();
    assert_eq!(prims, vec![0, 2, 3], "the zero-area face is number 1 in the file");
    let out = check_small(&obj, &dump);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("triangle 1 is in no leaf (it is degenerate"), "{text}");
}

/// The README's dumping snippets (examples/dump/): the C++ one compiled and run when a C++
/// compiler is present, the Python one when Python is; their dumps of a hand-made tree check clean.
#[test]
fn the_dumping_snippets_write_dumps_that_check_clean() {
    let dir = std::env::temp_dir().join(format!("bvhscope-snippets-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let row = dir.join("row.obj");
    let mut obj = String::new();
    for k in 0..4 {
        obj += &format!("v {k} 0 0\nv {} 0 0\nv {k} 1 0\n", k + 1);
    }
    for k in 0..4 {
        obj += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
    }
    std::fs::write(&row, obj).unwrap();
    let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/dump");
    let check = |dump: &std::path::Path| {
        let out = check_small(&row, dump);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let exe = dir.join("dump_bvh");
    match Command::new("c++").args(["-std=c++17", "-O1", "-o"]).arg(&exe).arg(examples.join("dump_bvh.cpp")).output() {
        Ok(out) if out.status.success() => {
            let run = Command::new(&exe).output().unwrap();
            let txt = dir.join("tree.txt");
            std::fs::write(&txt, run.stdout).unwrap();
            check(&txt);
        }
        Ok(out) => panic!("dump_bvh.cpp does not compile: {}", String::from_utf8_lossy(&out.stderr)),
        Err(_) => eprintln!("notice: no C++ compiler (c++): the C++ dumping snippet is not compiled"),
    }
    match Command::new("python3").arg(examples.join("dump_bvh.py")).output() {
        Ok(out) if out.status.success() => {
            let json = dir.join("tree.json");
            std::fs::write(&json, out.stdout).unwrap();
            check(&json);
        }
        Ok(out) => panic!("dump_bvh.py fails: {}", String::from_utf8_lossy(&out.stderr)),
        Err(_) => eprintln!("notice: no python3: the Python dumping snippet is not run"),
    }
    // The README walkthrough's broken dump: centroid boxes made from an exported tree are found
    // out, by the bounds they miss and the rays that miss with them.
    let (mid, bad) = (dir.join("mid.txt"), dir.join("centroid.txt"));
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    assert!(bvhscope(&["export-bvh", torus, "--strategy", "midpoint", "-o", mid.to_str().unwrap()]).status.success());
    if let Ok(out) = Command::new("python3").arg(examples.join("centroid_boxes.py")).arg(torus).arg(&mid).output() {
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        std::fs::write(&bad, out.stdout).unwrap();
        let out = bvhscope(&["check", torus, "--bvh", bad.to_str().unwrap(), "--rays", "2000", "--size", "48x32"]);
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(1), "{text}");
        assert!(text.contains("sticks out of") && text.contains("rays hit differently"), "{text}");
    }
}

/// `render --bvh FILE` traces an imported tree: an exported midpoint tree gives, pixel for pixel,
/// the counts of midpoint's own binary tree; with --against it is A of the difference.
#[test]
fn render_through_an_imported_tree() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let (dump, a, b, png, d) = (
        tmp("render-bvh.json"),
        tmp("render-bvh-a.csv"),
        tmp("render-bvh-b.csv"),
        tmp("render-bvh.png"),
        tmp("render-bvh-d.csv"),
    );
    let p = |x: &PathBuf| x.to_str().unwrap().to_string();
    assert!(bvhscope(&["export-bvh", torus, "--strategy", "midpoint", "-o", &p(&dump)]).status.success());
    let run = |extra: &[&str]| render_small_visits(torus, extra);
    run(&["--bvh", &p(&dump), "--counts", &p(&a), "-o", &p(&png)]);
    run(&["--strategy", "midpoint", "--counts", &p(&b), "-o", &p(&png)]);
    assert_eq!(
        std::fs::read_to_string(&a).unwrap(),
        std::fs::read_to_string(&b).unwrap(),
        "the same counts at every pixel"
    );
    let err = run(&["--bvh", &p(&dump), "--against", "sah", "--difference", &p(&d), "-o", &p(&png)]);
    assert!(err.contains("minus A imported: render-bvh.json"), "{err}");

    // A 4-wide tree: exported, it checks clean with the same row as SAH's own 4-wide tree, and
    // traces pixel for pixel as that tree; a trace names its leaves by the dump's ids.
    let wide = tmp("render-bvh-wide.json");
    assert!(bvhscope(&["export-bvh", torus, "--layout", "wide4", "-o", &p(&wide)]).status.success());
    let out = bvhscope(&["check", torus, "--bvh", &p(&wide), "--rays", "5000", "--size", "48x32"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    let row = |name: &str| {
        let w: Vec<&str> = text.lines().find(|l| l.starts_with(name)).unwrap().split_whitespace().collect();
        w[w.len() - 6..].to_vec() // the six figures after the name
    };
    assert_eq!(row("imported:"), row("SAH binned, wide4"), "{text}");
    for (src, csv) in [(["--bvh", &p(&wide)], &a), (["--layout", "wide4"], &b)] {
        let args = [
            "render",
            torus,
            "--size",
            "48x32",
            "--view",
            "visits",
            src[0],
            src[1],
            "--counts",
            &p(csv),
            "-o",
            &p(&png),
        ];
        assert!(bvhscope(&args).status.success());
    }
    assert_eq!(std::fs::read_to_string(&a).unwrap(), std::fs::read_to_string(&b).unwrap(), "4-wide counts");
    let out =
        bvhscope(&["trace", torus, "--bvh", &p(&wide), "--pixel", "24,16", "--size", "48x32", "--format", "json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["build"], "imported: render-bvh-wide.json, wide4");
    let steps = v["steps"].to_string();
    assert!(steps.contains("\"step\":\"leaf\"") && !steps.contains("slot"), "leaves named as dump nodes: {steps}");
}

/// A reader that stops early (`bvhscope stats … | head -1`) closes the pipe: the program ends
/// quietly with status 141, as a Unix tool killed by SIGPIPE, and never panics.
#[test]
fn a_closed_pipe_ends_the_output_without_a_panic() {
    use std::io::Read;
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let mut child = Command::new(env!("CARGO_BIN_EXE_bvhscope"))
        .args(["inspect", torus, "--node", "0", "--format", "json"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take()); // the reader is gone before the first byte
    let status = child.wait().unwrap();
    let mut err = String::new();
    child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(status.code(), Some(141), "{err}");
}

/// The bonus builders on the command line: LBVH and PLOC build and report, `--ploc-radius` is
/// taken, and `--reinsert-passes` reports the SAH cost before and after, never higher.
#[test]
fn lbvh_ploc_and_reinsertion_on_the_command_line() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    for args in [
        vec!["stats", torus, "--strategy", "lbvh", "--layout", "binary"],
        vec!["stats", torus, "--strategy", "ploc", "--ploc-radius", "4", "--layout", "binary"],
    ] {
        let out = bvhscope(&args);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success() && text.contains("SAH cost"), "{text}");
    }
    let out = bvhscope(&["stats", torus, "--strategy", "lbvh", "--layout", "binary", "--reinsert-passes", "3"]);
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().find(|l| l.starts_with("reinsertion")).unwrap_or_else(|| panic!("{text}"));
    let w: Vec<&str> = line.split_whitespace().collect();
    let (before, after): (f64, f64) = (w[3].parse().unwrap(), w[5].parse().unwrap());
    assert!(after < before, "{line}");
    let out = bvhscope(&["stats", torus, "--ploc-radius", "0"]);
    assert_eq!(out.status.code(), Some(2), "a radius of 0 is refused");
}
