//! The specular step of camera paths that run through mirrors and glass to the first
//! diffuse surface: SPPM's visible points, the photon mapper's eye paths and final
//! gather rays, the radiosity display. (The path tracer also weighs each bounce for
//! multiple importance sampling, so it keeps its own.)

use glam::Vec3;

use crate::material::{Material, TransportMode};
use crate::sampler::PixelSample;
use radiant_math::Frame;
use radiant_math::color::Rgb;

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
    let u_lobe = sampler.get_1d();
    let u_dir = sampler.get_2d();
    let bs = material.sample(wo, u_lobe, u_dir, TransportMode::Radiance)?;
    *beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
    if beta.is_black() {
        return None;
    }
    Some(frame.to_world(bs.wi))
}
