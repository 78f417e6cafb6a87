//! The path tracer: radiance by random walks from the camera with next-event estimation
//! and multiple importance sampling (Veach & Guibas 1995, power heuristic), Russian
//! roulette and specular chains. An iterative loop carrying a throughput — no recursion.

use crate::geometry::Ray;
use crate::light::{Light, LightSampleContext};
use crate::material::TransportMode;
use crate::sampler::PixelSample;
use crate::world::{NO_LIGHT, World};
use radiant_math::color::Rgb;
use radiant_math::sampling::power_heuristic;
use radiant_scene::{IntegratorDesc, SceneError};

use super::direct;
use super::{Integrator, PixelEstimator, PixelId, RenderControl, RenderOutput, render_passes};
use crate::context::RenderContext;

/// `Integrator "path"` parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSettings {
    /// `"integer maxdepth" [5]`: the number of bounces; emission seen after the last
    /// bounce still counts.
    pub max_depth: u32,
    /// Bounces before Russian roulette may end a path: [`DEFAULT_RR_DEPTH`] unless the
    /// scene says `"integer rrdepth"` (pbrt-v4 starts after 1).
    pub rr_depth: u32,
}

/// Russian roulette starts after this many bounces by default.
///
/// Chosen by efficiency, 1 / (relMSE × CPU time) against the references, at equal
/// samples per pixel on one thread (two seeds, medians); relMSE × CPU-s for `rrdepth`
/// 1 / 2 / 3 / 4 / 5 / 6 / 8 (lower is better):
///
/// - cornell-box, 128 spp: 0.0214 / 0.0186 / 0.0176 / **0.0168** / 0.0173 / 0.0180 / 0.0187;
/// - cornell-caustics, 64 spp, `rrdepth` 1 / 2 / 3 / 4 / 6: 0.256 / 0.268 / 0.292 / 0.289 /
///   0.309 — its error is the caustics' rare bright paths, heavy-tailed, so two seeds
///   hardly separate the settings; the caustics are SPPM's to render.
///
/// Starting at 1 ends many paths whose next vertex still gathers much light (the white
/// walls reflect 70–90 %), for little time saved: each path's first bounces are its
/// cheapest in error per ray. Past 4 the deep bounces cost more time than the variance
/// they remove. 4 is also where Mitsuba 3's `rr_depth` 5 starts (it counts the camera
/// vertex), so the two renderers compare at matched settings.
///
/// The survival rule stays the throughput's: a path survives with probability
/// min(1, max channel of β η²) (η² undoing the radiance scaling at refractions, so that
/// roulette sees the transported importance), and β is divided by it — each surviving
/// path then carries about the weight it had at the start of the roulette (Arvo & Kirk,
/// "Particle Transport and Image Synthesis", 1990).
pub const DEFAULT_RR_DEPTH: u32 = 4;

impl PathSettings {
    pub fn from_desc(desc: &IntegratorDesc) -> Result<PathSettings, SceneError> {
        Ok(PathSettings {
            max_depth: desc.params.count("maxdepth", 5)?,
            rr_depth: desc.params.count("rrdepth", DEFAULT_RR_DEPTH)?,
        })
    }
}

impl Default for PathSettings {
    fn default() -> Self {
        PathSettings {
            max_depth: 5,
            rr_depth: DEFAULT_RR_DEPTH,
        }
    }
}

/// The path tracer as an integrator: one path per pixel sample through the pass loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathIntegrator {
    pub settings: PathSettings,
}

impl Integrator for PathIntegrator {
    fn name(&self) -> &'static str {
        "path"
    }

    fn render(&self, ctx: &RenderContext, control: &mut RenderControl<'_>) -> RenderOutput {
        render_passes(
            ctx,
            &PathEstimator {
                world: &ctx.world,
                settings: &self.settings,
            },
            control,
        )
    }
}

struct PathEstimator<'a> {
    world: &'a World,
    settings: &'a PathSettings,
}

impl PixelEstimator for PathEstimator<'_> {
    type Scratch = ();

    fn scratch(&self) {}

    fn radiance(
        &self,
        ray: Ray,
        sampler: &mut PixelSample,
        _pixel: PixelId,
        _scratch: &mut (),
    ) -> (Rgb, u32) {
        radiance(self.world, self.settings, ray, sampler)
    }
}

