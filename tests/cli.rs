//! The command line as a user runs it: outputs, formats, and one-line errors with exit code 2.

mod cli_support;
mod common;

use cli_support::{bvhscope, tent, tmp};
use std::process::Command;

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
    let strategies = bvhscope::bvh::Strategy::ALL.len();
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
    let strategies = bvhscope::bvh::Strategy::ALL.len();
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
            r#"{{"note": "Three tents. Two of one file, moved and turned.", "meshes": [
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
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("Three tents. Two of one file, moved and turned."), "stats shows the whole note: {err}");

    let png = tmp("tents-top.png");
    let out =
        bvhscope(&["render", s, "--two-level", "--view", "top-visits", "--size", "64x48", "-o", png.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("top-level nodes visited per ray"), "{err}");
    // Other commands print the note's first sentence and where the rest is.
    assert!(err.contains("about this scene: Three tents. (the whole note: bvhscope stats"), "{err}");
    assert!(!err.contains("moved and turned"), "{err}");
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
    let strategies = bvhscope::bvh::Strategy::ALL.len();
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
                strategy: bvhscope::bvh::Strategy::Midpoint,
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
