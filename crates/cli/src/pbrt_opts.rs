//! pbrt-v4's command-line habits for `radiant render` (and `radiant SCENE.pbrt`): the
//! quick mode, log levels, per-pass watchers (partial images, an error curve against a
//! reference, a live view in tev), G-buffer channels and the end-of-render statistics.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use radiant::image::{Film, Image, ImageMeta, write_image};
use radiant::render::aov::AovSet;
use radiant::render::budget::format_bytes;
use radiant::render::stats::Counts;
use radiant_report::tev::TevLiveView;

/// pbrt-v4's logging levels, mapped onto radiant's messages.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, ValueEnum)]
pub enum LogLevel {
    /// Everything: warnings, the summary, and a line per pass with its time.
    Verbose,
    /// Warnings and the summary (radiant's default).
    #[default]
    Error,
    /// Errors only: no warnings, no summary.
    Fatal,
}

/// One extra channel group of `--aov`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum AovName {
    /// Albedo.R/G/B: the first hit's directional albedo.
    Albedo,
    /// N.X/Y/Z: the first hit's geometric normal.
    Normal,
    /// Ns.X/Y/Z: the first hit's shading normal.
    ShadingNormal,
    /// P.X/Y/Z: the first hit's position.
    Position,
    /// Z: the first hit's camera-space depth.
    Depth,
    /// Variance.R/G/B: the variance of the pixel's samples (pass-loop integrators).
    Variance,
}

/// The pbrt-v4 flags of `radiant render`.
#[derive(Args, Debug, Default)]
pub struct PbrtArgs {
    /// pbrt-v4's quick mode: a quarter of the film's width and height, and one sample
    /// per pixel (SPPM: one iteration), whatever --spp and --resolution say.
    #[arg(long)]
    pub quick: bool,
    /// Messages shown: verbose (adds a line per pass), error (warnings and the summary,
    /// the default) or fatal (errors only).
    #[arg(long, value_enum, default_value_t = LogLevel::Error)]
    pub log_level: LogLevel,
    /// Write the image so far after every pass (atomically, so a reader never sees a
    /// half-written file).
    #[arg(long)]
    pub write_partial_images: bool,
    /// Reference image for --mse-reference-out.
    #[arg(long, value_name = "IMAGE", requires = "mse_reference_out")]
    pub mse_reference_image: Option<PathBuf>,
    /// After every pass, append "SPP, MSE" (the mean over pixels and R, G, B of the
    /// squared difference to --mse-reference-image) to this file, as pbrt-v4 does.
    #[arg(long, value_name = "FILE", requires = "mse_reference_image")]
    pub mse_reference_out: Option<PathBuf>,
    /// Print statistics at the end: rays by kind, scene queries, paths, photons,
    /// memory by category and time per phase.
    #[arg(long)]
    pub stats: bool,
    /// Show the image in the tev viewer at HOST:PORT as it renders (updated after every
    /// pass); the render goes on if tev is not there or goes away.
    #[arg(long, value_name = "HOST:PORT")]
    pub display_server: Option<String>,
    /// Extra EXR channels: from the camera rays' first hits, averaged over the pixel's
    /// first (up to 64) samples with the filter's weights, albedo, normal,
    /// shading-normal, position, depth; and the samples' variance (`Film "gbuffer"`
    /// asks for all of them).
    #[arg(long, value_enum, value_delimiter = ',', value_name = "LIST")]
    pub aov: Vec<AovName>,
}

impl PbrtArgs {
    /// True when `--aov` asks for the variance channels.
    pub fn wants_variance(&self) -> bool {
        self.aov.contains(&AovName::Variance)
    }

    /// The first-hit channels asked for by `--aov` (the film may add more).
    pub fn aov_set(&self) -> AovSet {
        let mut set = AovSet::default();
        for a in &self.aov {
            match a {
                AovName::Albedo => set.albedo = true,
                AovName::Normal => set.normal = true,
                AovName::ShadingNormal => set.shading_normal = true,
                AovName::Position => set.position = true,
                AovName::Depth => set.depth = true,
                AovName::Variance => {}
            }
        }
        set
    }

    /// Refuses, before any work, an --mse-reference-out path that cannot be written.
    pub fn check_outputs(&self) -> anyhow::Result<()> {
        if let Some(path) = &self.mse_reference_out {
            radiant::image::atomic::check_writable(path)
                .with_context(|| format!("cannot write --mse-reference-out {}", path.display()))?;
        }
        Ok(())
    }

    /// `--quick` applied to a resolution.
    pub fn quick_resolution(&self, (w, h): (u32, u32)) -> (u32, u32) {
        if self.quick {
            ((w / 4).max(1), (h / 4).max(1))
        } else {
            (w, h)
        }
    }
}

/// Most camera samples per pixel the G-buffer pass takes: its first-hit values settle
/// long before the image does.
pub const AOV_SAMPLES: u32 = 64;

/// The `--mse-reference-out` curve: its lines so far, rewritten whole after each pass.
struct MseCurve {
    reference: Image,
    path: PathBuf,
    text: String,
}

