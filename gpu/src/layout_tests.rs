//! Every WGSL struct the CPU writes or reads has a Rust mirror, and the two must agree byte for
//! byte: the struct's size and each field's offset, as naga (the compiler wgpu runs) lays the WGSL
//! out. A field moved, resized or added on one side only fails here, on a machine with no GPU.

use crate::trace::Stack;
use naga::{Module, TypeInner};

/// The size and the members' `(name, offset)` of the WGSL struct `name` in `source`.
fn wgsl_struct(source: &str, name: &str) -> (u32, Vec<(String, u32)>) {
    let module: Module =
        naga::front::wgsl::parse_str(source).unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
    let ty = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name}"));
    match &ty.1.inner {
        TypeInner::Struct { members, span } => {
            (*span, members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect())
        }
        other => panic!("{name} is no struct: {other:?}"),
    }
}

/// The offset of member `member` in a struct's members.
fn offset(members: &[(String, u32)], member: &str) -> u32 {
    members.iter().find(|(n, _)| n == member).unwrap_or_else(|| panic!("no member {member}")).1
}

/// `$ty` (Rust) mirrors the WGSL struct `$wgsl` of `$source`: the same size, each Rust field at
/// its WGSL member's offset, and every Rust field named (the struct pattern has no `..`, so a
/// field added to the Rust side does not compile until it is listed here). Every WGSL member
/// must lie at or after the previous one's offset inside the size, so listing the first member
/// of a run (`ox` for `o: [f32; 3]`) with the size check covers the run. Fields packed inside
/// one WGSL member (`; inside axis, _pad`) are listed but have no offset of their own there.
macro_rules! mirror {
    ($ty:ty, $pattern:ident, $source:expr, $wgsl:literal { $($field:ident => $member:literal),* $(,)? $(; inside $($packed:ident),*)? }) => {{
        #[allow(dead_code)]
        fn every_field_is_listed(v: $ty) {
            let $pattern { $($field: _,)* $($($packed: _),*)? } = v;
        }
        let (size, members) = wgsl_struct(&$source, $wgsl);
        assert_eq!(size as usize, std::mem::size_of::<$ty>(), "{}: WGSL {} bytes, Rust {}", $wgsl, size, std::mem::size_of::<$ty>());
        let mut listed = Vec::new();
        $(
            let wgsl = offset(&members, $member);
            let rust = std::mem::offset_of!($ty, $field);
            assert_eq!(wgsl as usize, rust, "{}.{} at {} in WGSL, {}.{} at {} in Rust", $wgsl, $member, wgsl, stringify!($ty), stringify!($field), rust);
            listed.push($member);
        )*
        listed.len()
    }};
}

fn walk_source() -> String {
    crate::binary::KERNELS.source(false, Stack::Private(32))
}

#[test]
fn the_trace_uniforms_and_rays_match_their_rust_mirrors() {
    use crate::trace::{Params, RayIn};
    mirror!(Params, Params, walk_source(), "Params" {
        origin => "origin", forward => "forward", right => "right", up => "up", root_lo => "root_lo",
        root_hi => "root_hi", inv_w => "inv_w", inv_h => "inv_h", width => "width", height => "height",
        count => "count", offset => "offset", stack_stride => "stack_stride", never => "never",
    });
    mirror!(RayIn, RayIn, walk_source(), "RayIn" { o => "ox", t_min => "t_min", d => "dx", t_max => "t_max" });
}

#[test]
fn the_nodes_and_triangles_match_core_and_the_cwbvh_format() {
    use bvhscope_core::bvh::BvhNode;
    // core's 32-byte node, uploaded byte for byte: count, axis and pad are `info`'s bytes.
    mirror!(BvhNode, BvhNode, walk_source(), "Node" {
        lo => "lo_x", hi => "hi_x", index => "index", count => "info"; inside axis, _pad
    });
    let (size, _) = wgsl_struct(&walk_source(), "Tri");
    assert_eq!(size as usize, std::mem::size_of::<[glam::Vec3; 3]>());
    let cwbvh = crate::cwbvh::gpu::KERNELS.source(false, Stack::Private(32));
    let (size, _) = wgsl_struct(&cwbvh, "CNode");
    assert_eq!(size as usize, std::mem::size_of::<crate::cwbvh::CwbvhNode>());
}

#[test]
fn the_builders_parameters_match_their_rust_mirrors() {
    use crate::{lbvh::LParams, ploc::PParams, scan::ScanParams, sort::SortParams};
    mirror!(LParams, LParams, crate::lbvh::source(), "LParams" {
        lo => "lo", scale => "scale", n => "n", max_leaf => "max_leaf", pad => "_pad0",
    });
    mirror!(PParams, PParams, crate::ploc::source(), "PParams" { count => "count", radius => "radius", n => "n", never => "never" });
    mirror!(SortParams, SortParams, crate::shaders::source("radix_sort.wgsl"), "SortParams" {
        n => "n", shift => "shift", tiles => "tiles", pad => "_pad",
    });
    mirror!(ScanParams, ScanParams, crate::shaders::source("scan.wgsl"), "ScanParams" {
        len => "len", blocks => "blocks", pad => "_pad0",
    });
}

/// The check can fail: a mirror with two fields swapped is caught.
#[test]
#[should_panic(expected = "RayIn.t_min at 12 in WGSL")]
fn a_moved_field_is_caught() {
    #[repr(C)]
    #[allow(dead_code)]
    struct Moved {
        o: [f32; 3],
        d: [f32; 3],
        t_min: f32,
        t_max: f32,
    }
    mirror!(Moved, Moved, walk_source(), "RayIn" { o => "ox", t_min => "t_min", d => "dx", t_max => "t_max" });
}
