//! The pass loop of the per-pixel integrators: samples are taken in passes (1, 1, 2, 4,
//! … up to 64 samples per pixel), rows in parallel, every sample a pure function of
//! (pixel, sample index, seed). Between rows the loop checks for cancellation, so an
//! interrupted render still has a consistent image: every pixel is the mean of the
//! samples it received, and the film says how many.

use std::sync::atomic::Ordering;
use std::time::Instant;

use rayon::prelude::*;

use super::{IntegratorState, RenderControl, RenderOutput, Stats};
use crate::context::{Progress, RenderContext};
use crate::geometry::Ray;
use crate::sampler::PixelSample;
use radiant_image::{Film, NonFinite};
use radiant_math::color::Rgb;

/// Which sample of which pixel is being estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelId {
    pub x: u32,
    pub y: u32,
    pub index: u32,
}

/// Radiance along a camera ray, estimated per pixel sample (the path tracer, the photon
/// mapper's eye paths, the radiosity display).
pub trait PixelEstimator: Sync {
    /// Per-row working memory, made once per row of a pass.
    type Scratch: Send;

    fn scratch(&self) -> Self::Scratch;

    /// Radiance arriving along `ray` (before the camera's weight and the sensor), and
    /// the number of rays traced. `sampler` continues after the camera's dimensions.
    fn radiance(
        &self,
        ray: Ray,
        sampler: &mut PixelSample,
        pixel: PixelId,
        scratch: &mut Self::Scratch,
    ) -> (Rgb, u32);
}

/// Takes `ctx.spp` samples per pixel with `estimator` into a new film, or into the
/// film of `control.resume`, continuing each pixel after the samples it has.
pub fn render_passes<E: PixelEstimator>(
    ctx: &RenderContext,
    estimator: &E,
    control: &mut RenderControl<'_>,
) -> RenderOutput {
    let start = Instant::now();
    let progress = control.progress;
    let mut film = match control.resume.take() {
        Some(IntegratorState::Film(film))
            if (film.width as u32, film.height as u32) == ctx.resolution =>
        {
            Film {
                sensor: ctx.sensor,
                ..film
            }
        }
        _ => ctx.new_film(),
    };
    let (w, h) = (film.width as u64, film.height as u64);
    progress
        .total
        .store(w * h * ctx.spp as u64, Ordering::Relaxed);
    let taken: u64 = film
        .pixels
        .iter()
        .map(|p| p.samples.min(ctx.spp) as u64)
        .sum();
    progress.done.fetch_add(taken, Ordering::Relaxed);
    let mut spp_done = film.min_samples();
    // The pass schedule of a fresh render (1, 1, 2, 4, … 64, 64, …), picked up where a
    // resumed film left off; the image does not depend on it, the snapshots do.
    let mut pass = if spp_done < 2 {
        1
    } else {
        (1u32 << (31 - spp_done.leading_zeros())).min(64)
    };
    while spp_done < ctx.spp && !progress.cancelled() {
        let mut n = pass.min(ctx.spp - spp_done);
        if spp_done > 0 && !spp_done.is_power_of_two() {
            n = n.min(spp_done.next_power_of_two() - spp_done);
        }
        let nonfinite = render_pass(ctx, estimator, &mut film, spp_done, n, progress);
        film.nonfinite.merge(nonfinite);
        if progress.cancelled() {
            break;
        }
        spp_done += n;
        if spp_done.is_power_of_two() {
            (control.snapshot)(spp_done, &film);
        }
        control.boundary(spp_done, &|| IntegratorState::Film(film.clone()));
        if spp_done >= 2 {
            pass = (pass * 2).min(64);
        }
    }
    let interrupted = progress.cancelled();
    RenderOutput {
        spp_done: film.min_samples(),
        state: control.final_state(|| IntegratorState::Film(film.clone())),
        film,
        seconds: start.elapsed().as_secs_f64(),
        rays: progress.rays.load(Ordering::Relaxed),
        interrupted,
        stats: Stats::default(),
    }
}

/// Adds samples `first .. first + count` to every pixel (those it does not have yet:
/// a resumed film may hold some of them already).
fn render_pass<E: PixelEstimator>(
    ctx: &RenderContext,
    estimator: &E,
    film: &mut Film,
    first: u32,
    count: u32,
    progress: &Progress,
) -> NonFinite {
    let width = film.width;
    film.pixels
        .par_chunks_mut(width)
        .enumerate()
        .map(|(y, row)| {
            let mut nonfinite = NonFinite::default();
            if progress.cancelled() {
                return nonfinite;
            }
            let mut rays = 0u64;
            let mut row_samples = 0u64;
            let mut scratch = estimator.scratch();
            for (x, film_pixel) in row.iter_mut().enumerate() {
                for index in film_pixel.samples.max(first)..first + count {
                    let pixel = PixelId {
                        x: x as u32,
                        y: y as u32,
                        index,
                    };
                    row_samples += 1;
                    let (l, weight, r) = sample_pixel(ctx, estimator, &mut scratch, pixel);
                    rays += r as u64;
                    if l.is_finite() && weight.is_finite() {
                        film_pixel.add(ctx.sensor.clamp_sample(l), weight);
                    } else {
                        film_pixel.samples += 1;
                        nonfinite.merge(NonFinite {
                            count: 1,
                            first_pixel: Some((pixel.x, pixel.y)),
                        });
                    }
                }
            }
            progress.rays.fetch_add(rays, Ordering::Relaxed);
            progress.done.fetch_add(row_samples, Ordering::Relaxed);
            nonfinite
        })
        .reduce(NonFinite::default, |mut a, b| {
            a.merge(b);
            a
        })
}

/// One camera sample: radiance times the camera's weight, filter weight, rays traced.
fn sample_pixel<E: PixelEstimator>(
    ctx: &RenderContext,
    estimator: &E,
    scratch: &mut E::Scratch,
    pixel: PixelId,
) -> (Rgb, f32, u32) {
    let mut sampler = ctx.pixel_sample(ctx.seed, pixel.x, pixel.y, pixel.index);
    let cs = ctx.camera_sample(&mut sampler, pixel.x, pixel.y);
    let Some(cr) = cs.ray else {
        return (Rgb::BLACK, cs.filter_weight, 0);
    };
    let (l, rays) = estimator.radiance(cr.ray, &mut sampler, pixel, scratch);
    (l * cr.weight, cs.filter_weight, rays)
}
