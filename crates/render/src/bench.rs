//! Figures for `radiant bench`: ray throughput through the whole world (BVHs, shape
//! dispatch, hit expansion) on the canonical Cornell box, and the wall time of a
//! canonical render. The million-triangle figures come from
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
