//! (issue 59) — filled in by this session.

#[allow(unused_imports)]
use super::*;
