//! Lights at infinity: the constant environment and the distant (parallel) light.
//! Photons from them start on a disk of the scene's bounding radius, perpendicular to
//! their direction, so that every photon crosses the scene's bounding sphere.

use glam::{Vec2, Vec3};

use super::{EmittedRay, LightSample, SceneSphere};
use crate::geometry::Ray;
use radiant_math::color::Rgb;
use radiant_math::{Frame, PI, sampling};

/// Uniform sphere sampling: the density of every direction.
pub(super) const PDF: f32 = sampling::UNIFORM_SPHERE_PDF;

pub(super) fn sample_li(
    p: Vec3,
    radiance: Rgb,
    u: Vec2,
    scene: SceneSphere,
) -> Option<LightSample> {
    let wi = sampling::uniform_sphere(u);
    Some(LightSample {
        li: radiance,
        wi,
        p: p + wi * (2.0 * scene.radius + (p - scene.center).length()),
        n: Vec3::ZERO,
        pdf: PDF,
        delta: false,
        at_infinity: true,
    })
}

/// A ray travelling along `direction` through a uniformly chosen point of the disk
/// that covers the scene; power = radiance * disk area.
pub(super) fn emit_parallel(
    direction: Vec3,
    radiance: Rgb,
    u: Vec2,
    scene: SceneSphere,
) -> EmittedRay {
    let frame = Frame::from_normal(direction);
    let d = sampling::concentric_disk(u) * scene.radius;
    let origin = scene.center + frame.to_world(Vec3::new(d.x, d.y, 0.0)) - direction * scene.radius;
    EmittedRay {
        ray: Ray::new(origin, direction),
        n: Vec3::ZERO,
        power: radiance * (PI * scene.radius * scene.radius),
    }
}
