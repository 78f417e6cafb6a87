//! Point and spot lights.

use glam::{Vec2, Vec3};

use super::{LightLeSample, LightLiSample, LightPoint};
use crate::geometry::Ray;
use radiant_math::color::Rgb;
use radiant_math::{Frame, sampling};

pub(super) fn sample_point(p: Vec3, position: Vec3, intensity: Rgb) -> Option<LightLiSample> {
    let d = position - p;
    let dist2 = d.length_squared();
    if dist2 == 0.0 {
        return None;
    }
    Some(LightLiSample {
        li: intensity / dist2,
        wi: d / dist2.sqrt(),
        pdf: 1.0,
        p_light: LightPoint::free(position),
        delta: true,
        at_infinity: false,
    })
}

/// pbrt-v4's spot profile: 1 inside the falloff start, smoothstep to 0 at the edge.
pub(super) fn spot_falloff(
    w: Vec3,
    axis: Vec3,
    cos_falloff_start: f32,
    cos_total_width: f32,
) -> f32 {
    let cos = w.dot(axis);
    if cos >= cos_falloff_start {
        return 1.0;
    }
    if cos <= cos_total_width {
        return 0.0;
    }
    let t = (cos - cos_total_width) / (cos_falloff_start - cos_total_width);
    t * t * (3.0 - 2.0 * t)
}

pub(super) fn emit_point(position: Vec3, intensity: Rgb, u: Vec2) -> LightLeSample {
    LightLeSample::from_point(
        position,
        sampling::uniform_sphere(u),
        intensity,
        sampling::UNIFORM_SPHERE_PDF,
    )
}

/// Directions uniform in the spot's whole cone; the falloff goes into the power.
pub(super) fn emit_spot(
    position: Vec3,
    axis: Vec3,
    intensity: Rgb,
    cos_falloff_start: f32,
    cos_total_width: f32,
    u: Vec2,
) -> Option<LightLeSample> {
    let local = sampling::uniform_cone(u, cos_total_width);
    let d = Frame::from_normal(axis).to_world(local);
    let falloff = spot_falloff(d, axis, cos_falloff_start, cos_total_width);
    let pdf_dir = sampling::uniform_cone_pdf(cos_total_width);
    (falloff > 0.0).then(|| LightLeSample {
        ray: Ray::new(position, d),
        n: Vec3::ZERO,
        pdf_pos: 1.0,
        pdf_dir,
        le: intensity * falloff,
        power: intensity * (falloff / pdf_dir),
    })
}
