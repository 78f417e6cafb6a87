//! The specular step of camera paths that run through mirrors and glass to the first
//! diffuse surface: SPPM's visible points, the photon mapper's eye paths and final
//! gather rays, the radiosity display. (The path tracer also weighs each bounce for
//! multiple importance sampling, so it keeps its own.)
//!
//! Rough glass also passes camera paths on (photons are not stored on it), but its
//! lobes are wide: a light seen in it, reflected or through it, found only by BSDF
//! sampling is a rare, bright sample. Camera chains of the photon mappers therefore
//! take a light sample at each such glossy vertex and weigh it, and the emission the
//! next ray finds, by multiple importance sampling (Veach & Guibas 1995, the power
//! heuristic) — [`ChainVertex`] and [`glossy_direct`].

use glam::Vec3;

use crate::integrator::direct::{ShadingPoint, sample_direct, sides_agree, surface_emission};
use crate::light::{Light, LightSampleContext, SceneSphere};
use crate::material::{CoatPart, Layered, Material, TransportMode};
use crate::sampler::PixelSample;
use crate::world::{NO_LIGHT, SurfaceHit, World};
use radiant_math::Frame;
use radiant_math::color::Rgb;
use radiant_math::sampling::power_heuristic;

/// Samples `material` for a camera path arriving from `wo` (in the shading `frame`),
/// with the next lobe and direction dimensions of `sampler`, scales the throughput
/// `beta` by f |cos θ| / pdf and returns the world direction to go on in. `None` ends
/// the path: the BSDF gave no direction, or the throughput is black.
pub fn specular_bounce(
    material: &Material,
    frame: &Frame,
    wo: Vec3,
    sampler: &mut PixelSample,
    beta: &mut Rgb,
) -> Option<Vec3> {
    let u_lobe = sampler.get_1d_if(material.uses_lobe_sample());
    let u_dir = sampler.get_2d();
    let bs = material.sample(wo, u_lobe, u_dir, TransportMode::Radiance)?;
    *beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
    if beta.is_black() {
        return None;
    }
    Some(frame.to_world(bs.wi))
}

/// How a camera chain's last vertex chose the direction of the ray now being traced:
/// what the emission that ray finds is weighted by.
#[derive(Clone, Copy, Debug)]
pub struct ChainVertex {
    /// Solid-angle density of the sampled direction (unused after a delta bounce).
    pdf: f32,
    /// The camera, or a delta BSDF: no light sample competed for the direction.
    specular: bool,
    /// The vertex as a receiver, as its light sample saw it.
    receiver: LightSampleContext,
    /// The vertex's direct light was taken in full before this direction was chosen
    /// ([`coat_step`]): the ray counts no emission, only what lies beyond.
    indirect_only: bool,
}

impl ChainVertex {
    /// The camera: whatever its ray finds counts in full.
    pub fn camera(origin: Vec3) -> ChainVertex {
        ChainVertex {
            pdf: 0.0,
            specular: true,
            receiver: LightSampleContext::at_point(origin),
            indirect_only: false,
        }
    }

    /// A vertex whose direct light has been counted: the ray it spawns finds no
    /// emission, lit surfaces only.
    fn indirect_only(origin: Vec3) -> ChainVertex {
        ChainVertex {
            indirect_only: true,
            ..ChainVertex::camera(origin)
        }
    }

    /// Emitted radiance at `hit` towards `wo_world`, weighted against the light sample
    /// the previous vertex took, when it took one.
    pub fn emission(&self, world: &World, hit: &SurfaceHit, wo_world: Vec3) -> Rgb {
        if self.indirect_only {
            return Rgb::BLACK;
        }
        let le = surface_emission(world, hit, wo_world);
        if self.specular || le.is_black() || hit.light == NO_LIGHT {
            return le;
        }
        let Light::Area(area) = &world.lights[hit.light as usize] else {
            return le;
        };
        let pdf_light = world.light_sampler.pmf(&self.receiver, hit.light as usize)
            * area.pdf_li(&self.receiver, &hit.light_hit());
        le * power_heuristic(self.pdf, pdf_light)
    }

    /// Radiance of the lights at infinity along an escaping ray `d`, each weighted
    /// against the previous vertex's light sample.
    pub fn environment(&self, world: &World, d: Vec3) -> Rgb {
        let mut sum = Rgb::BLACK;
        if self.indirect_only {
            return sum;
        }
        for (i, light) in world.lights.iter().enumerate() {
            let le = light.environment(d);
            if le.is_black() {
                continue;
            }
            let w = if self.specular {
                1.0
            } else {
                let pdf_light = world.light_sampler.pmf(&self.receiver, i)
                    * light.pdf_li(&self.receiver, d, None);
                power_heuristic(self.pdf, pdf_light)
            };
            sum += le * w;
        }
        sum
    }
}

