//! The `shipsim` command line.
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "shipsim",
    version,
    about = "FMI 2.0 co-simulation master for ship-control systems"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Show an FMU's variables, units and capabilities.
    Inspect {
        /// The .fmu file.
        fmu: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result: shipsim::Result<()> = match cli.command {
        Command::Inspect { fmu } => shipsim::inspect::inspect(&fmu).map(|s| print!("{s}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
