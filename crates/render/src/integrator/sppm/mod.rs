//! Stochastic progressive photon mapping (Hachisuka, Ogaki & Jensen, "Progressive
//! Photon Mapping", SIGGRAPH Asia 2008; Hachisuka & Jensen, "Stochastic Progressive
//! Photon Mapping", SIGGRAPH Asia 2009).
//!
//! Each iteration: (1) a camera pass leaves one visible point per pixel at the first
//! diffuse vertex (random per iteration) and adds direct light by next-event
//! estimation; (2) the visible points go into a spatial hash grid; (3) photons are
//! traced and, from their second hit on, add f Φ to every visible point whose radius
//! contains them; (4) each pixel shrinks its radius: with M new photons,
//! N ← N + αM, R² ← R² (N + αM)/(N + M), τ ← (τ + β Φ) R'²/R².
//! After k iterations of N_p photons a pixel is L_d/k + τ / (k N_p π R²). The radius
//! shrinks to zero while the photon count grows without bound, so bias and variance
//! both vanish: the estimate is consistent.
//!
//! Caustics get an estimate of their own, as in Jensen's two photon maps (Jensen 1996,
//! "Global Illumination using Photon Maps"): photons that reach a surface through
//! specular (or photon-passing rough) surfaces only are traced in a separate pass,
//! aimed at the specular objects by projection maps, and gathered with their own,
//! smaller radius; the global pass then skips exactly those arrivals. The two sets of
//! paths are disjoint and together are the single estimate's, and each estimate is
//! SPPM's, so the sum is consistent. Why: a caustic is sharp and wants a small radius,
//! the diffuse interreflection is smooth and wants many photons per pixel, a large one
//! (docs/speed.md measures both); and aimed photons put the caustic's share of the
//! work where the caustic is.
//!
//! Photon contributions are collected per chunk of photons and applied in chunk order,
//! so images are bit-identical at any thread count.

pub mod photongrid;
pub mod settings;
pub mod visible;

use std::fmt;
use std::sync::atomic::Ordering;
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

pub use settings::SppmSettings;

use super::footprint::pixel_footprint;
use super::photon::projection::ProjectionMaps;
use super::photon::trace::{Landing, PhotonPass, PhotonStream};
use crate::context::RenderContext;
use crate::integrator::{
    Integrator, IntegratorState, PhotonEstimate, RenderControl, RenderOutput, SppmPixel, StateKind,
    Stats,
};
use photongrid::{Deposit, PhotonGrid};
use radiant_image::{Film, FilmPixel, NonFinite};
use radiant_math::PI;
use radiant_math::color::Rgb;
use radiant_math::sampling::SystematicDraw;
use visible::{CameraSample, VisiblePoint, camera_sample, sees_sharp_direct_light};

const SPPM_PASS: u64 = 0x5bb3;
const SPPM_CAUSTIC_PASS: u64 = 0x5bb4;
/// Seed offset of the extra direct-light camera samples of sharp pixels.
const SHARP_SAMPLES_SEED: u64 = 0x5bb5_0000_0000;

/// Pixel footprints in the default initial radius of the global estimate, at most
/// [`GLOBAL_RADIUS_IMAGE_FRACTION`] of the image's larger side.
pub const GLOBAL_RADIUS_PIXELS: f32 = 8.0;
/// The largest default global radius as a share of the image: a wider blur shows as
/// darkened corners and contact shadows long after the first iterations (measured on
/// a 64 × 64 image, docs/speed.md).
pub const GLOBAL_RADIUS_IMAGE_FRACTION: f32 = 1.0 / 32.0;
/// Pixel footprints in the default initial radius of the caustic estimate.
pub const CAUSTIC_RADIUS_PIXELS: f32 = 1.0;
/// Aimed caustic photons per global photon, by default.
pub const CAUSTIC_PHOTONS_PER_PHOTON: u64 = 2;

