//! `radiant radiosity`: solve a scene's diffuse transport on a patch mesh, print the
//! energy balance, and write the lit mesh, the patch table, an image or the classic
//! progressive-refinement sequence.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::Ordering;

use anyhow::{Context, bail};
use clap::Args;
use radiant::image::{ImageMeta, write_image};
use radiant::radiosity::RadiosityIntegrator;
use radiant::radiosity::integrator::solve_session_resumed;
use radiant::radiosity::output::export::{LitMesh, write_lit_mesh, write_patch_csv, write_ply};
use radiant::radiosity::output::shading::Shading;
use radiant::radiosity::settings::RadiositySettings;
use radiant::radiosity::solve::{EscapeContext, SolveEvent};
use radiant::render::integrator::render_passes;
use radiant::render::{Overrides, Progress, RenderContext, RenderControl};
use radiant::scene::{FileLoc, Param, ParamValue};

use crate::render_cmd::{
    CheckpointArgs, capped_threads, check_output, draw_progress, load_scene, worker_pool,
};
use crate::signals::Interrupts;
use radiant::checkpoint::{self, RunKey};

fn parse_positive(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(n) => Ok(n),
        Err(_) => Err(format!("expected a positive whole number, got \"{s}\"")),
    }
}

/// Refuses, before any work, output paths that cannot be written: an unknown mesh
/// format, a missing or read-only folder.
fn check_outputs(args: &RadiosityArgs) -> anyhow::Result<()> {
    use radiant::image::atomic::check_writable;
    if let Some(path) = &args.output {
        check_output(path)?;
    }
    if let Some(pattern) = &args.sequence {
        check_output(&frame_path(pattern, 1))?;
    }
    if let Some(path) = &args.export {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("gltf" | "glb" | "ply")) {
            bail!(
                "--export {}: unknown mesh format (use .gltf, .glb or .ply)",
                path.display()
            );
        }
        check_writable(path)
            .with_context(|| format!("cannot write the mesh {}", path.display()))?;
    }
    if let Some(path) = &args.patches {
        check_writable(path)
            .with_context(|| format!("cannot write the patch table {}", path.display()))?;
    }
    if let Some(path) = &args.save_solution {
        check_writable(path)
            .with_context(|| format!("cannot write the solution {}", path.display()))?;
    }
    Ok(())
}

