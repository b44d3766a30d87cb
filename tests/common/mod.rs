//! Helpers shared by the integration tests: core's (`core/tests/common`), written once for every
//! package's tests.

#[path = "../../core/tests/common/mod.rs"]
mod core_helpers;
#[allow(unused_imports)]
pub use core_helpers::*;