/// What an SPPM render did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SppmStats {
    pub iterations: u32,
    pub photons_per_iteration: u64,
    /// Photons of the caustic pass per iteration (0: no separate caustic estimate).
    pub caustic_photons_per_iteration: u64,
    /// Initial radius of the global estimate (scene units).
    pub initial_radius: f32,
    /// Initial radius of the caustic estimate (scene units).
    pub initial_caustic_radius: f32,
    /// True when the radius was derived from the pixel footprint (no `radius` given).
    pub radius_derived: bool,
    /// Pixel footprints in the derived radius.
    pub radius_pixels: f32,
    /// Root-mean-square radius over the pixels at the end (global estimate).
    pub final_radius: f32,
    /// Root-mean-square radius over the pixels at the end (caustic estimate).
    pub final_caustic_radius: f32,
    pub camera_seconds: f64,
    /// Both photon passes and the pixels' updates.
    pub photon_seconds: f64,
    /// The caustic pass's share of `photon_seconds`.
    pub caustic_seconds: f64,
    /// Pixels whose direct light takes `sharpdirectsamples` samples per iteration.
    pub sharp_pixels: u64,
    pub rays: u64,
}

impl fmt::Display for SppmStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "sppm: initial radius {:.4}{}, final rms radius {:.4}",
            self.initial_radius,
            if self.radius_derived {
                format!(
                    " ({} pixel footprints at the scene centre)",
                    self.radius_pixels
                )
            } else {
                String::new()
            },
            self.final_radius
        )?;
        if self.sharp_pixels > 0 {
            writeln!(
                f,
                "sppm: {} pixels see mirrors, glass or emitters and take more direct-light samples",
                self.sharp_pixels
            )?;
        }
        if self.caustic_photons_per_iteration > 0 {
            writeln!(
                f,
                "sppm: caustic estimate: {} aimed photons per iteration, initial radius {:.4}, final rms radius {:.4}; caustic passes {:.3} s",
                self.caustic_photons_per_iteration,
                self.initial_caustic_radius,
                self.final_caustic_radius,
                self.caustic_seconds
            )?;
        }
        let photons = self.iterations as u64
            * (self.photons_per_iteration + self.caustic_photons_per_iteration);
        write!(
            f,
            "sppm: {} iterations x {} photons; camera passes {:.3} s, photon passes {:.3} s ({:.2} M photons/s)",
            self.iterations,
            self.photons_per_iteration,
            self.camera_seconds,
            self.photon_seconds,
            photons as f64 / self.photon_seconds.max(1e-9) / 1e6
        )
    }
}

/// A pixel's progressive statistics (f64: thousands of iterations are summed).
type PixelState = SppmPixel;

/// `pixels` pixel footprints at the distance of the scene's centre (or `pixels`/200 of
/// the scene's radius without one): how default radii are set.
pub fn footprint_radius(ctx: &RenderContext, pixels: f32) -> f32 {
    pixel_footprint(&ctx.camera, ctx.resolution, &ctx.world).map_or(
        0.005 * pixels * ctx.world.scene_sphere().radius,
        |(w, _)| pixels * w,
    )
}

/// The default initial radius of the global estimate: [`GLOBAL_RADIUS_PIXELS`] pixel
/// footprints, fewer on small images.
pub fn default_radius(ctx: &RenderContext) -> f32 {
    footprint_radius(ctx, default_radius_pixels(ctx.resolution))
}

/// Pixel footprints of the default global radius at `resolution`.
pub fn default_radius_pixels(resolution: (u32, u32)) -> f32 {
    let side = resolution.0.max(resolution.1) as f32;
    GLOBAL_RADIUS_PIXELS.min(GLOBAL_RADIUS_IMAGE_FRACTION * side)
}

/// The default initial radius of the caustic estimate.
pub fn default_caustic_radius(ctx: &RenderContext) -> f32 {
    footprint_radius(ctx, CAUSTIC_RADIUS_PIXELS)
}

/// `Integrator "sppm"`: `ctx.spp` iterations; snapshots after every power-of-two
/// iteration. Stops after the current iteration when cancelled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SppmIntegrator {
    pub settings: SppmSettings,
}

impl Integrator for SppmIntegrator {
    fn name(&self) -> &'static str {
        "sppm"
    }

    fn render(&self, ctx: &RenderContext, control: &mut RenderControl<'_>) -> RenderOutput {
        render(ctx, &self.settings, control)
    }

    fn state_kind(&self) -> StateKind {
        StateKind::Sppm
    }
}

