//! Every WGSL file of `shaders/`, one row each with what it is: a node format's walk, a builder,
//! or a part that modules share. Code takes a file's source from here (`source`), and a test
//! reads the folder: every file has its row and every row its file, every walk is a node format
//! of `WALKS` and every builder one of `BUILDS`, so a shader can be neither forgotten nor left
//! behind.

#[cfg(test)]
use crate::trace::Kernels;

/// What a WGSL file is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Role {
    /// The walk of a node format (its `Kernels`, in `WALKS`).
    Walk,
    /// A builder's kernels (in `BUILDS`).
    Build,
    /// A part several modules put together (`kernel::module`, `Kernels::source`), or a kernel of
    /// the builders' sort and scan.
    Shared,
}

pub(crate) struct Shader {
    pub file: &'static str,
    pub source: &'static str,
    /// Read by the test that holds the table against the folder and the registries.
    #[cfg_attr(not(test), allow(dead_code))]
    pub role: Role,
}

macro_rules! shader {
    ($file:literal, $role:ident) => {
        Shader { file: $file, source: include_str!(concat!("shaders/", $file)), role: Role::$role }
    };
}

/// Every file of `shaders/`.
pub(crate) const SHADERS: [Shader; 16] = [
    shader!("prelude.wgsl", Shared),
    shader!("common.wgsl", Shared),
    shader!("triangle.wgsl", Shared),
    shader!("edge_f32.wgsl", Shared),
    shader!("edge_f64.wgsl", Shared),
    shader!("leaf.wgsl", Shared),
    shader!("stack_private.wgsl", Shared),
    shader!("stack_global.wgsl", Shared),
    shader!("entry.wgsl", Shared),
    shader!("boxes.wgsl", Shared),
    shader!("scan.wgsl", Shared),
    shader!("radix_sort.wgsl", Shared),
    shader!("binary.wgsl", Walk),
    shader!("cwbvh.wgsl", Walk),
    shader!("lbvh.wgsl", Build),
    shader!("ploc.wgsl", Build),
];

/// The node formats the GPU walks, by their kernels (each names its walk's file): the shaders'
/// validation and the folder's test go over them.
#[cfg(test)]
pub(crate) const WALKS: [&Kernels; 2] = [&crate::binary::KERNELS, &crate::cwbvh::gpu::KERNELS];

/// A builder: its shader file and its whole module's source.
#[cfg(test)]
type Build = (&'static str, fn() -> String);

/// The builders, for the same tests.
#[cfg(test)]
pub(crate) const BUILDS: [Build; 2] = [("lbvh.wgsl", crate::lbvh::source), ("ploc.wgsl", crate::ploc::source)];

/// The source of `file` (a row of `SHADERS`; a test checks every name code asks for).
pub(crate) fn source(file: &str) -> &'static str {
    match SHADERS.iter().find(|s| s.file == file) {
        Some(s) => s.source,
        None => panic!("{file} is no row of shaders::SHADERS"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The folder and the table hold the same files, and every walk and builder is registered.
    #[test]
    fn every_shader_file_has_one_row_and_every_row_its_file() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/shaders");
        let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
            .expect("the shader folder")
            .map(|e| e.expect("an entry").file_name().to_string_lossy().into_owned())
            .collect();
        on_disk.sort();
        let mut listed: Vec<String> = SHADERS.iter().map(|s| s.file.to_string()).collect();
        listed.sort();
        assert_eq!(on_disk, listed, "shaders/ and shaders::SHADERS");
        listed.dedup();
        assert_eq!(listed.len(), SHADERS.len(), "a file listed twice");
        for s in &SHADERS {
            let registered = match s.role {
                Role::Walk => WALKS.iter().filter(|k| k.walk_file == s.file).count(),
                Role::Build => BUILDS.iter().filter(|(f, _)| *f == s.file).count(),
                Role::Shared => 1,
            };
            assert_eq!(registered, 1, "{}: {:?} registered once", s.file, s.role);
        }
        for k in WALKS {
            assert!(SHADERS.iter().any(|s| s.file == k.walk_file && s.role == Role::Walk), "{}", k.walk_file);
        }
        for (file, _) in BUILDS {
            assert!(SHADERS.iter().any(|s| s.file == file && s.role == Role::Build), "{file}");
        }
    }
}