/// What runs after every pass: partial images, the MSE curve, the live view.
pub struct PassWatchers {
    partial: Option<(PathBuf, f32)>,
    mse: Option<MseCurve>,
    /// Why the MSE curve could not be written: the render fails at its end.
    mse_failure: Option<String>,
    tev: Option<TevLiveView>,
    verbose: Option<Instant>,
    pub errors: Vec<String>,
}

impl PassWatchers {
    /// Opens what `args` asks for; `output` is the image being rendered.
    pub fn new(
        args: &PbrtArgs,
        output: &Path,
        exposure: f32,
        resolution: (u32, u32),
    ) -> anyhow::Result<PassWatchers> {
        let mse = match (&args.mse_reference_image, &args.mse_reference_out) {
            (Some(reference), Some(out)) => {
                let image = radiant::image::read_image(reference)
                    .with_context(|| format!("--mse-reference-image {}", reference.display()))?;
                if (image.width as u32, image.height as u32) != resolution {
                    bail!(
                        "--mse-reference-image {}: {}x{}, the render is {}x{}",
                        reference.display(),
                        image.width,
                        image.height,
                        resolution.0,
                        resolution.1
                    );
                }
                Some(MseCurve {
                    reference: image,
                    path: out.clone(),
                    text: String::new(),
                })
            }
            _ => None,
        };
        let tev = args.display_server.as_ref().map(|addr| {
            let name = output
                .file_name()
                .map_or_else(|| "radiant".into(), |n| n.to_string_lossy().into_owned());
            TevLiveView::start(addr.as_str(), &name, resolution.0, resolution.1)
        });
        if let Some(view) = &tev
            && let Some(e) = view.failure()
            && args.log_level < LogLevel::Fatal
        {
            eprintln!(
                "warning: --display-server {}: {e}; rendering without it",
                args.display_server.as_deref().unwrap_or("")
            );
        }
        Ok(PassWatchers {
            partial: args
                .write_partial_images
                .then(|| (output.to_path_buf(), exposure)),
            mse,
            mse_failure: None,
            tev,
            verbose: (args.log_level == LogLevel::Verbose).then(Instant::now),
            errors: Vec::new(),
        })
    }

    /// True when anything watches the passes.
    pub fn any(&self) -> bool {
        self.partial.is_some() || self.mse.is_some() || self.tev.is_some() || self.verbose.is_some()
    }

    /// After a pass with `spp` samples per pixel done.
    pub fn pass(&mut self, spp: u32, film: &Film) {
        let image = film.image();
        if let Some(start) = self.verbose {
            eprintln!(
                "pass done: {spp} spp at {:.3} s",
                start.elapsed().as_secs_f64()
            );
        }
        if let Some(curve) = &mut self.mse {
            let mse = mean_squared_error(&image, &curve.reference);
            // pbrt-v4 writes "%d, %.9g": samples, then the channels' mean MSE.
            let _ = writeln!(
                curve.text,
                "{spp}, {}",
                crate::compare_cmd::format_g(mse, 9)
            );
            // The whole curve replaces the file, as every output is written: a reader
            // sees whole lines, and a failed write leaves the previous curve.
            if let Err(e) =
                radiant::image::atomic::atomic_write_bytes(&curve.path, curve.text.as_bytes())
            {
                self.mse_failure = Some(format!(
                    "writing --mse-reference-out {}: {e}",
                    curve.path.display()
                ));
                self.mse = None;
            }
        }
        if let Some((path, exposure)) = &self.partial {
            let meta = ImageMeta {
                samples_per_pixel: Some(spp),
                render_time_seconds: None,
                software: format!("radiant {}", env!("CARGO_PKG_VERSION")),
            };
            if let Err(e) = write_image(path, &image, &meta, *exposure) {
                self.errors
                    .push(format!("writing the partial image {}: {e}", path.display()));
            } else if self.verbose.is_some() {
                eprintln!("partial image: {} ({spp} spp)", path.display());
            }
        }
        if let Some(view) = &mut self.tev {
            let pixels: Vec<[f32; 3]> = image.pixels.iter().map(|p| p.to_array()).collect();
            view.update(&pixels);
        }
    }

    /// The final image to the live view, then closes it; an MSE curve that could not
    /// be written is an error (the render is written by then).
    pub fn finish(&mut self, image: &Image) -> anyhow::Result<()> {
        if let Some(view) = &mut self.tev {
            let pixels: Vec<[f32; 3]> = image.pixels.iter().map(|p| p.to_array()).collect();
            view.update(&pixels);
            view.close();
        }
        match self.mse_failure.take() {
            Some(e) => bail!("{e}"),
            None => Ok(()),
        }
    }
}

/// Mean over pixels and the three channels of the squared difference (pbrt-v4's
/// `Image::MSE` averaged over channels).
pub fn mean_squared_error(image: &Image, reference: &Image) -> f64 {
    let mut sum = 0.0f64;
    for (a, b) in image.pixels.iter().zip(&reference.pixels) {
        for (x, y) in a.to_array().into_iter().zip(b.to_array()) {
            let d = x as f64 - y as f64;
            sum += d * d;
        }
    }
    sum / (3 * image.pixels.len().max(1)) as f64
}

