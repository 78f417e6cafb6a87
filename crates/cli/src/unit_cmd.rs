//! Work units of `radiant render` (pixel bounds, sample ranges, parts, partial files)
//! and `radiant merge`.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use radiant::Session;
use radiant::image::{ImageMeta, write_image};
use radiant::partial::{self, Partial, Split};
use radiant::render::{RenderOutput, WorkUnit};
use radiant::scene::SceneDesc;

/// How `--part K/N` divides the render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum PartBy {
    /// N bands of rows (every integrator).
    #[default]
    Tiles,
    /// N runs of 64-sample blocks (path, photonmap, photonviz, radiosity display).
    Samples,
}

#[derive(Args, Debug, Default)]
pub struct UnitArgs {
    /// Render only pixels x0 <= x < x1, y0 <= y < y1 of the image: x0,x1,y0,y1.
    #[arg(long, value_name = "X0,X1,Y0,Y1", value_parser = partial::parse_pixel_bounds,
          conflicts_with_all = ["pixelbounds", "cropwindow", "part"])]
    pub pixel_bounds: Option<radiant::render::PixelBounds>,
    /// pbrt-v4's spelling of --pixel-bounds: x0 x1 y0 y1.
    #[arg(long, num_args = 4, value_names = ["X0", "X1", "Y0", "Y1"],
          conflicts_with_all = ["cropwindow", "part"])]
    pub pixelbounds: Option<Vec<u32>>,
    /// pbrt-v4's crop window in fractions of the image, x0 x1 y0 y1 (edges at
    /// ceil(resolution × fraction)).
    #[arg(long, num_args = 4, value_names = ["X0", "X1", "Y0", "Y1"], conflicts_with = "part")]
    pub cropwindow: Option<Vec<f32>>,
    /// Take only samples a..b-1 of each pixel (both ends multiples of 64, or the spp).
    #[arg(long, value_name = "A..B", value_parser = partial::parse_sample_range,
          conflicts_with = "part")]
    pub sample_range: Option<(u32, u32)>,
    /// Render the K-th (from 0) of N units (see --part-by).
    #[arg(long, value_name = "K/N", value_parser = partial::parse_part)]
    pub part: Option<(u32, u32)>,
    /// How --part divides the render: bands of rows (tiles), or runs of sample blocks.
    #[arg(long, value_enum, default_value_t = PartBy::Tiles, requires = "part")]
    pub part_by: PartBy,
    /// Write the unit's sums to FILE (a partial for `radiant merge`); with no -o, no
    /// image is written.
    #[arg(long, value_name = "FILE")]
    pub partial: Option<PathBuf>,
    /// With --integrator radiosity: display this saved solution (`radiant radiosity
    /// --save-solution`) instead of solving.
    #[arg(long, value_name = "FILE")]
    pub solution: Option<PathBuf>,
}

impl UnitArgs {
    /// Whether any unit flag was given (the render is then a unit of a larger one).
    pub fn any(&self) -> bool {
        self.pixel_bounds.is_some()
            || self.pixelbounds.is_some()
            || self.cropwindow.is_some()
            || self.sample_range.is_some()
            || self.part.is_some()
            || self.partial.is_some()
    }

    /// Refuses, before any work, a --partial path that cannot be written.
    pub fn check_outputs(&self) -> anyhow::Result<()> {
        if let Some(path) = &self.partial {
            radiant::image::atomic::check_writable(path)
                .with_context(|| format!("cannot write the partial {}", path.display()))?;
        }
        Ok(())
    }

    /// Replaces the session's radiosity integrator by the display of a saved solution.
    pub fn load_solution(&self, session: &mut Session, desc: &SceneDesc) -> anyhow::Result<()> {
        let Some(path) = &self.solution else {
            return Ok(());
        };
        if session.integrator.name() != "radiosity" {
            bail!("--solution: for the radiosity integrator (--integrator radiosity)");
        }
        let placeholder: Box<dyn radiant::render::Integrator> =
            Box::new(radiant::render::integrator::PathIntegrator {
                settings: Default::default(),
            });
        let integrator = std::mem::replace(&mut session.integrator, placeholder);
        let integrator: Box<dyn std::any::Any> = integrator;
        let radiosity = *integrator
            .downcast::<radiant::radiosity::RadiosityIntegrator>()
            .map_err(|_| anyhow::anyhow!("--solution: the integrator is not radiosity"))?;
        let solution = radiant::solution::read(
            path,
            radiant::checkpoint::scene_hash(desc),
            &radiosity.scene,
        )
        .with_context(|| format!("--solution {}", path.display()))?;
        session.integrator = Box::new(radiant::solution::SolvedRadiosity {
            radiosity,
            solution,
        });
        Ok(())
    }

