//! `bvhscope trace`: one ray's walk through the BVH, step by step: the steps the app's Ray panel
//! lists, from the same traversal (`bvh::trace`). The ray is a pixel of the camera (0-based, x from
//! the left, y from the top, as everywhere) or typed as an origin and a direction.

use super::args::{BuildArgs, ViewArgs};
use super::{build_scene, load_mesh, CliError};
use crate::bvh::{trace_ray, RayCounters, Step, StepKind, TraceLevel};
use crate::geometry::Ray;
use clap::{Args, ValueEnum};
use glam::Vec3;
use std::fmt::Write;
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum TraceFormat {
    Text,
    Json,
}

#[derive(Args, Debug)]
pub struct TraceArgs {
    /// The mesh (.obj) or scene (.json: bvhscope's or Moer-lite's).
    pub mesh: PathBuf,
    /// The pixel X,Y of the camera's image (0-based, x from the left, y from the top).
    #[arg(long, value_parser = parse_pixel, conflicts_with = "ray", required_unless_present = "ray")]
    pub pixel: Option<(u32, u32)>,
    /// A ray typed as OX,OY,OZ:DX,DY,DZ (origin and direction, world space).
    #[arg(long, value_parser = parse_ray, allow_hyphen_values = true)]
    pub ray: Option<(Vec3, Vec3)>,
    #[command(flatten)]
    pub build: BuildArgs,
    /// The camera whose pixel is traced (as `render` takes it).
    #[command(flatten)]
    pub view_args: ViewArgs,
    #[arg(long, value_enum, default_value = "text")]
    pub format: TraceFormat,
}

fn parse_pixel(s: &str) -> Result<(u32, u32), String> {
    let (x, y) = s.split_once(',').ok_or_else(|| format!("'{s}' is not X,Y"))?;
    match (x.trim().parse::<u32>(), y.trim().parse::<u32>()) {
        (Ok(x), Ok(y)) => Ok((x, y)),
        _ => Err(format!("'{s}' is not X,Y (two whole numbers from 0)")),
    }
}

fn parse_ray(s: &str) -> Result<(Vec3, Vec3), String> {
    let (o, d) = s.split_once(':').ok_or_else(|| format!("'{s}' is not OX,OY,OZ:DX,DY,DZ"))?;
    let (o, d) = (super::args::parse_vec3(o)?, super::args::parse_vec3(d)?);
    if d == Vec3::ZERO {
        return Err(format!("'{s}': the direction is zero"));
    }
    Ok((o, d))
}

/// The step as one line of the table, and the depth of the node it is about (`None`: a step of
/// the node entered last, indented under it).
pub fn step_text(s: &Step) -> (Option<u32>, String) {
    let t = |v: Option<f32>| v.map_or("-".to_string(), |v| format!("{v:.4}"));
    let stack = |st: &[(crate::bvh::NodeId, f32)]| {
        let items: Vec<String> = st.iter().map(|(n, t)| format!("{n}@{t:.3}")).collect();
        format!("[{}]", items.join(", "))
    };
    match &s.kind {
        StepKind::BoxTest { node, depth, hit: true, t_entry, t_exit } => {
            (Some(*depth), format!("box of {node}: hit, t {}..{}", t(*t_entry), t(*t_exit)))
        }
        StepKind::BoxTest { node, depth, hit: false, .. } => (Some(*depth), format!("box of {node}: miss")),
        StepKind::Enter { node, depth, t_entry, t_exit } => {
            (Some(*depth), format!("enter {node} (depth {depth}, t {t_entry:.4}..{t_exit:.4})"))
        }
        StepKind::Leaf { node, depth } => (Some(*depth), format!("leaf {node}: test its triangles")),
        StepKind::Push { node, t_entry, stack: st } => {
            (None, format!("push {node} (enters at {t_entry:.4})  stack {}", stack(st)))
        }
        StepKind::Pop { node, t_entry, stack: st } => {
            (None, format!("pop {node} (enters at {t_entry:.4})  stack {}", stack(st)))
        }
        StepKind::Skip { node, t_entry, closest_t, stack: st } => (
            None,
            format!("skip {node}: enters at {t_entry:.4}, beyond the closest hit {closest_t:.4}  stack {}", stack(st)),
        ),
        StepKind::Triangle { triangle, hit, t: th, u, v } => {
            let what = if *hit { format!("hit t {} u {} v {}", t(*th), t(*u), t(*v)) } else { "miss".into() };
            (None, format!("triangle {triangle}: {what}"))
        }
        StepKind::ClosestHit { triangle, t } => (None, format!("closest hit so far: triangle {triangle} at t {t:.4}")),
        StepKind::Instance { instance, origin, dir } => (
            None,
            format!(
                "enter placement {instance}: object-space ray ({:.3}, {:.3}, {:.3}) → ({:.3}, {:.3}, {:.3})",
                origin[0], origin[1], origin[2], dir[0], dir[1], dir[2]
            ),
        ),
        StepKind::InstanceDone { instance } => (None, format!("back from placement {instance}")),
    }
}