fn render(
    ctx: &RenderContext,
    settings: &SppmSettings,
    control: &mut RenderControl<'_>,
) -> RenderOutput {
    let start = Instant::now();
    let progress = control.progress;
    // A work unit gathers into its own pixels only; the photon stream of every
    // iteration is the whole image's, so each pixel sees the photons it would see in
    // the full render, in the same order.
    let (w, h) = (ctx.film_size().0 as usize, ctx.film_size().1 as usize);
    let (x0, y0) = (ctx.work.pixels.x0, ctx.work.pixels.y0);
    let n_pix = w * h;
    let full_pixels = ctx.resolution.0 as u64 * ctx.resolution.1 as u64;
    let seed = settings.seed.unwrap_or(ctx.seed);
    let radius = settings.radius.unwrap_or_else(|| default_radius(ctx));
    let caustic_radius = settings
        .caustic_radius
        .or(settings.radius)
        .unwrap_or_else(|| default_caustic_radius(ctx));
    let n_photons = settings
        .photons_per_iteration
        .map_or(full_pixels, u64::from)
        .max(1);
    let world = &ctx.world;
    // Without specular objects there are no caustics to aim at: one estimate.
    let wanted_caustic = settings
        .caustic_photons_per_iteration
        .map_or(CAUSTIC_PHOTONS_PER_PHOTON * n_photons, u64::from);
    let maps = (wanted_caustic > 0)
        .then(|| ProjectionMaps::build(world))
        .flatten();
    let n_caustic = if maps.is_some() { wanted_caustic } else { 0 };
    let mut stats = SppmStats {
        photons_per_iteration: n_photons,
        caustic_photons_per_iteration: n_caustic,
        initial_radius: radius,
        initial_caustic_radius: if n_caustic > 0 { caustic_radius } else { 0.0 },
        radius_derived: settings.radius.is_none(),
        radius_pixels: default_radius_pixels(ctx.resolution),
        ..Default::default()
    };
    progress
        .total
        .store(ctx.spp as u64 * n_pix as u64, Ordering::Relaxed);
    let (mut state, first) = match control.resume.take() {
        Some(IntegratorState::Sppm {
            iterations,
            width,
            height,
            pixels,
        }) if (width, height) == ctx.film_size() && pixels.len() == n_pix => (pixels, iterations),
        _ => {
            let start = |r: f32| PhotonEstimate {
                r2: r as f64 * r as f64,
                ..Default::default()
            };
            let pixel = PixelState {
                global: start(radius),
                caustic: start(caustic_radius),
                ..Default::default()
            };
            (vec![pixel; n_pix], 0)
        }
    };
    progress
        .done
        .fetch_add(first.min(ctx.spp) as u64 * n_pix as u64, Ordering::Relaxed);
    let mut samples = vec![CameraSample::default(); n_pix];
    let sharp_samples = settings.sharp_direct_samples.max(1);
    let sharp: Vec<bool> = if sharp_samples > 1 {
        (0..n_pix)
            .into_par_iter()
            .map(|i| sees_sharp_direct_light(ctx, x0 + (i % w) as u32, y0 + (i / w) as u32))
            .collect()
    } else {
        vec![false; n_pix]
    };
    stats.sharp_pixels = sharp.iter().filter(|&&b| b).count() as u64;
    let mut film = ctx.new_film();
    // Its pixels are progressive estimates, not means of samples: no sample variance.
    film.moments = None;
    let mut done = first;
    let snapshot_state = |state: &[PixelState], done: u32| IntegratorState::Sppm {
        iterations: done,
        width: w as u32,
        height: h as u32,
        pixels: state.to_vec(),
    };
    let alpha = settings.alpha as f64;
    for it in first..ctx.spp {
        if progress.cancelled() {
            break;
        }
        let t0 = Instant::now();
        samples.par_iter_mut().enumerate().for_each(|(i, s)| {
            let (x, y) = (x0 + (i % w) as u32, y0 + (i / w) as u32);
            *s = camera_sample(ctx, seed, settings.max_depth, x, y, it);
            if sharp[i] {
                // More samples of the direct light only, from a stream of their own:
                // which pixels get them was fixed before any random number was drawn.
                let extra = sharp_samples - 1;
                let mut ld = s.ld;
                for e in 0..extra {
                    let index = it.wrapping_mul(extra).wrapping_add(e);
                    let more = camera_sample(
                        ctx,
                        seed ^ SHARP_SAMPLES_SEED,
                        settings.max_depth,
                        x,
                        y,
                        index,
                    );
                    ld += more.ld;
                    s.rays += more.rays;
                }
                s.ld = ld * (1.0 / sharp_samples as f32);
            }
        });
        let camera_rays: u64 = samples.par_iter().map(|s| s.rays as u64).sum();
        stats.camera_seconds += t0.elapsed().as_secs_f64();

        let t1 = Instant::now();
        let mut photon_rays = 0;
        let mut caustic_grid = PhotonGrid::default();
        if let Some(maps) = &maps {
            // Aimed photons count only where they arrive through specular surfaces;
            // whatever they do after that is the global pass's.
            let (deposits, rays) = PhotonPass {
                world,
                stream: PhotonStream::new(ctx.sampler, seed, &[SPPM_CAUSTIC_PASS, it as u64]),
                photons: n_caustic,
                emitted_of: 1.0,
                projection: Some(maps),
                max_depth: settings.max_depth,
            }
            .trace(
                || progress.cancelled(),
                |l, out: &mut Vec<Deposit>| {
                    if l.bounces > 0 && l.landings == 0 {
                        out.push(deposit(l));
                    }
                    false
                },
            );
            photon_rays += rays;
            caustic_grid = PhotonGrid::build(deposits, caustic_radius);
            stats.caustic_seconds += t1.elapsed().as_secs_f64();
        }
        if progress.cancelled() {
            break;
        }
        let split = n_caustic > 0;
        let (deposits, rays) = PhotonPass {
            world,
            stream: PhotonStream::new(ctx.sampler, seed, &[SPPM_PASS, it as u64]),
            photons: n_photons,
            emitted_of: 1.0,
            projection: None,
            max_depth: settings.max_depth,
        }
        .trace(
            || progress.cancelled(),
            |l, out: &mut Vec<Deposit>| {
                // Direct light is next-event estimation's: skip first hits; caustics
                // are the caustic pass's when there is one.
                if l.bounces > 0 && !(split && l.landings == 0) {
                    out.push(deposit(l));
                }
                true
            },
        );
        photon_rays += rays;
        if progress.cancelled() {
            break;
        }
        // Cells as wide as the initial radius, which no pixel's exceeds: the grid, and
        // so the order in which a pixel adds its photons, is then the same whichever
        // part of the image is rendered (a pixel that got no photons keeps its initial
        // radius, so the largest radius would hardly be smaller).
        let global_grid = PhotonGrid::build(deposits, radius);
        state
            .par_iter_mut()
            .zip(samples.par_iter())
            .for_each(|(st, s)| {
                for (c, v) in st.ld.iter_mut().zip(s.ld.to_array()) {
                    *c += v as f64;
                }
                if s.vp.valid {
                    progress_estimate(&mut st.global, &global_grid, &s.vp, alpha);
                    if split {
                        progress_estimate(&mut st.caustic, &caustic_grid, &s.vp, alpha);
                    }
                }
            });
        stats.photon_seconds += t1.elapsed().as_secs_f64();
        stats.rays += camera_rays + photon_rays;
        progress
            .rays
            .fetch_add(camera_rays + photon_rays, Ordering::Relaxed);
        progress.done.fetch_add(n_pix as u64, Ordering::Relaxed);
        done = it + 1;
        let snapshot = done.is_power_of_two();
        if snapshot || control.watches_passes() {
            write_estimates(&mut film, &state, done, n_photons, n_caustic);
            control.after_pass(done, &film);
        }
        if snapshot {
            (control.snapshot)(done, &film);
        }
        control.boundary(done, &|| snapshot_state(&state, done));
    }
    stats.iterations = done;
    let rms = |r2: fn(&PixelState) -> f64| {
        (state.iter().map(r2).sum::<f64>() / n_pix.max(1) as f64).sqrt() as f32
    };
    stats.final_radius = rms(|s| s.global.r2);
    if n_caustic > 0 {
        stats.final_caustic_radius = rms(|s| s.caustic.r2);
    }
    write_estimates(&mut film, &state, done, n_photons, n_caustic);
    // Pixels are named in the full image's coordinates.
    if let Some((x, y)) = film.nonfinite.first_pixel {
        film.nonfinite.first_pixel = Some((x + x0, y + y0));
    }
    let interrupted = done < ctx.spp;
    RenderOutput {
        state: control.final_state(|| snapshot_state(&state, done)),
        film,
        seconds: start.elapsed().as_secs_f64(),
        rays: progress.rays.load(Ordering::Relaxed),
        spp_done: done,
        interrupted,
        stats: Stats::new(stats),
        blocks: Vec::new(),
    }
}

