//! Next-event estimation shared by the integrators: pick a light in proportion to its
//! power, sample a point or direction on it, test visibility. The path tracer weights
//! the result against BSDF sampling (multiple importance sampling); the photon mappers,
//! which never pick up emission through BSDF-sampled rays at diffuse vertices, use it
//! alone.

use glam::{Vec2, Vec3};

use crate::light::{Light, SceneSphere};
use crate::material::Material;
use crate::world::{NO_LIGHT, SurfaceHit, World};
use radiant_math::Frame;
use radiant_math::color::Rgb;

/// One unoccluded light sample seen from a surface point.
#[derive(Clone, Copy, Debug)]
pub struct DirectSample {
    /// BSDF value times |cos| at the receiver (shading frame).
    pub f: Rgb,
    /// Radiance arriving from the light (intensity / distance² for delta lights).
    pub li: Rgb,
    /// Probability of the light choice times the light's solid-angle density.
    pub light_pdf: f32,
    /// Solid-angle density with which BSDF sampling would pick the same direction.
    pub bsdf_pdf: f32,
    pub delta: bool,
}

impl DirectSample {
    /// The contribution without MIS: f L / pdf.
    pub fn unweighted(&self) -> Rgb {
        self.f * self.li * (1.0 / self.light_pdf)
    }
}

/// Samples one light for the non-specular surface point `hit` seen along `wo_world`
/// (`wo` is the same direction in `frame`). `u_choice` picks the light, `u_light` the
/// point on it. Adds 1 to `shadow_rays` when a visibility ray is traced. `None` when the
/// sample carries nothing (back side, occluded, zero BSDF).
#[allow(clippy::too_many_arguments)]
pub fn sample_direct(
    world: &World,
    scene: SceneSphere,
    hit: &SurfaceHit,
    material: &Material,
    frame: &Frame,
    wo: Vec3,
    wo_world: Vec3,
    u_choice: f32,
    u_light: Vec2,
    shadow_rays: &mut u32,
) -> Option<DirectSample> {
    if world.lights.is_empty() {
        return None;
    }
    let (light_index, pmf, _) = world.light_distribution.sample(u_choice);
    let ls = world.lights[light_index].sample_li(hit.p, u_light, scene)?;
    let wi = frame.to_local(ls.wi);
    // Light must arrive on the side the path came from (the geometric test prevents
    // leaks through shading normals).
    let same_side = ls.wi.dot(hit.ng) * wo_world.dot(hit.ng) > 0.0;
    let f = material.eval(wo, wi) * wi.z.abs();
    if !same_side || f.is_black() {
        return None;
    }
    *shadow_rays += 1;
    let unoccluded = if ls.at_infinity {
        !world.occluded(&hit.spawn_ray(ls.wi), f32::INFINITY)
    } else {
        world.visible(hit.p, hit.ng, ls.p, ls.n)
    };
    unoccluded.then(|| DirectSample {
        f,
        li: ls.li,
        light_pdf: pmf * ls.pdf,
        bsdf_pdf: material.pdf(wo, wi),
        delta: ls.delta,
    })
}

/// Radiance emitted by the surface at `hit` towards `wo` (zero off emitters).
pub fn surface_emission(world: &World, hit: &SurfaceHit, wo: Vec3) -> Rgb {
    if hit.light == NO_LIGHT {
        return Rgb::BLACK;
    }
    match &world.lights[hit.light as usize] {
        Light::Area(a) => a.radiance(hit.ng, wo),
        _ => Rgb::BLACK,
    }
}

/// Radiance emitted towards `-d` by the lights at infinity, for a ray that escapes.
pub fn environment(world: &World, d: Vec3) -> Rgb {
    world
        .lights
        .iter()
        .fold(Rgb::BLACK, |acc, l| acc + l.environment(d))
}
