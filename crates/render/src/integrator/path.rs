//! The path tracer: radiance by random walks from the camera with next-event estimation
//! and multiple importance sampling (Veach & Guibas 1995, power heuristic), Russian
//! roulette and specular chains. An iterative loop carrying a throughput — no recursion.
//! Optionally the first vertex's bounce is split k ways, each branch walked on by that
//! loop (splitting, the counterpart of roulette: Arvo & Kirk, "Particle Transport and
//! Image Synthesis", 1990).

use crate::geometry::Ray;
use crate::light::{Light, LightSampleContext};
use crate::material::{Material, TransportMode};
use crate::sampler::{ContinuedPair, PixelSample, SobolAnchor};
use crate::world::{NO_LIGHT, SurfaceHit, World};
use glam::Vec3;
use radiant_math::color::Rgb;
use radiant_math::frame::Frame;
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
    /// scene says `"integer rrdepth"` (pbrt-v4's default is 1 too).
    pub rr_depth: u32,
    /// The throughput below which roulette plays, [`DEFAULT_RR_THRESHOLD`] unless the
    /// scene says `"float rrthreshold"` (a radiant parameter; 1 is pbrt-v4's and
    /// Mitsuba 3's rule).
    pub rr_threshold: f32,
    /// `"integer primarysplit" [1]`: bounces taken from each camera ray's first vertex,
    /// each followed to its own end and the k averaged (a radiant parameter). Worth it
    /// where the indirect light is the noise and the camera ray and first hit are a
    /// large share of a path's cost; docs/speed.md measures it.
    pub primary_split: u32,
}

/// Russian roulette starts after this many bounces by default.
///
/// With [`DEFAULT_RR_THRESHOLD`] the start matters less than with θ = 1, since paths
/// whose throughput is above the threshold are never ended whatever their depth; what
/// it still decides is how soon the paths of dark surfaces are thinned out. Measured
/// (docs/speed.md, θ = 0.35, 128 spp, relMSE × CPU-s against the pbrt-v4 references):
/// starting after 1 bounce saves the most time in dark scenes (dining-room: 0.55× the
/// CPU time of the earlier default, after 4 at θ = 1, for about its error) but its
/// early survivors carry weights up to θ / β and add fireflies to glossy ones
/// (material-testball: relMSE +24 %); after 2 keeps the earlier default's error there
/// at 0.88× its time, and after 3 gives up most of the dark-scene gain. pbrt-v4 starts after 1, Mitsuba 3 after 4 (its
/// `rr_depth` 5 counts the camera vertex).
pub const DEFAULT_RR_DEPTH: u32 = 2;

/// The throughput below which Russian roulette plays, by default: a path survives with
/// probability min(1, max channel of β η² / θ), and β is divided by it, so that each
/// survivor carries throughput θ (η² undoes the radiance scaling at refractions, so
/// that roulette sees the transported importance; Arvo & Kirk, "Particle Transport and
/// Image Synthesis", 1990). pbrt-v4 and Mitsuba 3 play it below θ = 1, the camera's
/// weight.
///
/// Chosen by efficiency, 1 / (relMSE × cost), against the references (docs/speed.md).
/// cornell-box, relMSE at 128 spp (1e-3) × rays at 16 spp (millions), for (`rrdepth`,
/// θ): (4, 1) 8.38, (4, 0.5) 7.24, (4, 0.35) 7.07, (2, 0.5) 6.89, **(2, 0.35) 6.69**,
/// (2, 0.25) 6.75, (1, 0.35) 6.62. The optimum is flat between 0.25 and 0.5. At θ = 1 a
/// path whose throughput has fallen to 0.3 is ended seven times in ten and the
/// survivors are weighted by 3.3: in a room whose walls reflect 70–90 % they still
/// gather much light, and those weights are the noise. A lower threshold lets paths
/// decay to θ first; past it each survival renormalises the path to θ and later bounces
/// survive about as often as the albedo, as with θ = 1, so the extra cost is a few rays
/// per path. Against the old default (4, 1) on the real scenes (128 spp, two seeds):
/// relMSE × CPU-s 0.80× on cornell-caustics (path), 0.88× material-testball, 0.96×
/// teapot, 0.91× coffee, 0.73× dining-room, 0.92× staircase2.
pub const DEFAULT_RR_THRESHOLD: f32 = 0.35;

