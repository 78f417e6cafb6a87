//! `radiant render`: render a scene file or a canonical scene to an image.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Duration;

use anyhow::{Context, bail};
use clap::Args;
use radiant::checkpoint::{self, RunKey};
use radiant::image::{ImageMeta, write_image};
use radiant::render::integrator::{CheckpointHook, IntegratorState, StateKind};
use radiant::render::{Overrides, Progress};

use crate::pbrt_opts::{AOV_SAMPLES, LogLevel, MemoryUse, PassWatchers, PbrtArgs, PhaseTimes};
use crate::signals::Interrupts;
use radiant::scene::{
    SceneDesc,
    builtin::{BUILTIN_SCENES, builtin_scene},
};
use radiant::{INTEGRATOR_NAMES, Session};

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// A pbrt-v4 scene file, or a canonical scene: cornell-box (default), cornell-caustics, furnace.
    pub scene: Option<String>,
    /// More pbrt-v4 scene files, read after the first as if appended to it (as
    /// `pbrt a.pbrt b.pbrt` does).
    #[arg(value_name = "MORE_SCENES")]
    pub more_scenes: Vec<String>,
    /// Samples per pixel (overrides the scene's Sampler "pixelsamples").
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: Option<u32>,
    /// Seed of the sampler (overrides the scene's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long, alias = "nthreads")]
    pub threads: Option<usize>,
    /// Output image; the format follows the extension (.exr, .pfm, .png).
    #[arg(short = 'o', long = "outfile")]
    pub output: Option<PathBuf>,
    /// Integrator, overriding the scene's (path, sppm, photonmap, photonviz, radiosity).
    #[arg(long)]
    pub integrator: Option<String>,
    /// Also write the image whenever the samples per pixel (SPPM: iterations) reach a
    /// power of two, as NAME-00016.EXT beside the output.
    #[arg(long)]
    pub snapshots: bool,
    /// Adaptive sampling: --spp becomes the mean samples per pixel; a uniform pilot of a
    /// quarter of them estimates each pixel's relative variance, and the rest go where
    /// it is highest (in proportion to its square root, 5x5-smoothed). Path tracer,
    /// photon map and radiosity display; whole images, not units.
    #[arg(long)]
    pub adaptive: bool,
    /// Image size as WIDTHxHEIGHT, overriding the film's.
    #[arg(long, value_parser = parse_resolution)]
    pub resolution: Option<(u32, u32)>,
    /// Exposure in stops for PNG output.
    #[arg(long, default_value_t = 0.0, value_parser = parse_exposure, allow_hyphen_values = true)]
    pub exposure: f32,
    /// No progress bar and no summary.
    #[arg(long)]
    pub quiet: bool,
    /// Largest memory the render may plan for (bytes, or with K, M, G, T: 16G); default
    /// three quarters of the physical memory.
    #[arg(long, value_parser = parse_bytes, value_name = "BYTES")]
    pub memory_limit: Option<u64>,
    #[command(flatten)]
    pub checkpoint: CheckpointArgs,
    #[command(flatten)]
    pub unit: crate::unit_cmd::UnitArgs,
    #[command(flatten)]
    pub pbrt: PbrtArgs,
}

/// Checkpoint and resume flags (shared by `render` and `radiosity`).
#[derive(Args, Debug, Default)]
pub struct CheckpointArgs {
    /// Save the render's state to FILE at pass boundaries every --checkpoint-every
    /// seconds, on SIGINT, SIGTERM or SIGHUP, and at the end; --resume FILE continues it.
    #[arg(long, value_name = "FILE")]
    pub checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints (at the first pass boundary after each interval).
    #[arg(long, value_name = "SECONDS", default_value_t = 300.0, value_parser = parse_seconds)]
    pub checkpoint_every: f64,
    /// Continue from a checkpoint of the same scene and settings; the final image is
    /// bit-identical to an uninterrupted render. Checkpoints go on to FILE unless
    /// --checkpoint names another.
    #[arg(long, value_name = "FILE")]
    pub resume: Option<PathBuf>,
    /// Stop (as if interrupted, saving the checkpoint) at the first pass boundary with
    /// this many samples per pixel (an adaptive render's mean, after its pilot),
    /// iterations or shots done (for tests).
    #[arg(long, value_name = "N", hide = true)]
    pub stop_after: Option<u32>,
}

