//! A method study: one scene rendered by several integrators (path tracing, SPPM,
//! photon mapping, radiosity …) at equal samples or equal time, every progressive
//! snapshot measured against one reference, gathered into a [`radiant_report::StudyReport`].
//!
//! How the work is measured:
//! - **Time** of a method is wall-clock from the start of its session (BVH, radiosity
//!   meshing and solve, photon tracing all count: they are the method's cost) to its last
//!   pass, less the time spent here measuring snapshots.
//! - **Equal time** runs passes until the budget is spent: after every pass boundary
//!   (the render's checkpoint hook) the render stops when the time so far plus half the
//!   predicted next pass reaches the budget, i.e. at the boundary nearest the budget. The
//!   next pass is predicted from the last pass's time per sample and the pass schedule
//!   (passes double up to 64 spp; SPPM: one iteration). At the first boundary nothing is
//!   predicted, as its pass includes the method's preparation: it stops only a render
//!   already over the budget. A render thus always ends on a pass boundary, with the same
//!   number of samples in every pixel, and a method's preparation is never cut short.
//! - **Snapshots** are the renders' own, at powers of two of samples per pixel (SPPM:
//!   iterations), plus the final image when its count is not a power of two.
//! - **Errors** are `radiant_image::metrics::compare`'s relMSE, RMSE and MAE, and the
//!   mean HDR-ꟻLIP error (Andersson et al. 2020, 2021) over the same pixels, so
//!   `radiant compare --flip` on the saved images prints the same numbers.
//! - **The reference**, when none is given, is a longer path-traced render with a
//!   different seed: with the method's own seed the path tracer's first samples would be
//!   the reference's too, and its error would be underestimated.

use std::cell::Cell;
use std::ops::ControlFlow;
use std::time::{Duration, Instant};

use radiant_image::flip::{DEFAULT_PIXELS_PER_DEGREE, FlipError, FlipMap, flip_hdr};
use radiant_image::metrics::{Metrics, compare};
use radiant_image::{Crop, Film, Image, ImageError};
use radiant_render::integrator::IntegratorState;
use radiant_render::{Overrides, Progress};
use radiant_report::{
    CropInfo, Effort, MethodResult, MetricsRow, Precision, ReportImage, Snapshot, StudyReport,
};
use radiant_scene::{CameraKind, SceneDesc, SceneError};

use crate::Session;
use crate::integrators::INTEGRATOR_NAMES;

/// The methods a study renders when none are named.
pub const DEFAULT_METHODS: [&str; 4] = ["path", "sppm", "photonmap", "radiosity"];

/// Samples per pixel (iterations) given to a render that is stopped by time: large enough
/// never to be reached.
const UNBOUNDED_SPP: u32 = 1 << 24;

/// Seed offset of a self-made reference (the golden-ratio constant, so it shares no
/// low bits with small seeds).
const REFERENCE_SEED_OFFSET: u64 = 0x9e37_79b9_7f4a_7c15;

/// How much work each render may do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Budget {
    /// The same samples per pixel (SPPM: iterations) for every method.
    Spp(u32),
    /// About the same wall-clock seconds for every method.
    Seconds(f64),
}

impl Budget {
    fn describe(self) -> String {
        match self {
            Budget::Spp(n) => format!("{n} samples per pixel (SPPM: iterations)"),
            Budget::Seconds(s) => format!("{s} s"),
        }
    }
}

/// Where the reference comes from.
#[derive(Clone, Debug)]
pub enum ReferenceSpec {
    /// An image read by the caller; `label` says what it is (a file name).
    Image { image: Image, label: String },
    /// A path-traced render made by the study with this budget.
    PathTraced(Budget),
}

/// What to study.
#[derive(Clone, Debug)]
pub struct StudyConfig {
    /// Integrator names (see [`INTEGRATOR_NAMES`]), in display order.
    pub methods: Vec<String>,
    pub budget: Budget,
    pub reference: ReferenceSpec,
    /// Pixels the errors are measured over (all when `None`).
    pub crop: Option<Crop>,
    /// Image size, overriding the film's (a given reference's size when `None`).
    pub resolution: Option<(u32, u32)>,
    pub seed: Option<u64>,
    /// Viewing condition of ꟻLIP.
    pub pixels_per_degree: f32,
    pub precision: Precision,
}

