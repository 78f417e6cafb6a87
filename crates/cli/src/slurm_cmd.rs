//! `radiant slurm`: a distributed render as a Slurm array job (one task per `--part`)
//! and a merge job that runs once every task has succeeded (`--dependency=afterok`).
//! radiant schedules nothing itself: Slurm does, radiant computes and merges.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};
use clap::Args;

use radiant::Session;
use radiant::render::Overrides;

use crate::unit_cmd::{PartBy, UnitArgs};

#[derive(Args, Debug)]
pub struct SlurmArgs {
    /// A pbrt-v4 scene file, or a canonical scene: cornell-box (default), cornell-caustics, furnace.
    pub scene: Option<String>,
    /// Number of units (array tasks).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub parts: u32,
    /// How the render is divided: bands of rows (tiles) or runs of sample blocks.
    #[arg(long, value_enum, default_value_t = PartBy::Tiles)]
    pub part_by: PartBy,
    /// The merged image.
    #[arg(short = 'o', long = "outfile")]
    pub output: PathBuf,
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: Option<u32>,
    #[arg(long)]
    pub seed: Option<u64>,
    #[arg(long)]
    pub integrator: Option<String>,
    /// Image size as WIDTHxHEIGHT.
    #[arg(long, value_parser = crate::render_cmd::parse_resolution)]
    pub resolution: Option<(u32, u32)>,
    /// A saved radiosity solution to display (with --integrator radiosity).
    #[arg(long, value_name = "FILE")]
    pub solution: Option<PathBuf>,
    /// Folder for the job scripts, partial files and logs (default: beside the output,
    /// NAME.slurm).
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// CPUs per task (`--cpus-per-task`); the render uses them all.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    pub cpus: u32,
    /// Slurm partition (`--partition`).
    #[arg(long)]
    pub partition: Option<String>,
    /// Time limit per task (`--time`): minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM or
    /// D-HH:MM:SS.
    #[arg(long, value_parser = parse_time)]
    pub time: Option<String>,
    /// Submit the jobs with sbatch (otherwise only write the scripts).
    #[arg(long)]
    pub submit: bool,
}

/// Slurm's time formats (`--time`): minutes, minutes:seconds, hours:minutes:seconds,
/// days-hours, days-hours:minutes, days-hours:minutes:seconds.
fn parse_time(s: &str) -> Result<String, String> {
    let number = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit());
    let fields = |t: &str, most: usize| {
        let parts: Vec<&str> = t.split(':').collect();
        parts.len() <= most && parts.iter().all(|p| number(p))
    };
    let ok = match s.split_once('-') {
        Some((days, rest)) => number(days) && fields(rest, 3),
        None => fields(s, 3),
    };
    if ok {
        Ok(s.to_string())
    } else {
        Err(format!(
            "\"{}\" is not a Slurm time (minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM or D-HH:MM:SS)",
            s.escape_debug()
        ))
    }
}

/// `path` absolute (the jobs may start in another folder).
fn absolute(path: &Path) -> anyhow::Result<PathBuf> {
    if path.is_absolute() {
        return Ok(path.to_path_buf());
    }
    Ok(std::env::current_dir()?.join(path))
}

/// Single-quoted for the shell.
fn quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// Double-quoted for an `#SBATCH` line, which sbatch splits at blank space, where an
/// unquoted `#` starts a comment and a backslash escapes the next character.
fn sbatch_quote(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', r"\\").replace('"', "\\\""))
}

/// `value` as it may go into a job script: UTF-8 (the script is text) without control
/// characters, which could end a line and start a command of their own.
fn script_text<'a>(what: &str, value: &'a std::ffi::OsStr) -> anyhow::Result<&'a str> {
    let Some(text) = value.to_str() else {
        bail!(
            "{what} {}: not UTF-8, it cannot go into a job script",
            value.to_string_lossy()
        );
    };
    if text.chars().any(char::is_control) {
        bail!(
            "{what} \"{}\": control characters (a newline, a tab…) cannot go into a job script",
            text.escape_debug()
        );
    }
    Ok(text)
}

/// [`script_text`] of a path, as a string.
fn script_path(what: &str, path: &Path) -> anyhow::Result<String> {
    script_text(what, path.as_os_str()).map(str::to_string)
}

/// Folders and files this run made, removed again unless it succeeds (or has queued a
/// job that will write into them), so a failed run leaves nothing behind.
#[derive(Default)]
struct Made {
    paths: Vec<PathBuf>,
    keep: bool,
}

