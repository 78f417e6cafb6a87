//! Light sources. The set is closed (area, point, spot, distant, infinite), so it is
//! one enum; each variant's sampling lives in its own file.
//!
//! Two kinds of sampling are offered: `sample_li` picks a direction towards the light
//! from a receiving point (next-event estimation), `sample_emission` picks a ray
//! leaving the light with the power it carries (photon tracing).

mod area;
mod infinite;
mod point;

use glam::{Vec2, Vec3};

pub use area::{AreaLight, LightShape};

use crate::geometry::Ray;
use radiant_math::PI;
use radiant_math::color::Rgb;

/// A sampled direction towards a light, seen from a receiving point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Radiance arriving along `-wi` (for delta lights: intensity / distance²).
    pub li: Rgb,
    /// Unit direction from the receiver towards the light.
    pub wi: Vec3,
    /// The sampled point on the light (far away for distant and infinite lights).
    pub p: Vec3,
    /// Surface normal at `p`; zero for lights without a surface.
    pub n: Vec3,
    /// Density per solid angle; for delta lights, 1 (the choice is certain).
    pub pdf: f32,
    pub delta: bool,
    /// True when `p` lies at infinity: visibility is tested along a ray, not a segment.
    pub at_infinity: bool,
}

/// A ray leaving a light and the power it carries, for photon tracing: `power` is
/// Le cos / (pdf_position pdf_direction) — the flux of one sample from this light.
#[derive(Clone, Copy, Debug)]
pub struct EmittedRay {
    pub ray: Ray,
    /// Normal at the origin (zero for point-like and infinite lights).
    pub n: Vec3,
    pub power: Rgb,
}

/// Centre and radius of a sphere bounding the scene (for lights at infinity).
#[derive(Clone, Copy, Debug)]
pub struct SceneSphere {
    pub center: Vec3,
    pub radius: f32,
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
    /// Constant radiance from every direction.
    Infinite {
        radiance: Rgb,
    },
}

impl Light {
    pub fn is_delta(&self) -> bool {
        matches!(
            self,
            Light::Point { .. } | Light::Spot { .. } | Light::Distant { .. }
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
            Light::Infinite { radiance } => {
                *radiance * (4.0 * PI * PI * scene.radius * scene.radius)
            }
        }
    }

    pub fn sample_li(&self, p: Vec3, u: Vec2, scene: SceneSphere) -> Option<LightSample> {
        match self {
            Light::Area(a) => a.sample_li(p, u),
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
            } => Some(LightSample {
                li: *radiance,
                wi: -*direction,
                p: p - *direction * (2.0 * scene.radius + (p - scene.center).length()),
                n: Vec3::ZERO,
                pdf: 1.0,
                delta: true,
                at_infinity: true,
            }),
            Light::Infinite { radiance } => infinite::sample_li(p, *radiance, u, scene),
        }
    }

    /// Solid-angle density with which `sample_li` from `p` would have produced the
    /// direction towards point `q` (normal `n`, surface parameters `uv`) on this light.
    /// Zero for delta lights.
    pub fn pdf_li(&self, p: Vec3, q: Vec3, n: Vec3, uv: Vec2) -> f32 {
        match self {
            Light::Area(a) => a.pdf_li(p, q, n, uv),
            Light::Infinite { .. } => infinite::PDF,
            _ => 0.0,
        }
    }

    /// Radiance from an infinite light along a ray that escapes in direction `d`.
    pub fn environment(&self, _d: Vec3) -> Rgb {
        match self {
            Light::Infinite { radiance } => *radiance,
            _ => Rgb::BLACK,
        }
    }

    pub fn sample_emission(
        &self,
        u_pos: Vec2,
        u_dir: Vec2,
        scene: SceneSphere,
    ) -> Option<EmittedRay> {
        match self {
            Light::Area(a) => a.sample_emission(u_pos, u_dir),
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
            Light::Infinite { radiance } => {
                let d = -radiant_math::sampling::uniform_sphere(u_dir);
                let mut e = infinite::emit_parallel(d, *radiance, u_pos, scene);
                e.power *= 1.0 / radiant_math::sampling::UNIFORM_SPHERE_PDF;
                Some(e)
            }
        }
    }
}

#[cfg(test)]
mod tests;