impl StudyConfig {
    pub fn new(methods: Vec<String>, budget: Budget, reference: ReferenceSpec) -> StudyConfig {
        StudyConfig {
            methods,
            budget,
            reference,
            crop: None,
            resolution: None,
            seed: None,
            pixels_per_degree: DEFAULT_PIXELS_PER_DEGREE,
            precision: Precision::F32,
        }
    }
}

/// Why a study could not be made.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Image(#[from] ImageError),
    #[error("ꟻLIP: {0}")]
    Flip(#[from] FlipError),
    #[error("unknown method \"{0}\" (radiant has: {names})", names = INTEGRATOR_NAMES.join(", "))]
    UnknownMethod(String),
    #[error("no methods to study")]
    NoMethods,
    #[error("the reference is {ref_w}x{ref_h}, the renders {w}x{h}")]
    ReferenceSize {
        ref_w: usize,
        ref_h: usize,
        w: usize,
        h: usize,
    },
}

/// Display name of an integrator in the report.
pub fn method_label(integrator: &str) -> String {
    match integrator {
        "path" => "path tracing",
        "sppm" => "SPPM",
        "photonmap" => "photon mapping",
        "photonviz" => "photon density",
        "radiosity" => "radiosity",
        other => other,
    }
    .to_string()
}

/// The errors of one image against the reference.
#[derive(Clone, Debug)]
pub struct Measured {
    pub metrics: Metrics,
    pub flip: FlipMap,
    /// Mean ꟻLIP error over the crop.
    pub flip_mean: f64,
}

/// Errors of `test` against `reference` over `crop`: `compare`'s metrics and the mean of
/// the HDR-ꟻLIP map (computed on the whole image, its filters need the neighbours)
/// over the crop. Non-finite test values count as 0, as in `compare`. A reference pixel
/// with a non-finite channel leaves nothing to measure against, as in `compare`: the
/// test's pixel stands in for it, so that no made-up difference spreads through the
/// filters to its neighbours, its error is 0 in the map, and the mean leaves it out.
pub fn measure(
    test: &Image,
    reference: &Image,
    crop: Option<Crop>,
    pixels_per_degree: f32,
) -> Result<Measured, StudyError> {
    let metrics = compare(test, reference, crop)?;
    let finite = |p: [f32; 3]| p.map(|v| if v.is_finite() { v } else { 0.0 });
    let test_pixels: Vec<[f32; 3]> = test.pixels.iter().map(|p| finite(p.to_array())).collect();
    let unmeasured: Vec<bool> = reference
        .pixels
        .iter()
        .map(|p| !p.to_array().iter().all(|v| v.is_finite()))
        .collect();
    let reference_pixels: Vec<[f32; 3]> = reference
        .pixels
        .iter()
        .zip(&test_pixels)
        .zip(&unmeasured)
        .map(|((r, &t), &skip)| if skip { t } else { finite(r.to_array()) })
        .collect();
    let mut flip = flip_hdr(
        &test_pixels,
        &reference_pixels,
        test.width,
        test.height,
        pixels_per_degree,
        None,
    )?;
    for (e, _) in flip.errors.iter_mut().zip(&unmeasured).filter(|(_, s)| **s) {
        *e = 0.0;
    }
    let whole = Crop::full(test.width, test.height);
    flip.mean = measured_mean(&flip.errors, &unmeasured, flip.width, whole);
    let flip_mean = measured_mean(&flip.errors, &unmeasured, flip.width, crop.unwrap_or(whole));
    Ok(Measured {
        metrics,
        flip,
        flip_mean,
    })
}

/// Mean of a row-major map over `crop`, summed in f64 in row order, leaving out the
/// pixels marked in `skip`; NaN where every pixel is left out.
fn measured_mean(values: &[f32], skip: &[bool], width: usize, crop: Crop) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for y in crop.y0..crop.y1 {
        let row = y * width + crop.x0..y * width + crop.x1;
        for (&v, _) in values[row.clone()]
            .iter()
            .zip(&skip[row])
            .filter(|(_, s)| !**s)
        {
            sum += f64::from(v);
            n += 1;
        }
    }
    if n == 0 { f64::NAN } else { sum / n as f64 }
}

