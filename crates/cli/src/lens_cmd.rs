//! `radiant lens FILE`: first-order data, focus, field of view and exit-pupil statistics of a
//! realistic-camera lens file, optionally with an SVG cross-section.

use anyhow::Context;
use clap::Args;
use radiant::math::Vec2;
use radiant::math::hash::{hash_u64s, u32_to_unit_f32};
use radiant::render::camera::realistic::{
    ExitPupilBounds, LensPrescription, RealisticCamera, lens_report, lens_svg,
};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `radiant lens`.
#[derive(Args, Debug)]
pub struct LensArgs {
    /// Lens description file (rows of radius, thickness, index, aperture in mm).
    pub file: PathBuf,
    /// Focus distance in metres, measured from the film (default: infinity).
    #[arg(long)]
    pub focus: Option<f64>,
    /// Film diagonal in mm.
    #[arg(long, default_value_t = 35.0)]
    pub film_diagonal: f64,
    /// Aperture stop diameter in mm (default: the stop in the file; larger values are clamped).
    #[arg(long)]
    pub aperture: Option<f64>,
    /// Film resolution WIDTHxHEIGHT (sets the film's aspect ratio).
    #[arg(long, default_value = "1000x1000", value_parser = parse_resolution)]
    pub resolution: (u32, u32),
    /// Write the lens cross-section with ray bundles to this SVG file.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Camera rays to generate for the throughput measurement (0 skips it).
    #[arg(long, default_value_t = 500_000)]
    pub rays: u64,
}

fn parse_resolution(text: &str) -> Result<(u32, u32), String> {
    let (w, h) = text
        .split_once('x')
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got '{text}'"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|&v| v > 0)
            .ok_or_else(|| format!("'{s}' is not a positive integer"))
    };
    Ok((parse(w)?, parse(h)?))
}

/// Runs `radiant lens`.
pub fn run(args: LensArgs) -> anyhow::Result<()> {
    // Refused before the report is printed and the rays are timed.
    if let Some(path) = &args.svg {
        radiant::image::atomic::check_writable(path)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    let prescription = LensPrescription::from_file(&args.file)?;
    let stop = prescription
        .stop_index()
        .map(|i| prescription.surfaces[i].aperture_diameter)
        .unwrap_or(0.0);
    let aperture = args.aperture.unwrap_or(stop);
    let focus = args.focus.unwrap_or(f64::INFINITY);
    let camera = RealisticCamera::new(
        prescription,
        aperture,
        focus,
        args.film_diagonal,
        args.resolution,
    )?;

    // The camera already holds its bounds; recompute them once more to time exactly that step.
    let start = Instant::now();
    let _ = ExitPupilBounds::compute(
        camera.system(),
        camera.film_gap(),
        0.5 * camera.film_diagonal(),
        ExitPupilBounds::DEFAULT_BUCKETS,
    )?;
    let pupil_time = start.elapsed();

    out_part!("{}", lens_report(&camera, Some(pupil_time)));
    if args.rays > 0 {
        let (rays_per_second, passed) = measure_ray_throughput(&camera, args.rays);
        out!(
            "camera rays: {:.2} M/s on one thread ({:.1} % of {} samples passed the lens)",
            rays_per_second * 1e-6,
            100.0 * passed as f64 / args.rays as f64,
            args.rays
        );
    }
    if let Some(path) = &args.svg {
        radiant::image::atomic::atomic_write_bytes(path, lens_svg(&camera).as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        out!("cross-section written to {}", path.display());
    }
    Ok(())
}

/// Generates `count` rays at hashed raster positions and lens samples (deterministic), returning
/// rays per second and how many passed.
/// Seed of the throughput measurement's sample hashes.
const SEED: u64 = 0x6c656e73;

fn measure_ray_throughput(camera: &RealisticCamera, count: u64) -> (f64, u64) {
    let (w, h) = camera.resolution();
    let start = Instant::now();
    let mut passed = 0u64;
    for i in 0..count {
        let film_hash = hash_u64s(&[SEED, i, 0]);
        let lens_hash = hash_u64s(&[SEED, i, 1]);
        let raster = Vec2::new(
            u32_to_unit_f32(film_hash as u32) * w as f32,
            u32_to_unit_f32((film_hash >> 32) as u32) * h as f32,
        );
        let u = Vec2::new(
            u32_to_unit_f32(lens_hash as u32),
            u32_to_unit_f32((lens_hash >> 32) as u32),
        );
        if camera.generate_ray(raster, u).is_some() {
            passed += 1;
        }
    }
    (count as f64 / start.elapsed().as_secs_f64(), passed)
}
