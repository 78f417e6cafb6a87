//! `radiant slurm`: a distributed render as a Slurm array job (one task per `--part`)
//! and a merge job that runs once every task has succeeded (`--dependency=afterok`).
//! radiant schedules nothing itself: Slurm does, radiant computes and merges.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};
use clap::Args;

use crate::unit_cmd::PartBy;

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
    #[arg(long)]
    pub resolution: Option<String>,
    /// A saved radiosity solution to display (with --integrator radiosity).
    #[arg(long, value_name = "FILE")]
    pub solution: Option<PathBuf>,
    /// Folder for the job scripts, partial files and logs (default: beside the output,
    /// NAME.slurm).
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// CPUs per task (`--cpus-per-task`); the render uses them all.
    #[arg(long, default_value_t = 1)]
    pub cpus: u32,
    /// Slurm partition (`--partition`).
    #[arg(long)]
    pub partition: Option<String>,
    /// Time limit per task (`--time`, e.g. 01:00:00).
    #[arg(long)]
    pub time: Option<String>,
    /// Submit the jobs with sbatch (otherwise only write the scripts).
    #[arg(long)]
    pub submit: bool,
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

pub fn run(args: SlurmArgs) -> anyhow::Result<()> {
    crate::render_cmd::check_output(&args.output)?;
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
    std::fs::create_dir_all(dir.join("parts"))
        .and_then(|_| std::fs::create_dir_all(dir.join("logs")))
        .with_context(|| format!("creating {}", dir.display()))?;
    let scene = args.scene.clone().unwrap_or_else(|| "cornell-box".into());
    // A file by its absolute path; a canonical scene by its name.
    let scene = if Path::new(&scene).exists() {
        absolute(Path::new(&scene))?.display().to_string()
    } else {
        scene
    };
    // The scene and settings are read and checked here, once, before anything is queued.
    crate::render_cmd::load_scene(Some(&scene))?;
    let exe = std::env::current_exe().context("finding the radiant executable")?;
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
    push("--resolution", args.resolution.clone());
    push(
        "--solution",
        args.solution
            .as_deref()
            .map(absolute)
            .transpose()?
            .map(|p| p.display().to_string()),
    );
    if args.part_by == PartBy::Samples {
        render.push("--part-by".into());
        render.push("samples".into());
    }
    let n = args.parts;
    let part_file = |k: u32| dir.join("parts").join(format!("part-{k}.rpart"));
    let mut header = String::from("#!/bin/bash\n");
    if let Some(p) = &args.partition {
        let _ = writeln!(header, "#SBATCH --partition={p}");
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
        dir.join("logs/render-%A_%a.log").display()
    );
    // A preempted or failed task may be run again: its partial is written atomically,
    // so a file that exists is complete, and a rerun replaces it whole.
    let _ = writeln!(array, "#SBATCH --requeue");
    let _ = writeln!(array, "set -euo pipefail");
    let _ = writeln!(array, "K=${{SLURM_ARRAY_TASK_ID}}");
    let _ = writeln!(array, "DIR={}", quote(&dir.display().to_string()));
    let _ = writeln!(array, "PART=\"$DIR/parts/part-$K.rpart\"");
    let _ = writeln!(
        array,
        "if [ -s \"$PART\" ] && [ -z \"${{RADIANT_RERUN:-}}\" ]; then echo \"unit $K/{n}: $PART exists\"; exit 0; fi"
    );
    let _ = writeln!(
        array,
        "exec {} {} --threads {} --part \"$K/{n}\" --partial \"$PART\" --quiet",
        quote(&exe.display().to_string()),
        quoted.join(" "),
        args.cpus
    );
    let mut merge = header;
    let _ = writeln!(merge, "#SBATCH --job-name=radiant-merge");
    let _ = writeln!(
        merge,
        "#SBATCH --output={}",
        dir.join("logs/merge-%j.log").display()
    );
    let _ = writeln!(merge, "set -euo pipefail");
    let parts: Vec<String> = (0..n)
        .map(|k| quote(&part_file(k).display().to_string()))
        .collect();
    let _ = writeln!(
        merge,
        "exec {} merge {} -o {}",
        quote(&exe.display().to_string()),
        parts.join(" "),
        quote(&output.display().to_string())
    );
    let array_path = dir.join("render.sbatch");
    let merge_path = dir.join("merge.sbatch");
    for (path, text) in [(&array_path, &array), (&merge_path, &merge)] {
        radiant::image::atomic::atomic_write_bytes(path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    out!("array job: {}", array_path.display());
    out!("merge job: {}", merge_path.display());
    if !args.submit {
        out!(
            "submit with: id=$(sbatch --parsable {}) && sbatch --dependency=afterok:$id {}",
            array_path.display(),
            merge_path.display()
        );
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
    let merge_id = sbatch(&[format!("--dependency=afterok:{array_id}")], &merge_path)?;
    out!("submitted array job {array_id} ({n} tasks), merge job {merge_id}");
    Ok(())
}
