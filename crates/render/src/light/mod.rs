//! Light sources. The set is closed (area, point, spot, distant, infinite,
//! goniometric, projection), so it is
//! one enum; each variant's sampling lives in its own file, and the choice among the
//! lights is the [`LightSampler`]'s.
//!
//! Two kinds of sampling are offered (Pharr, Jakob & Humphreys, *Physically Based
//! Rendering*, 4th ed., ch. 12): `sample_li` picks a direction towards the light as
//! seen from a receiver described by a [`LightSampleContext`] (next-event
//! estimation), with `pdf_li` the density of any direction; `sample_le` picks a ray
//! leaving the light with the flux it carries (photon tracing).

mod area;
mod emission_image;
mod environment;
mod image_point;
mod infinite;
mod point;
mod sampler;
mod tree;

use glam::{Vec2, Vec3};

pub use area::{AreaLight, EmittingMesh, LightShape, parallelogram_of};
pub use emission_image::EmissionImage;
pub use environment::{EnvironmentMap, EnvironmentPicture, rotation_of};
pub use image_point::{GoniometricLight, ProjectionLight};
pub use sampler::{
    LIGHT_SAMPLER_NAMES, LIGHT_SAMPLER_PARAM, LightSampler, SampledLight, UnknownLightSampler,
};
pub use tree::LightTree;

use crate::geometry::{Aabb, Ray};
use radiant_math::PI;
use radiant_math::color::Rgb;

/// The receiver a light is sampled from: a point with its geometric normal `n` and
/// shading normal `ns`, both zero for a point in space (a camera ray's origin).
///
/// Surface points get theirs from the hit record (`SurfaceHit::light_sample_context`),
/// so whatever a hit learns about itself (such as a bound on its rounding error, for
/// offsetting the shadow ray's origin) reaches the lights through that one function.
/// Today only `p` is used; `n` and `ns` are for samplers that look at the receiver's
/// orientation (a light tree's importance, sampling only the visible hemisphere).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSampleContext {
    pub p: Vec3,
    pub n: Vec3,
    pub ns: Vec3,
    /// The caller weights light samples against BSDF samples by multiple importance
    /// sampling, so a light may leave directions it would sample poorly to the BSDF
    /// (zero density there; pbrt-v4's `allowIncompletePDF`). Only environment images
    /// use it. `sample_li` and `pdf_li` must see the same value.
    pub mis_with_bsdf: bool,
}

impl LightSampleContext {
    /// A receiver in free space (no normal).
    pub fn at_point(p: Vec3) -> LightSampleContext {
        LightSampleContext {
            p,
            n: Vec3::ZERO,
            ns: Vec3::ZERO,
            mis_with_bsdf: false,
        }
    }

    /// The same receiver, for light samples that MIS combines with BSDF samples. The
    /// flag is set in place: rebuilding the struct made the path loop copy it through
    /// memory in words wider than its fields were written, which stalls store-to-load
    /// forwarding.
    #[inline(always)]
    pub fn with_mis(mut self) -> LightSampleContext {
        self.mis_with_bsdf = true;
        self
    }

    /// A receiver on a surface without a separate shading normal (radiosity patches).
    pub fn on_surface(p: Vec3, n: Vec3) -> LightSampleContext {
        LightSampleContext {
            p,
            n,
            ns: n,
            mis_with_bsdf: false,
        }
    }
}

/// A point on a light: where a shadow ray towards it ends, with the error bound of its
/// position and its surface normal (zero for lights without a surface: the shadow ray then
/// ends at `p` itself, not at a point moved off a surface).
pub type LightPoint = crate::geometry::SurfacePoint;

/// Where a ray from a receiver met a light's surface: what `pdf_li` needs to give the
/// density of that direction (a surface hit makes one by `SurfaceHit::light_hit`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightHit {
    pub p: Vec3,
    /// Geometric normal at `p` (either side).
    pub n: Vec3,
    /// Surface parameters (the bilinear patch's density depends on them).
    pub uv: Vec2,
}

