//! Words the app and the command line both print, written once: ordinals, and the command lines
//! that reproduce what the app shows.

use crate::bvh::{SceneBuild, TraceOptions};
use crate::geometry::Ray;
use crate::options::BUILD_PARAMS;
use glam::Vec3;
use std::path::Path;

/// 1st, 2nd, 3rd, 4th, … (11th, 12th, 13th).
pub fn ordinal(k: u32) -> String {
    let suffix = match (k % 10, k % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{k}{suffix}")
}

/// The options that rebuild `build` and trace with `opts`, every one given (so neither a preset
/// nor a scene file's settings change them): what the app writes when it names the command line
/// that reproduces what it shows. `BuildArgs` parses them back to the same values.
pub fn build_flags(build: &SceneBuild, opts: TraceOptions) -> Vec<String> {
    let p = &build.bvh;
    let mut out = vec![
        format!("--strategy {}", p.strategy.name()),
        format!("--layout {}", p.layout.name()),
        format!("--order {}", opts.order.name()),
        format!("--triangle-test {}", opts.test.name()),
    ];
    out.splice(1..1, BUILD_PARAMS.iter().map(|o| format!("--{} {}", o.name, o.param.get(p))));
    if let Some(top) = &build.top {
        out.push("--two-level".into());
        out.push(format!("--top-strategy {}", top.strategy.name()));
        out.push(format!("--top-max-leaf-size {}", top.max_leaf_size));
    }
    out
}

/// A path as one shell word: as it is when it needs no quoting, else in single quotes.
pub fn shell_word(s: &str) -> String {
    if !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || "/._-+,:=@%".contains(c)) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// The `bvhscope trace` command that rebuilds `build` over the scene file at `path` and traces
/// `ray` as the app did (the Ray window shows it, to paste into a terminal or a lab report). The
/// ray is given as numbers (each written so it reads back to the same `f32`), not as a pixel, so
/// the window's size does not matter.
/// An imported tree's trace names its dump (`--bvh`) instead of the build.
/// The text up to its first full stop followed by a space, if more follows it (a scene's note
/// in one line: the command line and the app show the rest on asking).
pub fn first_sentence(text: &str) -> Option<&str> {
    let end = text.find(". ")?;
    Some(&text[..=end])
}

pub fn trace_command(path: &Path, ray: &Ray, build: &SceneBuild, opts: TraceOptions, dump: Option<&Path>) -> String {
    let v = |v: Vec3| format!("{},{},{}", v.x, v.y, v.z);
    let mut words = vec!["bvhscope trace".to_string(), shell_word(&path.display().to_string())];
    words.push(format!("--ray {}:{}", v(ray.origin()), v(ray.dir())));
    match dump {
        Some(d) => {
            words.push(format!("--bvh {}", shell_word(&d.display().to_string())));
            words.extend(
                build_flags(build, opts)
                    .into_iter()
                    .filter(|w| w.starts_with("--order") || w.starts_with("--triangle-test")),
            );
        }
        None => words.extend(build_flags(build, opts)),
    }
    words.join(" ")
}

/// The `bvhscope trace` command that walks secondary ray `index` of pixel `pixel` on `camera`
/// (a secondary ray starts at the pixel's hit, so it is named by the pixel, the camera and the
/// rays' settings, not as numbers), through `build` over the scene file at `path`.
pub fn secondary_trace_command(
    path: &Path,
    camera: &crate::render::Camera,
    (x, y): (u32, u32),
    spec: &crate::render::SecondarySpec,
    index: usize,
    build: &SceneBuild,
    opts: TraceOptions,
) -> String {
    let v = |v: Vec3| format!("{},{},{}", v.x, v.y, v.z);
    let mut words = vec!["bvhscope trace".to_string(), shell_word(&path.display().to_string())];
    words.push(format!("--pixel {x},{y}"));
    words.push(format!("--camera {}:{}:{}", v(camera.position), v(camera.look_at), v(camera.up)));
    words.push(format!("--fov {} --size {}x{}", camera.vfov_deg, camera.width, camera.height));
    words.push(format!("--ray-kind {} --samples {} --ao-length {}", spec.kind.name(), spec.samples, spec.ao_length));
    if let Some(l) = spec.light {
        words.push(format!("--light {}", v(l)));
    }
    words.push(format!("--seed {} --secondary {index}", spec.seed));
    words.extend(build_flags(build, opts));
    words.join(" ")
}

/// The `bvhscope compare` command that times `build`'s tree on the same rays as the app's
/// speed-up over the linear scan: the same camera and image size, the same traversal, the same
/// runs (`explain::timing`); its row of the strategy is the app's figure, up to timing noise.
pub fn compare_command(path: &Path, build: &SceneBuild, opts: TraceOptions, camera: &crate::render::Camera) -> String {
    let v = |v: Vec3| format!("{},{},{}", v.x, v.y, v.z);
    let mut words = vec!["bvhscope compare".to_string(), shell_word(&path.display().to_string())];
    words.extend(build_flags(build, opts).into_iter().filter(|w| !w.starts_with("--strategy")));
    words.push(format!("--camera {}:{}:{}", v(camera.position), v(camera.look_at), v(camera.up)));
    words.push(format!("--fov {} --size {}x{}", camera.vfov_deg, camera.width, camera.height));
    words.join(" ")
}

#[cfg(test)]
mod tests {
    #[test]
    fn ordinals() {
        let o: Vec<String> = [1, 2, 3, 4, 11, 12, 13, 21, 22, 101, 111].into_iter().map(super::ordinal).collect();
        assert_eq!(o, ["1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "22nd", "101st", "111th"]);
    }
}
