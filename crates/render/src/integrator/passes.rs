//! The pass loop of the per-pixel integrators: samples are taken in passes (1, 1, 2, 4,
//! … up to 64 samples per pixel), rows in parallel, every sample a pure function of
//! (pixel, sample index, seed). Between rows the loop checks for cancellation, so an
//! interrupted render still has a consistent image: every pixel is the mean of the
//! samples it received, and the film says how many. An adaptive render
//! ([`super::adaptive`]) runs the loop up to its pilot, then gives each pixel its own
//! count.

use std::sync::atomic::Ordering;
use std::time::Instant;

use rayon::prelude::*;

use super::{AdaptivePlan, IntegratorState, RenderControl, RenderOutput, Stats, adaptive};
use crate::context::{Progress, RenderContext, SAMPLE_BLOCK};
use crate::geometry::Ray;
use crate::sampler::PixelSample;
use radiant_image::{Film, FilmPixel, NonFinite};
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

/// Takes samples `ctx.work.samples` of each pixel of `ctx.work.pixels` with
/// `estimator` into a new film, or into the film of `control.resume`, continuing each
/// pixel after the samples it has. A sample range that starts past 0 also returns the
/// film of each [`SAMPLE_BLOCK`] it covers ([`RenderOutput::blocks`]), which is what a
/// merge adds to the films of the samples before it.
pub fn render_passes<E: PixelEstimator>(
    ctx: &RenderContext,
    estimator: &E,
    control: &mut RenderControl<'_>,
) -> RenderOutput {
    let start = Instant::now();
    let progress = control.progress;
    let (first, end) = ctx.work.samples;
    if first > 0 {
        return render_blocks(ctx, estimator, control, start);
    }
    // An adaptive render is uniform up to its pilot, then spends the rest of the budget
    // where the pilot saw the most error. It starts from a fresh film or from its own
    // state; a uniform render's film resumed with `ctx.adaptive` is finished uniformly
    // (its samples' rays were not counted).
    let resumed = control
        .resume
        .take()
        .filter(|s| s.resolution() == ctx.film_size());
    let (mut film, plan) = match resumed {
        Some(IntegratorState::Film(film)) => (film, None),
        Some(IntegratorState::AdaptiveFilm { film, plan }) if ctx.adaptive => (film, Some(plan)),
        Some(IntegratorState::AdaptiveFilm { film, .. }) => (film, None),
        _ if ctx.adaptive => {
            let film = ctx.new_film().with_moments();
            let plan = AdaptivePlan {
                pilot_rays: vec![0; film.pixels.len()],
                targets: None,
            };
            (film, Some(plan))
        }
        _ => (ctx.new_film(), None),
    };
    film.sensor = ctx.sensor;
    let (w, h) = (film.width as u64, film.height as u64);
    progress.total.store(w * h * end as u64, Ordering::Relaxed);
    let taken: u64 = film.pixels.iter().map(|p| p.samples.min(end) as u64).sum();
    progress.done.fetch_add(taken, Ordering::Relaxed);
    let Some(mut plan) = plan.filter(|p| p.pilot_rays.len() == film.pixels.len()) else {
        render_uniform(ctx, estimator, control, &mut film, end, None);
        let state = control.final_state(|| IntegratorState::Film(film.clone()));
        return output(film, state, start, progress);
    };
    let budget = end;
    let pilot = adaptive::pilot_samples(budget);
    if plan.targets.is_none() {
        render_uniform(ctx, estimator, control, &mut film, pilot, Some(&mut plan));
    }
    if pilot < budget && !progress.cancelled() {
        render_adaptive(ctx, estimator, control, &mut film, &mut plan, budget);
    }
    let state = control.final_state(|| IntegratorState::AdaptiveFilm {
        film: film.clone(),
        plan: plan.clone(),
    });
    output(film, state, start, progress)
}

