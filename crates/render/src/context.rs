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
        };
        let context = RenderContext {
            world,
            camera,
            filter,
            sampler: desc.sampler.kind,
            seed: overrides.seed.unwrap_or(desc.sampler.seed),
            sensor: Sensor::new(desc.film.iso, 1.0)
                .with_max_component(desc.film.max_component_value)
                .with_white_balance(desc.film.white_balance),
            resolution,
            spp: overrides.spp.unwrap_or(desc.sampler.pixel_samples).max(1),
        };
        Ok((context, warnings))
    }

    /// An empty film of the image's size, recording through the scene's sensor.
    pub fn new_film(&self) -> Film {
        Film::new(
            self.resolution.0 as usize,
            self.resolution.1 as usize,
            self.sensor,
        )
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
        let u_lens = sampler.get_2d();
        CameraSample {
            ray: self.camera.generate_ray(raster, u_lens),
            filter_weight: fs.weight,
        }
    }
}
