//! This package only holds the app's UI tests: `cargo test --workspace` runs them; the tests are
//! in `../tests/ui/app.rs`.
