//! A render session: the scene prepared for rendering (world, camera, sampler, filter,
//! integrator), and the pass loop that fills the film.
//!
//! Samples are taken in passes (1, 1, 2, 4, … samples per pixel), rows in parallel.
//! Between rows the loop checks for cancellation, so an interrupted render still has a
//! consistent image: every pixel is the mean of the samples it received.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

use glam::Vec2;
use rayon::prelude::*;

use super::camera::Camera;
use super::integrator::{Integrator, path};
use super::sampler::PixelSample;
use super::world::World;
use crate::color::Rgb;
use crate::image::film::{Film, NonFinite};
use crate::image::filter::Filter;
use crate::scene::{SamplerKind, SceneDesc, SceneError, Warning};

/// Command-line overrides of the scene's settings.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub spp: Option<u32>,
    pub seed: Option<u64>,
    pub resolution: Option<(u32, u32)>,
    pub integrator: Option<String>,
}

/// Shared counters for progress display and cancellation (Ctrl-C).
#[derive(Debug, Default)]
pub struct Progress {
    /// Work units to do and done (pixel samples for per-pixel integrators).
    pub total: AtomicU64,
    pub done: AtomicU64,
    pub rays: AtomicU64,
    pub cancel: AtomicBool,
}

impl Progress {
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

/// Everything needed to render, built from a scene description.
pub struct Session {
    pub world: World,
    pub camera: Camera,
    pub filter: Filter,
    pub integrator: Integrator,
    pub resolution: (u32, u32),
    pub spp: u32,
    pub seed: u64,
    pub sampler: SamplerKind,
    /// The sensor's imaging ratio, ISO / 100 (pbrt-v4's `PixelSensor` with a 1 s shutter).
    pub imaging_ratio: f32,
    /// Warnings from preparing the session (the parser's are in the scene).
    pub warnings: Vec<Warning>,
}

/// A finished (or interrupted) render.
pub struct RenderOutput {
    pub film: Film,
    pub seconds: f64,
    pub rays: u64,
    /// Samples per pixel actually completed in every pixel.
    pub spp_done: u32,
    pub interrupted: bool,
}

impl Session {
    pub fn new(desc: &SceneDesc, overrides: &Overrides) -> Result<Session, SceneError> {
        let mut warnings = Vec::new();
        let mut integrator_desc = desc.integrator.clone();
        if let Some(name) = &overrides.integrator {
            integrator_desc.name = name.clone();
        }
        let (integrator, w) = Integrator::from_desc(&integrator_desc)?;
        warnings.extend(w);
        let resolution = overrides
            .resolution
            .unwrap_or((desc.film.xresolution, desc.film.yresolution));
        let (world, w) = World::build(desc)?;
        warnings.extend(w);
        let camera = super::camera::from_desc(&desc.camera, &desc.film, resolution, &mut warnings)?;
        let filter = match desc.filter.kind {
            crate::scene::FilterKind::Box => Filter::box_filter(desc.filter.radius),
            crate::scene::FilterKind::Triangle => Filter::triangle(desc.filter.radius),
            crate::scene::FilterKind::Gaussian { sigma } => {
                Filter::gaussian(desc.filter.radius, sigma)
            }
        };
        Ok(Session {
            world,
            camera,
            filter,
            integrator,
            resolution,
            spp: overrides.spp.unwrap_or(desc.sampler.pixel_samples).max(1),
            seed: overrides.seed.unwrap_or(desc.sampler.seed),
            sampler: desc.sampler.kind,
            imaging_ratio: desc.film.iso / 100.0,
            warnings,
        })
    }

    /// Renders the image. Rayon's current thread pool sets the parallelism.
    pub fn render(&self, progress: &Progress) -> RenderOutput {
        let start = Instant::now();
        let (w, h) = (self.resolution.0 as usize, self.resolution.1 as usize);
        let mut film = Film::new(w, h);
        progress
            .total
            .store(w as u64 * h as u64 * self.spp as u64, Ordering::Relaxed);
        let mut spp_done = 0u32;
        let mut pass = 1u32;
        while spp_done < self.spp && !progress.cancelled() {
            let n = pass.min(self.spp - spp_done);
            let nonfinite = self.render_pass(&mut film, spp_done, n, progress);
            film.nonfinite.merge(nonfinite);
            if progress.cancelled() {
                break;
            }
            spp_done += n;
            if spp_done >= 2 {
                pass = (pass * 2).min(64);
            }
        }
        RenderOutput {
            spp_done: film.min_samples(),
            film,
            seconds: start.elapsed().as_secs_f64(),
            rays: progress.rays.load(Ordering::Relaxed),
            interrupted: progress.cancelled(),
        }
    }

    /// Adds samples `first .. first + count` to every pixel.
    fn render_pass(
        &self,
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
                for (x, pixel) in row.iter_mut().enumerate() {
                    for index in first..first + count {
                        let (l, weight, r) = self.sample_pixel(x as u32, y as u32, index);
                        rays += r as u64;
                        if l.is_finite() && weight.is_finite() {
                            pixel.add(l, weight);
                        } else {
                            pixel.samples += 1;
                            nonfinite.merge(NonFinite {
                                count: 1,
                                first_pixel: Some((x as u32, y as u32)),
                            });
                        }
                    }
                }
                progress.rays.fetch_add(rays, Ordering::Relaxed);
                progress
                    .done
                    .fetch_add(row.len() as u64 * count as u64, Ordering::Relaxed);
                nonfinite
            })
            .reduce(NonFinite::default, |mut a, b| {
                a.merge(b);
                a
            })
    }

    /// One camera sample: radiance, filter weight and rays traced.
    pub fn sample_pixel(&self, x: u32, y: u32, index: u32) -> (Rgb, f32, u32) {
        let mut sampler = PixelSample::new(self.sampler, self.seed, x, y, index);
        let fs = self.filter.sample(sampler.get_2d());
        let raster = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + fs.offset;
        let u_lens = sampler.get_2d();
        let Some(cr) = self.camera.generate_ray(raster, u_lens) else {
            return (Rgb::BLACK, fs.weight, 0);
        };
        let (l, rays) = match &self.integrator {
            Integrator::Path(s) => path::radiance(&self.world, s, cr.ray, &mut sampler),
        };
        (l * (cr.weight * self.imaging_ratio), fs.weight, rays)
    }
}