/// The bounce of a camera chain at `hit`: like [`specular_bounce`], and it records how
/// the direction was chosen for [`ChainVertex::emission`]. A glossy sample whose
/// direction the shading and geometric normals disagree on ends the chain.
pub fn chain_bounce(
    hit: &SurfaceHit,
    material: &Material,
    frame: &Frame,
    wo_world: Vec3,
    sampler: &mut PixelSample,
    beta: &mut Rgb,
) -> Option<(Vec3, ChainVertex)> {
    let wo = frame.to_local(wo_world);
    let u_lobe = sampler.get_1d_if(material.uses_lobe_sample());
    let u_dir = sampler.get_2d();
    let bs = material.sample(wo, u_lobe, u_dir, TransportMode::Radiance)?;
    let wi = frame.to_world(bs.wi);
    if !bs.specular && !sides_agree(hit, wo_world, wi, wo, bs.wi) {
        return None;
    }
    *beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
    if beta.is_black() {
        return None;
    }
    let vertex = ChainVertex {
        pdf: bs.pdf,
        specular: bs.specular,
        receiver: hit.light_sample_context().with_mis(),
        indirect_only: false,
    };
    Some((wi, vertex))
}

/// Direct light at a glossy vertex of a camera chain (rough glass), weighted by MIS
/// against the chain's own BSDF sample there; with the number of shadow rays. Draws
/// three dimensions of `sampler`, only at non-delta vertices (chains through smooth
/// glass and mirrors keep their dimension layout).
pub fn glossy_direct(
    world: &World,
    scene: SceneSphere,
    hit: &SurfaceHit,
    material: Material,
    wo_world: Vec3,
    sampler: &mut PixelSample,
) -> (Rgb, u32) {
    let u_choice = sampler.get_1d_if(world.light_sampler.uses_choice_sample());
    let u_light = sampler.get_2d();
    let at = ShadingPoint::new(hit, material, wo_world).with_mis();
    let ds = sample_direct(world, scene, &at, u_choice, u_light);
    let l = ds.light.map_or(Rgb::BLACK, |d| {
        let w = if d.delta {
            1.0
        } else {
            power_heuristic(d.light_pdf, d.bsdf_pdf)
        };
        d.f * d.li * (w / d.light_pdf)
    });
    (l, ds.shadow_rays)
}

/// Direct light where a camera chain ends (an SPPM visible point, the photon mapper's
/// estimate point), with the number of rays traced. At a Lambertian point a light
/// sample; where the BSDF is not Lambertian (glossy conductors, coated surfaces), a
/// light sample and a BSDF sample weighted by multiple importance sampling (Veach &
/// Guibas 1995, the power heuristic). A light sample alone finds a narrow lobe's
/// reflection of a light (an environment in a varnish coat) only in rare, very bright
/// samples, so the pixel mean converged slowly from below; the BSDF sample finds it
/// every time. The photons carry only indirect light.
pub fn chain_end_direct(
    world: &World,
    scene: SceneSphere,
    hit: &SurfaceHit,
    material: Material,
    frame: &Frame,
    wo_world: Vec3,
    sampler: &mut PixelSample,
) -> (Rgb, u32) {
    if material.is_diffuse() {
        let u_choice = sampler.get_1d_if(world.light_sampler.uses_choice_sample());
        let u_light = sampler.get_2d();
        let at = ShadingPoint::new(hit, material, wo_world);
        let direct = sample_direct(world, scene, &at, u_choice, u_light);
        return (direct.unweighted(), direct.shadow_rays);
    }
    let (mut l, mut rays) = glossy_direct(world, scene, hit, material, wo_world, sampler);
    let mut through = Rgb::WHITE;
    if let Some((wi, vertex)) = chain_bounce(hit, &material, frame, wo_world, sampler, &mut through)
    {
        rays += 1;
        let ray = hit.spawn_ray(wi);
        l += through
            * match world.intersect(&ray, f32::INFINITY) {
                Some(next) => vertex.emission(world, &next, -ray.d.normalize()),
                None => vertex.environment(world, ray.d),
            };
    }
    (l, rays)
}

/// Where a camera chain goes on at a surface under a narrow coat
/// ([`Material::narrow_coat`]).
#[derive(Clone, Copy, Debug)]
pub enum CoatStep {
    /// Along the coat's reflection: the ray to trace and how it was chosen.
    Reflect(Vec3, ChainVertex),
    /// The chain ends here and the light under the coat is gathered
    /// ([`crate::material::BsdfPart::UnderCoat`]).
    Under,
}

/// The choice between a narrow coat's reflection and the light under it
/// ([`Layered::choose_coat_part`]), made after the vertex's direct light has been
/// taken with the whole BSDF ([`chain_end_direct`]): the reflected ray therefore
/// counts no emission, and its chain gathers what the coat reflects of lit surfaces
/// (indirect light and caustics, which the photons under the coat no longer carry).
/// Scales `beta` by the chosen part's weight; `None` ends the path. Draws three
/// dimensions of `sampler` either way.
pub fn coat_step(
    hit: &SurfaceHit,
    layers: &Layered,
    frame: &Frame,
    wo_world: Vec3,
    sampler: &mut PixelSample,
    beta: &mut Rgb,
) -> Option<CoatStep> {
    let u_part = sampler.get_1d();
    let u_dir = sampler.get_2d();
    let wo = frame.to_local(wo_world);
    match layers.choose_coat_part(wo, u_part, u_dir)? {
        CoatPart::Under { weight } => {
            *beta *= weight;
            Some(CoatStep::Under)
        }
        CoatPart::Reflection { wi, weight } => {
            let wi_world = frame.to_world(wi);
            if !sides_agree(hit, wo_world, wi_world, wo, wi) {
                return None;
            }
            *beta *= weight;
            if beta.is_black() {
                return None;
            }
            Some(CoatStep::Reflect(
                wi_world,
                ChainVertex::indirect_only(hit.p),
            ))
        }
    }
}