impl CheckpointArgs {
    /// Where checkpoints are written, if anywhere.
    pub fn target(&self) -> Option<&Path> {
        self.checkpoint.as_deref().or(self.resume.as_deref())
    }

    /// Refuses, before any work, flags that cannot work together or a checkpoint path
    /// that cannot be written.
    pub fn check(&self) -> anyhow::Result<()> {
        if self.stop_after.is_some() && self.target().is_none() {
            bail!("--stop-after needs --checkpoint FILE");
        }
        if let Some(path) = self.target() {
            radiant::image::atomic::check_writable(path)
                .with_context(|| format!("cannot write the checkpoint {}", path.display()))?;
        }
        Ok(())
    }

    /// Reads the checkpoint to resume from, refusing one of another run.
    pub fn load(&self, key: &RunKey) -> anyhow::Result<Option<checkpoint::State>> {
        let Some(path) = &self.resume else {
            return Ok(None);
        };
        let saved = checkpoint::read(path)
            .with_context(|| format!("--resume {}: cannot read the checkpoint", path.display()))?;
        saved
            .key
            .check(key)
            .with_context(|| format!("--resume {}", path.display()))?;
        Ok(Some(saved.state))
    }
}

/// A positive, finite number of seconds.
pub fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!(
            "expected a positive number of seconds, got \"{s}\""
        )),
    }
}

/// `16G`, `512M`, `1.5e9`: a number of bytes with an optional binary unit suffix.
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (number, scale) = match t.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => {
            let scale = match c.to_ascii_uppercase() {
                'K' => 1u64 << 10,
                'M' => 1 << 20,
                'G' => 1 << 30,
                'T' => 1 << 40,
                _ => return Err(format!("unknown unit '{c}' in \"{s}\" (use K, M, G or T)")),
            };
            (&t[..i], scale)
        }
        _ => (t, 1),
    };
    match number.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 1.0 => Ok((v * scale as f64).min(u64::MAX as f64) as u64),
        _ => Err(format!("expected a positive number of bytes, got \"{s}\"")),
    }
}

/// A finite number of stops (NaN or infinity would make every pixel black or white).
pub fn parse_exposure(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(format!("must be a finite number of stops, got {v}")),
        Err(_) => Err(format!("expected a number of stops, got \"{s}\"")),
    }
}

pub fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got \"{s}\""))?;
    let parse = |v: &str| v.trim().parse::<u32>().ok().filter(|&n| n > 0);
    match (parse(w), parse(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(format!("expected positive WIDTHxHEIGHT, got \"{s}\"")),
    }
}

/// A scene may name pbrt integrators radiant lacks (a warning, then the path tracer);
/// a name typed on the command line must be one radiant has.
pub fn check_integrator(name: Option<&str>) -> anyhow::Result<()> {
    if let Some(name) = name
        && !INTEGRATOR_NAMES.contains(&name)
    {
        bail!(
            "--integrator {name}: unknown integrator (radiant has: {})",
            INTEGRATOR_NAMES.join(", ")
        );
    }
    Ok(())
}

/// Reads a scene file, or builds a canonical scene by name.
pub fn load_scene(scene: Option<&str>) -> anyhow::Result<SceneDesc> {
    let name = scene.unwrap_or("cornell-box");
    let path = Path::new(name);
    if !path.exists() {
        if let Some(desc) = builtin_scene(name) {
            return Ok(desc);
        }
        if path.extension().is_none() {
            bail!(
                "{name}: no such scene file, and not a canonical scene ({})",
                BUILTIN_SCENES.join(", ")
            );
        }
    }
    Ok(radiant::scene::parse_file(path)?)
}