fn level_text(l: TraceLevel) -> String {
    match l {
        TraceLevel::Mesh => "".into(),
        TraceLevel::Top => "top".into(),
        TraceLevel::Bottom { instance } => format!("mesh@{instance}"),
    }
}

fn counts_json(c: &RayCounters) -> serde_json::Value {
    serde_json::json!({
        "nodes_visited": c.nodes_visited, "box_tests": c.box_tests,
        "leaves_visited": c.leaves_visited, "triangle_tests": c.triangle_tests,
    })
}

pub fn run(a: &TraceArgs) -> Result<(), CliError> {
    let scene = load_mesh(&a.mesh)?;
    let params = a.build.params(scene.build.as_ref());
    let bvh = build_scene(&scene, &a.build.scene_build(params))?;
    let (ray, source) = match (a.pixel, a.ray) {
        (_, Some((o, d))) => (Ray::new(o, d), serde_json::json!({ "typed": true })),
        (Some((x, y)), None) => {
            let camera = a.view_args.camera(&scene.bounds(), scene.camera.as_ref())?;
            if x >= camera.width || y >= camera.height {
                return Err(CliError::Usage(format!(
                    "--pixel {x},{y} is outside the {}x{} image (pixels are 0-based)",
                    camera.width, camera.height
                )));
            }
            (camera.ray_gen().pixel_ray(x, y), serde_json::json!({ "pixel": [x, y], "camera": camera }))
        }
        (None, None) => unreachable!("clap requires --pixel or --ray"),
    };
    let opts = a.build.trace();
    let (hit, trace) = trace_ray(&bvh, &ray, opts);
    let counts = trace.counts();
    let mut o = String::new();
    match a.format {
        TraceFormat::Json => {
            let v = serde_json::json!({
                "ray": { "origin": ray.origin().to_array(), "dir": ray.dir().to_array(), "from": source },
                "build": bvh.build_params().label(),
                "trace": opts,
                "hit": hit.map(|h| serde_json::json!({ "triangle": h.prim, "t": h.t })),
                "counts": counts_json(&counts),
                "steps": trace.steps,
            });
            let _ = writeln!(o, "{}", serde_json::to_string_pretty(&v).expect("plain data serialises"));
        }
        TraceFormat::Text => {
            let (o3, d3) = (ray.origin(), ray.dir());
            let _ = writeln!(
                o,
                "ray             origin ({}, {}, {}), direction ({}, {}, {})",
                o3.x, o3.y, o3.z, d3.x, d3.y, d3.z
            );
            if let Some((x, y)) = a.pixel.filter(|_| a.ray.is_none()) {
                let _ = writeln!(o, "pixel           {x},{y}");
            }
            let _ = writeln!(o, "build           {}", bvh.build_params().label());
            let _ = writeln!(o, "traversal       {} order, {} test", opts.order.label(), opts.test.label());
            let _ = writeln!(o);
            let levels = trace.steps.iter().any(|s| s.level != TraceLevel::Mesh);
            let mut entered = 0;
            for (i, s) in trace.steps.iter().enumerate() {
                let (depth, text) = step_text(s);
                if let StepKind::Enter { depth, .. } = s.kind {
                    entered = depth;
                }
                let depth = depth.unwrap_or(entered + 1);
                let level = if levels { format!("{:<10}", level_text(s.level)) } else { String::new() };
                let _ = writeln!(o, "{:>5}  {level}{}{text}", i + 1, "  ".repeat(depth as usize));
            }
            let _ = writeln!(o);
            match hit {
                Some(h) => {
                    let _ = writeln!(
                        o,
                        "hit             triangle {} at t = {:.6} (u {:.4}, v {:.4})",
                        h.prim, h.t, h.u, h.v
                    );
                }
                None => {
                    let _ = writeln!(o, "hit             nothing");
                }
            }
            let _ = writeln!(
                o,
                "counts          nodes visited {}, box tests {}, leaves visited {}, triangle tests {}",
                counts.nodes_visited, counts.box_tests, counts.leaves_visited, counts.triangle_tests
            );
        }
    }
    print!("{o}");
    Ok(())
}
