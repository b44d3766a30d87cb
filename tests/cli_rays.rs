//! Secondary rays on the command line (issue 50): `render --ray-kind ao --counts` and `trace
//! --secondary` tell the same story pixel by pixel; `stats` counts the kind's rays; `compare
//! --ray-kind all` measures every tree on every kind, with the rank correlations under it; what a
//! kind cannot do is refused in one line.

mod cli_support;

use cli_support::{bvhscope, tmp};
use std::path::PathBuf;

fn knot() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/knot.obj")
}

fn ok(args: &[&str]) -> std::process::Output {
    let out = bvhscope(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    out
}

fn json(args: &[&str]) -> serde_json::Value {
    serde_json::from_slice(&ok(args).stdout).unwrap()
}

/// A pixel's row of the ao counts file is the sum of its ao rays walked one by one by `trace`;
/// pixels whose camera ray missed have no rays and say so.
#[test]
fn render_counts_of_ao_rays_are_the_sums_of_the_pixels_walked_rays() {
    let mesh = knot();
    let (csv, png) = (tmp("ao-counts.csv"), tmp("ao.png"));
    let m = mesh.to_str().unwrap();
    let common = ["--size", "32x24", "--layout", "binary", "--ray-kind", "ao", "--samples", "3"];
    let mut args =
        vec!["render", m, "--view", "visits", "--counts", csv.to_str().unwrap(), "-o", png.to_str().unwrap()];
    args.extend(common);
    let out = ok(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("wrote"), "{err}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("x,y,rays,nodes_visited,box_tests,leaves_visited,triangle_tests,hit_triangle,primary_nodes_visited,primary_triangle_tests")
    );
    let rows: Vec<Vec<i64>> = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 32 * 24);
    let (hit, missed): (Vec<_>, Vec<_>) = rows.iter().partition(|r| r[7] >= 0);
    assert!(!hit.is_empty() && !missed.is_empty());
    assert!(missed.iter().all(|r| r[2] == 0 && r[3] == 0), "a missed pixel has no secondary rays");
    assert!(hit.iter().all(|r| r[2] == 3 && r[8] > 0), "three rays per hit pixel, and the camera ray's own counts");
    for r in hit.iter().step_by(11) {
        let pixel = format!("{},{}", r[0], r[1]);
        let (mut nodes, mut tris) = (0, 0);
        for k in 0..3 {
            let k = k.to_string();
            let mut args = vec!["trace", m, "--pixel", &pixel, "--secondary", &k, "--format", "json"];
            args.extend(common);
            let v = json(&args);
            nodes += v["counts"]["nodes_visited"].as_i64().unwrap();
            tris += v["counts"]["triangle_tests"].as_i64().unwrap();
            assert_eq!(v["ray"]["from"]["secondary"]["rays"].as_array().unwrap().len(), 3);
        }
        assert_eq!((nodes, tris), (r[3], r[6]), "pixel {pixel}");
    }
}

