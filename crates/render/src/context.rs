//! The render context: what every integrator renders with — the world, the camera, the
//! sampler, the seed, the pixel filter and the sensor — built once from a scene
//! description (pbrt-v4 keeps the same set in its `ImageTileIntegrator`).
//!
//! Camera samples are made here for every integrator: a pixel sample's filter offset
//! and lens point are its first two 2D dimensions, and the camera's weight (the
//! realistic camera's film-irradiance factor) travels with the ray. The sensor's scale
//! is left to the film.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use glam::Vec2;

use crate::camera::{self, Camera, CameraRay};
use crate::sampler::PixelSample;
use crate::world::World;
use radiant_image::{Film, Filter, Sensor};
use radiant_scene::{FileLoc, FilterKind, SamplerKind, SceneDesc, SceneError, Warning};

/// Command-line overrides of the scene's settings.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub spp: Option<u32>,
    pub seed: Option<u64>,
    pub resolution: Option<(u32, u32)>,
    /// The integrator's name, replacing the scene's `Integrator` (read by the layer
    /// that chooses integrators by name).
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

/// Samples per block of the film's accumulation: a pixel's samples are summed in order
/// within blocks `[0, 64)`, `[64, 128)`, … (the last ends at the render's spp), and the
/// block sums are added to the pixel in block order. A render split into sample ranges
/// on block boundaries therefore merges to the same bits as one render: floating-point
/// addition is not associative, so the grouping of the sum is fixed once and for all.
/// Renders of at most 64 samples per pixel are one block (a plain running sum). The
/// size equals the pass loop's largest pass, so passes past the first block are blocks.
pub const SAMPLE_BLOCK: u32 = 64;

/// A rectangle of pixels `[x0, x1) × [y0, y1)` of the full image (pbrt-v4's
/// `pixelbounds`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PixelBounds {
    pub x0: u32,
    pub x1: u32,
    pub y0: u32,
    pub y1: u32,
}

impl PixelBounds {
    /// The whole of a `w × h` image.
    pub fn full(resolution: (u32, u32)) -> PixelBounds {
        PixelBounds {
            x0: 0,
            x1: resolution.0,
            y0: 0,
            y1: resolution.1,
        }
    }

    pub fn width(&self) -> u32 {
        self.x1.saturating_sub(self.x0)
    }

    pub fn height(&self) -> u32 {
        self.y1.saturating_sub(self.y0)
    }

    pub fn is_empty(&self) -> bool {
        self.width() == 0 || self.height() == 0
    }

    pub fn contains(&self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// The overlap of two rectangles (empty when they do not meet).
    pub fn intersect(&self, other: &PixelBounds) -> PixelBounds {
        PixelBounds {
            x0: self.x0.max(other.x0),
            x1: self.x1.min(other.x1),
            y0: self.y0.max(other.y0),
            y1: self.y1.min(other.y1),
        }
    }
}

impl std::fmt::Display for PixelBounds {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.x1, self.y0, self.y1)
    }
}

/// The share of a render one job computes: the pixels of a rectangle and, of each,
/// the samples `[samples.0, samples.1)`. Every sample is a function of (pixel, sample
/// index, seed) alone, so a unit draws exactly the samples the full render draws there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WorkUnit {
    pub pixels: PixelBounds,
    pub samples: (u32, u32),
}

impl WorkUnit {
    /// All pixels, all samples.
    pub fn full(resolution: (u32, u32), spp: u32) -> WorkUnit {
        WorkUnit {
            pixels: PixelBounds::full(resolution),
            samples: (0, spp),
        }
    }
}

/// Everything an integrator needs besides its own settings.
pub struct RenderContext {
    pub world: World,
    pub camera: Camera,
    pub filter: Filter,
    pub sampler: SamplerKind,
    pub seed: u64,
    pub sensor: Sensor,
    pub resolution: (u32, u32),
    /// Samples per pixel (SPPM: iterations).
    pub spp: u32,
    /// The pixels and samples to render (all of them unless set after `new`); the film
    /// covers `work.pixels` only.
    pub work: WorkUnit,
    /// Films keep second moments for a variance channel (pass-loop integrators).
    pub moments: bool,
    /// Pass-loop integrators spread `spp` samples per pixel on average by the error a
    /// uniform pilot sees ([`crate::integrator::adaptive`]) instead of evenly.
    pub adaptive: bool,
}

/// One pixel sample's camera ray.
#[derive(Clone, Copy, Debug)]
pub struct CameraSample {
    /// The ray and the camera's weight; `None` where the camera makes no ray (outside
    /// a lens's image circle): the sample then counts as black.
    pub ray: Option<CameraRay>,
    /// The pixel filter's weight f/pdf for this sample's offset.
    pub filter_weight: f32,
}

