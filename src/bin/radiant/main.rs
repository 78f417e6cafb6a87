//! The `radiant` command line: a thin layer over the library.

mod lens_cmd;

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
    /// Inspect a realistic-camera lens file: paraxial data, focus, field of view, exit pupil.
    Lens(lens_cmd::LensArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Lens(args) => lens_cmd::run(args),
    }
}
