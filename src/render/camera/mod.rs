//! Cameras: map a film position (and a lens sample) to a ray in render space with a
//! weight. Pinhole/thin-lens perspective and orthographic projections live here; the
//! realistic camera traces through a lens prescription (`realistic/`).

mod projective;

use glam::Vec2;

pub use projective::{Projection, ProjectiveCamera};

use crate::render::geometry::Ray;

/// A camera ray and its weight (1 for ideal projections; the realistic camera's
/// weight carries the film-irradiance factors).
#[derive(Clone, Copy, Debug)]
pub struct CameraRay {
    pub ray: Ray,
    pub weight: f32,
}

#[derive(Clone, Debug)]
pub enum Camera {
    Projective(ProjectiveCamera),
}

impl Camera {
    /// A ray through continuous raster position `raster` ((0,0) is the top-left corner
    /// of the image, +x right, +y down), using `u_lens` for the aperture.
    pub fn generate_ray(&self, raster: Vec2, u_lens: Vec2) -> Option<CameraRay> {
        match self {
            Camera::Projective(c) => Some(c.generate_ray(raster, u_lens)),
        }
    }
}