/// The output of a render of the whole sample range into `film`, begun at `start`.
fn output(
    film: Film,
    state: Option<IntegratorState>,
    start: Instant,
    progress: &Progress,
) -> RenderOutput {
    RenderOutput {
        spp_done: film.min_samples(),
        state,
        film,
        seconds: start.elapsed().as_secs_f64(),
        rays: progress.rays.load(Ordering::Relaxed),
        interrupted: progress.cancelled(),
        stats: Stats::default(),
        blocks: Vec::new(),
    }
}

/// The uniform pass loop: every pixel of `film` up to `end` samples, in passes that
/// double (1, 1, 2, 4, … [`SAMPLE_BLOCK`]), picked up where the film left off. With an
/// adaptive `plan` (its pilot), each sample's rays are added to its pixel's count and
/// checkpoints save the plan with the film.
fn render_uniform<E: PixelEstimator>(
    ctx: &RenderContext,
    estimator: &E,
    control: &mut RenderControl<'_>,
    film: &mut Film,
    end: u32,
    mut plan: Option<&mut AdaptivePlan>,
) {
    let progress = control.progress;
    let mut spp_done = film.min_samples();
    // The image does not depend on the schedule, the snapshots do.
    let mut pass = if spp_done < 2 {
        1
    } else {
        (1u32 << (31 - spp_done.leading_zeros())).min(SAMPLE_BLOCK)
    };
    while spp_done < end && !progress.cancelled() {
        let mut n = pass.min(end - spp_done);
        if spp_done > 0 && !spp_done.is_power_of_two() {
            n = n.min(spp_done.next_power_of_two() - spp_done);
        }
        let range = SampleRange {
            first: spp_done,
            last: spp_done + n,
            targets: None,
        };
        let rays = plan.as_deref_mut().map(|p| p.pilot_rays.as_mut_slice());
        let nonfinite = render_range(ctx, estimator, film, range, rays, progress);
        film.nonfinite.merge(nonfinite);
        if progress.cancelled() {
            break;
        }
        spp_done += n;
        control.after_pass(spp_done, film);
        if spp_done.is_power_of_two() {
            (control.snapshot)(spp_done, film);
        }
        let film = &*film;
        match plan.as_deref() {
            Some(plan) => control.boundary(spp_done, &|| IntegratorState::AdaptiveFilm {
                film: film.clone(),
                plan: plan.clone(),
            }),
            None => control.boundary(spp_done, &|| IntegratorState::Film(film.clone())),
        }
        if spp_done >= 2 {
            pass = (pass * 2).min(SAMPLE_BLOCK);
        }
    }
}

/// The adaptive phase after the pilot in `film`: each pixel's target from
/// [`adaptive::sample_targets`] (chosen once, kept in `plan`), reached in rounds that
/// double the samples a pixel may have (2 × pilot, 4 × pilot, …), so that an
/// interrupted render has spread its work over the image. After each round the pass
/// watcher sees the film with the mean samples per pixel so far (rounded down) and a
/// checkpoint may save it; the last round is a snapshot of `budget` samples per pixel
/// on average when `budget` is a power of two.
fn render_adaptive<E: PixelEstimator>(
    ctx: &RenderContext,
    estimator: &E,
    control: &mut RenderControl<'_>,
    film: &mut Film,
    plan: &mut AdaptivePlan,
    budget: u32,
) {
    let progress = control.progress;
    let pilot = adaptive::pilot_samples(budget);
    let targets = plan
        .targets
        .get_or_insert_with(|| adaptive::sample_targets(film, &plan.pilot_rays, budget, pilot))
        .clone();
    let total: u64 = targets.iter().map(|&t| t as u64).sum();
    progress.total.store(total, Ordering::Relaxed);
    let taken: u64 = film
        .pixels
        .iter()
        .zip(&targets)
        .map(|(p, &t)| p.samples.min(t) as u64)
        .sum();
    progress.done.store(taken, Ordering::Relaxed);
    let most = targets.iter().copied().max().unwrap_or(0);
    let mut limit = pilot;
    while limit < most && !progress.cancelled() {
        limit = limit.saturating_mul(2).min(most);
        // Rounds a resumed film has already done add nothing.
        let range = SampleRange {
            first: pilot,
            last: limit,
            targets: Some(&targets),
        };
        let nonfinite = render_range(ctx, estimator, film, range, None, progress);
        film.nonfinite.merge(nonfinite);
        if progress.cancelled() {
            break;
        }
        let done = film.mean_samples() as u32;
        control.after_pass(done, film);
        let (film, plan) = (&*film, &*plan);
        control.boundary(done, &|| IntegratorState::AdaptiveFilm {
            film: film.clone(),
            plan: plan.clone(),
        });
    }
    if !progress.cancelled() && budget.is_power_of_two() {
        (control.snapshot)(budget, film);
    }
}