/// A direction towards a light sampled from a receiver.
#[derive(Clone, Copy, Debug)]
pub struct LightLiSample {
    /// Radiance arriving along `-wi` (for delta lights: intensity / distance²).
    pub li: Rgb,
    /// Unit direction from the receiver towards the light.
    pub wi: Vec3,
    /// Density per solid angle; for delta lights, 1 (the choice is certain).
    pub pdf: f32,
    /// The sampled point on the light (far away for distant and infinite lights).
    pub p_light: LightPoint,
    pub delta: bool,
    /// True when `p_light` lies at infinity: visibility is tested along a ray, not a
    /// segment.
    pub at_infinity: bool,
}

/// A ray leaving a light, for photon tracing (and any method that starts paths at
/// the lights).
#[derive(Clone, Copy, Debug)]
pub struct LightLeSample {
    pub ray: Ray,
    /// Normal at the origin, on the emitting side (zero for point-like and infinite
    /// lights).
    pub n: Vec3,
    /// Density of the origin per unit area: on the light's surface, or on the disk
    /// that rays of lights at infinity start from; 1 for a point or spot light's
    /// certain position.
    pub pdf_pos: f32,
    /// Density of the direction per unit solid angle; 1 for a distant light's certain
    /// direction.
    pub pdf_dir: f32,
    /// Radiance leaving along the ray (intensity for point and spot lights).
    pub le: Rgb,
    /// The flux of one sample from this light, le |cos| / (pdf_pos pdf_dir), in closed
    /// form (for a cosine-sampled area light: L π A per side, without the cosine's
    /// round-off).
    pub power: Rgb,
}

impl LightLeSample {
    /// A ray leaving a point light's certain position along `d`, drawn with density
    /// `pdf_dir`, carrying the intensity `le`.
    pub fn from_point(position: Vec3, d: Vec3, le: Rgb, pdf_dir: f32) -> LightLeSample {
        LightLeSample {
            ray: Ray::new(position, d),
            n: Vec3::ZERO,
            pdf_pos: 1.0,
            pdf_dir,
            le,
            power: le / pdf_dir,
        }
    }
}

/// Centre and radius of a sphere bounding the scene (for lights at infinity).
#[derive(Clone, Copy, Debug)]
pub struct SceneSphere {
    pub center: Vec3,
    pub radius: f32,
}

impl SceneSphere {
    /// The sphere around `bounds` (its radius at least 10⁻³, so that the disks rays of
    /// lights at infinity start from never vanish).
    pub fn around(bounds: &Aabb) -> SceneSphere {
        let (center, radius) = bounds.bounding_sphere();
        SceneSphere {
            center,
            radius: radius.max(1e-3),
        }
    }
}

#[derive(Clone, Debug)]
pub enum Light {
    Area(AreaLight),
    /// Isotropic point light; `intensity` in W/sr.
    Point {
        position: Vec3,
        intensity: Rgb,
    },
    /// pbrt-v4 spot light: full intensity inside `cos_falloff_start`, a smoothstep to
    /// zero at `cos_total_width`.
    Spot {
        position: Vec3,
        direction: Vec3,
        intensity: Rgb,
        cos_falloff_start: f32,
        cos_total_width: f32,
    },
    /// Parallel light travelling along `direction`, radiance-scale `radiance`
    /// (irradiance on a perpendicular surface).
    Distant {
        direction: Vec3,
        radiance: Rgb,
    },
    /// Light from every direction: constant `radiance` (sampled uniformly), or an
    /// environment image (`map`, which holds its own scale; `radiance` is then unused).
    Infinite {
        radiance: Rgb,
        map: Option<std::sync::Arc<EnvironmentMap>>,
    },
    /// Point light with intensity per direction from an equal-area octahedral image.
    Goniometric(std::sync::Arc<GoniometricLight>),
    /// Point light projecting an image through a pinhole.
    Projection(std::sync::Arc<ProjectionLight>),
}

impl Light {
    pub fn is_delta(&self) -> bool {
        matches!(
            self,
            Light::Point { .. }
                | Light::Spot { .. }
                | Light::Distant { .. }
                | Light::Goniometric(_)
                | Light::Projection(_)
        )
    }