/// Seconds spent in each phase of a render.
#[derive(Clone, Copy, Debug, Default)]
pub struct PhaseTimes {
    pub parse: f64,
    pub build: f64,
    pub render: f64,
    pub aov: f64,
    pub write: f64,
}

/// Memory of the render's large parts, in bytes.
#[derive(Clone, Copy, Debug, Default)]
pub struct MemoryUse {
    pub film: f64,
    pub geometry: f64,
    pub photon_maps: f64,
    pub radiosity_patches: f64,
    pub aovs: f64,
}

/// Bytes a built primitive takes, as measured on a 2-million-triangle mesh (vertices,
/// per-primitive record, BVH nodes): an estimate, the BVH keeps no byte count.
const BYTES_PER_PRIMITIVE: f64 = 150.0;

impl MemoryUse {
    pub fn of(
        session: &radiant::Session,
        out: &radiant::render::RenderOutput,
        aov_channels: usize,
    ) -> MemoryUse {
        use radiant::render::integrator::PhotonMapStats;
        let pixels = out.film.pixels.len() as f64;
        let photons = out
            .stats
            .get::<PhotonMapStats>()
            .map_or(0.0, |s| (s.global_stored + s.caustic_stored) as f64);
        let patches = out
            .stats
            .get::<radiant::radiosity::solve::RadiosityStats>()
            .map_or(0.0, |s| s.patches as f64);
        MemoryUse {
            film: pixels * std::mem::size_of::<radiant::image::FilmPixel>() as f64,
            geometry: session.ctx.world.primitive_count() as f64 * BYTES_PER_PRIMITIVE,
            photon_maps: photons
                * std::mem::size_of::<radiant::render::integrator::photon::record::Photon>() as f64,
            radiosity_patches: patches * std::mem::size_of::<radiant::radiosity::Patch>() as f64,
            aovs: pixels * aov_channels as f64 * 4.0,
        }
    }
}

/// Peak resident memory of the process (Linux's VmHWM), if the platform reports it.
fn peak_resident_bytes() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// The statistics block printed by `--stats`, laid out like pbrt's: a category, then
/// indented names with right-aligned values.
pub fn format_stats(
    counts: &Counts,
    photons_stored: Option<u64>,
    memory: &MemoryUse,
    times: &PhaseTimes,
) -> String {
    let mut rows: Vec<(&str, Vec<(&str, String)>)> = vec![
        (
            "Rays",
            vec![
                ("Camera rays", counts.camera_rays.to_string()),
                ("Indirect rays", counts.indirect_rays().to_string()),
                ("Shadow rays", counts.shadow_tests.to_string()),
                ("Photon rays", counts.photon_rays.to_string()),
            ],
        ),
        (
            "Intersections",
            vec![
                ("Closest-hit tests", counts.closest_hit_tests.to_string()),
                ("Any-hit (shadow) tests", counts.shadow_tests.to_string()),
            ],
        ),
        (
            "Paths",
            vec![
                ("Camera paths", counts.camera_rays.to_string()),
                ("Photon paths", counts.photon_paths.to_string()),
            ],
        ),
    ];
    if let Some(n) = photons_stored {
        rows.push(("Photons", vec![("Photons stored", n.to_string())]));
    }
    let mut mem = vec![
        ("Film", format_bytes(memory.film)),
        ("BVH and geometry (estimate)", format_bytes(memory.geometry)),
        ("Photon maps", format_bytes(memory.photon_maps)),
        ("Radiosity patches", format_bytes(memory.radiosity_patches)),
        ("AOV channels", format_bytes(memory.aovs)),
    ];
    if let Some(peak) = peak_resident_bytes() {
        mem.push(("Peak resident (process)", format_bytes(peak)));
    }
    rows.push(("Memory", mem));
    rows.push((
        "Time",
        vec![
            ("Scene parsing", format!("{:.3} s", times.parse)),
            (
                "Scene building (BVH, lights)",
                format!("{:.3} s", times.build),
            ),
            ("Rendering", format!("{:.3} s", times.render)),
            ("AOV pass", format!("{:.3} s", times.aov)),
            ("Image writing", format!("{:.3} s", times.write)),
        ],
    ));
    let mut out = String::from("Statistics:\n");
    for (category, entries) in rows {
        let _ = writeln!(out, "  {category}");
        for (name, value) in entries {
            let _ = writeln!(out, "    {name:<40}{value:>16}");
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mse_is_the_channel_mean_of_squared_differences() {
        let mut a = Image::new(2, 1);
        let b = Image::new(2, 1);
        a.set(0, 0, radiant::color::Rgb::new(1.0, 2.0, 0.0));
        // (1 + 4 + 0 + 0 + 0 + 0) / 6
        assert!((mean_squared_error(&a, &b) - 5.0 / 6.0).abs() < 1e-12);
    }
}