#[derive(Args, Debug)]
pub struct RadiosityArgs {
    /// A pbrt-v4 scene file, or a canonical scene: cornell-box (default), cornell-caustics, furnace.
    pub scene: Option<String>,
    /// Write the lit mesh with linear float vertex colours (radiance B/pi): .gltf (+ .bin), .glb or .ply.
    #[arg(long)]
    pub export: Option<PathBuf>,
    /// Write PLY as ASCII instead of binary little-endian.
    #[arg(long)]
    pub ascii: bool,
    /// Write one CSV row per patch: area, centroid, normal, reflectance, E, B, H.
    #[arg(long)]
    pub patches: Option<PathBuf>,
    /// With --sequence: write an image every K progressive shots.
    #[arg(long, value_name = "K", value_parser = parse_positive)]
    pub every: Option<usize>,
    /// Image sequence name; the run of '#' becomes the frame number (out-####.png).
    #[arg(long)]
    pub sequence: Option<PathBuf>,
    /// Render the solution from the scene camera to this image (.exr, .pfm, .png).
    #[arg(short = 'o', long = "outfile")]
    pub output: Option<PathBuf>,
    /// Largest patch area in scene units squared ("maxpatcharea").
    #[arg(long)]
    pub max_patch_area: Option<f32>,
    /// Split every input edge into at least this many segments ("subdivision").
    #[arg(long)]
    pub subdivision: Option<u32>,
    /// Form factors: raycast or hemicube ("formfactor").
    #[arg(long)]
    pub formfactor: Option<String>,
    /// Hemi-cube resolution ("hemicuberes").
    #[arg(long)]
    pub hemicube_res: Option<u32>,
    /// Solver: progressive, gaussseidel or jacobi ("solver").
    #[arg(long)]
    pub solver: Option<String>,
    /// Unshot fraction (progressive) or sweep change (matrix solvers) to stop at ("tolerance").
    #[arg(long)]
    pub tolerance: Option<f32>,
    /// Most shots or sweeps ("maxiterations").
    #[arg(long)]
    pub max_iterations: Option<u32>,
    /// Final-gather rays per camera sample, 0 for Gouraud display ("finalgather").
    #[arg(long)]
    pub final_gather: Option<u32>,
    /// Shadow rays against the patches' faces or the render world ("visibility").
    #[arg(long)]
    pub visibility: Option<String>,
    /// Mesh the back side of non-emitting diffuse surfaces too ("twosided").
    #[arg(long)]
    pub two_sided: bool,
    /// Adaptive refinement passes: split patches of strong contrast and solve again ("refine").
    #[arg(long, value_name = "PASSES")]
    pub refine: Option<u32>,
    /// Neighbour radiosity contrast that splits patches ("refinethreshold").
    #[arg(long)]
    pub refine_threshold: Option<f32>,
    /// Rows of elements halving towards contact edges, this many levels ("contactgrading").
    #[arg(long, value_name = "LEVELS")]
    pub contact_grading: Option<u32>,
    /// Save the solution to FILE for `radiant render --integrator radiosity --solution
    /// FILE` (the display of a distributed render, solved once).
    #[arg(long, value_name = "FILE")]
    pub save_solution: Option<PathBuf>,
    /// Samples per pixel of the images.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: Option<u32>,
    /// Image size as WIDTHxHEIGHT, overriding the film's.
    #[arg(long, value_parser = crate::render_cmd::parse_resolution)]
    pub resolution: Option<(u32, u32)>,
    /// Worker threads (default: all cores).
    #[arg(long, alias = "nthreads")]
    pub threads: Option<usize>,
    /// Exposure in stops for PNG output.
    #[arg(long, default_value_t = 0.0, value_parser = crate::render_cmd::parse_exposure, allow_hyphen_values = true)]
    pub exposure: f32,
    /// No progress bar and no summary (the energy balance is still printed).
    #[arg(long)]
    pub quiet: bool,
    /// Largest memory the solve may plan for (bytes, or with K, M, G, T: 16G); default
    /// three quarters of the physical memory.
    #[arg(long, value_parser = crate::render_cmd::parse_bytes, value_name = "BYTES")]
    pub memory_limit: Option<u64>,
    /// Progressive refinement's state (radiosity and unshot radiosity per patch, the
    /// shot count, the power booked) goes to --checkpoint FILE; --resume continues it.
    #[command(flatten)]
    pub checkpoint: CheckpointArgs,
}

impl RadiosityArgs {
    /// The command-line settings as `Integrator "radiosity"` parameters, so they are
    /// checked and documented in one place.
    fn params(&self) -> Vec<Param> {
        let mut out = Vec::new();
        // Each parameter is located at its flag, so a bad value is reported as
        // "--max-patch-area: error: ...".
        let mut push = |flag: &str, name: &str, value: ParamValue| {
            out.push(Param::new(name, value, FileLoc::new(flag, 0, 0)))
        };
        let int = |v: u32| ParamValue::Int(vec![i32::try_from(v).unwrap_or(i32::MAX)]);
        if let Some(v) = self.max_patch_area {
            push(
                "--max-patch-area",
                "maxpatcharea",
                ParamValue::Float(vec![v]),
            );
        }
        if let Some(v) = self.subdivision {
            push("--subdivision", "subdivision", int(v));
        }
        if let Some(v) = &self.formfactor {
            push(
                "--formfactor",
                "formfactor",
                ParamValue::String(vec![v.clone()]),
            );
        }
        if let Some(v) = self.hemicube_res {
            push("--hemicube-res", "hemicuberes", int(v));
        }
        if let Some(v) = &self.solver {
            push("--solver", "solver", ParamValue::String(vec![v.clone()]));
        }
        if let Some(v) = self.tolerance {
            push("--tolerance", "tolerance", ParamValue::Float(vec![v]));
        }
        if let Some(v) = self.max_iterations {
            push("--max-iterations", "maxiterations", int(v));
        }
        if let Some(v) = self.final_gather {
            push("--final-gather", "finalgather", int(v));
        }
        if let Some(v) = &self.visibility {
            push(
                "--visibility",
                "visibility",
                ParamValue::String(vec![v.clone()]),
            );
        }
        if self.two_sided {
            push("--two-sided", "twosided", ParamValue::Bool(vec![true]));
        }
        if let Some(v) = self.refine {
            push("--refine", "refine", int(v));
        }
        if let Some(v) = self.refine_threshold {
            push(
                "--refine-threshold",
                "refinethreshold",
                ParamValue::Float(vec![v]),
            );
        }
        if let Some(v) = self.contact_grading {
            push("--contact-grading", "contactgrading", int(v));
        }
        out
    }
}

