//! Every WGSL module this crate compiles (the walks and builders of `shaders::WALKS` and
//! `shaders::BUILDS`, the sort's and the scan's kernels), parsed and validated by naga (the compiler wgpu runs)
//! without any adapter: a machine with no GPU at all still checks the shaders.

#[cfg(test)]
mod tests {
    use crate::trace::Stack;

    fn validate(name: &str, source: &str, f64: bool) {
        let module =
            naga::front::wgsl::parse_str(source).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
        let caps = if f64 { naga::valid::Capabilities::FLOAT64 } else { naga::valid::Capabilities::empty() };
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), caps)
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    }

    #[test]
    fn every_shader_variant_parses_and_validates() {
        for kernels in crate::shaders::WALKS {
            for f64 in [true, false] {
                for stack in [Stack::Private(32), Stack::Private(128), Stack::Global(1000)] {
                    validate(&format!("{} {stack:?} f64={f64}", kernels.walk_file), &kernels.source(f64, stack), f64);
                }
            }
        }
        for file in ["scan.wgsl", "radix_sort.wgsl"] {
            validate(file, crate::shaders::source(file), false);
        }
        for (file, source) in crate::shaders::BUILDS {
            validate(file, &source(), false);
        }
    }

    /// Without doubles, a module that uses them is refused: the check can fail.
    #[test]
    #[should_panic(expected = "f64")]
    fn a_module_with_doubles_needs_the_capability() {
        validate("f64", &crate::binary::KERNELS.source(true, Stack::Private(32)), false);
    }
}
