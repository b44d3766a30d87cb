use bvhscope::cli::{run, Cli, CliError};
use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(command) => run(command),
        None => open_app(cli.file, cli.bvh),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // `check` has printed its report: exit 1 says the BVH has defects.
        Err(CliError::Defects(_)) => ExitCode::from(1),
        Err(e) => {
            // A file name in the message may hold anything, an escape sequence included.
            eprintln!("error: {}", bvhscope::cli::printable(&e.to_string()));
            ExitCode::from(2)
        }
    }
}

#[cfg(feature = "gui")]
fn open_app(file: Option<std::path::PathBuf>, bvh: Option<std::path::PathBuf>) -> Result<(), CliError> {
    bvhscope::app::run(bvhscope::app::AppOptions { file, bvh }).map_err(CliError::Usage)
}

#[cfg(not(feature = "gui"))]
fn open_app(_file: Option<std::path::PathBuf>, _bvh: Option<std::path::PathBuf>) -> Result<(), CliError> {
    Err(CliError::Usage(
        "this build has no desktop app (built without the `gui` feature); use a subcommand, see --help".into(),
    ))
}
