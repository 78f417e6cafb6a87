//! The photon mapper as an integrator: build the maps, then one camera path per pixel
//! sample through the shared pass loop.

use std::time::Instant;

use super::PhotonMaps;
use super::eye::{self, EyeContext, EyeScratch, GatherStream};
use super::settings::PhotonSettings;
use crate::context::RenderContext;
use crate::geometry::Ray;
use crate::integrator::footprint::pixel_footprint;
use crate::integrator::{
    Integrator, PixelEstimator, PixelId, RenderControl, RenderOutput, Stats, render_passes,
};
use crate::sampler::PixelSample;
use radiant_math::color::Rgb;
use radiant_math::hash::hash_u64s;
use radiant_scene::SamplerKind;

/// Names the gather-ray streams of the photon mapper.
const GATHER_TAG: u64 = 0x6a7e;

/// `Integrator "photonmap"` (and `"photonviz"`, its visualisations).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonMapIntegrator {
    pub settings: PhotonSettings,
}

impl Integrator for PhotonMapIntegrator {
    fn name(&self) -> &'static str {
        if self.settings.visualize == super::Visualize::None {
            "photonmap"
        } else {
            "photonviz"
        }
    }

    fn render(&self, ctx: &RenderContext, control: &mut RenderControl<'_>) -> RenderOutput {
        let start = Instant::now();
        let seed = self.settings.seed.unwrap_or(ctx.seed);
        let progress = control.progress;
        let maps = PhotonMaps::build(&ctx.world, &self.settings, ctx.sampler, seed, progress);
        progress
            .rays
            .fetch_add(maps.stats.rays, std::sync::atomic::Ordering::Relaxed);
        let pixel_angle =
            pixel_footprint(&ctx.camera, ctx.resolution, &ctx.world).map_or(1e-3, |(w, t)| w / t);
        let estimator = EyeEstimator {
            eye: EyeContext {
                world: &ctx.world,
                maps: &maps,
                scene: ctx.world.scene_sphere(),
                pixel_angle,
            },
            kind: ctx.sampler,
            seed,
        };
        let mut out = render_passes(ctx, &estimator, control);
        out.stats = Stats::new(maps.stats);
        out.seconds = start.elapsed().as_secs_f64();
        out
    }
}

struct EyeEstimator<'a> {
    eye: EyeContext<'a>,
    kind: SamplerKind,
    seed: u64,
}

impl PixelEstimator for EyeEstimator<'_> {
    type Scratch = EyeScratch;

    fn scratch(&self) -> EyeScratch {
        EyeScratch::new(self.eye.maps)
    }

    fn radiance(
        &self,
        ray: Ray,
        sampler: &mut PixelSample,
        pixel: PixelId,
        scratch: &mut EyeScratch,
    ) -> (Rgb, u32) {
        let gather = GatherStream {
            kind: self.kind,
            seed: self.seed,
            key: hash_u64s(&[
                pixel.x as u64,
                pixel.y as u64,
                pixel.index as u64,
                GATHER_TAG,
            ]),
        };
        eye::radiance(&self.eye, ray, sampler, gather, scratch)
    }
}