/// A sample range past the first block: each block into a film of its own (no
/// snapshots or checkpoints: such a unit is rerun whole).
fn render_blocks<E: PixelEstimator>(
    ctx: &RenderContext,
    estimator: &E,
    control: &mut RenderControl<'_>,
    start: Instant,
) -> RenderOutput {
    let progress = control.progress;
    let (first, end) = ctx.work.samples;
    let (w, h) = ctx.film_size();
    progress.total.store(
        w as u64 * h as u64 * (end - first) as u64,
        Ordering::Relaxed,
    );
    let mut blocks = Vec::new();
    let mut film = ctx.new_film();
    let mut s = first;
    while s < end && !progress.cancelled() {
        let e = ((s / SAMPLE_BLOCK + 1) * SAMPLE_BLOCK).min(end);
        let mut block = ctx.new_film();
        block.nonfinite = render_pass(ctx, estimator, &mut block, s, e - s, progress);
        if progress.cancelled() {
            break;
        }
        for (p, b) in film.pixels.iter_mut().zip(&block.pixels) {
            fold(p, b);
        }
        film.nonfinite.merge(block.nonfinite);
        blocks.push(block);
        s = e;
    }
    RenderOutput {
        spp_done: film.min_samples(),
        state: None,
        film,
        seconds: start.elapsed().as_secs_f64(),
        rays: progress.rays.load(Ordering::Relaxed),
        interrupted: progress.cancelled(),
        stats: Stats::default(),
        blocks,
    }
}

/// Adds a block's sums to a pixel: the one step by which blocks are combined, on one
/// machine and in a merge alike.
pub fn fold(pixel: &mut FilmPixel, block: &FilmPixel) {
    for (s, b) in pixel.sum.iter_mut().zip(block.sum) {
        *s += b;
    }
    pixel.weight += block.weight;
    pixel.samples += block.samples;
}

/// Adds samples `first .. first + count` to every pixel (those it does not have yet:
/// a resumed film may hold some of them already). Samples of the first block go
/// straight into the pixel's sums; those of a later block are summed apart and folded
/// in when the block (or the pass) ends.
fn render_pass<E: PixelEstimator>(
    ctx: &RenderContext,
    estimator: &E,
    film: &mut Film,
    first: u32,
    count: u32,
    progress: &Progress,
) -> NonFinite {
    let range = SampleRange {
        first,
        last: first + count,
        targets: None,
    };
    render_range(ctx, estimator, film, range, None, progress)
}

/// Which samples a pass adds to each pixel: those of `first .. last` it does not have
/// yet, and, with `targets` (one count per film pixel, row by row), none at or past the
/// pixel's own target.
#[derive(Clone, Copy)]
struct SampleRange<'a> {
    first: u32,
    last: u32,
    targets: Option<&'a [u32]>,
}

impl<'a> SampleRange<'a> {
    /// The range for the pixels of row `y` of a `width`-wide film.
    fn row(self, y: usize, width: usize) -> SampleRange<'a> {
        SampleRange {
            targets: self.targets.map(|t| &t[y * width..(y + 1) * width]),
            ..self
        }
    }

    /// One past the last sample of the row's pixel `column`.
    fn last(&self, column: usize) -> u32 {
        match self.targets {
            Some(t) => t[column].min(self.last),
            None => self.last,
        }
    }
}