impl PathSettings {
    pub fn from_desc(desc: &IntegratorDesc) -> Result<PathSettings, SceneError> {
        let rr_threshold = desc
            .params
            .finite_float("rrthreshold", DEFAULT_RR_THRESHOLD)?;
        if rr_threshold <= 0.0 {
            return Err(SceneError::at(
                &desc.loc,
                format!("\"rrthreshold\" must be positive, got {rr_threshold}"),
            ));
        }
        let primary_split = desc.params.count("primarysplit", 1)?;
        if primary_split == 0 {
            let loc = desc
                .params
                .lookup("primarysplit")
                .map_or(&desc.loc, |p| &p.loc);
            return Err(SceneError::at(
                loc,
                "\"primarysplit\" must be at least 1, got 0".to_string(),
            ));
        }
        Ok(PathSettings {
            max_depth: desc.params.count("maxdepth", 5)?,
            rr_depth: desc.params.count("rrdepth", DEFAULT_RR_DEPTH)?,
            rr_threshold,
            primary_split,
        })
    }
}

impl Default for PathSettings {
    fn default() -> Self {
        PathSettings {
            max_depth: 5,
            rr_depth: DEFAULT_RR_DEPTH,
            rr_threshold: DEFAULT_RR_THRESHOLD,
            primary_split: 1,
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
        let estimator = PathEstimator {
            world: &ctx.world,
            settings: &self.settings,
        };
        // Chosen once per render, so that the unsplit walk is compiled as if splitting
        // did not exist.
        if self.settings.primary_split > 1 {
            render_passes(ctx, &SplitPathEstimator(estimator), control)
        } else {
            render_passes(ctx, &estimator, control)
        }
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
        walk::<false>(self.world, self.settings, WalkStart::camera(ray), sampler)
    }
}

/// [`PathEstimator`] with the first vertex's bounce taken `settings.primary_split` times.
struct SplitPathEstimator<'a>(PathEstimator<'a>);

impl PixelEstimator for SplitPathEstimator<'_> {
    type Scratch = ();

    fn scratch(&self) {}

    fn radiance(
        &self,
        ray: Ray,
        sampler: &mut PixelSample,
        _pixel: PixelId,
        _scratch: &mut (),
    ) -> (Rgb, u32) {
        let PathEstimator { world, settings } = self.0;
        walk::<true>(world, settings, WalkStart::camera(ray), sampler)
    }
}

/// Radiance along a camera ray; also returns the number of rays traced.
pub fn radiance(
    world: &World,
    settings: &PathSettings,
    ray: Ray,
    sampler: &mut PixelSample,
) -> (Rgb, u32) {
    if settings.primary_split > 1 {
        walk::<true>(world, settings, WalkStart::camera(ray), sampler)
    } else {
        walk::<false>(world, settings, WalkStart::camera(ray), sampler)
    }
}

/// Where a walk starts: its first ray and what the path carries along it.
#[derive(Clone, Copy)]
struct WalkStart {
    ray: Ray,
    beta: Rgb,
    /// Product of eta^2 scalings at refractions, undone for Russian roulette decisions.
    eta_scale: f32,
    specular_bounce: bool,
    prev_pdf: f32,
    /// The previous vertex as a receiver, for the light-sampling density of what a
    /// BSDF-sampled ray finds (with MIS, as its light samples were drawn).
    prev_ctx: LightSampleContext,
    /// Vertices shaded so far.
    depth: u32,
    /// The draw of the first bounce's direction, which the second vertex's draws continue.
    first_direction: Option<SobolAnchor>,
    /// Distance along the path from the camera, for texture footprints.
    travelled: f32,
}