/// The photons for which a visible point on a layered surface evaluates the BSDF in an
/// iteration ([`gather_sampled`]). Chosen by time to error (docs/speed.md): on
/// staircase2, 8 takes 0.58× the CPU time of evaluating all for +0.08 % of relMSE (4:
/// 0.51×, +0.16 %); on a Cornell box of varnished walls, where a pixel gets fewer
/// photons an iteration, 4 added 3 % of error and 8 none.
const ESTIMATED_EVALS: usize = 8;

/// The photon as the grid keeps it.
fn deposit(l: &Landing) -> Deposit {
    Deposit {
        p: l.hit.p.to_array(),
        wi: l.wi.to_array(),
        power: l.power,
    }
}

/// One iteration of a pixel's estimate: the photons of `grid` within its radius,
/// weighted by the BSDF at the visible point, then the progressive update
/// (Hachisuka et al. 2008, §4.2): with M photons, N ← N + αM, R² ← R² (N + αM)/(N + M),
/// τ ← (τ + β Φ) R'²/R².
fn progress_estimate(est: &mut PhotonEstimate, grid: &PhotonGrid, vp: &VisiblePoint, alpha: f64) {
    let (sum, m) = if vp.material.eval_is_estimated() {
        gather_sampled(grid, vp, est.r2 as f32)
    } else {
        gather(grid, vp, est.r2 as f32)
    };
    if m == 0 {
        return;
    }
    let m = m as f64;
    let n_new = est.n + alpha * m;
    let r2_new = est.r2 * n_new / (est.n + m);
    let scale = r2_new / est.r2;
    let flux = (vp.beta * vp.weigh(sum)).to_array();
    for (t, v) in est.tau.iter_mut().zip(flux) {
        *t = (*t + v as f64) * scale;
    }
    est.n = n_new;
    est.r2 = r2_new;
}

