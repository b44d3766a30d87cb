use bvhscope::cli::{run, Cli, CliError};
use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match (cli.command, cli.file) {
        (Some(command), _) => run(command),
        (None, _) => Err(CliError::Usage(
            "the desktop app is not part of this build yet; use a subcommand (see --help)".into(),
        )),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