impl WalkStart {
    #[inline(always)]
    fn camera(ray: Ray) -> WalkStart {
        WalkStart {
            ray,
            beta: Rgb::WHITE,
            eta_scale: 1.0,
            specular_bounce: true,
            prev_pdf: 0.0,
            prev_ctx: LightSampleContext::at_point(ray.o),
            depth: 0,
            first_direction: None,
            travelled: 0.0,
        }
    }
}

/// Follows a path from `start` to its end: its radiance and the rays it traced. With
/// `SPLIT` the walk ends at the first vertex's light sample and [`split_first_bounce`]
/// takes the bounce from there.
#[inline(always)]
fn walk<const SPLIT: bool>(
    world: &World,
    settings: &PathSettings,
    start: WalkStart,
    sampler: &mut PixelSample,
) -> (Rgb, u32) {
    let scene = world.scene_sphere();
    let WalkStart {
        mut ray,
        mut beta,
        mut eta_scale,
        mut specular_bounce,
        mut prev_pdf,
        mut prev_ctx,
        mut depth,
        mut first_direction,
        mut travelled,
    } = start;
    let mut l = Rgb::BLACK;
    let mut rays = 0u32;
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
        let lit = !material.is_specular();
        let u_choice = sampler.get_1d_if(lit && world.light_sampler.uses_choice_sample());
        // The second vertex's light sample and direction continue the Sobol point of the
        // first direction, so that two-bounce paths, much of a pixel's indirect light,
        // are stratified jointly rather than pair by pair: cornell-box at 256 spp has a
        // relMSE of 4.42e-4 instead of 5.04e-4 (docs/speed.md).
        let continued = if depth == 2 { first_direction } else { None };
        let u_light = match continued {
            Some(anchor) => sampler.get_2d_continuing_if(lit, anchor, ContinuedPair::Third),
            None => sampler.get_2d_if(lit),
        };
        if lit {
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

        if SPLIT {
            let vertex = FirstVertex {
                hit: &hit,
                material: &material,
                frame: &frame,
                wo_world,
                wo,
                beta,
                travelled,
            };
            let (split_l, split_rays) = split_first_bounce(world, settings, &vertex, sampler);
            l += split_l;
            rays += split_rays;
            break;
        }

        let u_lobe = sampler.get_1d_if(material.uses_lobe_sample());
        let u_dir = match continued {
            Some(anchor) => sampler.get_2d_continuing(anchor, ContinuedPair::Second),
            None if depth == 1 => {
                let (u, anchor) = sampler.get_2d_as_anchor();
                first_direction = Some(anchor);
                u
            }
            None => sampler.get_2d(),
        };
        let Some(bs) = material.sample(wo, u_lobe, u_dir, TransportMode::Radiance) else {
            break;
        };
        let wi = frame.to_world(bs.wi);
        if !bs.specular && !direct::sides_agree(&hit, wo_world, wi, wo, bs.wi) {
            break;
        }
        beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
        if let Some(scale) = refraction_scale(&material, hit.ng, wo_world, wi) {
            eta_scale *= scale;
        }
        specular_bounce = bs.specular;
        prev_pdf = bs.pdf;
        // Field by field: a whole new context went through a stack temporary that was
        // read back in wider words than it was written (a store-forwarding stall).
        prev_ctx.p = hit.p;
        prev_ctx.n = hit.ng;
        prev_ctx.ns = hit.ns;
        prev_ctx.mis_with_bsdf = true;
        ray = hit.spawn_ray(wi);

        if !survives_roulette(settings, depth, &mut beta, eta_scale, sampler) {
            break;
        }
    }
    (l, rays)
}

/// The factor by which a refraction through `material` (from `wo_world` to `wi`, across
/// the surface of normal `ng`) scales radiance, η² or 1/η²; `None` for anything else.
/// Paths track its product so that roulette sees the unscaled throughput.
#[inline(always)]
fn refraction_scale(material: &Material, ng: Vec3, wo_world: Vec3, wi: Vec3) -> Option<f32> {
    let eta = material.dielectric_eta()?;
    if wi.dot(ng) * wo_world.dot(ng) >= 0.0 {
        return None;
    }
    Some(if wo_world.dot(ng) > 0.0 {
        eta * eta
    } else {
        1.0 / (eta * eta)
    })
}