impl Made {
    /// Creates `dir` and any missing folders above it, noting those it made.
    fn dir(&mut self, dir: &Path) -> std::io::Result<()> {
        let mut missing = Vec::new();
        let mut at = Some(dir);
        while let Some(d) = at {
            if d.as_os_str().is_empty() || d.exists() {
                break;
            }
            missing.push(d.to_path_buf());
            at = d.parent();
        }
        for d in missing.into_iter().rev() {
            std::fs::create_dir(&d)?;
            self.paths.push(d);
        }
        Ok(())
    }

    /// Writes `path` atomically, noting it if it is new.
    fn file(&mut self, path: &Path, text: &str) -> anyhow::Result<()> {
        let new = !path.exists();
        radiant::image::atomic::atomic_write_bytes(path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        if new {
            self.paths.push(path.to_path_buf());
        }
        Ok(())
    }
}

impl Drop for Made {
    fn drop(&mut self) {
        if self.keep {
            return;
        }
        for p in self.paths.iter().rev() {
            let _ = if p.is_dir() {
                std::fs::remove_dir(p)
            } else {
                std::fs::remove_file(p)
            };
        }
    }
}

pub fn run(args: SlurmArgs) -> anyhow::Result<()> {
    crate::render_cmd::check_output(&args.output)?;
    crate::render_cmd::check_integrator(args.integrator.as_deref())?;
    let partition = args
        .partition
        .as_deref()
        .map(|p| script_text("--partition", p.as_ref()))
        .transpose()?;
    let output = absolute(&args.output)?;
    let dir = match &args.dir {
        Some(d) => absolute(d)?,
        None => {
            let stem = output
                .file_stem()
                .map_or_else(|| "render".into(), |s| s.to_string_lossy().into_owned());
            output.with_file_name(format!("{stem}.slurm"))
        }
    };
    let exe = std::env::current_exe().context("finding the radiant executable")?;
    let exe = script_path("the radiant executable", &exe)?;
    let dir_text = script_path("--dir", &dir)?;
    let output_text = script_path("-o", &output)?;
    let scene = args.scene.clone().unwrap_or_else(|| "cornell-box".into());
    // A file by its absolute path; a canonical scene by its name.
    let scene = if Path::new(&scene).exists() {
        absolute(Path::new(&scene))?.display().to_string()
    } else {
        scene
    };
    script_text("the scene", scene.as_ref())?;
    let solution = match &args.solution {
        Some(p) => {
            let p = absolute(p)?;
            script_path("--solution", &p)?;
            Some(p)
        }
        None => None,
    };
    let n = args.parts;

    // Every task runs `render --part K/N` with these settings: the scene, the settings
    // and each part are checked here by the code that checks them there, once, before
    // anything is written or queued.
    let desc = crate::render_cmd::load_scene(Some(&scene))?;
    let overrides = Overrides {
        spp: args.spp,
        seed: args.seed,
        resolution: args.resolution,
        integrator: args.integrator.clone(),
    };
    let mut session = Session::new(&desc, &overrides)?;
    let mut unit = UnitArgs {
        part_by: args.part_by,
        solution: solution.clone(),
        ..Default::default()
    };
    unit.load_solution(&mut session, &desc)?;
    for k in 0..n {
        unit.part = Some((k, n));
        unit.unit(&session)
            .with_context(|| format!("--parts {n}: render --part {k}/{n} would refuse it"))?;
    }

    let mut render = vec!["render".to_string(), scene.clone()];
    let mut push = |flag: &str, v: Option<String>| {
        if let Some(v) = v {
            render.push(flag.into());
            render.push(v);
        }
    };
    push("--spp", args.spp.map(|v| v.to_string()));
    push("--seed", args.seed.map(|v| v.to_string()));
    push("--integrator", args.integrator.clone());
    push(
        "--resolution",
        args.resolution.map(|(w, h)| format!("{w}x{h}")),
    );
    push(
        "--solution",
        solution.as_ref().map(|p| p.display().to_string()),
    );
    if args.part_by == PartBy::Samples {
        render.push("--part-by".into());
        render.push("samples".into());
    }
    let part_file = |k: u32| dir.join("parts").join(format!("part-{k}.rpart"));
    let mut header = String::from("#!/bin/bash\n");
    if let Some(p) = partition {
        let _ = writeln!(header, "#SBATCH --partition={}", sbatch_quote(p));
    }
    if let Some(t) = &args.time {
        let _ = writeln!(header, "#SBATCH --time={t}");
    }
    let quoted: Vec<String> = render.iter().map(|a| quote(a)).collect();
    let mut array = header.clone();
    let _ = writeln!(array, "#SBATCH --job-name=radiant-render");
    let _ = writeln!(array, "#SBATCH --array=0-{}", n - 1);
    let _ = writeln!(array, "#SBATCH --cpus-per-task={}", args.cpus);
    let _ = writeln!(
        array,
        "#SBATCH --output={}",
        sbatch_quote(&format!("{dir_text}/logs/render-%A_%a.log"))
    );
    // A preempted or failed task may be run again: its partial is written atomically,
    // so a file that exists is complete, and a rerun replaces it whole.
    let _ = writeln!(array, "#SBATCH --requeue");
    let _ = writeln!(array, "set -euo pipefail");
    let _ = writeln!(array, "K=${{SLURM_ARRAY_TASK_ID}}");
    let _ = writeln!(array, "DIR={}", quote(&dir_text));
    let _ = writeln!(array, "PART=\"$DIR/parts/part-$K.rpart\"");
    let _ = writeln!(
        array,
        "if [ -s \"$PART\" ] && [ -z \"${{RADIANT_RERUN:-}}\" ]; then echo \"unit $K/{n}: $PART exists\"; exit 0; fi"
    );
    let _ = writeln!(
        array,
        "exec {} {} --threads {} --part \"$K/{n}\" --partial \"$PART\" --quiet",
        quote(&exe),
        quoted.join(" "),
        args.cpus
    );
    let mut merge = header;
    let _ = writeln!(merge, "#SBATCH --job-name=radiant-merge");
    let _ = writeln!(
        merge,
        "#SBATCH --output={}",
        sbatch_quote(&format!("{dir_text}/logs/merge-%j.log"))
    );
    let _ = writeln!(merge, "set -euo pipefail");
    let parts: Vec<String> = (0..n)
        .map(|k| quote(&part_file(k).display().to_string()))
        .collect();
    let _ = writeln!(
        merge,
        "exec {} merge {} -o {}",
        quote(&exe),
        parts.join(" "),
        quote(&output_text)
    );
    let mut made = Made::default();
    for d in [dir.join("parts"), dir.join("logs")] {
        made.dir(&d)
            .with_context(|| format!("creating {}", d.display()))?;
    }
    let array_path = dir.join("render.sbatch");
    let merge_path = dir.join("merge.sbatch");
    for (path, text) in [(&array_path, &array), (&merge_path, &merge)] {
        made.file(path, text)?;
    }
    out!("array job: {}", array_path.display());
    out!("merge job: {}", merge_path.display());
    if !args.submit {
        out!(
            "submit with: id=$(sbatch --parsable {}) && sbatch --dependency=afterok:$id {}",
            quote(&format!("{dir_text}/render.sbatch")),
            quote(&format!("{dir_text}/merge.sbatch"))
        );
        made.keep = true;
        return Ok(());
    }
    let sbatch = |extra: &[String], script: &Path| -> anyhow::Result<String> {
        let out = Command::new("sbatch")
            .arg("--parsable")
            .args(extra)
            .arg(script)
            .output()
            .context("running sbatch (is Slurm installed?)")?;
        if !out.status.success() {
            bail!(
                "sbatch {}: {}",
                script.display(),
                String::from_utf8_lossy(&out.stderr).trim()
            );
        }
        // `--parsable` prints "id" or "id;cluster".
        let text = String::from_utf8_lossy(&out.stdout);
        Ok(text.trim().split(';').next().unwrap_or("").to_string())
    };
    let array_id = sbatch(&[], &array_path)?;
    // Its tasks write into the folders now.
    made.keep = true;
    let merge_id = sbatch(&[format!("--dependency=afterok:{array_id}")], &merge_path)?;
    out!("submitted array job {array_id} ({n} tasks), merge job {merge_id}");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{parse_time, sbatch_quote};

    #[test]
    fn times_take_slurms_formats_only() {
        for ok in [
            "90",
            "0",
            "10:30",
            "01:00:00",
            "2-12",
            "2-12:30",
            "2-12:30:15",
        ] {
            assert_eq!(parse_time(ok).as_deref(), Ok(ok));
        }
        for bad in [
            "",
            "1h",
            "1:2:3:4",
            "-5",
            "2-",
            "2-1:2:3:4",
            "1::2",
            "1:00\n",
            "1 0",
            "1-2-3",
            "$(reboot)",
        ] {
            assert!(parse_time(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn sbatch_values_are_one_quoted_word() {
        assert_eq!(sbatch_quote("a b"), r#""a b""#);
        assert_eq!(sbatch_quote(r##"a"#b\"##), r##""a\"#b\\""##);
    }
}