/// [`render_pass`] over a [`SampleRange`]; adds each sample's rays to its pixel in
/// `rays`, when given (one count per film pixel).
fn render_range<E: PixelEstimator>(
    ctx: &RenderContext,
    estimator: &E,
    film: &mut Film,
    range: SampleRange<'_>,
    rays: Option<&mut [u32]>,
    progress: &Progress,
) -> NonFinite {
    let width = film.width;
    let Film {
        pixels, moments, ..
    } = film;
    // Per row, the row's slice of each optional per-pixel array.
    fn rows<T>(values: Option<&mut [T]>, width: usize, height: usize) -> Vec<Option<&mut [T]>> {
        match values {
            Some(v) => v.chunks_mut(width).map(Some).collect(),
            None => (0..height).map(|_| None).collect(),
        }
    }
    let height = pixels.len() / width.max(1);
    let moment_rows = rows(moments.as_deref_mut(), width, height);
    let ray_rows = rows(rays, width, height);
    pixels
        .par_chunks_mut(width)
        .zip(moment_rows)
        .zip(ray_rows)
        .enumerate()
        .map(|(y, ((row, moments), rays))| {
            let extra = RowExtras { moments, rays };
            render_row(ctx, estimator, y, row, extra, range.row(y, width), progress)
        })
        .reduce(NonFinite::default, |mut a, b| {
            a.merge(b);
            a
        })
}

/// What a row's samples add to besides the film's sums: their squares (for the
/// variance) and their ray counts (for adaptive sampling's cost), each when kept.
struct RowExtras<'a> {
    moments: Option<&'a mut [[f64; 3]]>,
    rays: Option<&'a mut [u32]>,
}

/// Adds the samples of `range` to the pixels of the film's row `row_index` (and, when
/// kept, their squares and rays to `extra`).
fn render_row<E: PixelEstimator>(
    ctx: &RenderContext,
    estimator: &E,
    row_index: usize,
    row: &mut [FilmPixel],
    extra: RowExtras<'_>,
    range: SampleRange<'_>,
    progress: &Progress,
) -> NonFinite {
    let RowExtras {
        mut moments,
        rays: mut pixel_rays,
    } = extra;
    let mut nonfinite = NonFinite::default();
    if progress.cancelled() {
        return nonfinite;
    }
    let (x0, y0) = (ctx.work.pixels.x0, ctx.work.pixels.y0);
    let y = y0 + row_index as u32;
    let mut rays = 0u64;
    let mut row_samples = 0u64;
    let mut scratch = estimator.scratch();
    for (column, film_pixel) in row.iter_mut().enumerate() {
        let x = x0 + column as u32;
        let last = range.last(column);
        let mut open = FilmPixel::default();
        for index in film_pixel.samples.max(range.first)..last {
            let pixel = PixelId { x, y, index };
            row_samples += 1;
            let (l, weight, r) = sample_pixel(ctx, estimator, &mut scratch, pixel);
            rays += r as u64;
            if let Some(counts) = pixel_rays.as_deref_mut() {
                counts[column] = counts[column].saturating_add(r);
            }
            let target = if index < SAMPLE_BLOCK {
                &mut *film_pixel
            } else {
                &mut open
            };
            if l.is_finite() && weight.is_finite() {
                let l = ctx.sensor.clamp_sample(l);
                target.add(l, weight);
                if let Some(m) = moments.as_deref_mut() {
                    for (s, v) in m[column].iter_mut().zip(l.to_array()) {
                        *s += (v as f64) * (v as f64) * weight as f64;
                    }
                }
            } else {
                target.samples += 1;
                nonfinite.merge(NonFinite {
                    count: 1,
                    first_pixel: Some((pixel.x, pixel.y)),
                });
            }
            if index >= SAMPLE_BLOCK && ((index + 1) % SAMPLE_BLOCK == 0 || index + 1 == last) {
                fold(film_pixel, &open);
                open = FilmPixel::default();
            }
        }
    }
    progress.rays.fetch_add(rays, Ordering::Relaxed);
    progress.done.fetch_add(row_samples, Ordering::Relaxed);
    nonfinite
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
