//! Lights at infinity: the constant environment and the distant (parallel) light.
//! Photons from them start on a disk of the scene's bounding radius, perpendicular to
//! their direction, so that every photon crosses the scene's bounding sphere.

use glam::{Vec2, Vec3};

use super::{LightLeSample, LightLiSample, LightPoint, LightSampleContext, SceneSphere};
use crate::geometry::Ray;
use radiant_math::color::Rgb;
use radiant_math::{Frame, PI, sampling};

/// Uniform sphere sampling: the density of every direction.
pub(super) fn pdf_li(_wi: Vec3) -> f32 {
    sampling::UNIFORM_SPHERE_PDF
}

pub(super) fn sample_li(
    ctx: &LightSampleContext,
    radiance: Rgb,
    u: Vec2,
    scene: SceneSphere,
) -> Option<LightLiSample> {
    let p = ctx.p;
    let wi = sampling::uniform_sphere(u);
    Some(LightLiSample {
        li: radiance,
        wi,
        pdf: pdf_li(wi),
        p_light: LightPoint::free(p + wi * (2.0 * scene.radius + (p - scene.center).length())),
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
) -> LightLeSample {
    let frame = Frame::from_normal(direction);
    let d = sampling::concentric_disk(u) * scene.radius;
    let origin = scene.center + frame.to_world(Vec3::new(d.x, d.y, 0.0)) - direction * scene.radius;
    let disk_area = PI * scene.radius * scene.radius;
    LightLeSample {
        ray: Ray::new(origin, direction),
        n: Vec3::ZERO,
        pdf_pos: 1.0 / disk_area,
        pdf_dir: 1.0,
        le: radiance,
        power: radiance * disk_area,
    }
}

/// A ray of the constant environment: a uniformly chosen direction of arrival, then a
/// parallel ray in that direction through the scene's disk.
pub(super) fn emit_infinite(
    radiance: Rgb,
    u_pos: Vec2,
    u_dir: Vec2,
    scene: SceneSphere,
) -> LightLeSample {
    let d = -sampling::uniform_sphere(u_dir);
    let mut e = emit_parallel(d, radiance, u_pos, scene);
    e.pdf_dir = sampling::UNIFORM_SPHERE_PDF;
    e.power *= 1.0 / sampling::UNIFORM_SPHERE_PDF;
    e
}
