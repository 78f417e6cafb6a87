//! The `radiant` command line: a thin layer over the library.

mod compare_cmd;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "radiant",
    version,
    about = "A physically based global-illumination renderer"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Error metrics of a render against a reference image (B is the reference).
    Compare(compare_cmd::CompareArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Compare(args) => compare_cmd::run(args),
    }
}