/// The photons of `grid` within `r2` of the visible point: the sum of their powers
/// weighted by the BSDF (or, at a Lambertian point, unweighted), and their count.
fn gather(grid: &PhotonGrid, vp: &VisiblePoint, r2: f32) -> (Rgb, u32) {
    let mut sum = Rgb::BLACK;
    let mut m = 0u32;
    grid.for_each_within(vp.p, r2, |d| {
        let wi = Vec3::from_array(d.wi);
        // Photons from behind count only where the BSDF transmits diffusely.
        let front = wi.dot(vp.n) > 0.0;
        if vp.lambertian {
            // albedo/π in front, zero behind: weighed once, on the sum.
            if front {
                sum += d.power;
                m += 1;
            }
            return;
        }
        if !front && !vp.material.transmits_diffusely() {
            return;
        }
        let f = vp.bsdf(wi);
        if !f.is_black() {
            sum += d.power * f;
            m += 1;
        }
    });
    (sum, m)
}

/// [`gather`] where the BSDF's value is itself a random walk: the photons are counted
/// in a first pass; in a second the BSDF is evaluated for all of them where they are
/// at most [`ESTIMATED_EVALS`], otherwise for that many, drawn along their powers and
/// reweighted ([`SystematicDraw`]), which keeps the sum unbiased. Every photon on the
/// side the BSDF takes light from is counted, since a walk's value for one may be
/// zero by chance.
fn gather_sampled(grid: &PhotonGrid, vp: &VisiblePoint, r2: f32) -> (Rgb, u32) {
    let counts = |wi: Vec3| wi.dot(vp.n) > 0.0 || vp.material.transmits_diffusely();
    let weight = |power: Rgb| power.r + power.g + power.b;
    let mut total = 0.0f32;
    let mut m = 0u32;
    grid.for_each_within(vp.p, r2, |d| {
        if counts(Vec3::from_array(d.wi)) {
            total += weight(d.power);
            m += 1;
        }
    });
    if total <= 0.0 || !total.is_finite() {
        return (Rgb::BLACK, m);
    }
    let every = m as usize <= ESTIMATED_EVALS;
    let mut draw = SystematicDraw::new(total, ESTIMATED_EVALS, vp.u_evals);
    let mut sum = Rgb::BLACK;
    grid.for_each_within(vp.p, r2, |d| {
        let wi = Vec3::from_array(d.wi);
        if counts(wi) {
            let reweight = if every {
                1.0
            } else {
                draw.reweight(weight(d.power))
            };
            if reweight > 0.0 {
                sum += d.power * vp.bsdf(wi) * reweight;
            }
        }
    });
    (sum, m)
}

