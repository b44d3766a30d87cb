//! `--device gpu` on the command line (issues 38 and 39): the GPU's per-pixel counts, heatmaps,
//! warp figures, trace and LBVH/PLOC builds equal the CPU's, and a missing adapter is one line
//! and exit 2. The GPU tests run on any adapter (lavapipe in CI); without one they print a notice
//! and pass, except under `CI=true` (`bvhscope_gpu::gpu_for_tests`). Frames are small: lavapipe is
//! slow.

mod cli_support;
use cli_support::*;

/// Whether a GPU adapter is there (the notice printed when not; a failure under CI=true).
fn have_gpu() -> bool {
    bvhscope_gpu::gpu_for_tests().is_some()
}

fn ok(args: &[&str]) -> (String, String) {
    let out = bvhscope(args);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{args:?} failed: {stderr}");
    (stdout.into_owned(), stderr.into_owned())
}

/// A mesh whose coordinates are small integers (every box and triangle test of the camera's rays
/// is then decided far from its rounding): unit cubes of a staircase and a tilted quad.
fn exact_mesh() -> std::path::PathBuf {
    let mut v = Vec::new();
    let mut f = Vec::new();
    for (k, (x, y, z)) in
        [(0, 0, 0), (1, 0, 0), (1, 1, 0), (2, 1, 1), (3, 2, 1), (-2, 0, 2), (0, 3, -1)].iter().enumerate()
    {
        let base = 8 * k + 1;
        for c in 0..8 {
            v.push(format!("v {} {} {}", x + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1)));
        }
        for [a, b, c, d] in [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]] {
            f.push(format!("f {} {} {}", base + a, base + b, base + c));
            f.push(format!("f {} {} {}", base + a, base + c, base + d));
        }
    }
    let n = v.len();
    v.extend(["v -3 -1 -3".into(), "v 5 -1 -3".into(), "v 5 0 4".into(), "v -3 0 4".into()]);
    f.push(format!("f {} {} {}", n + 1, n + 2, n + 3));
    f.push(format!("f {} {} {}", n + 1, n + 3, n + 4));
    let p = tmp("exact.obj");
    std::fs::write(&p, format!("{}\n{}\n", v.join("\n"), f.join("\n"))).unwrap();
    p
}

/// The exact mesh's camera: looking down at the staircase.
const EXACT_CAMERA: [&str; 4] = ["--camera", "0.5,6,12:0.5,1,0", "--size", "64x48"];
/// Any mesh framed by the default camera, small.
const FRAMED: [&str; 2] = ["--size", "64x48"];

#[test]
fn gpu_counts_csv_and_heatmaps_are_the_cpus() {
    if !have_gpu() {
        return;
    }
    let exact = exact_mesh();
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    for (mesh, strategy) in [(exact.to_str().unwrap(), "sah"), (torus, "midpoint"), (torus, "lbvh")] {
        let csv = |device: &str, name: &str| {
            let (png, counts) = (tmp(&format!("{name}.png")), tmp(&format!("{name}.csv")));
            let mut args = vec!["render", mesh, "--view", "visits", "--strategy", strategy, "--device", device];
            args.extend(["--counts", counts.to_str().unwrap(), "-o", png.to_str().unwrap()]);
            args.extend(if mesh.ends_with("exact.obj") { &EXACT_CAMERA[..] } else { &FRAMED[..] });
            if device == "cpu" {
                args.extend(["--layout", "binary"]);
            }
            let (_, stderr) = ok(&args);
            (std::fs::read_to_string(&counts).unwrap(), std::fs::read(&png).unwrap(), stderr)
        };
        let tag = format!("{}-{strategy}", mesh.len());
        let (gpu, gpu_png, said) = csv("gpu", &format!("gpu-{tag}"));
        let (cpu, cpu_png, _) = csv("cpu", &format!("cpu-{tag}"));
        assert!(said.contains("traced on the GPU, binary nodes"), "{said}");
        assert_eq!(gpu.lines().count(), 64 * 48 + 1);
        let hits = gpu.lines().skip(1).filter(|l| !l.ends_with(",-1")).count();
        assert!(hits > 300 && hits < 64 * 48, "{mesh}: {hits} pixels hit");
        assert!(gpu == cpu, "{mesh} {strategy}: the GPU's counts CSV differs from the CPU's");
        assert!(gpu_png == cpu_png, "{mesh} {strategy}: the heatmaps differ");
    }
    // The warp views from the GPU's counts: the CPU's pictures, 32 and 64 lanes.
    for view in ["warp-cost", "simt-efficiency-64"] {
        let png = |device: &str| {
            let out = tmp(&format!("warp-{view}-{device}.png"));
            let mut args = vec!["render", torus, "--view", view, "--device", device, "-o", out.to_str().unwrap()];
            args.extend(FRAMED);
            if device == "cpu" {
                args.extend(["--layout", "binary"]);
            }
            ok(&args);
            std::fs::read(out).unwrap()
        };
        assert!(png("gpu") == png("cpu"), "{view}");
    }
}