impl RenderContext {
    /// Builds the world, camera and filter of a scene; returns the warnings of doing so
    /// (the parser's are in the scene).
    pub fn new(
        desc: &SceneDesc,
        overrides: &Overrides,
    ) -> Result<(RenderContext, Vec<Warning>), SceneError> {
        let mut warnings = Vec::new();
        let resolution = overrides
            .resolution
            .unwrap_or((desc.film.xresolution, desc.film.yresolution));
        // The film (and the image made from it) before anything else is built.
        let pixels = resolution.0 as f64 * resolution.1 as f64;
        let bytes = pixels
            * (std::mem::size_of::<radiant_image::FilmPixel>()
                + std::mem::size_of::<radiant_math::color::Rgb>()) as f64;
        if let Err(over) = crate::budget::check(bytes) {
            let loc = if overrides.resolution.is_some() {
                FileLoc::new("--resolution", 0, 0)
            } else {
                desc.film.loc.clone()
            };
            return Err(SceneError::at(
                &loc,
                format!("a {}x{} film would need {over}", resolution.0, resolution.1),
            ));
        }
        let (mut world, w) = World::build(desc)?;
        warnings.extend(w);
        // Nothing to see or nothing to see by: the image will be black, which is worth a
        // word before the render rather than a puzzle after it.
        let scene_loc = FileLoc::new(desc.camera.loc.file.clone(), 0, 0);
        if world.primitive_count() == 0 && world.lights.is_empty() {
            warnings.push(Warning {
                loc: scene_loc,
                message: "the scene has no shapes and no lights: the image will be black".into(),
            });
        } else if world.lights.is_empty() {
            warnings.push(Warning {
                loc: scene_loc,
                message: "the scene has no lights: the image will be black".into(),
            });
        }
        let camera = camera::from_desc(&desc.camera, &desc.film, resolution, &mut warnings)?;
        let spp = overrides.spp.unwrap_or(desc.sampler.pixel_samples).max(1);
        world.ray_spread = camera::RaySpread::of_camera(&camera, resolution, spp);
        let filter = match desc.filter.kind {
            FilterKind::Box => Filter::box_filter(desc.filter.radius),
            FilterKind::Triangle => Filter::triangle(desc.filter.radius),
            FilterKind::Gaussian { sigma } => Filter::gaussian(desc.filter.radius, sigma),
            FilterKind::Mitchell { b, c } => Filter::mitchell(desc.filter.radius, b, c),
            FilterKind::LanczosSinc { tau } => Filter::lanczos_sinc(desc.filter.radius, tau),
        };
        let spp = spp.max(1);
        let context = RenderContext {
            world,
            camera,
            filter,
            sampler: desc.sampler.kind,
            seed: overrides.seed.unwrap_or(desc.sampler.seed),
            sensor: Sensor::new(desc.film.iso, desc.camera.exposure_time)
                .with_max_component(desc.film.max_component_value)
                .with_white_balance(desc.film.white_balance),
            resolution,
            spp,
            work: WorkUnit::full(resolution, spp),
            moments: false,
            adaptive: false,
        };
        Ok((context, warnings))
    }

    /// An empty film of the work unit's pixels, recording through the scene's sensor.
    pub fn new_film(&self) -> Film {
        let (w, h) = self.film_size();
        let film = Film::new(w as usize, h as usize, self.sensor);
        if self.moments {
            film.with_moments()
        } else {
            film
        }
    }

    /// The film's size: the work unit's pixel rectangle.
    pub fn film_size(&self) -> (u32, u32) {
        (self.work.pixels.width(), self.work.pixels.height())
    }

    /// The pixel sampler of sample `index` of pixel `(x, y)`, with stream `seed`.
    pub fn pixel_sample(&self, seed: u64, x: u32, y: u32, index: u32) -> PixelSample {
        PixelSample::new(self.sampler, seed, x, y, index)
    }

    /// The camera ray of pixel `(x, y)` from the sampler's first two 2D dimensions
    /// (filter offset, lens).
    pub fn camera_sample(&self, sampler: &mut PixelSample, x: u32, y: u32) -> CameraSample {
        let fs = self.filter.sample(sampler.get_2d());
        let raster = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + fs.offset;
        let u_lens = sampler.get_2d_if(self.camera.uses_lens_sample());
        let mut ray = self.camera.generate_ray(raster, u_lens);
        if ray.is_some() {
            crate::stats::add(crate::stats::Counter::CameraRays, 1);
        }
        if self.filter.has_negative_lobes() {
            // Signed weights would make the film's weighted mean Σ w L / Σ w blow up
            // wherever a pixel's few weights nearly cancel (one sample in a negative lobe
            // of two gives ±10⁶). Carried by the radiance instead, with the film weighing
            // every sample 1, the pixel is Σ w L / n: unbiased, as E[w] = 1, and bounded.
            if let Some(r) = &mut ray {
                r.weight *= fs.weight;
            }
            return CameraSample {
                ray,
                filter_weight: 1.0,
            };
        }
        CameraSample {
            ray,
            filter_weight: fs.weight,
        }
    }
}