/// Radiance along a camera ray; also returns the number of rays traced.
pub fn radiance(
    world: &World,
    settings: &PathSettings,
    mut ray: Ray,
    sampler: &mut PixelSample,
) -> (Rgb, u32) {
    let scene = world.scene_sphere();
    let mut l = Rgb::BLACK;
    let mut beta = Rgb::WHITE;
    // Product of eta^2 scalings at refractions, undone for Russian roulette decisions.
    let mut eta_scale = 1.0f32;
    let mut specular_bounce = true;
    let mut prev_pdf = 0.0f32;
    // The previous vertex as a receiver, for the light-sampling density of what a
    // BSDF-sampled ray finds (with MIS, as its light samples were drawn).
    let mut prev_ctx = LightSampleContext::at_point(ray.o);
    let mut rays = 0u32;
    let mut depth = 0u32;
    // Distance along the path from the camera, for texture footprints.
    let mut travelled = 0.0f32;
    loop {
        rays += 1;
        let Some(hit) = world.intersect_with_footprint(&ray, f32::INFINITY, travelled) else {
            for (i, light) in world.lights.iter().enumerate() {
                let le = light.environment(ray.d);
                if le.is_black() {
                    continue;
                }
                let w = if specular_bounce {
                    1.0
                } else {
                    let pdf_light = world.light_sampler.pmf(&prev_ctx, i)
                        * light.pdf_li(&prev_ctx, ray.d, None);
                    power_heuristic(prev_pdf, pdf_light)
                };
                l += beta * le * w;
            }
            break;
        };
        let d_length = ray.d.length();
        travelled += hit.t * d_length;
        // `normalize` without a second square root.
        let wo_world = -ray.d * (1.0 / d_length);
        if hit.light != NO_LIGHT {
            let Light::Area(area) = &world.lights[hit.light as usize] else {
                unreachable!("primitives only carry area lights")
            };
            let le = area.radiance(hit.ng, hit.uv, wo_world);
            if !le.is_black() {
                let w = if specular_bounce {
                    1.0
                } else {
                    let pdf_light = world.light_sampler.pmf(&prev_ctx, hit.light as usize)
                        * area.pdf_li(&prev_ctx, &hit.light_hit());
                    power_heuristic(prev_pdf, pdf_light)
                };
                l += beta * le * w;
            }
        }
        if depth == settings.max_depth {
            break;
        }
        depth += 1;

        let material = world.material_at(&hit, wo_world);
        let frame = World::shading_frame(&hit, &material);
        let wo = frame.to_local(wo_world);

        // Drawn for every vertex so that the dimension layout does not depend on the material.
        let u_choice = sampler.get_1d_if(world.light_sampler.uses_choice_sample());
        let u_light = sampler.get_2d();
        if !material.is_specular() {
            let at = direct::ShadingPoint::in_frame(&hit, material, frame, wo_world, wo).with_mis();
            let ds = direct::sample_direct(world, scene, &at, u_choice, u_light);
            rays += ds.shadow_rays;
            if let Some(ds) = ds.light {
                let w = if ds.delta {
                    1.0
                } else {
                    power_heuristic(ds.light_pdf, ds.bsdf_pdf)
                };
                l += beta * ds.f * ds.li * (w / ds.light_pdf);
            }
        }

        let u_lobe = sampler.get_1d();
        let u_dir = sampler.get_2d();
        let Some(bs) = material.sample(wo, u_lobe, u_dir, TransportMode::Radiance) else {
            break;
        };
        let wi = frame.to_world(bs.wi);
        if !bs.specular && !direct::sides_agree(&hit, wo_world, wi, wo, bs.wi) {
            break;
        }
        beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
        if let Some(eta) = material.dielectric_eta()
            && wi.dot(hit.ng) * wo_world.dot(hit.ng) < 0.0
        {
            // Refraction: track eta^2 so roulette sees the unscaled throughput.
            eta_scale *= if wo_world.dot(hit.ng) > 0.0 {
                eta * eta
            } else {
                1.0 / (eta * eta)
            };
        }
        specular_bounce = bs.specular;
        prev_pdf = bs.pdf;
        prev_ctx = hit.light_sample_context().with_mis();
        ray = hit.spawn_ray(wi);

        let roulette = depth > settings.rr_depth;
        let u_rr = sampler.get_1d_if(roulette);
        let rr_beta = beta.max_component() * eta_scale;
        if roulette && rr_beta < 1.0 {
            let q = (1.0 - rr_beta).max(0.0);
            if u_rr < q {
                break;
            }
            beta /= 1.0 - q;
        }
        if beta.is_black() {
            break;
        }
    }
    (l, rays)
}
