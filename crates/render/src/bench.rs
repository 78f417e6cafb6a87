//! Figures for `radiant bench`: ray throughput through the whole world (BVHs, shape
//! dispatch, hit expansion) on the canonical Cornell box, and the wall time of a
//! canonical render, and environment-light sampling. The million-triangle figures come from
//! [`ray_benchmark`](crate::accel::ray_benchmark).

use std::fmt;
use std::time::Instant;

use glam::Vec2;
use rayon::prelude::*;

use super::sampler::PixelSample;
use crate::context::{Overrides, RenderContext};
use crate::integrator::{Integrator, PathIntegrator, PathSettings};
use radiant_math::{Frame, sampling};
use radiant_scene::{SamplerKind, SceneDesc};

/// Rays per second of the three kinds a path tracer casts.
#[derive(Clone, Copy, Debug)]
pub struct WorldRayFigures {
    pub camera_mrays_per_s: f64,
    pub bounce_mrays_per_s: f64,
    pub shadow_mrays_per_s: f64,
    pub rays_each: usize,
    pub threads: usize,
}

impl fmt::Display for WorldRayFigures {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "camera {:.2} / bounce {:.2} / shadow {:.2} Mrays/s ({} rays each, {} threads)",
            self.camera_mrays_per_s,
            self.bounce_mrays_per_s,
            self.shadow_mrays_per_s,
            self.rays_each,
            self.threads
        )
    }
}

/// Traces one camera ray per pixel of a `size`² image of `desc`, one cosine-distributed
/// bounce ray from every camera hit (closest hit) and one shadow ray from every camera
/// hit to a point sampled on a light (any hit); reports the fastest of `repetitions`.
pub fn world_ray_benchmark(desc: &SceneDesc, size: u32, repetitions: u32) -> WorldRayFigures {
    let (ctx, _) = RenderContext::new(
        desc,
        &Overrides {
            resolution: Some((size, size)),
            spp: Some(1),
            ..Default::default()
        },
    )
    .expect("benchmark scene builds");
    let world = &ctx.world;
    let scene = world.scene_sphere();
    let camera_rays: Vec<_> = (0..size * size)
        .into_par_iter()
        .filter_map(|i| {
            let (x, y) = (i % size, i / size);
            let raster = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            ctx.camera
                .generate_ray(raster, Vec2::splat(0.5))
                .map(|c| c.ray)
        })
        .collect();
    let hits: Vec<_> = camera_rays
        .par_iter()
        .filter_map(|r| world.intersect(r, f32::INFINITY))
        .collect();
    let bounce_rays: Vec<_> = hits
        .par_iter()
        .enumerate()
        .map(|(i, h)| {
            let mut s = PixelSample::for_stream(SamplerKind::Independent, 1, i as u64, 0);
            let d = Frame::from_normal(h.ng).to_world(sampling::cosine_hemisphere(s.get_2d()));
            h.spawn_ray(d)
        })
        .collect();
    let shadow_rays: Vec<_> = hits
        .par_iter()
        .enumerate()
        .filter_map(|(i, h)| {
            let mut s = PixelSample::for_stream(SamplerKind::Independent, 2, i as u64, 0);
            let ctx = h.light_sample_context();
            let chosen = world.light_sampler.sample(&ctx, s.get_1d())?;
            let ls = world.lights[chosen.index].sample_li(&ctx, s.get_2d(), scene)?;
            Some(if ls.at_infinity {
                (h.spawn_ray(ls.wi), f32::INFINITY)
            } else {
                h.surface_point().spawn_ray_to(&ls.p_light)
            })
        })
        .collect();
    let best = |f: &dyn Fn() -> usize| -> f64 {
        (0..repetitions.max(1))
            .map(|_| {
                let t = Instant::now();
                std::hint::black_box(f());
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    };
    let t_camera = best(&|| {
        camera_rays
            .par_iter()
            .filter(|r| world.intersect(r, f32::INFINITY).is_some())
            .count()
    });
    let t_bounce = best(&|| {
        bounce_rays
            .par_iter()
            .filter(|r| world.intersect(r, f32::INFINITY).is_some())
            .count()
    });
    let t_shadow = best(&|| {
        shadow_rays
            .par_iter()
            .filter(|(r, d)| world.occluded(r, *d))
            .count()
    });
    WorldRayFigures {
        camera_mrays_per_s: camera_rays.len() as f64 / t_camera / 1e6,
        bounce_mrays_per_s: bounce_rays.len() as f64 / t_bounce / 1e6,
        shadow_mrays_per_s: shadow_rays.len() as f64 / t_shadow / 1e6,
        rays_each: camera_rays.len(),
        threads: rayon::current_num_threads(),
    }
}

/// Wall time of path tracing `desc` at its own settings with `spp` samples per pixel.
pub fn render_benchmark(desc: &SceneDesc, spp: u32) -> (f64, radiant_image::Image) {
    let (ctx, _) = RenderContext::new(
        desc,
        &Overrides {
            spp: Some(spp),
            ..Default::default()
        },
    )
    .expect("benchmark scene builds");
    let path = PathIntegrator {
        settings: PathSettings::from_desc(&desc.integrator).unwrap_or_default(),
    };
    let t = Instant::now();
    let out = path.render_unobserved(&ctx);
    (t.elapsed().as_secs_f64(), out.film.image())
}

/// Environment sampling figures (one thread): light samples per second from an
/// environment image with a small bright sun, by importance sampling and by uniform
/// sphere sampling, and the noise of each for the irradiance of a surface the sun
/// shines on.
#[derive(Clone, Copy, Debug)]
pub struct EnvironmentFigures {
    pub size: usize,
    pub samples: usize,
    pub importance_msamples_per_s: f64,
    pub uniform_msamples_per_s: f64,
    /// Radiance lookups by direction per second.
    pub lookup_mlookups_per_s: f64,
    /// Variance of uniform sampling over that of importance sampling, per sample.
    pub variance_ratio: f64,
    /// The same at equal time: `variance_ratio` times the uniform sampler's speed-up.
    pub equal_time_ratio: f64,
}

impl fmt::Display for EnvironmentFigures {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{s}x{s} image: importance {:.2} / uniform {:.2} Msamples/s, lookups {:.2} M/s; \
             variance uniform/importance {:.0}x per sample, {:.0}x at equal time ({} samples, 1 thread)",
            self.importance_msamples_per_s,
            self.uniform_msamples_per_s,
            self.lookup_mlookups_per_s,
            self.variance_ratio,
            self.equal_time_ratio,
            self.samples,
            s = self.size,
        )
    }
}

