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
use super::integrator::footprint::pixel_footprint;
use super::integrator::photon::PhotonMaps;
use super::integrator::photon::eye::{self, EyeContext, EyeScratch, GatherStream};
use super::integrator::{Integrator, IntegratorStats, PathSettings, path, sppm};
use super::sampler::PixelSample;
use super::world::World;
use crate::color::Rgb;
use crate::image::Image;
use crate::image::film::{Film, FilmPixel, NonFinite};
use crate::image::filter::Filter;
use crate::math::hash::hash_u64s;
use crate::radiosity::render::Shading;
use crate::radiosity::scene::RadiosityScene;
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
    /// The meshed scene, when the integrator is radiosity.
    pub radiosity: Option<Box<RadiosityScene>>,
}

/// A finished (or interrupted) render.
pub struct RenderOutput {
    pub film: Film,
    pub seconds: f64,
    pub rays: u64,
    /// Samples per pixel (SPPM: iterations) actually completed in every pixel.
    pub spp_done: u32,
    pub interrupted: bool,
    /// Photon counts, radii and timings of the photon mappers.
    pub stats: IntegratorStats,
}

/// The per-pixel integrator of a render, with what it prepared (photon maps, a solved
/// radiosity scene).
enum PixelIntegrator<'a> {
    Path(&'a PathSettings),
    PhotonMap { ctx: EyeContext<'a>, seed: u64 },
    Radiosity(&'a Shading<'a>),
}

/// Names the gather-ray streams of the photon mapper.
const GATHER_TAG: u64 = 0x6a7e;

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
        let radiosity = match &integrator {
            Integrator::Radiosity(settings) => {
                let scene = RadiosityScene::from_desc(desc, settings)?;
                warnings.extend(scene.warnings.iter().cloned());
                Some(Box::new(scene))
            }
            _ => None,
        };
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
            radiosity,
        })
    }

    /// Renders the image. Rayon's current thread pool sets the parallelism.
    pub fn render(&self, progress: &Progress) -> RenderOutput {
        self.render_with_snapshots(progress, &mut |_, _| {})
    }

    /// Renders the image, calling `snapshot(n, image)` each time the samples per pixel
    /// completed (SPPM: iterations) reach a power of two n.
    pub fn render_with_snapshots(
        &self,
        progress: &Progress,
        snapshot: &mut dyn FnMut(u32, &Image),
    ) -> RenderOutput {
        let start = Instant::now();
        match &self.integrator {
            Integrator::Path(settings) => {
                let mut out =
                    self.render_passes(&PixelIntegrator::Path(settings), progress, snapshot);
                out.seconds = start.elapsed().as_secs_f64();
                out
            }
            Integrator::PhotonMap(settings) => {
                let seed = settings.seed.unwrap_or(self.seed);
                let maps = PhotonMaps::build(&self.world, settings, self.sampler, seed, progress);
                progress.rays.fetch_add(maps.stats.rays, Ordering::Relaxed);
                let pixel_angle = pixel_footprint(&self.camera, self.resolution, &self.world)
                    .map_or(1e-3, |(w, t)| w / t);
                let ctx = EyeContext {
                    world: &self.world,
                    maps: &maps,
                    scene: self.world.scene_sphere(),
                    pixel_angle,
                };
                let mut out = self.render_passes(
                    &PixelIntegrator::PhotonMap { ctx, seed },
                    progress,
                    snapshot,
                );
                out.stats = IntegratorStats::PhotonMap(maps.stats);
                out.seconds = start.elapsed().as_secs_f64();
                out
            }
            Integrator::Radiosity(settings) => {
                let scene = self
                    .radiosity
                    .as_deref()
                    .expect("Session::new meshes the scene for radiosity");
                crate::radiosity::render::render_session(self, scene, settings, progress, snapshot)
            }
            Integrator::Sppm(settings) => {
                let out = sppm::render(self, settings, progress, snapshot);
                let mut film = Film::new(out.image.width, out.image.height);
                for (fp, c) in film.pixels.iter_mut().zip(&out.image.pixels) {
                    *fp = FilmPixel {
                        sum: [c.r as f64, c.g as f64, c.b as f64],
                        weight: 1.0,
                        samples: out.stats.iterations,
                    };
                }
                RenderOutput {
                    film,
                    seconds: start.elapsed().as_secs_f64(),
                    rays: progress.rays.load(Ordering::Relaxed),
                    spp_done: out.stats.iterations,
                    interrupted: out.interrupted,
                    stats: IntegratorStats::Sppm(out.stats),
                }
            }
        }
    }

    /// The pass loop over a solved radiosity scene's shading (the radiosity integrator,
    /// and the images of `radiant radiosity`).
    pub fn render_shading(
        &self,
        shading: &Shading<'_>,
        progress: &Progress,
        snapshot: &mut dyn FnMut(u32, &Image),
    ) -> RenderOutput {
        let start = Instant::now();
        let mut out = self.render_passes(&PixelIntegrator::Radiosity(shading), progress, snapshot);
        out.seconds = start.elapsed().as_secs_f64();
        out
    }

    /// The pass loop of the per-pixel integrators.
    fn render_passes(
        &self,
        pixel: &PixelIntegrator,
        progress: &Progress,
        snapshot: &mut dyn FnMut(u32, &Image),
    ) -> RenderOutput {
        let (w, h) = (self.resolution.0 as usize, self.resolution.1 as usize);
        let mut film = Film::new(w, h);
        progress
            .total
            .store(w as u64 * h as u64 * self.spp as u64, Ordering::Relaxed);
        let mut spp_done = 0u32;
        let mut pass = 1u32;
        while spp_done < self.spp && !progress.cancelled() {
            let n = pass.min(self.spp - spp_done);
            let nonfinite = self.render_pass(pixel, &mut film, spp_done, n, progress);
            film.nonfinite.merge(nonfinite);
            if progress.cancelled() {
                break;
            }
            spp_done += n;
            if spp_done.is_power_of_two() {
                snapshot(spp_done, &film.image());
            }
            if spp_done >= 2 {
                pass = (pass * 2).min(64);
            }
        }
        RenderOutput {
            spp_done: film.min_samples(),
            film,
            seconds: 0.0,
            rays: progress.rays.load(Ordering::Relaxed),
            interrupted: progress.cancelled(),
            stats: IntegratorStats::None,
        }
    }

    /// Adds samples `first .. first + count` to every pixel.
    fn render_pass(
        &self,
        pixel: &PixelIntegrator,
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
                let mut scratch = match pixel {
                    PixelIntegrator::PhotonMap { ctx, .. } => Some(EyeScratch::new(ctx.maps)),
                    PixelIntegrator::Path(_) | PixelIntegrator::Radiosity(_) => None,
                };
                for (x, film_pixel) in row.iter_mut().enumerate() {
                    for index in first..first + count {
                        let (l, weight, r) =
                            self.sample_pixel(pixel, &mut scratch, x as u32, y as u32, index);
                        rays += r as u64;
                        if l.is_finite() && weight.is_finite() {
                            film_pixel.add(l, weight);
                        } else {
                            film_pixel.samples += 1;
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
    fn sample_pixel(
        &self,
        pixel: &PixelIntegrator,
        scratch: &mut Option<EyeScratch>,
        x: u32,
        y: u32,
        index: u32,
    ) -> (Rgb, f32, u32) {
        let mut sampler = PixelSample::new(self.sampler, self.seed, x, y, index);
        let fs = self.filter.sample(sampler.get_2d());
        let raster = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + fs.offset;
        let u_lens = sampler.get_2d();
        let Some(cr) = self.camera.generate_ray(raster, u_lens) else {
            return (Rgb::BLACK, fs.weight, 0);
        };
        let (l, rays) = match (pixel, scratch) {
            (PixelIntegrator::Path(s), _) => path::radiance(&self.world, s, cr.ray, &mut sampler),
            (PixelIntegrator::Radiosity(shading), _) => shading.radiance(cr.ray, &mut sampler),
            (PixelIntegrator::PhotonMap { ctx, seed }, Some(scratch)) => {
                let gather = GatherStream {
                    kind: self.sampler,
                    seed: *seed,
                    key: hash_u64s(&[x as u64, y as u64, index as u64, GATHER_TAG]),
                };
                eye::radiance(ctx, cr.ray, &mut sampler, gather, scratch)
            }
            (PixelIntegrator::PhotonMap { .. }, None) => {
                unreachable!("render_pass makes the scratch")
            }
        };
        (l * (cr.weight * self.imaging_ratio), fs.weight, rays)
    }
}
