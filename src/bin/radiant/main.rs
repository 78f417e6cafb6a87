//! The `radiant` command line: a thin layer over the library.

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
enum Command {}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {}
}
