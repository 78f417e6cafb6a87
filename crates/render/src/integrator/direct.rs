//! Next-event estimation shared by the integrators: pick a light by the world's light
//! sampler, sample a point or direction on it, test visibility. The path tracer weights
//! the result against BSDF sampling (multiple importance sampling); the photon mappers,
//! which never pick up emission through BSDF-sampled rays at diffuse vertices, use it
//! alone.

use glam::{Vec2, Vec3};

use crate::light::{Light, SceneSphere};
use crate::material::Material;
use crate::world::{NO_LIGHT, SurfaceHit, World};
use radiant_math::Frame;
use radiant_math::color::Rgb;

/// A non-specular surface point being shaded, and the direction it is seen from.
#[derive(Clone, Copy, Debug)]
pub struct ShadingPoint<'a> {
    pub hit: &'a SurfaceHit,
    pub material: Material,
    /// The shading frame (about `hit.ns`).
    pub frame: Frame,
    /// Unit direction towards the viewer, in `frame`.
    pub wo: Vec3,
    /// The same direction in render space.
    pub wo_world: Vec3,
    /// The light sample will be weighted against BSDF sampling by MIS (see
    /// `LightSampleContext::mis_with_bsdf`).
    pub mis_with_bsdf: bool,
}

impl<'a> ShadingPoint<'a> {
    /// `hit` with `material`, seen along the unit direction `wo_world`.
    pub fn new(hit: &'a SurfaceHit, material: Material, wo_world: Vec3) -> ShadingPoint<'a> {
        let frame = World::shading_frame(hit, &material);
        ShadingPoint::in_frame(hit, material, frame, wo_world, frame.to_local(wo_world))
    }

    /// `hit` with `material` in the shading `frame` it already has, seen along
    /// `wo_world` (`wo` in the frame): what [`ShadingPoint::new`] computes, for a caller
    /// that needed the frame before.
    pub fn in_frame(
        hit: &'a SurfaceHit,
        material: Material,
        frame: Frame,
        wo_world: Vec3,
        wo: Vec3,
    ) -> ShadingPoint<'a> {
        ShadingPoint {
            hit,
            material,
            frame,
            wo,
            wo_world,
            mis_with_bsdf: false,
        }
    }

    /// The same point, for a light sample that MIS combines with a BSDF sample.
    pub fn with_mis(self) -> ShadingPoint<'a> {
        ShadingPoint {
            mis_with_bsdf: true,
            ..self
        }
    }
}

/// One unoccluded light sample seen from a surface point.
#[derive(Clone, Copy, Debug)]
pub struct DirectLight {
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

impl DirectLight {
    /// The contribution without MIS: f L / pdf.
    pub fn unweighted(&self) -> Rgb {
        self.f * self.li * (1.0 / self.light_pdf)
    }
}

/// What one light sample found, and what it cost.
#[derive(Clone, Copy, Debug)]
pub struct DirectSample {
    /// `None` when the sample carries nothing (back side, occluded, zero BSDF).
    pub light: Option<DirectLight>,
    /// Visibility rays traced (0 or 1).
    pub shadow_rays: u32,
}

impl DirectSample {
    /// The contribution without MIS (black when nothing was found).
    pub fn unweighted(&self) -> Rgb {
        self.light.map_or(Rgb::BLACK, |d| d.unweighted())
    }
}

/// Samples one light for the shading point `at`: `u_choice` picks the light (through
/// the world's light sampler), `u_light` the point on it.
#[inline]
pub fn sample_direct(
    world: &World,
    scene: SceneSphere,
    at: &ShadingPoint,
    u_choice: f32,
    u_light: Vec2,
) -> DirectSample {
    let mut out = DirectSample {
        light: None,
        shadow_rays: 0,
    };
    let hit = at.hit;
    let mut ctx = hit.light_sample_context();
    ctx.mis_with_bsdf = at.mis_with_bsdf;
    let Some(chosen) = world.light_sampler.sample(&ctx, u_choice) else {
        return out;
    };
    let Some(ls) = world.lights[chosen.index].sample_li(&ctx, u_light, scene) else {
        return out;
    };
    let wi = at.frame.to_local(ls.wi);
    // Light must arrive on the side the BSDF sees it on: the side the path came from
    // for reflection, the other one for transmission (the geometric test prevents
    // leaks through shading normals).
    let f = at.material.eval(at.wo, wi) * wi.z.abs();
    if !sides_agree(hit, at.wo_world, ls.wi, at.wo, wi) || f.is_black() {
        return out;
    }
    out.shadow_rays = 1;
    let unoccluded = if ls.at_infinity {
        !world.occluded(&hit.spawn_ray(ls.wi), f32::INFINITY)
    } else {
        world.visible(&hit.surface_point(), &ls.p_light)
    };
    out.light = unoccluded.then(|| DirectLight {
        f,
        li: ls.li,
        light_pdf: chosen.pmf * ls.pdf,
        bsdf_pdf: at.material.pdf(at.wo, wi),
        delta: ls.delta,
    });
    out
}

/// True when the pair (`wo`, `wi`) is a reflection by the geometric normal exactly
/// when it is one in the shading frame (local `wo_local`, `wi_local`): a BSDF value
/// computed in the shading frame then applies. Grazing directions (zero cosine with
/// the geometric normal) count as transmission.
pub fn sides_agree(
    hit: &SurfaceHit,
    wo_world: Vec3,
    wi_world: Vec3,
    wo_local: Vec3,
    wi_local: Vec3,
) -> bool {
    let geometric = wi_world.dot(hit.ng) * wo_world.dot(hit.ng) > 0.0;
    let shading = wi_local.z * wo_local.z > 0.0;
    geometric == shading
}

/// Radiance emitted by the surface at `hit` towards `wo` (zero off emitters).
pub fn surface_emission(world: &World, hit: &SurfaceHit, wo: Vec3) -> Rgb {
    if hit.light == NO_LIGHT {
        return Rgb::BLACK;
    }
    match &world.lights[hit.light as usize] {
        Light::Area(a) => a.radiance(hit.ng, hit.uv, wo),
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