/// The lines of `stats`' warp block: (who, figures).
fn warp_lines(text: &str) -> Vec<(String, String)> {
    text.lines()
        .filter(|l| l.starts_with("  GPU's counts") || l.starts_with("  CPU's counts"))
        .map(|l| (l[..16].trim().to_string(), l[16..].to_string()))
        .collect()
}

#[test]
fn stats_on_the_gpu_prints_the_warp_figures_of_the_cpus_counts() {
    if !have_gpu() {
        return;
    }
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    for (nodes, warp) in [("binary", "32"), ("cwbvh", "64")] {
        let mut args = vec!["stats", torus, "--device", "gpu", "--gpu-nodes", nodes, "--warp", warp];
        args.extend(FRAMED);
        let (text, _) = ok(&args);
        assert!(text.contains(&format!("warp            {warp} lanes")), "{text}");
        let lines = warp_lines(&text);
        assert_eq!(lines.len(), 2, "{text}");
        assert_eq!((lines[0].0.as_str(), lines[1].0.as_str()), ("GPU's counts", "CPU's counts"));
        assert_eq!(lines[0].1, lines[1].1, "{nodes}: the warp figures of the GPU's and the CPU's counts");
        assert!(lines[0].1.contains("SIMT efficiency 0.") && !lines[0].1.contains("total 0 steps"), "{text}");
        // The JSON's figures are the numbers themselves.
        args.extend(["--format", "json"]);
        let v: serde_json::Value = serde_json::from_str(&ok(&args).0).unwrap();
        let w = &v["rays"]["warp"];
        assert_eq!(w["lanes"], warp.parse::<u32>().unwrap());
        assert_eq!(w["gpu_counts"], w["cpu_counts"]);
        assert!(w["gpu_counts"]["simt_efficiency"].as_f64().unwrap() > 0.0);
    }
    // The CPU's own render of the binary tree gives the same figures and per-ray block.
    let mut gpu = vec!["stats", torus, "--device", "gpu"];
    gpu.extend(FRAMED);
    let mut cpu = vec!["stats", torus, "--layout", "binary"];
    cpu.extend(FRAMED);
    let (g, c) = (ok(&gpu).0, ok(&cpu).0);
    assert_eq!(warp_lines(&g)[1].1, warp_lines(&c)[0].1);
    let rays = |t: &str| {
        t.lines().filter(|l| l.starts_with("rays") || l.starts_with("  ")).map(String::from).collect::<Vec<_>>()
    };
    let per_ray = |t: &str| rays(t).into_iter().filter(|l| l.contains("per ray")).collect::<Vec<_>>();
    assert_eq!(per_ray(&g), per_ray(&c));
}

