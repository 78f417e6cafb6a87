//! `radiant study SCENE`: every method on one scene, measured against one reference at
//! every snapshot, written as one self-contained HTML report (see `radiant::study`).

use std::path::PathBuf;

use anyhow::{Context, bail};
use radiant::image::{Crop, ImageMeta, read_image, write_image};
use radiant::report::{Precision, write_report};
use radiant::study::{Budget, ReferenceSpec, StudyConfig, StudyEvent, run_study};

use crate::render_cmd::{capped_threads, load_scene, parse_resolution, parse_seconds};

/// Arguments of `radiant study`.
#[derive(clap::Args, Debug)]
pub struct StudyArgs {
    /// A pbrt-v4 scene file, or a canonical scene: cornell-box (default), cornell-caustics, furnace.
    pub scene: Option<String>,
    /// Methods (integrators) to compare, in order.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "path,sppm,photonmap,radiosity"
    )]
    pub methods: Vec<String>,
    /// Give every method about this many seconds (passes run until the time is spent).
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds, conflicts_with = "equal_spp")]
    pub equal_time: Option<f64>,
    /// Give every method this many samples per pixel (SPPM: iterations); default 64.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub equal_spp: Option<u32>,
    /// Reference image (.exr, .pfm, .png); without it a long path-traced render is made.
    #[arg(long, value_name = "REF.exr")]
    pub reference: Option<PathBuf>,
    /// Samples per pixel of the self-made reference (default: 64 × --equal-spp, at
    /// least 1024; with --equal-time: 8 × the time instead).
    #[arg(long, value_name = "N", conflicts_with_all = ["reference", "reference_time"],
          value_parser = clap::value_parser!(u32).range(1..))]
    pub reference_spp: Option<u32>,
    /// Seconds for the self-made reference.
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds, conflicts_with = "reference")]
    pub reference_time: Option<f64>,
    /// Measure errors only over pixels x0 <= x < x1, y0 <= y < y1 (row 0 at the top).
    #[arg(long, value_name = "X0,Y0,X1,Y1")]
    pub crop: Option<Crop>,
    /// Image size as WIDTHxHEIGHT, overriding the film's (default with --reference: its size).
    #[arg(long, value_parser = parse_resolution)]
    pub resolution: Option<(u32, u32)>,
    /// Seed of the methods' samplers (the self-made reference uses another).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long, alias = "nthreads")]
    pub threads: Option<usize>,
    /// Store images in the page as half floats (half the size, about 3 digits).
    #[arg(long)]
    pub half: bool,
    /// Also write every final image, and the reference, as DIR/METHOD.exr.
    #[arg(long, value_name = "DIR")]
    pub save_images: Option<PathBuf>,
    /// The report.
    #[arg(short = 'o', long = "outfile", default_value = "study.html")]
    pub output: PathBuf,
    /// No progress lines on stderr.
    #[arg(long)]
    pub quiet: bool,
}

fn describe(budget: Budget) -> String {
    match budget {
        Budget::Spp(n) => format!("{n} spp"),
        Budget::Seconds(s) => format!("{s} s"),
    }
}