/// [`load_scene`], or with more files the files read in order as one scene.
pub fn load_scenes(scene: Option<&str>, more: &[String]) -> anyhow::Result<SceneDesc> {
    if more.is_empty() {
        return load_scene(scene);
    }
    let paths: Vec<PathBuf> = scene
        .into_iter()
        .chain(more.iter().map(String::as_str))
        .map(PathBuf::from)
        .collect();
    Ok(radiant::scene::parse_files(&paths)?)
}

pub fn run(args: RenderArgs) -> anyhow::Result<()> {
    check_integrator(args.integrator.as_deref())?;
    // A path the image, or any other output, cannot be written to is refused before
    // any work.
    if let Some(output) = &args.output {
        check_output(output)?;
    }
    args.checkpoint.check()?;
    args.unit.check_outputs()?;
    args.pbrt.check_outputs()?;
    let threads = capped_threads(args.threads);
    if let Some(bytes) = args.memory_limit {
        radiant::render::budget::set_limit(bytes);
    }
    let mut times = PhaseTimes::default();
    let phase = std::time::Instant::now();
    let desc = load_scenes(args.scene.as_deref(), &args.more_scenes)?;
    times.parse = phase.elapsed().as_secs_f64();
    let warn = args.pbrt.log_level < LogLevel::Fatal;
    let summary = !args.quiet && warn;
    if warn {
        for w in &desc.warnings {
            eprintln!("{w}");
        }
    }
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(desc.output_name()));
    if args.output.is_none() {
        // The name came from the scene's Film: say where it was written.
        check_output(&output)
            .map_err(|e| anyhow::anyhow!("{}: Film \"filename\": {e:#}", desc.film.loc))?;
    }
    let mut aovs = args.pbrt.aov_set();
    let variance = args.pbrt.wants_variance() || desc.film.gbuffer.is_some();
    if desc.film.gbuffer.is_some() {
        aovs = radiant::render::aov::AovSet::ALL;
    }
    if (aovs.any() || variance)
        && radiant::image::Format::from_path(&output).ok() != Some(radiant::image::Format::Exr)
    {
        bail!(
            "{}: AOV channels (--aov, Film \"gbuffer\") need an EXR output",
            output.display()
        );
    }
    let overrides = Overrides {
        spp: if args.pbrt.quick { Some(1) } else { args.spp },
        seed: args.seed,
        resolution: if args.pbrt.quick {
            Some(
                args.pbrt.quick_resolution(
                    args.resolution
                        .unwrap_or((desc.film.xresolution, desc.film.yresolution)),
                ),
            )
        } else {
            args.resolution
        },
        integrator: args.integrator.clone(),
    };
    let phase = std::time::Instant::now();
    let mut session = Session::new(&desc, &overrides)?;
    session.ctx.moments = variance;
    times.build = phase.elapsed().as_secs_f64();
    if args.adaptive {
        // Its counts come from the whole image's pilot, which a unit does not see.
        if session.integrator.state_kind() != StateKind::Film {
            bail!(
                "--adaptive: the {} integrator does not take its samples pixel by pixel",
                session.integrator.name()
            );
        }
        if args.unit.any() {
            bail!("--adaptive renders whole images, not a unit of one");
        }
        session.ctx.adaptive = true;
    }
    if warn {
        for w in &session.warnings {
            eprintln!("{w}");
        }
    }
    // A unit of a distributed render restarts whole: its checkpoint would be its
    // partial file.
    if args.unit.any() && args.checkpoint.target().is_some() {
        bail!("--checkpoint and --resume render the whole image, not a unit of it");
    }
    if args.unit.any() && (aovs.any() || variance) {
        bail!(
            "AOV channels (--aov, Film \"gbuffer\") are written for whole images, not for a unit of one"
        );
    }
    args.unit.load_solution(&mut session, &desc)?;
    let unit = args.unit.apply(&mut session)?;
    let image_wanted = args.unit.partial.is_none() || args.output.is_some();
    let mut watchers =
        PassWatchers::new(&args.pbrt, &output, args.exposure, session.ctx.film_size())?;
    let counts_before = radiant::render::stats::Counts::now();
    let ckpt = &args.checkpoint;
    let key = ckpt.target().map(|_| session.run_key(&desc));
    let resume = match &key {
        Some(key) => match ckpt.load(key)? {
            Some(checkpoint::State::Render(state)) => Some(state),
            Some(other) => bail!(
                "--resume: the checkpoint holds {} state, not a render's",
                other.kind()
            ),
            None => None,
        },
        None => None,
    };
    if let Some(state) = &resume
        && !args.quiet
    {
        eprintln!(
            "resuming from {} spp (SPPM: iterations) of {}",
            state.done(),
            session.ctx.spp
        );
    }

    let interrupts = Interrupts::install()?;
    let progress = Arc::clone(&interrupts.progress);
    let pool = worker_pool(threads)?;
    let show_bar = !args.quiet && std::io::stderr().is_terminal();
    let mut output_data = std::thread::scope(|scope| {
        let bar_done = Arc::new(std::sync::atomic::AtomicBool::new(false));
        if show_bar {
            let progress = Arc::clone(&progress);
            let bar_done = Arc::clone(&bar_done);
            scope.spawn(move || draw_progress(&progress, &bar_done));
        }
        let mut snapshot_errors = Vec::new();
        let mut snapshot = |n: u32, film: &radiant::image::Film| {
            if !args.snapshots {
                return;
            }
            let path = snapshot_path(&output, n);
            let meta = ImageMeta {
                samples_per_pixel: Some(n),
                render_time_seconds: None,
                software: format!("radiant {}", env!("CARGO_PKG_VERSION")),
            };
            let _writing = interrupts.writing();
            if let Err(e) = write_image(&path, &film.image(), &meta, args.exposure) {
                snapshot_errors.push(format!("writing {}: {e}", path.display()));
            }
        };
        let mut checkpoint_errors = Vec::new();
        let mut last_checkpoint = std::time::Instant::now();
        let every = Duration::from_secs_f64(ckpt.checkpoint_every);
        let mut hook = |done: u32, state: &dyn Fn() -> IntegratorState| {
            if ckpt.stop_after.is_some_and(|k| done >= k) {
                // Saved with the interrupted render's state below.
                return std::ops::ControlFlow::Break(());
            }
            if let (Some(path), Some(key)) = (ckpt.target(), &key)
                && last_checkpoint.elapsed() >= every
            {
                let _writing = interrupts.writing();
                if let Err(e) = checkpoint::write(path, key, &checkpoint::State::Render(state())) {
                    checkpoint_errors.push(format!("writing {}: {e}", path.display()));
                }
                last_checkpoint = std::time::Instant::now();
            }
            std::ops::ControlFlow::Continue(())
        };
        let want_hook = key.is_some();
        let want_watch = watchers.any();
        let mut watch = |n: u32, film: &radiant::image::Film| watchers.pass(n, film);
        let out = pool.install(|| {
            let hook = want_hook.then_some(&mut hook as &mut CheckpointHook<'_>);
            let watch =
                want_watch.then_some(&mut watch as &mut dyn FnMut(u32, &radiant::image::Film));
            session.render_watched(&progress, &mut snapshot, resume, hook, watch)
        });
        bar_done.store(true, Ordering::SeqCst);
        for e in snapshot_errors.iter().chain(&checkpoint_errors) {
            eprintln!("warning: {e}");
        }
        out
    })?;

    // The state goes to the checkpoint before the image: it is what an interrupted
    // render cannot make again.
    if let (Some(path), Some(key), Some(state)) = (ckpt.target(), &key, output_data.state.take()) {
        let _writing = interrupts.writing();
        checkpoint::write(path, key, &checkpoint::State::Render(state))
            .with_context(|| format!("writing the checkpoint {}", path.display()))?;
        if !args.quiet || output_data.interrupted {
            eprintln!("checkpoint: {}", path.display());
        }
    }

    // A radiosity solve that diverged leaves no image: an error, not a black picture.
    if let Some(failure) = output_data
        .stats
        .get::<radiant::radiosity::integrator::RadiosityFailure>()
    {
        bail!("{failure}; no image written");
    }
    // Interrupted solves have not distributed their light yet: no escape warning.
    if let Some(warning) = output_data
        .stats
        .get::<radiant::radiosity::solve::RadiosityStats>()
        .filter(|_| !output_data.interrupted)
        .and_then(|s| s.balance.escape_warning(s.escape))
    {
        eprintln!("warning: {warning}");
    }
    // Stopped before every pixel had a sample (photon tracing, radiosity solve, the first
    // pass): such an image would pass for a black render, so the previous file stays.
    if output_data.interrupted && output_data.spp_done == 0 {
        bail!(
            "interrupted before every pixel had a sample: no image written ({} left as it was)",
            output.display()
        );
    }
    if args.unit.partial.is_some() {
        if output_data.interrupted {
            bail!("interrupted: the unit's partial file is not written (run the unit again)");
        }
        let _writing = interrupts.writing();
        args.unit
            .write_partial(&session, &desc, unit, &mut output_data)?;
    }
    times.render = output_data.seconds;
    let counts = radiant::render::stats::Counts::now().since(&counts_before);
    let phase = std::time::Instant::now();
    let channels = if aovs.any() {
        let space = match desc.film.gbuffer {
            Some(radiant::scene::GBufferSpace::World) => radiant::render::aov::AovSpace::World,
            _ => radiant::render::aov::AovSpace::Camera(desc.camera.camera_from_world),
        };
        pool.install(|| {
            radiant::render::aov::render_aovs(
                &session.ctx,
                aovs,
                output_data.spp_done.clamp(1, AOV_SAMPLES),
                space,
                &desc.camera.camera_from_world,
            )
        })
    } else {
        Vec::new()
    };
    let mut channels = channels;
    if variance {
        match output_data.film.variance() {
            Some(v) => {
                for (name, values) in ["Variance.R", "Variance.G", "Variance.B"]
                    .into_iter()
                    .zip(v)
                {
                    channels.push(radiant::render::aov::Channel {
                        name: name.into(),
                        values,
                    });
                }
            }
            None if warn => eprintln!(
                "warning: no variance channels: the {} integrator (or the render this one resumed) kept no per-sample moments",
                session.integrator.name()
            ),
            None => {}
        }
    }
    times.aov = phase.elapsed().as_secs_f64();
    let meta = ImageMeta {
        samples_per_pixel: Some(output_data.spp_done),
        render_time_seconds: Some(output_data.seconds),
        software: format!("radiant {}", env!("CARGO_PKG_VERSION")),
    };
    let image = output_data.film.image();
    let phase = std::time::Instant::now();
    if image_wanted {
        let _writing = interrupts.writing();
        if channels.is_empty() {
            write_image(&output, &image, &meta, args.exposure)
        } else {
            let extra: Vec<(String, Vec<f32>)> =
                channels.into_iter().map(|c| (c.name, c.values)).collect();
            radiant::image::exr::write_exr_channels(&output, &image, &meta, &extra)
        }
        .with_context(|| format!("writing {}", output.display()))?;
    }
    times.write = phase.elapsed().as_secs_f64();
    let watched = watchers.finish(&image);
    for e in &watchers.errors {
        eprintln!("warning: {e}");
    }
    watched?;
    if args.pbrt.stats {
        let memory = MemoryUse::of(
            &session,
            &output_data,
            aovs_channel_count(aovs) + 3 * variance as usize,
        );
        let photons = output_data
            .stats
            .get::<radiant::render::integrator::PhotonMapStats>()
            .map(|s| s.global_stored + s.caustic_stored);
        out_part!(
            "{}",
            crate::pbrt_opts::format_stats(&counts, photons, &memory, &times)
        );
    }
    let nf = output_data.film.nonfinite;
    if nf.count > 0 {
        let (x, y) = nf.first_pixel.unwrap_or((0, 0));
        eprintln!(
            "warning: {} non-finite sample(s) dropped (first at pixel {x},{y})",
            nf.count
        );
    }
    if summary {
        let stats = output_data.stats.to_string();
        for line in stats.lines() {
            eprintln!("{line}");
        }
        let spp = if session.ctx.adaptive {
            let film = &output_data.film;
            format!(
                "{:.1} spp adaptive ({}-{} per pixel)",
                film.mean_samples(),
                output_data.spp_done,
                film.max_samples()
            )
        } else {
            format!("{} spp", output_data.spp_done)
        };
        // A split path tracer's samples are camera samples of k paths each.
        let integrator: &dyn std::any::Any = session.integrator.as_ref();
        let spp = match integrator.downcast_ref::<radiant::render::integrator::PathIntegrator>() {
            Some(path) if path.settings.primary_split > 1 => {
                format!(
                    "{spp} x {} paths split at the first vertex",
                    path.settings.primary_split
                )
            }
            _ => spp,
        };
        eprintln!(
            "{}: {}x{}, {spp}, {} integrator, {:.2} s, {:.2} Mrays/s",
            output.display(),
            session.ctx.resolution.0,
            session.ctx.resolution.1,
            session.integrator.name(),
            output_data.seconds,
            output_data.rays as f64 / output_data.seconds.max(1e-9) / 1e6
        );
    }
    if output_data.interrupted {
        bail!(
            "interrupted: wrote the image so far ({} spp) to {}",
            output_data.spp_done,
            output.display()
        );
    }
    Ok(())
}

