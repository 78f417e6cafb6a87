//! Cameras: map a film position (and a lens sample) to a ray in render space with a
//! weight. Pinhole/thin-lens perspective and orthographic projections live here; the
//! realistic camera traces through a lens prescription (`realistic/`).

pub mod projective;
pub mod realistic;
pub mod spread;

use glam::Vec2;

pub use projective::{Projection, ProjectiveCamera};
pub use spread::RaySpread;

use crate::geometry::Ray;

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
    /// A lens prescription in front of the film; rays are made in camera space (metres)
    /// and carried to render space by `world_from_camera`.
    Realistic {
        camera: Box<realistic::RealisticCamera>,
        world_from_camera: radiant_math::Transform,
    },
}

impl Camera {
    /// True when [`Camera::generate_ray`] reads its aperture sample `u_lens` (a pinhole
    /// does not).
    pub fn uses_lens_sample(&self) -> bool {
        match self {
            Camera::Projective(c) => c.lens_radius > 0.0,
            Camera::Realistic { .. } => true,
        }
    }

    /// A ray through continuous raster position `raster` ((0,0) is the top-left corner
    /// of the image, +x right, +y down), using `u_lens` for the aperture.
    pub fn generate_ray(&self, raster: Vec2, u_lens: Vec2) -> Option<CameraRay> {
        match self {
            Camera::Projective(c) => Some(c.generate_ray(raster, u_lens)),
            Camera::Realistic {
                camera,
                world_from_camera,
            } => {
                let s = camera.generate_ray(raster, u_lens)?;
                Some(CameraRay {
                    ray: Ray::new(
                        world_from_camera.point(s.origin),
                        world_from_camera.vector(s.dir).normalize(),
                    ),
                    weight: s.weight,
                })
            }
        }
    }
}

/// Builds the camera of a scene for an image of `resolution` pixels.
pub fn from_desc(
    desc: &radiant_scene::CameraDesc,
    film: &radiant_scene::FilmDesc,
    resolution: (u32, u32),
    warnings: &mut Vec<radiant_scene::Warning>,
) -> Result<Camera, radiant_scene::SceneError> {
    use radiant_scene::{CameraKind, SceneError};
    let world_from_camera = desc.camera_from_world.inverse();
    let window =
        |w: &Option<[f32; 4]>| w.unwrap_or_else(|| projective::default_screen_window(resolution));
    match &desc.kind {
        CameraKind::Perspective {
            fov_deg,
            lens_radius,
            focal_distance,
            screen_window,
        } => {
            if !(*fov_deg > 0.0 && *fov_deg < 180.0) {
                return Err(SceneError::at(
                    &desc.loc,
                    format!("fov must lie in (0, 180) degrees, got {fov_deg}"),
                ));
            }
            Ok(Camera::Projective(ProjectiveCamera {
                projection: Projection::Perspective {
                    tan_half_fov: (fov_deg.to_radians() / 2.0).tan(),
                },
                world_from_camera,
                screen_window: window(screen_window),
                resolution,
                lens_radius: *lens_radius,
                focal_distance: *focal_distance,
            }))
        }
        CameraKind::Orthographic {
            lens_radius,
            focal_distance,
            screen_window,
        } => Ok(Camera::Projective(ProjectiveCamera {
            projection: Projection::Orthographic,
            world_from_camera,
            screen_window: window(screen_window),
            resolution,
            lens_radius: *lens_radius,
            focal_distance: *focal_distance,
        })),
        CameraKind::Realistic {
            lens_file,
            aperture_diameter_mm,
            focus_distance,
        } => {
            let lens_error = |e: realistic::LensError| {
                SceneError::at(&desc.loc, format!("Camera \"realistic\": {e}"))
            };
            let lens = realistic::LensPrescription::from_file(lens_file).map_err(lens_error)?;
            let camera = realistic::RealisticCamera::new(
                lens,
                *aperture_diameter_mm as f64,
                *focus_distance as f64,
                film.diagonal_mm as f64,
                resolution,
            )
            .map_err(lens_error)?;
            for w in camera.warnings() {
                warnings.push(radiant_scene::Warning {
                    loc: desc.loc.clone(),
                    message: format!("Camera \"realistic\": {w}"),
                });
            }
            Ok(Camera::Realistic {
                camera: Box::new(camera),
                world_from_camera,
            })
        }
    }
}