/// The error of one snapshot, with every figure (the report plots relMSE and ꟻLIP).
#[derive(Clone, Copy, Debug)]
pub struct SnapshotMetrics {
    pub seconds: f64,
    pub samples: u32,
    pub metrics: Metrics,
    pub flip_mean: f64,
}

/// One method's render and its errors.
#[derive(Clone, Debug)]
pub struct MethodRun {
    /// Integrator name.
    pub integrator: String,
    pub label: String,
    pub image: Image,
    pub measured: Measured,
    pub seconds: f64,
    /// Samples per pixel (SPPM: iterations) in every pixel.
    pub samples: u32,
    pub snapshots: Vec<SnapshotMetrics>,
}

impl MethodRun {
    pub fn effort(&self) -> Effort {
        match self.integrator.as_str() {
            "sppm" => Effort::Iterations(u64::from(self.samples)),
            _ => Effort::SamplesPerPixel(u64::from(self.samples)),
        }
    }

    /// Least-squares slope of log relMSE against log samples over the later snapshots
    /// (the report's legend value); `None` where those span less than a factor of two.
    pub fn slope_vs_samples(&self) -> Option<f64> {
        spread_slope(
            self.snapshots
                .iter()
                .map(|s| (f64::from(s.samples), s.metrics.relmse)),
        )
    }

    /// The same against time (for radiosity, whose solve is most of its time, the
    /// snapshots are too close in time for a slope).
    pub fn slope_vs_time(&self) -> Option<f64> {
        spread_slope(self.snapshots.iter().map(|s| (s.seconds, s.metrics.relmse)))
    }
}

/// [`radiant_report::fitted_slope`], when the later half of the points (those it fits)
/// spans at least a factor of two in x: over less, the slope is noise.
fn spread_slope(points: impl Iterator<Item = (f64, f64)>) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points.collect();
    let tail = &pts[pts.len() / 2..];
    let (lo, hi) = tail
        .iter()
        .map(|p| p.0)
        .filter(|x| x.is_finite() && *x > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
    if hi < 2.0 * lo {
        return None;
    }
    radiant_report::fitted_slope(&pts)
}

/// A finished study.
#[derive(Clone, Debug)]
pub struct Study {
    pub scene: String,
    pub reference: Image,
    /// How the reference was made.
    pub reference_note: String,
    pub camera: String,
    pub config_note: String,
    pub crop: Option<Crop>,
    pub runs: Vec<MethodRun>,
    pub precision: Precision,
}

/// What a study tells its caller as it goes (the CLI prints it).
#[derive(Debug)]
pub enum StudyEvent<'a> {
    /// A render is starting.
    Start { label: &'a str, budget: Budget },
    /// A render finished.
    Done {
        label: &'a str,
        seconds: f64,
        samples: u32,
    },
    /// A warning from preparing a session.
    Warning(String),
}

/// A render's clock: wall time since its start less the time spent measuring.
struct Clock {
    start: Instant,
    paused: Cell<Duration>,
}

impl Clock {
    fn new() -> Clock {
        Clock {
            start: Instant::now(),
            paused: Cell::new(Duration::ZERO),
        }
    }

    fn seconds(&self) -> f64 {
        (self.start.elapsed().saturating_sub(self.paused.get())).as_secs_f64()
    }

    /// Runs `f` off the clock.
    fn off<T>(&self, f: impl FnOnce() -> T) -> T {
        let t0 = Instant::now();
        let out = f();
        self.paused.set(self.paused.get() + t0.elapsed());
        out
    }
}

/// Samples per pixel (SPPM: iterations) of the pass after the boundary at `done`: SPPM
/// does one iteration per boundary; the per-pixel integrators' passes
/// (`radiant_render::integrator::passes`) double from 1, 1, 2, 4 up to 64 spp. Only a
/// prediction for the equal-time stop: a wrong guess moves the stop by a pass.
fn next_pass(integrator: &str, done: u32) -> u32 {
    match integrator {
        "sppm" => 1,
        _ => done.clamp(1, 64),
    }
}