/// Channels the AOV set writes.
fn aovs_channel_count(set: radiant::render::aov::AovSet) -> usize {
    3 * (set.albedo as usize
        + set.position as usize
        + set.normal as usize
        + set.shading_normal as usize)
        + set.depth as usize
}

/// Checks that `path` names an image format and that its folder takes a new file.
pub fn check_output(path: &Path) -> anyhow::Result<()> {
    // The image error names the path already.
    radiant::image::check_output(path)
        .map(|_| ())
        .context("cannot write the output image")
}

/// More worker threads than this many per core only add scheduling overhead.
const THREADS_PER_CORE: usize = 4;

/// `--threads`, capped at a few per core (with a warning): tens of thousands of threads
/// exhaust memory and the scheduler long before the render starts.
pub fn capped_threads(threads: Option<usize>) -> Option<usize> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cap = THREADS_PER_CORE * cores;
    match threads {
        Some(n) if n > cap => {
            eprintln!(
                "warning: --threads {n}: using {cap} ({THREADS_PER_CORE} per core, {cores} cores)"
            );
            Some(cap)
        }
        // 0 asks for the default, as rayon reads it: all cores.
        other => other,
    }
}

/// `out.exr` → `out-00016.exr`.
fn snapshot_path(output: &Path, n: u32) -> PathBuf {
    let stem = output
        .file_stem()
        .map_or_else(|| "image".into(), |s| s.to_string_lossy().into_owned());
    let name = match output.extension() {
        Some(ext) => format!("{stem}-{n:05}.{}", ext.to_string_lossy()),
        None => format!("{stem}-{n:05}"),
    };
    output.with_file_name(name)
}

/// The rayon pool for `--threads` (all cores when `None`).
pub fn worker_pool(threads: Option<usize>) -> anyhow::Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .context("starting worker threads")
}

pub fn draw_progress(progress: &Progress, done: &std::sync::atomic::AtomicBool) {
    let bar = indicatif::ProgressBar::new(progress.total.load(Ordering::Relaxed).max(1));
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {percent:>3}% samples {human_pos}/{human_len} {elapsed} ETA {eta} {msg}",
        )
        .expect("valid template"),
    );
    let start = std::time::Instant::now();
    while !done.load(Ordering::SeqCst) {
        std::thread::sleep(Duration::from_millis(200));
        bar.set_length(progress.total.load(Ordering::Relaxed).max(1));
        bar.set_position(progress.done.load(Ordering::Relaxed));
        let mrays =
            progress.rays.load(Ordering::Relaxed) as f64 / start.elapsed().as_secs_f64() / 1e6;
        bar.set_message(format!("{mrays:.1} Mrays/s"));
    }
    bar.finish_and_clear();
}
