//! The `radiant` command line: a thin layer over the library.

/// `println!` for the commands' reports. Standard output closed by its reader
/// (`radiant compare a b | head -1`) ends the process quietly instead of panicking, as
/// `println!` does; whatever the command wrote to files is already complete.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!(std::io::stdout(), $($arg)*) {
            $crate::stdout_failed(e)
        }
    }};
}

/// `print!` with [`out!`]'s handling of a closed standard output.
macro_rules! out_part {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = write!(std::io::stdout(), $($arg)*) {
            $crate::stdout_failed(e)
        }
    }};
}

mod bench_cmd;
mod compare_cmd;
mod lens_cmd;
mod pbrt_opts;
mod radiosity_cmd;
mod render_cmd;
mod signals;
mod slurm_cmd;
mod study_cmd;
mod unit_cmd;

use clap::{CommandFactory, Parser, Subcommand};

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
    /// Render a scene (default: the built-in Cornell box).
    Render(render_cmd::RenderArgs),
    /// Error metrics of a render against a reference image (B is the reference).
    ///
    /// Prints rmse, relmse (squared error over reference² + 0.01), mae, the two images'
    /// means, and the non-finite (NaN, ±inf) channel values of each image: `nonfinite`
    /// in the test image, `nonfinite_ref` in the reference. A non-finite test value
    /// counts as 0, so a renderer's NaN raises its error (as `compare.py` treats it); a
    /// non-finite reference value leaves nothing to measure against, so that channel
    /// value is left out of every figure, for both images (`--flip`, which compares
    /// whole pixels, leaves out the pixel).
    Compare(compare_cmd::CompareArgs),
    /// Throughput figures: Mrays/s on the Cornell box and a 1M-triangle mesh, render time.
    Bench(bench_cmd::BenchArgs),
    /// Inspect a realistic-camera lens file: paraxial data, focus, field of view, exit pupil.
    Lens(lens_cmd::LensArgs),
    /// Solve diffuse interreflection on a patch mesh (radiosity): energy balance, lit
    /// mesh export (glTF, PLY), patch table, image or progressive image sequence.
    Radiosity(radiosity_cmd::RadiosityArgs),
    /// Render a scene with several methods (path, sppm, photonmap, radiosity), measure
    /// each snapshot against a reference, and write one interactive HTML report.
    Study(study_cmd::StudyArgs),
    /// Merge the partial files of a distributed render into its image, bit-identical
    /// to the render on one machine.
    Merge(unit_cmd::MergeArgs),
    /// Write (and with --submit, submit) a Slurm array job of a render's parts and a
    /// merge job that runs after them.
    Slurm(slurm_cmd::SlurmArgs),
}

/// pbrt's habit `radiant scene.pbrt [more.pbrt …] [flags]`: when the first argument
/// is neither a subcommand nor a top-level flag (help, version), the arguments are
/// `render`'s. A scene file named like a subcommand is reached as `./render`.
fn with_default_subcommand(mut args: Vec<std::ffi::OsString>) -> Vec<std::ffi::OsString> {
    let Some(first) = args.get(1) else {
        return args;
    };
    // A name that is not UTF-8 is no subcommand: a scene path.
    let Some(first) = first.to_str() else {
        args.insert(1, "render".into());
        return args;
    };
    let cmd = Cli::command();
    let is_subcommand = first == "help"
        || cmd
            .get_subcommands()
            .any(|c| c.get_name() == first || c.get_all_aliases().any(|a| a == first));
    let top_level_flag = matches!(first, "-h" | "--help" | "-V" | "--version");
    if !is_subcommand && !top_level_flag {
        args.insert(1, "render".into());
    }
    args
}

fn main() {
    let cli = Cli::parse_from(with_default_subcommand(std::env::args_os().collect()));
    let result = match cli.command {
        Command::Render(args) => render_cmd::run(args),
        Command::Compare(args) => compare_cmd::run(args),
        Command::Lens(args) => lens_cmd::run(args),
        Command::Bench(args) => bench_cmd::run(args),
        Command::Radiosity(args) => radiosity_cmd::run(args),
        Command::Study(args) => study_cmd::run(args),
        Command::Merge(args) => unit_cmd::run_merge(args),
        Command::Slurm(args) => slurm_cmd::run(args),
    };
    if let Err(e) = result {
        eprintln!("radiant: {}", error_message(&e));
        std::process::exit(1);
    }
}

/// The error and its causes joined by ": ", as anyhow's `{:#}` joins them, less each
/// cause whose text its parent's message already holds: a library error that puts its
/// source in its own message (`#[error("{0}")] Io(#[from] io::Error)`, or
/// `"{path}: {source}"`) would otherwise say the OS error twice.
fn error_message(e: &anyhow::Error) -> String {
    let mut text = String::new();
    let mut parent = String::new();
    for cause in e.chain() {
        let message = cause.to_string();
        if parent.is_empty() || !parent.contains(&message) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&message);
        }
        parent = message;
    }
    text
}

/// Standard output could not be written: a reader that stopped reading (a closed pipe)
/// ends the process with success, anything else is an error.
fn stdout_failed(e: std::io::Error) -> ! {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(0);
    }
    eprintln!("radiant: writing to standard output: {e}");
    std::process::exit(1);
}