/// One render of `integrator` under `budget`, calling `at_snapshot(samples, seconds,
/// image)` off the clock at every snapshot. Returns the final image, its samples and the
/// method's seconds.
fn render_method(
    desc: &SceneDesc,
    integrator: &str,
    budget: Budget,
    resolution: Option<(u32, u32)>,
    seed: Option<u64>,
    events: &mut dyn FnMut(StudyEvent<'_>),
    at_snapshot: &mut dyn FnMut(u32, f64, &Image) -> Result<(), StudyError>,
) -> Result<(Image, u32, f64), StudyError> {
    let clock = Clock::new();
    let overrides = Overrides {
        spp: Some(match budget {
            Budget::Spp(n) => n,
            Budget::Seconds(_) => UNBOUNDED_SPP,
        }),
        seed,
        resolution,
        integrator: Some(integrator.to_string()),
    };
    let session = Session::new(desc, &overrides)?;
    for w in &session.warnings {
        events(StudyEvent::Warning(w.to_string()));
    }
    let progress = Progress::default();
    let mut failure: Option<StudyError> = None;
    let mut last_snapshot = 0u32;
    let mut snapshot = |n: u32, film: &Film| {
        if failure.is_some() {
            return;
        }
        let seconds = clock.seconds();
        last_snapshot = n;
        if let Err(e) = clock.off(|| at_snapshot(n, seconds, &film.image())) {
            failure = Some(e);
        }
    };
    // (samples, seconds) at the last pass boundary; `None` before the first.
    let mut last_boundary: Option<(u32, f64)> = None;
    let mut hook = |done: u32, _state: &dyn Fn() -> IntegratorState| {
        let Budget::Seconds(limit) = budget else {
            return ControlFlow::Continue(());
        };
        let t = clock.seconds();
        let next = match last_boundary {
            Some((n, t0)) if done > n => {
                (t - t0) / f64::from(done - n) * f64::from(next_pass(integrator, done))
            }
            _ => 0.0,
        };
        last_boundary = Some((done, t));
        if t + 0.5 * next >= limit {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    };
    let out = session
        .render_resumable(&progress, &mut snapshot, None, Some(&mut hook))
        .expect("a fresh render has no state to check");
    let seconds = clock.seconds();
    if let Some(e) = failure {
        return Err(e);
    }
    let image = out.film.image();
    let samples = out.spp_done;
    if samples != last_snapshot && samples > 0 {
        clock.off(|| at_snapshot(samples, seconds, &image))?;
    }
    Ok((image, samples, seconds))
}

/// Describes the camera for the report's header.
pub fn camera_description(desc: &SceneDesc, resolution: (usize, usize)) -> String {
    let size = format!("{}×{}", resolution.0, resolution.1);
    match &desc.camera.kind {
        CameraKind::Perspective { fov_deg, .. } => format!("perspective, fov {fov_deg}°, {size}"),
        CameraKind::Orthographic { .. } => format!("orthographic, {size}"),
        CameraKind::Realistic {
            lens_file,
            aperture_diameter_mm,
            focus_distance,
        } => format!(
            "realistic, lens {}, aperture {aperture_diameter_mm} mm, focus {focus_distance} m, {size}",
            lens_file.file_name().map_or_else(
                || lens_file.display().to_string(),
                |n| n.to_string_lossy().into_owned()
            )
        ),
    }
}

/// Renders and measures every method of `config` on `desc` (named `scene` in the
/// report). Renders run on rayon's current pool.
pub fn run_study(
    scene: &str,
    desc: &SceneDesc,
    config: &StudyConfig,
    events: &mut dyn FnMut(StudyEvent<'_>),
) -> Result<Study, StudyError> {
    if config.methods.is_empty() {
        return Err(StudyError::NoMethods);
    }
    for m in &config.methods {
        if !INTEGRATOR_NAMES.contains(&m.as_str()) {
            return Err(StudyError::UnknownMethod(m.clone()));
        }
    }
    let seed = config.seed.unwrap_or(desc.sampler.seed);
    let (reference, reference_note, resolution) = match &config.reference {
        ReferenceSpec::Image { image, label } => {
            let res = config
                .resolution
                .unwrap_or((image.width as u32, image.height as u32));
            (image.clone(), format!("reference: {label}"), res)
        }
        ReferenceSpec::PathTraced(budget) => {
            let label = "reference (path tracing)";
            events(StudyEvent::Start {
                label,
                budget: *budget,
            });
            let ref_seed = seed.wrapping_add(REFERENCE_SEED_OFFSET);
            // The reference's own noise: the last power-of-two snapshot k before the end
            // N differs from the final image by (1/k − 1/N)·σ² in expectation, so that
            // squared difference over (N/k − 1) estimates the final image's σ²/N.
            let mut snaps: Vec<(u32, Image)> = Vec::new();
            let (image, samples, seconds) = render_method(
                desc,
                "path",
                *budget,
                config.resolution,
                Some(ref_seed),
                events,
                &mut |n, _, img| {
                    if snaps.len() == 2 {
                        snaps.remove(0);
                    }
                    snaps.push((n, img.clone()));
                    Ok(())
                },
            )?;
            events(StudyEvent::Done {
                label,
                seconds,
                samples,
            });
            let noise = snaps
                .iter()
                .rev()
                .find(|(k, _)| *k < samples)
                .and_then(|(k, img)| {
                    let m = compare(img, &image, config.crop).ok()?;
                    Some((*k, m.relmse / (f64::from(samples) / f64::from(*k) - 1.0)))
                });
            let mut note = format!(
                "reference: rendered by this study with the path tracer, {samples} spp, seed {ref_seed} \
                 (not the methods' seed {seed}), {seconds:.1} s"
            );
            if let Some((k, noise)) = noise {
                note.push_str(&format!(
                    "; its own relMSE is about {noise:.3e} (from its {k}-spp snapshot)"
                ));
            }
            let res = (image.width as u32, image.height as u32);
            (image, note, res)
        }
    };
    let (w, h) = (resolution.0 as usize, resolution.1 as usize);
    if (reference.width, reference.height) != (w, h) {
        return Err(StudyError::ReferenceSize {
            ref_w: reference.width,
            ref_h: reference.height,
            w,
            h,
        });
    }
    if let Some(c) = config.crop {
        c.check(w, h)?;
    }

    let mut runs = Vec::new();
    for integrator in &config.methods {
        let label = method_label(integrator);
        events(StudyEvent::Start {
            label: &label,
            budget: config.budget,
        });
        let mut snapshots = Vec::new();
        let (image, samples, seconds) = render_method(
            desc,
            integrator,
            config.budget,
            Some(resolution),
            Some(seed),
            events,
            &mut |n, seconds, img| {
                let m = measure(img, &reference, config.crop, config.pixels_per_degree)?;
                snapshots.push(SnapshotMetrics {
                    seconds,
                    samples: n,
                    metrics: m.metrics,
                    flip_mean: m.flip_mean,
                });
                Ok(())
            },
        )?;
        events(StudyEvent::Done {
            label: &label,
            seconds,
            samples,
        });
        let measured = measure(&image, &reference, config.crop, config.pixels_per_degree)?;
        runs.push(MethodRun {
            integrator: integrator.clone(),
            label,
            image,
            measured,
            seconds,
            samples,
            snapshots,
        });
    }
    let config_note = format!(
        "budget: {} per method, seed {seed}; times include each method's preparation \
         (BVH, photon tracing, radiosity meshing and solve) and exclude measuring snapshots",
        config.budget.describe()
    );
    Ok(Study {
        scene: scene.to_string(),
        camera: camera_description(desc, (w, h)),
        reference,
        reference_note,
        config_note,
        crop: config.crop,
        runs,
        precision: config.precision,
    })
}

fn report_image(img: &Image) -> ReportImage {
    ReportImage {
        width: img.width,
        height: img.height,
        pixels: img.pixels.iter().map(|p| p.to_array()).collect(),
    }
}

impl Study {
    /// The report's plain data: every number exactly as measured here.
    pub fn to_report(&self) -> StudyReport {
        let methods = self
            .runs
            .iter()
            .map(|r| MethodResult {
                name: r.label.clone(),
                image: report_image(&r.image),
                flip_map: Some(r.measured.flip.errors.clone()),
                metrics: MetricsRow {
                    relmse: r.measured.metrics.relmse,
                    rmse: r.measured.metrics.rmse,
                    mae: r.measured.metrics.mae,
                    flip_mean: Some(r.measured.flip_mean),
                    seconds: r.seconds,
                    effort: r.effort(),
                },
                convergence: r
                    .snapshots
                    .iter()
                    .map(|s| Snapshot {
                        seconds: s.seconds,
                        samples: u64::from(s.samples),
                        relmse: s.metrics.relmse,
                        flip_mean: Some(s.flip_mean),
                    })
                    .collect(),
            })
            .collect();
        StudyReport {
            scene: self.scene.clone(),
            notes: vec![self.reference_note.clone(), self.config_note.clone()],
            camera: Some(self.camera.clone()),
            crop: self.crop.map(|c| CropInfo {
                x0: c.x0,
                y0: c.y0,
                x1: c.x1,
                y1: c.y1,
            }),
            reference: report_image(&self.reference),
            methods,
            precision: self.precision,
        }
    }
}

/// A two-image report (`radiant compare --html`): `test` as the one method against
/// `reference`, with its errors and no convergence data. `seconds` and `effort` are
/// what is known of how the test image was made (0 when nothing is).
pub fn comparison_report(
    test_name: &str,
    test: &Image,
    reference: &Image,
    crop: Option<Crop>,
    pixels_per_degree: f32,
    seconds: f64,
    effort: Effort,
) -> Result<StudyReport, StudyError> {
    let m = measure(test, reference, crop, pixels_per_degree)?;
    Ok(StudyReport {
        scene: format!("{test_name} against the reference"),
        notes: Vec::new(),
        camera: None,
        crop: crop.map(|c| CropInfo {
            x0: c.x0,
            y0: c.y0,
            x1: c.x1,
            y1: c.y1,
        }),
        reference: report_image(reference),
        methods: vec![MethodResult {
            name: test_name.to_string(),
            image: report_image(test),
            flip_map: Some(m.flip.errors),
            metrics: MetricsRow {
                relmse: m.metrics.relmse,
                rmse: m.metrics.rmse,
                mae: m.metrics.mae,
                flip_mean: Some(m.flip_mean),
                seconds,
                effort,
            },
            convergence: Vec::new(),
        }],
        precision: Precision::F32,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::color::Rgb;

    fn image(w: usize, h: usize, f: impl Fn(usize, usize) -> f32) -> Image {
        let mut img = Image::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let v = f(x, y);
                img.set(x, y, Rgb::new(v, 0.5 * v, 0.25 * v));
            }
        }
        img
    }

    #[test]
    fn measure_agrees_with_compare_and_the_flip_map() {
        let reference = image(24, 16, |x, y| 0.1 + 0.03 * (x + y) as f32);
        let test = image(24, 16, |x, y| {
            0.1 + 0.03 * (x + y) as f32 + if (x * 7 + y * 3) % 5 == 0 { 0.4 } else { 0.0 }
        });
        let crop = Crop {
            x0: 3,
            y0: 2,
            x1: 20,
            y1: 11,
        };
        let whole = measure(&test, &reference, None, DEFAULT_PIXELS_PER_DEGREE).unwrap();
        let part = measure(&test, &reference, Some(crop), DEFAULT_PIXELS_PER_DEGREE).unwrap();
        assert_eq!(whole.metrics, compare(&test, &reference, None).unwrap());
        assert_eq!(
            part.metrics,
            compare(&test, &reference, Some(crop)).unwrap()
        );
        assert_eq!(whole.flip_mean, whole.flip.mean);
        let in_row_order: f64 = whole.flip.errors.iter().map(|&e| f64::from(e)).sum();
        assert_eq!(in_row_order / (24 * 16) as f64, whole.flip.mean);
        // The map is the same; only the pixels averaged differ.
        assert_eq!(part.flip.errors, whole.flip.errors);
        let by_hand: f64 = (crop.y0..crop.y1)
            .flat_map(|y| (crop.x0..crop.x1).map(move |x| (x, y)))
            .map(|(x, y)| f64::from(whole.flip.error_at(x, y)))
            .sum::<f64>()
            / (crop.width() * crop.height()) as f64;
        assert!((part.flip_mean - by_hand).abs() < 1e-12);
        assert!(whole.flip_mean > 0.0 && whole.metrics.relmse > 0.0);

        let same = measure(&reference, &reference, None, DEFAULT_PIXELS_PER_DEGREE).unwrap();
        assert_eq!((same.metrics.relmse, same.flip_mean), (0.0, 0.0));
    }

    #[test]
    fn non_finite_test_pixels_count_as_black_in_flip_too() {
        let reference = image(8, 8, |_, _| 0.5);
        let mut nan = reference.clone();
        nan.set(3, 3, Rgb::new(f32::NAN, f32::INFINITY, 0.0));
        let mut black = reference.clone();
        black.set(3, 3, Rgb::new(0.0, 0.0, 0.0));
        let a = measure(&nan, &reference, None, DEFAULT_PIXELS_PER_DEGREE).unwrap();
        let b = measure(&black, &reference, None, DEFAULT_PIXELS_PER_DEGREE).unwrap();
        assert_eq!(a.flip.errors, b.flip.errors);
        assert_eq!(a.metrics.relmse, b.metrics.relmse);
        assert_eq!(a.metrics.nonfinite, 2);
    }

    #[test]
    fn a_non_finite_reference_pixel_is_left_out_of_flip() {
        let test = image(12, 10, |x, y| 0.3 + 0.02 * ((x * 5 + y * 3) % 7) as f32);
        let mut reference = image(12, 10, |_, _| 0.35);
        reference.set(4, 5, Rgb::new(f32::NAN, 0.2, 0.1));
        // What the rule means: the reference agrees with the test there, and the pixel
        // is not averaged.
        let mut agreeing = reference.clone();
        agreeing.set(4, 5, test.get(4, 5));
        let m = measure(&test, &reference, None, DEFAULT_PIXELS_PER_DEGREE).unwrap();
        let a = measure(&test, &agreeing, None, DEFAULT_PIXELS_PER_DEGREE).unwrap();
        assert_eq!(m.flip.error_at(4, 5), 0.0);
        // The agreeing map's mean over a rectangle, the pixel (4, 5) left out.
        let mean_without = |xs: std::ops::Range<usize>, ys: std::ops::Range<usize>| {
            let others: Vec<f64> = ys
                .flat_map(|y| xs.clone().map(move |x| (x, y)))
                .filter(|&p| p != (4, 5))
                .map(|(x, y)| f64::from(a.flip.error_at(x, y)))
                .collect();
            others.iter().sum::<f64>() / others.len() as f64
        };
        let mean = mean_without(0..12, 0..10);
        assert!(
            (m.flip_mean - mean).abs() < 1e-12,
            "{} vs {mean}",
            m.flip_mean
        );
        assert_eq!(m.flip.mean, m.flip_mean);
        // A black stand-in would have made a difference of its own there.
        let mut black = reference.clone();
        black.set(4, 5, Rgb::new(0.0, 0.0, 0.0));
        let b = measure(&test, &black, None, DEFAULT_PIXELS_PER_DEGREE).unwrap();
        assert!(
            b.flip_mean > m.flip_mean * 1.05,
            "{} vs {}",
            b.flip_mean,
            m.flip_mean
        );
        let crop = Crop {
            x0: 2,
            y0: 3,
            x1: 7,
            y1: 8,
        };
        let c = measure(&test, &reference, Some(crop), DEFAULT_PIXELS_PER_DEGREE).unwrap();
        assert!((c.flip_mean - mean_without(2..7, 3..8)).abs() < 1e-12);
    }

    #[test]
    fn pass_prediction_follows_the_schedules() {
        // Per-pixel passes: 1, 1, 2, 4, … 64, 64: boundaries at 1, 2, 4, …, 64, 128, 192.
        let schedule: Vec<u32> = [1, 2, 4, 8, 16, 32, 64, 128, 192]
            .iter()
            .map(|&d| next_pass("path", d))
            .collect();
        assert_eq!(schedule, [1, 2, 4, 8, 16, 32, 64, 64, 64]);
        assert_eq!(next_pass("sppm", 37), 1);
    }

    #[test]
    fn unknown_methods_and_empty_lists_are_refused() {
        let desc = radiant_scene::builtin::builtin_scene("cornell-box").unwrap();
        let reference = ReferenceSpec::Image {
            image: Image::new(4, 4),
            label: "black".into(),
        };
        let config = StudyConfig::new(vec!["bdpt".into()], Budget::Spp(1), reference.clone());
        let err = run_study("box", &desc, &config, &mut |_| {}).unwrap_err();
        assert!(
            matches!(err, StudyError::UnknownMethod(ref m) if m == "bdpt"),
            "{err}"
        );
        let config = StudyConfig::new(vec![], Budget::Spp(1), reference);
        let err = run_study("box", &desc, &config, &mut |_| {}).unwrap_err();
        assert!(matches!(err, StudyError::NoMethods), "{err}");
    }
}