pub fn run(args: StudyArgs) -> anyhow::Result<()> {
    radiant::image::atomic::check_writable(&args.output)
        .with_context(|| format!("cannot write the report {}", args.output.display()))?;
    if let Some(dir) = &args.save_images {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let probe = dir.join("reference.exr");
        radiant::image::atomic::check_writable(&probe)
            .with_context(|| format!("cannot write the images into {}", dir.display()))?;
    }
    let budget = match (args.equal_time, args.equal_spp) {
        (Some(s), _) => Budget::Seconds(s),
        (None, n) => Budget::Spp(n.unwrap_or(64)),
    };
    let reference = match &args.reference {
        Some(path) => ReferenceSpec::Image {
            image: read_image(path)
                .with_context(|| format!("cannot read the reference {}", path.display()))?,
            label: path.display().to_string(),
        },
        None => {
            let ref_budget = match (args.reference_spp, args.reference_time, budget) {
                (Some(n), _, _) => Budget::Spp(n),
                (None, Some(s), _) => Budget::Seconds(s),
                (None, None, Budget::Spp(n)) => Budget::Spp(n.saturating_mul(64).max(1024)),
                (None, None, Budget::Seconds(s)) => Budget::Seconds(8.0 * s),
            };
            eprintln!(
                "study: no --reference given: the reference is a path-traced render made now ({}, \
                 another seed); the report says so",
                describe(ref_budget)
            );
            ReferenceSpec::PathTraced(ref_budget)
        }
    };
    let scene_name = args
        .scene
        .clone()
        .unwrap_or_else(|| "cornell-box".to_string());
    let desc = load_scene(Some(&scene_name))?;
    for w in &desc.warnings {
        eprintln!("{w}");
    }
    let title = std::path::Path::new(&scene_name)
        .file_stem()
        .map_or(scene_name.clone(), |s| s.to_string_lossy().into_owned());
    let mut config = StudyConfig::new(args.methods.clone(), budget, reference);
    config.crop = args.crop;
    config.resolution = args.resolution;
    config.seed = args.seed;
    if args.half {
        config.precision = Precision::F16;
    }
    if config.methods.iter().any(|m| m.is_empty()) {
        bail!("--methods: empty method name");
    }

    // The global pool: the scene description is not `Send`, so the study cannot move
    // into a pool's `install`, and one process makes one study.
    if let Some(n) = capped_threads(args.threads) {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("starting worker threads")?;
    }
    let quiet = args.quiet;
    let study = {
        run_study(&title, &desc, &config, &mut |event| match event {
            StudyEvent::Start { label, budget } if !quiet => {
                eprintln!("study: {label}: rendering ({})", describe(budget));
            }
            StudyEvent::Done {
                label,
                seconds,
                samples,
            } if !quiet => eprintln!("study: {label}: {samples} samples in {seconds:.2} s"),
            StudyEvent::Warning(w) => eprintln!("{w}"),
            _ => {}
        })
    }?;

    if let Some(dir) = &args.save_images {
        let meta = |spp: Option<u32>, secs: Option<f64>| ImageMeta {
            samples_per_pixel: spp,
            render_time_seconds: secs,
            software: format!("radiant {}", env!("CARGO_PKG_VERSION")),
        };
        let path = dir.join("reference.exr");
        write_image(&path, &study.reference, &meta(None, None), 0.0)
            .with_context(|| format!("writing {}", path.display()))?;
        for r in &study.runs {
            let path = dir.join(format!("{}.exr", r.integrator));
            write_image(
                &path,
                &r.image,
                &meta(Some(r.samples), Some(r.seconds)),
                0.0,
            )
            .with_context(|| format!("writing {}", path.display()))?;
        }
    }

    let html = write_report(&study.to_report());
    radiant::image::atomic::atomic_write_bytes(&args.output, html.as_bytes())
        .with_context(|| format!("writing {}", args.output.display()))?;

    let slope = |s: Option<f64>| s.map_or_else(|| "-".to_string(), |v| format!("{v:.3}"));
    out!(
        "{:<16} {:>9} {:>9} {:>12} {:>12} {:>10} {:>12} {:>12}",
        "method",
        "samples",
        "time_s",
        "relmse",
        "rmse",
        "flip",
        "slope_spp",
        "slope_time"
    );
    for r in &study.runs {
        let m = &r.measured.metrics;
        out!(
            "{:<16} {:>9} {:>9.2} {:>12.5e} {:>12.5e} {:>10.5} {:>12} {:>12}",
            r.integrator,
            r.samples,
            r.seconds,
            m.relmse,
            m.rmse,
            r.measured.flip_mean,
            slope(r.slope_vs_samples()),
            slope(r.slope_vs_time())
        );
    }
    if !quiet {
        eprintln!(
            "study: {} ({:.1} MB)",
            args.output.display(),
            html.len() as f64 / 1e6
        );
    }
    Ok(())
}