#[test]
fn a_gpu_build_of_lbvh_and_ploc_exports_the_cpus_dump_and_stats_gives_its_phases() {
    if !have_gpu() {
        return;
    }
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    for strategy in ["lbvh", "ploc"] {
        let dump = |device: &str| {
            let out = tmp(&format!("{strategy}-{device}.json"));
            let args = ["export-bvh", torus, "--strategy", strategy, "--device", device, "-o", out.to_str().unwrap()];
            ok(&args);
            std::fs::read_to_string(out).unwrap()
        };
        let (gpu, cpu) = (dump("gpu"), dump("cpu"));
        assert!(gpu.len() > 1000 && gpu == cpu, "{strategy}: the GPU's dump differs from the CPU's");
        // And the checker finds no defect in the GPU's tree (issue 39: "checked by check with zero defects").
        let gpu_dump = tmp(&format!("{strategy}-gpu.json"));
        let checked = ok(&["check", torus, "--bvh", gpu_dump.to_str().unwrap(), "--rays", "5000", "--size", "48x32"]).0;
        assert!(checked.contains(": 0 defects"), "{checked}");
        let (text, _) = ok(&["stats", torus, "--strategy", strategy, "--device", "gpu", "--no-rays"]);
        let line = text.lines().find(|l| l.starts_with("GPU build")).unwrap_or_else(|| panic!("{text}"));
        for phase in ["upload", "codes", "sort", "download"] {
            assert!(line.contains(phase), "{line}");
        }
        let middle = if strategy == "lbvh" { ["emission", "boxes"] } else { ["clustering", "layout on the host"] };
        assert!(middle.iter().all(|p| line.contains(p)), "{line}");
    }
    // Another strategy is built on the CPU and says so.
    let out = tmp("sah-gpu.json");
    let (_, said) = ok(&["export-bvh", torus, "--strategy", "sah", "--device", "gpu", "-o", out.to_str().unwrap()]);
    assert!(said.contains("sah is built on the CPU"), "{said}");
}

#[test]
fn trace_and_compare_on_the_gpu() {
    if !have_gpu() {
        return;
    }
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let mut gpu = vec!["trace", torus, "--hottest", "1", "--device", "gpu"];
    gpu.extend(FRAMED);
    let mut cpu = vec!["trace", torus, "--hottest", "1", "--layout", "binary"];
    cpu.extend(FRAMED);
    let (g, c) = (ok(&gpu).0, ok(&cpu).0);
    let pick =
        |t: &str, key: &str| t.lines().find(|l| l.starts_with(key)).unwrap_or_else(|| panic!("{key}: {t}")).to_string();
    for key in ["pixel", "hit", "counts"] {
        assert_eq!(pick(&g, key), pick(&c, key), "{key}");
    }
    assert!(pick(&g, "steps").contains("records no steps") && pick(&g, "steps").contains("--device cpu"));
    assert!(!g.contains("enter"), "no steps listed: {g}");

    // compare: every strategy's GPU rows, both formats, counted and plain, in one CSV with the CPU's.
    let args = [
        "compare", torus, "--device", "gpu", "--runs", "1", "--size", "24x16", "--format", "csv", "--layout", "binary",
    ];
    let (text, _) = ok(&args);
    let mut r = csv::Reader::from_reader(text.as_bytes());
    let header = r.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let records: Vec<csv::StringRecord> = r.records().map(|r| r.unwrap()).collect();
    let gpu_rows: Vec<_> = records.iter().filter(|r| &r[col("device")] == "gpu").collect();
    assert_eq!(gpu_rows.len(), 7 * 2 * 2, "{text}");
    for row in &gpu_rows {
        assert!(row[col("incoherent_mrays_per_s")].parse::<f64>().unwrap() > 0.0, "{row:?}");
        assert!(row[col("mrays_per_s")].parse::<f64>().unwrap() > 0.0, "{row:?}");
    }
    // A binary GPU row's work per ray is the CPU's binary row's.
    let cpu_sah = records.iter().find(|r| &r[0] == "SAH binned (binary)").unwrap();
    let gpu_sah = gpu_rows.iter().find(|r| &r[0] == "SAH binned (GPU binary, counted)").unwrap();
    assert_eq!(cpu_sah[col("nodes_per_ray")], gpu_sah[col("nodes_per_ray")]);
    assert_eq!(cpu_sah[col("tri_tests_per_ray")], gpu_sah[col("tri_tests_per_ray")]);
}

