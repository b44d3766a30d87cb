//! The command line: `render`, `stats` and `compare`, over the same core as the app.
//! Errors print one line naming the file and the problem and exit with code 2.

mod args;
pub mod check;
mod command;
mod compare;
pub mod device;
pub(crate) mod error;
mod export_bvh;
mod grade;
pub mod inspect;
pub mod lesson;
pub(crate) mod load;
pub(crate) mod print;
mod progress;
pub(crate) mod rays;
pub(crate) mod render;
pub mod replay;
pub mod stats;
pub mod trace;

pub use crate::gpu_path::{Device, GpuNodes};
pub use args::{parse_camera, parse_size, BuildArgs};
pub use compare::{compare_rows, CompareRow};

pub use command::{run, Cli, Command};
pub use error::CliError;
pub use print::{out, printable};