/// `out-####.png` with frame 7 -> `out-0007.png` (the last run of '#'; without one,
/// `-0007` goes before the extension).
fn frame_path(pattern: &Path, frame: usize) -> PathBuf {
    let text = pattern.to_string_lossy();
    if let Some(end) = text.rfind('#') {
        let start = text[..=end].trim_end_matches('#').len();
        let width = end + 1 - start;
        return PathBuf::from(format!(
            "{}{:0width$}{}",
            &text[..start],
            frame,
            &text[end + 1..]
        ));
    }
    let stem = pattern
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("frame");
    let ext = pattern
        .extension()
        .and_then(|s| s.to_str())
        .unwrap_or("png");
    pattern.with_file_name(format!("{stem}-{frame:04}.{ext}"))
}

pub fn run(args: RadiosityArgs) -> anyhow::Result<()> {
    if args.sequence.is_some() != args.every.is_some() {
        bail!("--every K and --sequence NAME go together");
    }
    check_outputs(&args)?;
    args.checkpoint.check()?;
    let threads = capped_threads(args.threads);
    if let Some(bytes) = args.memory_limit {
        radiant::render::budget::set_limit(bytes);
    }
    let mut desc = load_scene(args.scene.as_deref())?;
    for w in &desc.warnings {
        eprintln!("{w}");
    }
    // The scene's own radiosity parameters, if it asks for radiosity, then ours on top.
    if desc.integrator.name != "radiosity" {
        desc.integrator.name = "radiosity".into();
        desc.integrator.params = Default::default();
    }
    for p in args.params() {
        desc.integrator.params.push(p);
    }
    let overrides = Overrides {
        spp: args.spp,
        seed: None,
        resolution: args.resolution,
        integrator: None,
    };
    // The context first: its world reads the light-sampler parameter.
    let (ctx, w) = RenderContext::new(&desc, &overrides)?;
    let settings = RadiositySettings::for_scene(&desc.integrator, &desc)?;
    for w in desc
        .integrator
        .params
        .unused_warnings("Integrator \"radiosity\"")
    {
        eprintln!("{w}");
    }
    let (radiosity, warnings) = RadiosityIntegrator::new(&desc, settings)?;
    for w in warnings.iter().chain(&w) {
        eprintln!("{w}");
    }
    let (settings, scene) = (&radiosity.settings, &radiosity.scene);
    let ckpt = &args.checkpoint;
    let key = ckpt
        .target()
        .map(|_| RunKey::new(&desc, &desc.integrator, &ctx));
    if key.is_some() {
        // The state is progressive refinement's, on the mesh meshing makes: matrix
        // solvers have none worth saving, and refinement passes change the mesh.
        if settings.solver != radiant::radiosity::settings::SolverKind::Progressive {
            bail!(
                "--checkpoint/--resume: only the progressive solver can be checkpointed (the matrix solvers recompute their factors anyway)"
            );
        }
        if settings.refine > 0 {
            bail!(
                "--checkpoint/--resume: not with --refine (each refinement pass solves a new mesh)"
            );
        }
    }
    let resume = match &key {
        Some(key) => match ckpt.load(key)? {
            Some(checkpoint::State::Radiosity(state)) => Some(state),
            Some(other) => bail!(
                "--resume: the checkpoint holds {} state, not a radiosity solve's",
                other.kind()
            ),
            None => None,
        },
        None => None,
    };
    if let Some(state) = &resume
        && !args.quiet
    {
        eprintln!("resuming after {} shots", state.shots);
    }
    let mut checkpoint_error = None;
    let mut last_checkpoint = std::time::Instant::now();
    let every = std::time::Duration::from_secs_f64(ckpt.checkpoint_every);
    let render_shading = |shading: &Shading, progress: &Progress| {
        render_passes(
            &ctx,
            shading,
            &mut RenderControl::new(progress, &mut |_, _| {}),
        )
    };
    let interrupts = Interrupts::install()?;
    let progress = Arc::clone(&interrupts.progress);
    let pool = worker_pool(threads)?;
    let show_bar = !args.quiet && std::io::stderr().is_terminal();
    let meta = |spp: u32, seconds: f64| ImageMeta {
        samples_per_pixel: Some(spp),
        render_time_seconds: Some(seconds),
        software: format!("radiant {} radiosity", env!("CARGO_PKG_VERSION")),
    };
    if !args.quiet {
        eprintln!(
            "radiosity: {} patches (max edge {:.4} scene units), {:?} factors, {:?} solver",
            scene.patches.len(),
            scene.max_edge,
            settings.form_factor,
            settings.solver
        );
    }

    // Solve, writing the progressive sequence on the way.
    let mut frame_error = None;
    let solved = std::thread::scope(|s| {
        let bar_done = Arc::new(std::sync::atomic::AtomicBool::new(false));
        if show_bar {
            let progress = Arc::clone(&progress);
            let bar_done = Arc::clone(&bar_done);
            s.spawn(move || draw_progress(&progress, &bar_done));
        }
        let solved = pool.install(|| {
            solve_session_resumed(
                &ctx.world,
                scene,
                settings,
                &progress,
                resume.as_ref(),
                |event| {
                    if let (SolveEvent::Shot { state, .. }, Some(path), Some(key)) =
                        (event, ckpt.target(), &key)
                    {
                        // Read before deciding: the solve stops at this shot only if the
                        // flag was set before it was shown, and then this saves it.
                        let cancelled = progress.cancelled();
                        let stop = ckpt.stop_after.is_some_and(|k| state.shots >= k as usize);
                        if cancelled || stop || last_checkpoint.elapsed() >= every {
                            let _writing = interrupts.writing();
                            let saved = checkpoint::State::Radiosity((*state).clone());
                            if let Err(e) = checkpoint::write(path, key, &saved) {
                                checkpoint_error = Some(format!("writing {}: {e}", path.display()));
                            }
                            last_checkpoint = std::time::Instant::now();
                        }
                        if stop {
                            progress.cancel.store(true, Ordering::SeqCst);
                        }
                    }
                    if let (
                        SolveEvent::Shot {
                            scene: mesh, state, ..
                        },
                        Some(every),
                        Some(pattern),
                    ) = (event, args.every, &args.sequence)
                        && every > 0
                        && state.shots.is_multiple_of(every)
                        && frame_error.is_none()
                    {
                        let display = state.display_radiosity(&mesh.patches);
                        let shading =
                            Shading::new(mesh, &ctx.world, &display, &state.irradiance, 0)
                                .with_specular_depth(settings.max_depth);
                        let out = render_shading(&shading, &Progress::default());
                        let path = frame_path(pattern, state.shots / every);
                        let _writing = interrupts.writing();
                        if let Err(e) = write_image(
                            &path,
                            &out.film.image(),
                            &meta(out.spp_done, out.seconds),
                            args.exposure,
                        ) {
                            frame_error = Some(anyhow::anyhow!("writing {}: {e}", path.display()));
                        }
                    }
                },
            )
        });
        bar_done.store(true, Ordering::SeqCst);
        solved
    })?;
    if let Some(e) = frame_error {
        return Err(e);
    }
    if let Some(e) = checkpoint_error {
        eprintln!("warning: {e}");
    }
    let scene = solved.scene(scene);
    let solution = &solved.solution;
    if !args.quiet && solved.passes > 0 {
        eprintln!(
            "refined: {} passes, {} patches",
            solved.passes,
            scene.patches.len()
        );
    }
    if !args.quiet {
        eprintln!(
            "solved: {} {}, {}, {:.2} s (factors {:.2} s)",
            solution.iterations,
            if settings.solver == radiant::radiosity::settings::SolverKind::Progressive {
                "shots"
            } else {
                "sweeps"
            },
            if solution.converged {
                "converged"
            } else {
                "not converged"
            },
            solution.seconds,
            solution.factor_seconds
        );
    }
    out!("{}", solution.balance.summary());
    if let Some(warning) = solution
        .balance
        .escape_warning(EscapeContext::of(settings, &ctx.world.lights))
        .filter(|_| !solution.interrupted)
    {
        eprintln!("warning: {warning}");
    }
    // Rows a little above 1 are the centroid estimate's error next to much smaller
    // neighbours and are scaled quietly; far above 1 the mesh hides a modelling problem.
    if solution.closure.largest_row_sum > 1.5 || solution.closure.non_finite > 0 {
        eprintln!(
            "warning: radiosity: {} form-factor row(s) summed above 1 (largest {:.3}) and were scaled to 1, {} had non-finite factors (surfaces closer than the factors can resolve, or patches much larger than their neighbours where surfaces meet)",
            solution.closure.scaled_rows,
            solution.closure.largest_row_sum,
            solution.closure.non_finite
        );
    }
    if let Some(path) = &args.save_solution
        && !solution.interrupted
    {
        if solved.scene.is_some() {
            bail!("--save-solution: not with --refine (the refined mesh is not saved)");
        }
        radiant::solution::write(
            path,
            radiant::checkpoint::scene_hash(&desc),
            scene,
            solution,
        )
        .with_context(|| format!("writing the solution {}", path.display()))?;
        if !args.quiet {
            eprintln!("solution: {}", path.display());
        }
    }
    // A solve cut short is not the solution: writing it would replace good exports and
    // images with ones that look finished.
    if solution.interrupted {
        let frames = if args.sequence.is_some() {
            "; the sequence frames written so far are complete"
        } else {
            ""
        };
        let saved = match ckpt.target() {
            Some(path) => format!("; the solve's state is in {}", path.display()),
            None => String::new(),
        };
        bail!(
            "interrupted during the solve after {} iterations: no mesh, table or image written{frames}{saved}",
            solution.iterations
        );
    }

    let display = solution.display_radiosity(&scene.patches);
    let shading = Shading::new(
        scene,
        &ctx.world,
        &display,
        &solution.irradiance,
        settings.final_gather,
    )
    .with_specular_depth(settings.max_depth);
    if let Some(path) = &args.export {
        let mesh = LitMesh::new(scene, shading.mesh(), shading.vertex_radiosity());
        let _writing = interrupts.writing();
        let is_ply = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("ply"));
        if args.ascii && is_ply {
            write_ply(path, &mesh, true)?;
        } else {
            write_lit_mesh(path, &mesh)?;
        }
        if !args.quiet {
            eprintln!(
                "{}: {} vertices, {} faces",
                path.display(),
                mesh.positions.len(),
                mesh.faces.len()
            );
        }
    }
    if let Some(path) = &args.patches {
        let _writing = interrupts.writing();
        write_patch_csv(path, scene, solution)?;
    }
    let wrote_something =
        args.export.is_some() || args.patches.is_some() || args.sequence.is_some();
    let output = match (&args.output, wrote_something) {
        (Some(path), _) => Some(path.clone()),
        (None, false) => Some(PathBuf::from(desc.output_name())),
        (None, true) => None,
    };
    let mut written = None;
    if let Some(path) = output {
        progress.done.store(0, Ordering::Relaxed);
        let out = pool.install(|| render_shading(&shading, &progress));
        if out.interrupted && out.spp_done == 0 {
            bail!(
                "interrupted before every pixel had a sample: no image written ({} left as it was)",
                path.display()
            );
        }
        let _writing = interrupts.writing();
        write_image(
            &path,
            &out.film.image(),
            &meta(out.spp_done, out.seconds + solution.seconds),
            args.exposure,
        )
        .with_context(|| format!("writing {}", path.display()))?;
        if !args.quiet {
            eprintln!(
                "{}: {}x{}, {} spp, final gather {}, {:.2} s",
                path.display(),
                ctx.resolution.0,
                ctx.resolution.1,
                out.spp_done,
                settings.final_gather,
                out.seconds
            );
        }
        written = Some((path, out.spp_done));
    }
    if progress.cancelled() {
        match written {
            Some((path, spp)) => bail!(
                "interrupted: wrote the solution and the image so far ({spp} spp) to {}",
                path.display()
            ),
            None => bail!("interrupted after the solve: wrote the solution"),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_names_fill_the_hashes() {
        assert_eq!(
            frame_path(Path::new("out/seq-####.png"), 7),
            PathBuf::from("out/seq-0007.png")
        );
        assert_eq!(
            frame_path(Path::new("a##b.exr"), 123),
            PathBuf::from("a123b.exr")
        );
        assert_eq!(
            frame_path(Path::new("frames.png"), 3),
            PathBuf::from("frames-0003.png")
        );
    }
}