#[test]
fn stats_counts_the_kinds_rays_and_compare_measures_every_tree_on_every_kind() {
    let mesh = knot();
    let m = mesh.to_str().unwrap();
    let v = json(&["stats", m, "--size", "32x24", "--ray-kind", "bounce", "--samples", "2", "--format", "json"]);
    let s = &v["rays"]["summary"];
    assert_eq!(s["rays"].as_u64().unwrap(), 2 * s["hits"].as_u64().unwrap());
    assert_eq!(v["rays"]["ray_kind"]["samples"], 2);
    assert!(v["rays"]["warp"].is_null(), "no warp figures for secondary rays");

    let v = json(&[
        "compare",
        m,
        "--size",
        "32x24",
        "--runs",
        "1",
        "--layout",
        "binary",
        "--ray-kind",
        "all",
        "--format",
        "json",
    ]);
    let rows = v["rows"].as_array().unwrap();
    let k = &v["ray_kinds"];
    let cells = k["cells"].as_array().unwrap();
    assert_eq!(cells.len(), rows.len() * 4, "every tree and the linear scan on every kind");
    for row in rows {
        let name = row["name"].as_str().unwrap();
        let of = |kind: &str| cells.iter().find(|c| c["row"] == name && c["kind"] == kind).unwrap();
        // The primary rays are the table's own: the same work per ray.
        let p = of("primary");
        assert!((p["nodes_per_ray"].as_f64().unwrap() - row["nodes_per_ray"].as_f64().unwrap()).abs() < 1e-9, "{name}");
        for kind in ["shadow", "ao", "bounce"] {
            let c = of(kind);
            assert!(c["rays"].as_u64().unwrap() > 0 && c["mrays_per_s"].as_f64().unwrap() > 0.0, "{name} {kind}");
        }
    }
    let spearman = k["spearman"].as_array().unwrap();
    assert_eq!(spearman.len(), 4);
    for s in spearman {
        let r = s["sah_cost"].as_f64().expect("seven trees ranked");
        assert!((-1.0..=1.0).contains(&r));
    }
    let out = ok(&["compare", m, "--size", "32x24", "--runs", "1", "--layout", "binary", "--ray-kind", "ao"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("| strategy | primary | ao |"), "{text}");
    assert!(text.contains("Spearman rank correlation"), "{text}");
}

#[test]
fn what_a_kind_cannot_do_is_refused_in_one_line() {
    let mesh = knot();
    let m = mesh.to_str().unwrap();
    for (args, says) in [
        (vec!["render", m, "--ray-kind", "all"], "--ray-kind all is for compare"),
        (vec!["trace", m, "--ray", "0,0,5:0,0,-1", "--ray-kind", "shadow"], "give --pixel or --hottest"),
        (vec!["trace", m, "--pixel", "0,0", "--size", "32x24", "--ray-kind", "ao"], "its camera ray misses"),
        (vec!["render", m, "--ray-kind", "ao", "--samples", "0"], "--samples"),
    ] {
        let out = bvhscope(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{args:?}: {err}");
    }
}

/// `grade --ray-kind ao`: the heatmaps are of ao rays (their missed pixels grey), the page says
/// so, and the figures and ranks stay the camera rays' (the same as without it).
#[test]
fn grade_draws_its_heatmaps_of_the_kind_and_keeps_its_figures() {
    let mesh = knot();
    let m = mesh.to_str().unwrap();
    let dump = tmp("grade-ao-sah.json");
    ok(&["export-bvh", m, "-o", dump.to_str().unwrap()]);
    let small = ["--size", "32x24", "--rays", "300", "--time-rays", "64"];
    let run = |out: &str, extra: &[&str]| {
        let out = tmp(out);
        let mut args = vec!["grade", m, dump.to_str().unwrap(), "--out", out.to_str().unwrap()];
        args.extend(small);
        args.extend(extra);
        ok(&args);
        out
    };
    let (plain, ao) = (run("grade-plain", &[]), run("grade-ao", &["--ray-kind", "ao"]));
    let html = std::fs::read_to_string(ao.join("grade.html")).unwrap();
    assert!(html.contains("Heatmaps: nodes visited per ray of the ambient-occlusion rays"), "the page names the rays");
    assert!(!std::fs::read_to_string(plain.join("grade.html")).unwrap().contains("Heatmaps: nodes visited per ray"));
    let figures = |dir: &PathBuf| {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("grade.json")).unwrap()).unwrap();
        let row = &v["students"][0];
        (row["quality"]["nodes_per_ray"].clone(), row["quality"]["sah_cost"].clone(), row["rank"].clone())
    };
    assert_eq!(figures(&plain), figures(&ao), "the figures are the camera rays'");
    // The heatmap: a missed pixel's corner is grey, where the camera-ray heatmap has its colour of 0.
    let image = |dir: &PathBuf| {
        let file = std::fs::read_dir(dir.join("images"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.to_string_lossy().ends_with("-visits.png"))
            .expect("a heatmap");
        image::open(file).unwrap().to_rgb8()
    };
    assert_eq!(image(&ao).get_pixel(0, 0).0, [96, 96, 96], "the camera ray missed: grey");
    assert_ne!(image(&plain).get_pixel(0, 0).0, [96, 96, 96]);
}

/// A light 1e20 away shadows as one 1e19 away on the same line: its squared distance passes f32,
/// and every shadow ray had the direction 0, an empty ray shadowing nothing (issue 58).
#[test]
fn a_far_light_shadows_as_a_near_one_on_its_line() {
    let mesh = knot();
    let m = mesh.to_str().unwrap();
    let counts = |light: &str, name: &str| {
        let (csv, png) = (tmp(&format!("{name}.csv")), tmp(&format!("{name}.png")));
        let (c, p) = (csv.to_str().unwrap(), png.to_str().unwrap());
        ok(&[
            "render",
            m,
            "--size",
            "32x24",
            "--layout",
            "binary",
            "--ray-kind",
            "shadow",
            "--light",
            light,
            "--counts",
            c,
            "-o",
            p,
        ]);
        std::fs::read_to_string(&csv).unwrap()
    };
    let (near, far) = (counts("1e19,1e19,1e19", "light-near"), counts("1e20,1e20,1e20", "light-far"));
    // Column 3: the pixel's shadow ray's nodes visited (an empty ray visits none).
    let walked = far.lines().skip(1).filter(|l| l.split(',').nth(3).is_some_and(|v| v != "0")).count();
    assert!(walked > 100, "the far light's shadow rays walk the tree: {walked} pixels");
    assert_eq!(near, far, "the same rays, the same counts");
}

/// A camera that sees no surface: the secondary kinds have no rays, and `compare --ray-kind all`
/// says so where it printed rates and speed-ups of nothing (issue 58), in the table and the JSON.
#[test]
fn compare_says_a_kind_without_rays_has_none() {
    let mesh = knot();
    let m = mesh.to_str().unwrap();
    let args = ["compare", m, "--size", "16x12", "--runs", "1", "--layout", "binary", "--ray-kind", "all"];
    let away = ["--camera", "0,0,10:0,0,20"];
    let out = ok(&[&args[..], &away[..]].concat());
    let text = String::from_utf8_lossy(&out.stdout);
    let table = &text[text.find("| strategy | primary | shadow | ao | bounce |").expect("the kinds' table")..];
    let rows: Vec<&str> = table.lines().skip(2).take_while(|l| l.starts_with('|')).collect();
    assert!(rows.len() > 5, "{table}");
    for row in rows {
        let cells: Vec<&str> = row.trim_matches('|').split(" | ").map(str::trim).collect();
        assert!(cells[1].contains('×'), "camera rays are timed, hit or not: {row}");
        assert_eq!(cells[2..], ["no rays: the camera sees no surface"; 3], "{row}");
    }
    assert!(table.contains("- ao: no rays: the camera sees no surface"), "no correlation either: {table}");

    let v = json(&[&args[..], &away[..], &["--format", "json"]].concat());
    for c in v["ray_kinds"]["cells"].as_array().unwrap() {
        let rated = c["kind"] == "primary";
        assert_eq!(c["rays"].as_u64().unwrap() > 0, rated, "{c}");
        assert_eq!(c["mrays_per_s"].is_number(), rated, "{c}");
        assert_eq!(c["speedup_over_linear"].is_number(), rated, "{c}");
    }
}
