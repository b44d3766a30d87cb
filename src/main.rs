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
        // A reader that stopped early (`| head`): the rest was not wanted; the status a Unix tool
        // killed by SIGPIPE has.
        Err(CliError::Stdout(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::from(141),
        Err(e) => {
            // One line (a driver's message comes in several), and a file name in it may hold
            // anything, an escape sequence included.
            let text = e.to_string();
            let one: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
            eprintln!("error: {}", bvhscope::cli::printable(&one.join(" ")));
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