    /// Sets the session's work unit from the flags, checked against the render.
    pub fn apply(&self, session: &mut Session) -> anyhow::Result<WorkUnit> {
        let unit = self.unit(session)?;
        session.ctx.work = unit;
        Ok(unit)
    }

    /// The work unit the flags select, refused where the session's render cannot take
    /// it (`radiant slurm` checks every part of its job with this before writing it).
    pub fn unit(&self, session: &Session) -> anyhow::Result<WorkUnit> {
        let ctx = &session.ctx;
        let (resolution, spp) = (ctx.resolution, ctx.spp);
        let mut unit = WorkUnit::full(resolution, spp);
        if let Some((k, n)) = self.part {
            let split = match self.part_by {
                PartBy::Tiles => Split::Tiles,
                PartBy::Samples => Split::Samples,
            };
            unit = partial::part_unit(resolution, spp, k, n, split)?;
        }
        if let Some(b) = self.pixel_bounds {
            unit.pixels = b;
        }
        if let Some(v) = &self.pixelbounds {
            unit.pixels = radiant::render::PixelBounds {
                x0: v[0],
                x1: v[1],
                y0: v[2],
                y1: v[3],
            };
        }
        if let Some(v) = &self.cropwindow {
            if v.iter().any(|f| !(0.0..=1.0).contains(f)) || v[0] >= v[1] || v[2] >= v[3] {
                bail!("--cropwindow: need 0 <= x0 < x1 <= 1 and 0 <= y0 < y1 <= 1");
            }
            unit.pixels = partial::crop_window_bounds(resolution, [v[0], v[1], v[2], v[3]]);
        }
        if let Some(r) = self.sample_range {
            unit.samples = r;
        }
        partial::check_unit(&unit, resolution, spp)?;
        if unit.samples != (0, spp)
            && !SAMPLE_RANGE_INTEGRATORS.contains(&session.integrator.name())
        {
            bail!(
                "the {} integrator renders whole sample ranges only (split it by tiles)",
                session.integrator.name()
            );
        }
        Ok(unit)
    }

    /// Writes the unit's partial file, when asked for.
    pub fn write_partial(
        &self,
        session: &Session,
        desc: &SceneDesc,
        unit: WorkUnit,
        out: &mut RenderOutput,
    ) -> anyhow::Result<()> {
        let Some(path) = &self.partial else {
            return Ok(());
        };
        let film = out.film.clone();
        let output = RenderOutput {
            film,
            seconds: out.seconds,
            rays: out.rays,
            spp_done: out.spp_done,
            interrupted: out.interrupted,
            state: None,
            stats: Default::default(),
            blocks: std::mem::take(&mut out.blocks),
        };
        Partial::from_output(session.run_key(desc), unit, self.part, output)
            .write(path)
            .with_context(|| format!("writing the partial {}", path.display()))
    }
}

/// Integrators whose samples are per pixel and independent: these split by samples.
const SAMPLE_RANGE_INTEGRATORS: [&str; 4] = ["path", "photonmap", "photonviz", "radiosity"];

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Partial files of one render (from `radiant render --partial`).
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// The merged image; the format follows the extension (.exr, .pfm, .png).
    #[arg(short = 'o', long = "outfile")]
    pub output: PathBuf,
    /// Exposure in stops for PNG output.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub exposure: f32,
    #[arg(long)]
    pub quiet: bool,
}

pub fn run_merge(args: MergeArgs) -> anyhow::Result<()> {
    crate::render_cmd::check_output(&args.output)?;
    let mut parts = Vec::new();
    for path in &args.parts {
        let p = Partial::read(path).with_context(|| format!("reading {}", path.display()))?;
        parts.push((path.display().to_string(), p));
    }
    let film = partial::merge(&parts)?;
    let key = &parts[0].1.key;
    let meta = ImageMeta {
        samples_per_pixel: Some(key.spp),
        render_time_seconds: None,
        software: format!("radiant {}", env!("CARGO_PKG_VERSION")),
    };
    write_image(&args.output, &film.image(), &meta, args.exposure)
        .with_context(|| format!("writing {}", args.output.display()))?;
    if film.nonfinite.count > 0 {
        eprintln!(
            "warning: {} non-finite sample(s) dropped",
            film.nonfinite.count
        );
    }
    if !args.quiet {
        eprintln!(
            "{}: {}x{}, {} spp, {} integrator, merged from {} part(s)",
            args.output.display(),
            key.resolution.0,
            key.resolution.1,
            key.spp,
            key.integrator,
            parts.len()
        );
    }
    Ok(())
}
