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
//! Photon contributions are collected per chunk of photons and applied in chunk order,
//! so images are bit-identical at any thread count.

pub mod hashgrid;
pub mod settings;
pub mod visible;

use std::fmt;
use std::sync::atomic::Ordering;
use std::time::Instant;

use glam::{Vec3, Vec4};
use rayon::prelude::*;

pub use settings::SppmSettings;

use super::footprint::pixel_footprint;
use super::photon::trace::{PhotonPass, PhotonStream};
use crate::context::RenderContext;
use crate::integrator::{
    Integrator, IntegratorState, RenderControl, RenderOutput, SppmPixel, StateKind, Stats,
};
use hashgrid::HashGrid;
use radiant_image::{Film, FilmPixel, NonFinite};
use radiant_math::PI;
use radiant_math::color::Rgb;
use visible::{CameraSample, camera_sample};

const SPPM_PASS: u64 = 0x5bb3;

/// Pixel footprints in the default initial radius.
pub const DEFAULT_RADIUS_PIXELS: f32 = 2.0;

/// What an SPPM render did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SppmStats {
    pub iterations: u32,
    pub photons_per_iteration: u64,
    /// Initial radius (scene units).
    pub initial_radius: f32,
    /// True when the radius was derived from the pixel footprint (no `radius` given).
    pub radius_derived: bool,
    /// Root-mean-square radius over the pixels at the end.
    pub final_radius: f32,
    pub camera_seconds: f64,
    pub photon_seconds: f64,
    pub rays: u64,
}

impl fmt::Display for SppmStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "sppm: initial radius {:.4}{}, final rms radius {:.4}",
            self.initial_radius,
            if self.radius_derived {
                format!(" ({DEFAULT_RADIUS_PIXELS} pixel footprints at the scene centre)")
            } else {
                String::new()
            },
            self.final_radius
        )?;
        let photons = self.iterations as u64 * self.photons_per_iteration;
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

/// The default initial radius: [`DEFAULT_RADIUS_PIXELS`] pixel footprints at the
/// distance of the scene's centre (or 1/100 of the scene's radius without one).
pub fn default_radius(ctx: &RenderContext) -> f32 {
    pixel_footprint(&ctx.camera, ctx.resolution, &ctx.world)
        .map_or(0.01 * ctx.world.scene_sphere().radius, |(w, _)| {
            DEFAULT_RADIUS_PIXELS * w
        })
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
    let n_photons = settings
        .photons_per_iteration
        .map_or(full_pixels, u64::from)
        .max(1);
    let mut stats = SppmStats {
        photons_per_iteration: n_photons,
        initial_radius: radius,
        radius_derived: settings.radius.is_none(),
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
        _ => (
            vec![
                PixelState {
                    r2: radius as f64 * radius as f64,
                    ..Default::default()
                };
                n_pix
            ],
            0,
        ),
    };
    progress
        .done
        .fetch_add(first.min(ctx.spp) as u64 * n_pix as u64, Ordering::Relaxed);
    let mut samples = vec![CameraSample::default(); n_pix];
    let mut spheres = vec![Vec4::ZERO; n_pix];
    let mut phi = vec![Rgb::BLACK; n_pix];
    let mut count = vec![0u32; n_pix];
    let world = &ctx.world;
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
    for it in first..ctx.spp {
        if progress.cancelled() {
            break;
        }
        let t0 = Instant::now();
        samples.par_iter_mut().enumerate().for_each(|(i, s)| {
            *s = camera_sample(
                ctx,
                seed,
                settings.max_depth,
                x0 + (i % w) as u32,
                y0 + (i / w) as u32,
                it,
            );
        });
        let camera_rays: u64 = samples.par_iter().map(|s| s.rays as u64).sum();
        // Positions and squared radii side by side: the photon pass tests many
        // candidates per hit and reads little else.
        spheres
            .par_iter_mut()
            .zip(samples.par_iter().zip(state.par_iter()))
            .for_each(|(sp, (s, st))| {
                *sp = if s.vp.valid {
                    s.vp.p.extend(st.r2 as f32)
                } else {
                    Vec4::new(0.0, 0.0, 0.0, -1.0)
                };
            });
        let grid = HashGrid::build(&spheres);
        stats.camera_seconds += t0.elapsed().as_secs_f64();

        let t1 = Instant::now();
        let (hits, photon_rays) = PhotonPass {
            world,
            stream: PhotonStream::new(ctx.sampler, seed, &[SPPM_PASS, it as u64]),
            photons: n_photons,
            emitted_of: 1.0,
            projection: None,
            max_depth: settings.max_depth,
        }
        .trace(
            || progress.cancelled(),
            |l, out: &mut Vec<(u32, Rgb)>| {
                // Direct light is next-event estimation's: skip first hits.
                if l.bounces == 0 {
                    return true;
                }
                let p = l.hit.p;
                for e in grid.candidates(p) {
                    if (Vec3::from_array(e.centre) - p).length_squared() >= e.r2 {
                        continue;
                    }
                    let j = e.index;
                    let vp = &samples[j as usize].vp;
                    // Photons from behind count only where the BSDF transmits diffusely.
                    if l.wi.dot(vp.n) <= 0.0 && !vp.material.transmits_diffusely() {
                        continue;
                    }
                    let f = vp.material.eval(vp.wo, vp.frame.to_local(l.wi));
                    if !f.is_black() {
                        out.push((j, l.power * f));
                    }
                }
                true
            },
        );
        if progress.cancelled() {
            break;
        }
        phi.fill(Rgb::BLACK);
        count.fill(0);
        for &(j, c) in &hits {
            phi[j as usize] += c;
            count[j as usize] += 1;
        }
        let alpha = settings.alpha as f64;
        state
            .par_iter_mut()
            .zip(samples.par_iter())
            .zip(phi.par_iter().zip(count.par_iter()))
            .for_each(|((st, s), (phi, &m))| {
                for (c, v) in st.ld.iter_mut().zip(s.ld.to_array()) {
                    *c += v as f64;
                }
                if m > 0 {
                    let m = m as f64;
                    let n_new = st.n + alpha * m;
                    let r2_new = st.r2 * n_new / (st.n + m);
                    let scale = r2_new / st.r2;
                    let flux = (s.vp.beta * *phi).to_array();
                    for (t, v) in st.tau.iter_mut().zip(flux) {
                        *t = (*t + v as f64) * scale;
                    }
                    st.n = n_new;
                    st.r2 = r2_new;
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
            write_estimates(&mut film, &state, done, n_photons);
            control.after_pass(done, &film);
        }
        if snapshot {
            (control.snapshot)(done, &film);
        }
        control.boundary(done, &|| snapshot_state(&state, done));
    }
    stats.iterations = done;
    let mean_r2 = state.iter().map(|s| s.r2).sum::<f64>() / n_pix.max(1) as f64;
    stats.final_radius = mean_r2.sqrt() as f32;
    write_estimates(&mut film, &state, done, n_photons);
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

/// Writes each pixel's estimate after `k` iterations into the film (a non-finite one
/// is counted and left black, as the pass loop does with samples).
fn write_estimates(film: &mut Film, state: &[PixelState], k: u32, n_photons: u64) {
    film.nonfinite = NonFinite::default();
    if k == 0 {
        return;
    }
    let kf = k as f64;
    let width = film.width;
    for (i, (px, st)) in film.pixels.iter_mut().zip(state).enumerate() {
        let area = PI as f64 * st.r2;
        let v = |c: usize| st.ld[c] / kf + st.tau[c] / (kf * n_photons as f64 * area);
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