    /// Emitted power (flux), used to choose lights in proportion to it.
    pub fn power(&self, scene: SceneSphere) -> Rgb {
        match self {
            Light::Area(a) => a.power(),
            Light::Point { intensity, .. } => *intensity * (4.0 * PI),
            Light::Spot {
                intensity,
                cos_falloff_start,
                cos_total_width,
                ..
            } => *intensity * (2.0 * PI * (1.0 - 0.5 * (cos_falloff_start + cos_total_width))),
            Light::Distant { radiance, .. } => *radiance * (PI * scene.radius * scene.radius),
            Light::Infinite { map: Some(m), .. } => m.power(scene),
            Light::Infinite { radiance, .. } => {
                *radiance * (4.0 * PI * PI * scene.radius * scene.radius)
            }
            Light::Goniometric(g) => g.power(),
            Light::Projection(pr) => pr.power(),
        }
    }

    /// A direction towards the light from `ctx`, or `None` when the sample carries
    /// nothing (back side, outside a spot's cone).
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        scene: SceneSphere,
    ) -> Option<LightLiSample> {
        let p = ctx.p;
        match self {
            Light::Area(a) => a.sample_li(ctx, u),
            Light::Point {
                position,
                intensity,
            } => point::sample_point(p, *position, *intensity),
            Light::Spot {
                position,
                direction,
                intensity,
                cos_falloff_start,
                cos_total_width,
            } => {
                let mut s = point::sample_point(p, *position, *intensity)?;
                s.li *=
                    point::spot_falloff(-s.wi, *direction, *cos_falloff_start, *cos_total_width);
                (!s.li.is_black()).then_some(s)
            }
            Light::Distant {
                direction,
                radiance,
            } => Some(LightLiSample {
                li: *radiance,
                wi: -*direction,
                pdf: 1.0,
                p_light: LightPoint::free(
                    p - *direction * (2.0 * scene.radius + (p - scene.center).length()),
                ),
                delta: true,
                at_infinity: true,
            }),
            Light::Infinite { map: Some(m), .. } => m.sample_li(ctx, u, scene),
            Light::Infinite { radiance, .. } => infinite::sample_li(ctx, *radiance, u, scene),
            Light::Goniometric(g) => g.sample_li(p),
            Light::Projection(pr) => pr.sample_li(p),
        }
    }

    /// Solid-angle density with which `sample_li` from `ctx` produces the unit
    /// direction `wi`. Area lights need `hit`, where the ray along `wi` met them (zero
    /// without it); lights at infinity need only `wi`. Zero for delta lights, which no
    /// ray finds.
    pub fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3, hit: Option<&LightHit>) -> f32 {
        match self {
            Light::Area(a) => hit.map_or(0.0, |h| a.pdf_li(ctx, h)),
            Light::Infinite { map: Some(m), .. } => m.pdf_li(ctx, wi),
            Light::Infinite { .. } => infinite::pdf_li(wi),
            _ => 0.0,
        }
    }

    /// Radiance from an infinite light along a ray that escapes in direction `d`.
    pub fn environment(&self, d: Vec3) -> Rgb {
        match self {
            Light::Infinite { map: Some(m), .. } => m.radiance(d),
            Light::Infinite { radiance, .. } => *radiance,
            _ => Rgb::BLACK,
        }
    }

    /// A ray leaving the light: `u_pos` places its origin, `u_dir` its direction.
    /// `None` when the sample carries nothing.
    pub fn sample_le(&self, u_pos: Vec2, u_dir: Vec2, scene: SceneSphere) -> Option<LightLeSample> {
        match self {
            Light::Area(a) => a.sample_le(u_pos, u_dir),
            Light::Point {
                position,
                intensity,
            } => Some(point::emit_point(*position, *intensity, u_dir)),
            Light::Spot {
                position,
                direction,
                intensity,
                cos_falloff_start,
                cos_total_width,
            } => point::emit_spot(
                *position,
                *direction,
                *intensity,
                *cos_falloff_start,
                *cos_total_width,
                u_dir,
            ),
            Light::Distant {
                direction,
                radiance,
            } => Some(infinite::emit_parallel(*direction, *radiance, u_pos, scene)),
            Light::Infinite { map: Some(m), .. } => m.sample_le(u_pos, u_dir, scene),
            Light::Infinite { radiance, .. } => {
                Some(infinite::emit_infinite(*radiance, u_pos, u_dir, scene))
            }
            Light::Goniometric(g) => g.sample_le(u_dir),
            Light::Projection(pr) => pr.sample_le(u_dir),
        }
    }
}

#[cfg(test)]
mod tests;