#[test]
fn without_an_adapter_the_gpu_is_one_line_and_exit_2() {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    // No Metal on Linux or Windows; on a Mac, a backend name wgpu does not know selects none.
    let none = if cfg!(target_os = "macos") { "no-such-backend" } else { "metal" };
    let out_png = tmp("none.png");
    for args in [
        vec!["render", torus, "--device", "gpu", "-o", out_png.to_str().unwrap()],
        vec!["stats", torus, "--device", "gpu"],
        vec!["trace", torus, "--device", "gpu", "--pixel", "1,1"],
        vec!["compare", torus, "--device", "gpu", "--runs", "1"],
    ] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_bvhscope"))
            .args(&args)
            .env("WGPU_BACKEND", none)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
        assert_eq!(errors.len(), 1, "{err}");
        assert!(
            errors[0].contains("--device gpu: no GPU adapter") && errors[0].contains("mesa-vulkan-drivers"),
            "{err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out_png.exists(), "nothing written");
    }
    // What the GPU cannot do is refused, naming the option, before any GPU is needed.
    for (args, says) in [
        (vec!["render", torus, "--gpu-nodes", "cwbvh"], "add --device gpu"),
        (vec!["stats", torus, "--device", "gpu", "--layout", "wide4"], "--layout wide4: the GPU walks binary nodes"),
        (vec!["stats", torus, "--device", "gpu", "--two-level"], "--two-level: the GPU traces one BVH"),
    ] {
        let out = bvhscope(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        // Without an adapter the refusal may be the adapter's; with one it is the option's.
        if have_gpu() || args.contains(&"--gpu-nodes") {
            assert!(err.contains(says), "{args:?}: {err}");
        }
    }
}

/// The handout's preset (Möller–Trumbore, the split-axis-sign order) runs on the GPU, with the
/// CPU's counts and image (issue 46).
#[test]
fn the_handout_preset_runs_on_the_gpu_and_equals_the_cpu() {
    if !have_gpu() {
        return;
    }
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/torus.obj");
    let run = |device: &str| {
        let (png, counts) = (tmp(&format!("handout-{device}.png")), tmp(&format!("handout-{device}.csv")));
        let mut args = vec!["render", torus, "--preset", "handout", "--view", "visits", "--device", device];
        args.extend(["--counts", counts.to_str().unwrap(), "-o", png.to_str().unwrap()]);
        args.extend(FRAMED);
        let (_, stderr) = ok(&args);
        (std::fs::read_to_string(&counts).unwrap(), std::fs::read(&png).unwrap(), stderr)
    };
    let (gpu, gpu_png, said) = run("gpu");
    let (cpu, cpu_png, _) = run("cpu");
    assert!(said.contains("traced on the GPU"), "{said}");
    assert!(gpu == cpu, "the handout's counts on the GPU are the CPU's");
    assert!(gpu_png == cpu_png);
}

/// A frame whose walks pass the GPU's step budget (a fan of 20,000 triangles in one box) says how
/// many rays the CPU finished, and its counts are still the CPU's.
#[test]
fn rays_finished_on_the_cpu_are_said_and_counted_right() {
    if !have_gpu() {
        return;
    }
    let mesh = tmp("fan20k.obj");
    let mut text = String::from("v 0 0 0\nv 1 1 0\n");
    for k in 0..20_000 {
        let a = k as f32 / 20_000.0;
        text += &format!("v {a} {} 0\n", 1.0 - a * a);
    }
    for k in 0..20_000 {
        text += &format!("f 1 2 {}\n", k + 3);
    }
    std::fs::write(&mesh, text).unwrap();
    let run = |device: &str| {
        let (png, counts) = (tmp(&format!("fan-{device}.png")), tmp(&format!("fan-{device}.csv")));
        let mut args = vec!["render", mesh.to_str().unwrap(), "--view", "visits", "--device", device];
        args.extend(["--counts", counts.to_str().unwrap(), "-o", png.to_str().unwrap(), "--size", "16x12"]);
        args.extend(["--layout", "binary"]);
        let (_, stderr) = ok(&args);
        (std::fs::read_to_string(&counts).unwrap(), stderr)
    };
    let (gpu, said) = run("gpu");
    let (cpu, _) = run("cpu");
    assert!(said.contains("rays reached the GPU's step budget") && said.contains("finished on the CPU"), "{said}");
    assert!(gpu == cpu, "the counts are the CPU's");
}