/// Writes each pixel's estimate after `k` iterations into the film (a non-finite one
/// is counted and left black, as the pass loop does with samples): the direct light's
/// mean and each photon estimate's τ / (k N_p π R²).
fn write_estimates(film: &mut Film, state: &[PixelState], k: u32, n_photons: u64, n_caustic: u64) {
    film.nonfinite = NonFinite::default();
    if k == 0 {
        return;
    }
    let kf = k as f64;
    let width = film.width;
    let density = |est: &PhotonEstimate, c: usize, n: u64| {
        if n == 0 {
            0.0
        } else {
            est.tau[c] / (kf * n as f64 * PI as f64 * est.r2)
        }
    };
    for (i, (px, st)) in film.pixels.iter_mut().zip(state).enumerate() {
        let v = |c: usize| {
            st.ld[c] / kf + density(&st.global, c, n_photons) + density(&st.caustic, c, n_caustic)
        };
        let value = [v(0), v(1), v(2)];
        if value.iter().all(|c| c.is_finite()) {
            *px = FilmPixel::estimate(value, k);
        } else {
            *px = FilmPixel::estimate([0.0; 3], k);
            film.nonfinite.merge(NonFinite {
                count: 1,
                first_pixel: Some(((i % width) as u32, (i / width) as u32)),
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;
    use radiant_scene::CoatDesc;

    /// A varnished visible point among photons from all over its hemisphere: the gather
    /// that evaluates the layered BSDF for eight of them, averaged over its number,
    /// matches the gather that evaluates it for all (a walk's value is a function of
    /// the two directions, so the full sum is a fixed number), and counts the same
    /// photons; with no more photons than evaluations the two are the same.
    #[test]
    fn a_varnished_point_sampling_its_photons_gathers_what_evaluating_all_does() {
        let coat = CoatDesc {
            eta: 1.5,
            alpha_u: 0.3,
            alpha_v: 0.3,
            thickness: 0.01,
            albedo: Rgb::BLACK,
            g: 0.0,
            max_depth: 10,
            samples: 1,
        };
        let material = crate::material::Material::CoatedDiffuse {
            layers: crate::material::layered::coated_diffuse(Rgb::new(0.7, 0.4, 0.2), &coat),
        };
        let mut rng = Pcg32::new(3, 8);
        let photons = |n: usize, rng: &mut Pcg32| -> Vec<Deposit> {
            (0..n)
                .map(|_| {
                    let wi = radiant_math::sampling::uniform_hemisphere(glam::Vec2::new(
                        rng.uniform(),
                        rng.uniform(),
                    ));
                    Deposit {
                        p: [rng.uniform() - 0.5, rng.uniform() - 0.5, 0.0],
                        wi: wi.to_array(),
                        power: Rgb::new(rng.uniform(), rng.uniform(), 0.1 + rng.uniform()),
                    }
                })
                .collect()
        };
        let mut vp = VisiblePoint {
            p: Vec3::ZERO,
            n: Vec3::Z,
            frame: radiant_math::Frame::from_normal(Vec3::Z),
            wo: Vec3::new(0.3, 0.1, 0.95).normalize(),
            beta: Rgb::WHITE,
            material,
            lambertian: false,
            part: crate::material::BsdfPart::Whole,
            u_evals: 0.0,
            valid: true,
        };
        let grid = PhotonGrid::build(photons(400, &mut rng), 1.0);
        let (whole, m_whole) = gather(&grid, &vp, 0.25);
        assert!(m_whole > 4 * ESTIMATED_EVALS as u32, "{m_whole} photons");
        let draws = 2000;
        let mut mean = [0.0f64; 3];
        for j in 0..draws {
            vp.u_evals = (j as f32 + 0.5) / draws as f32;
            let (sum, m) = gather_sampled(&grid, &vp, 0.25);
            assert_eq!(m, m_whole);
            for (acc, c) in mean.iter_mut().zip(sum.to_array()) {
                *acc += c as f64 / draws as f64;
            }
        }
        for (m, w) in mean.into_iter().zip(whole.to_array()) {
            assert!(
                (m / w as f64 - 1.0).abs() < 2e-3,
                "{mean:?} against {whole:?}"
            );
        }
        let few = PhotonGrid::build(photons(3, &mut rng), 1.0);
        vp.u_evals = 0.7;
        assert_eq!(gather_sampled(&few, &vp, 1.0), gather(&few, &vp, 1.0));
    }
}