/// A sky of radiance 0.6 above the horizon, 0.15 below, and a sun of radiance 2000 and
/// half-angle 0.06 rad (about 82 % of the power), each pixel the mean of 4 x 4 points.
pub fn sun_sky_image(size: usize) -> Vec<radiant_math::Rgb> {
    use radiant_math::equal_area::square_to_sphere;
    let sun = glam::Vec3::new(0.45, -0.3, 0.84).normalize();
    let cos_sun = 0.06f32.cos();
    (0..size * size)
        .map(|i| {
            let (x, y) = ((i % size) as f32, (i / size) as f32);
            let mut s = 0.0;
            for k in 0..16 {
                let st = Vec2::new(
                    (x + ((k % 4) as f32 + 0.5) / 4.0) / size as f32,
                    (y + ((k / 4) as f32 + 0.5) / 4.0) / size as f32,
                );
                let w = square_to_sphere(st);
                s += if w.dot(sun) >= cos_sun {
                    2000.0
                } else if w.z > 0.0 {
                    0.6
                } else {
                    0.15
                };
            }
            radiant_math::Rgb::splat(s / 16.0)
        })
        .collect()
}

pub fn environment_benchmark(size: usize, samples: usize) -> EnvironmentFigures {
    use crate::light::{EnvironmentMap, Light, LightSampleContext, SceneSphere};
    use radiant_math::hash::Pcg32;
    use std::sync::Arc;
    let env = Light::Infinite {
        radiance: radiant_math::Rgb::WHITE,
        map: Some(Arc::new(EnvironmentMap::new(
            size,
            &sun_sky_image(size),
            radiant_math::Rgb::WHITE,
            glam::Mat3::IDENTITY,
        ))),
    };
    let uniform = Light::Infinite {
        radiance: radiant_math::Rgb::WHITE,
        map: None,
    };
    let scene = SceneSphere {
        center: glam::Vec3::ZERO,
        radius: 1.0,
    };
    let ctx = LightSampleContext::at_point(glam::Vec3::ZERO);
    let n = glam::Vec3::new(0.1, 0.2, 1.0).normalize();
    // (seconds, variance) of the irradiance estimate by `light`'s directions.
    let run = |light: &Light| -> (f64, f64) {
        let mut rng = Pcg32::new(1, 2);
        let (mut s, mut s2) = (0.0f64, 0.0f64);
        let t = Instant::now();
        for _ in 0..samples {
            let u = Vec2::new(rng.uniform(), rng.uniform());
            let v = light.sample_li(&ctx, u, scene).map_or(0.0, |ls| {
                (env.environment(ls.wi).g * ls.wi.dot(n).max(0.0) / ls.pdf) as f64
            });
            s += v;
            s2 += v * v;
        }
        let seconds = t.elapsed().as_secs_f64();
        let mean = s / samples as f64;
        (seconds, (s2 / samples as f64 - mean * mean).max(0.0))
    };
    let (t_is, var_is) = run(&env);
    let (t_u, var_u) = run(&uniform);
    let mut rng = Pcg32::new(3, 4);
    let t = Instant::now();
    let mut acc = 0.0f32;
    for _ in 0..samples {
        let d = sampling::uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
        acc += env.environment(d).g;
    }
    std::hint::black_box(acc);
    let t_lookup = t.elapsed().as_secs_f64();
    let variance_ratio = var_u / var_is.max(f64::MIN_POSITIVE);
    EnvironmentFigures {
        size,
        samples,
        importance_msamples_per_s: samples as f64 / t_is / 1e6,
        uniform_msamples_per_s: samples as f64 / t_u / 1e6,
        lookup_mlookups_per_s: samples as f64 / t_lookup / 1e6,
        variance_ratio,
        equal_time_ratio: variance_ratio * t_u / t_is,
    }
}