/// Russian roulette after the bounce at vertex `depth`: past `settings.rr_depth`, a path
/// whose throughput `beta` (times `eta_scale`) is below the threshold survives with
/// probability max channel / threshold and is reweighted. The number is drawn either
/// way, so that later dimensions do not depend on it. False where the path ends.
#[inline(always)]
fn survives_roulette(
    settings: &PathSettings,
    depth: u32,
    beta: &mut Rgb,
    eta_scale: f32,
    sampler: &mut PixelSample,
) -> bool {
    let rr_beta = beta.max_component() * eta_scale / settings.rr_threshold;
    let roulette = depth > settings.rr_depth && rr_beta < 1.0;
    let u_rr = sampler.get_1d_if(roulette);
    if roulette {
        let q = (1.0 - rr_beta).max(0.0);
        if u_rr < q {
            return false;
        }
        *beta /= 1.0 - q;
    }
    !beta.is_black()
}

/// The first vertex of a path, shaded and its light sample taken, before its bounce.
struct FirstVertex<'a> {
    hit: &'a SurfaceHit,
    material: &'a Material,
    frame: &'a Frame,
    wo_world: Vec3,
    wo: Vec3,
    beta: Rgb,
    travelled: f32,
}

/// The first vertex's bounce taken `settings.primary_split` = k times, each branch
/// walked to its end with a sampler of its own; their radiance averaged, and the rays
/// they traced.
///
/// The branches share the camera ray, the first hit and its light sample, and average
/// the indirect light, where a closed room's noise is. Branch j of camera sample i
/// draws as sample i·k + j of the pixel ([`PixelSample::branch`]), so that the k
/// branches of n camera samples stratify the bounces as n·k samples would. A branch
/// draws its bounce and roulette as the unsplit walk does at the first vertex, so that
/// with k = 1 the two would trace the same path.
#[inline(never)]
fn split_first_bounce(
    world: &World,
    settings: &PathSettings,
    vertex: &FirstVertex<'_>,
    sampler: &PixelSample,
) -> (Rgb, u32) {
    let k = settings.primary_split;
    let &FirstVertex {
        hit,
        material,
        frame,
        wo_world,
        wo,
        beta,
        travelled,
    } = vertex;
    let mut sum = Rgb::BLACK;
    let mut rays = 0u32;
    for j in 0..k {
        let mut branch = sampler.branch(k, j);
        let u_lobe = branch.get_1d_if(material.uses_lobe_sample());
        let (u_dir, anchor) = branch.get_2d_as_anchor();
        let Some(bs) = material.sample(wo, u_lobe, u_dir, TransportMode::Radiance) else {
            continue;
        };
        let wi = frame.to_world(bs.wi);
        if !bs.specular && !direct::sides_agree(hit, wo_world, wi, wo, bs.wi) {
            continue;
        }
        let mut branch_beta = beta * bs.f * (bs.wi.z.abs() / bs.pdf);
        let eta_scale = refraction_scale(material, hit.ng, wo_world, wi).unwrap_or(1.0);
        if !survives_roulette(settings, 1, &mut branch_beta, eta_scale, &mut branch) {
            continue;
        }
        let start = WalkStart {
            ray: hit.spawn_ray(wi),
            beta: branch_beta,
            eta_scale,
            specular_bounce: bs.specular,
            prev_pdf: bs.pdf,
            prev_ctx: LightSampleContext {
                p: hit.p,
                n: hit.ng,
                ns: hit.ns,
                mis_with_bsdf: true,
            },
            depth: 1,
            first_direction: Some(anchor),
            travelled,
        };
        let (l, r) = walk::<false>(world, settings, start, &mut branch);
        sum += l;
        rays += r;
    }
    (sum * (1.0 / k as f32), rays)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn settings(integrator: &str) -> Result<PathSettings, SceneError> {
        let text = format!("{integrator}\nWorldBegin\n");
        let desc = radiant_scene::parse_str(&text, "rr.pbrt", Path::new(".")).expect("parses");
        PathSettings::from_desc(&desc.integrator)
    }

    #[test]
    fn roulette_parameters_default_and_parse() {
        let d = settings(r#"Integrator "path""#).unwrap();
        assert_eq!(
            (d.rr_depth, d.rr_threshold),
            (DEFAULT_RR_DEPTH, DEFAULT_RR_THRESHOLD)
        );
        let s = settings(r#"Integrator "path" "integer rrdepth" 4 "float rrthreshold" 1"#).unwrap();
        assert_eq!((s.rr_depth, s.rr_threshold), (4, 1.0));
    }

    #[test]
    fn primary_split_defaults_to_one_and_zero_is_an_error_at_its_integrator() {
        assert_eq!(settings(r#"Integrator "path""#).unwrap().primary_split, 1);
        let s = settings(r#"Integrator "path" "integer primarysplit" 6"#).unwrap();
        assert_eq!(s.primary_split, 6);
        let e = settings(r#"Integrator "path" "integer primarysplit" 0"#)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("rr.pbrt:1:") && e.contains("primarysplit"),
            "{e}"
        );
    }

    /// The split walk with one branch traces the unsplit walk's path: the same draws
    /// (branch 0 of 1 is the sample itself), the same throughput, roulette and MIS state
    /// handed to the rest of the walk, so the same radiance up to the order of the sums
    /// and the same rays. Through glass and a mirror, with roulette from the first
    /// bounce, and with the Sobol (continued draws) and Halton samplers.
    #[test]
    fn one_branch_of_the_split_walk_is_the_unsplit_walk() {
        let path = radiant_testkit::repo_path("scenes/cornell-caustics.pbrt");
        let desc = radiant_scene::parse_file(&path).expect("parses");
        let world = World::build(&desc).expect("builds").0;
        let settings = PathSettings {
            max_depth: 100,
            rr_depth: 0,
            rr_threshold: 1.0,
            primary_split: 1,
        };
        let kinds = [
            radiant_scene::SamplerKind::Sobol,
            radiant_scene::SamplerKind::Halton {
                randomization: radiant_scene::DigitRandomization::Owen,
            },
        ];
        let (mut nonzero, mut compared) = (0, 0);
        for kind in kinds {
            for i in 0..4000u32 {
                let sample = PixelSample::new(kind, 7, i % 61, i / 61, i % 16);
                // Rays from inside the box towards its walls, blocks, glass and mirror.
                let mut u =
                    PixelSample::for_stream(radiant_scene::SamplerKind::Independent, 1, 9, i);
                let d = radiant_math::sampling::uniform_sphere(u.get_2d());
                let ray = Ray::new(glam::Vec3::new(278.0, 300.0, 250.0), d);
                let (a, rays_a) = walk::<false>(
                    &world,
                    &settings,
                    WalkStart::camera(ray),
                    &mut sample.clone(),
                );
                let (b, rays_b) = walk::<true>(
                    &world,
                    &settings,
                    WalkStart::camera(ray),
                    &mut sample.clone(),
                );
                assert_eq!(rays_a, rays_b, "sample {i}");
                for (x, y) in [(a.r, b.r), (a.g, b.g), (a.b, b.b)] {
                    assert!(
                        (x - y).abs() <= 1e-5 * x.abs().max(1e-3),
                        "sample {i}: {a:?} vs {b:?}"
                    );
                }
                nonzero += (a.g > 0.0) as u32;
                compared += 1;
            }
        }
        assert!(
            nonzero * 2 > compared,
            "{nonzero} of {compared} paths carried light"
        );
    }

    #[test]
    fn a_threshold_that_is_not_positive_is_an_error_at_its_integrator() {
        for bad in ["0", "-0.5"] {
            let e = settings(&format!(r#"Integrator "path" "float rrthreshold" {bad}"#))
                .unwrap_err()
                .to_string();
            assert!(e.contains("rr.pbrt:1:") && e.contains("rrthreshold"), "{e}");
        }
    }
}
