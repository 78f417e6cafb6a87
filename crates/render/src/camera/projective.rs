//! Perspective (pinhole or thin lens) and orthographic cameras with pbrt's conventions:
//! the field of view spans the shorter image axis, raster x grows with camera +x and
//! raster y with camera −y.

use glam::{Vec2, Vec3};

use super::CameraRay;
use crate::geometry::Ray;
use radiant_math::{Transform, sampling};

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// `tan_half_fov`: tangent of half the field of view on the shorter axis.
    Perspective {
        tan_half_fov: f32,
    },
    Orthographic,
}

#[derive(Clone, Debug)]
pub struct ProjectiveCamera {
    pub projection: Projection,
    pub world_from_camera: Transform,
    /// Screen window (x0, x1, y0, y1) on the plane z = 1 in units of tan_half_fov
    /// (perspective) or scene units (orthographic).
    pub screen_window: [f32; 4],
    pub resolution: (u32, u32),
    /// Thin-lens aperture radius and focus distance (Potmesil & Chakravarty 1981).
    pub lens_radius: f32,
    pub focal_distance: f32,
}

/// pbrt's default screen window: [-1, 1] on the shorter axis, aspect-scaled on the longer.
pub fn default_screen_window(resolution: (u32, u32)) -> [f32; 4] {
    let aspect = resolution.0 as f32 / resolution.1 as f32;
    if aspect > 1.0 {
        [-aspect, aspect, -1.0, 1.0]
    } else {
        [-1.0, 1.0, -1.0 / aspect, 1.0 / aspect]
    }
}

impl ProjectiveCamera {
    /// Point on the camera-space plane z = 1 (perspective) or z = 0 (orthographic)
    /// under raster position `raster`.
    fn camera_point(&self, raster: Vec2) -> Vec3 {
        let [x0, x1, y0, y1] = self.screen_window;
        let sx = x0 + raster.x / self.resolution.0 as f32 * (x1 - x0);
        let sy = y1 - raster.y / self.resolution.1 as f32 * (y1 - y0);
        match self.projection {
            Projection::Perspective { tan_half_fov } => {
                Vec3::new(sx * tan_half_fov, sy * tan_half_fov, 1.0)
            }
            Projection::Orthographic => Vec3::new(sx, sy, 0.0),
        }
    }

    pub fn generate_ray(&self, raster: Vec2, u_lens: Vec2) -> CameraRay {
        let p = self.camera_point(raster);
        let (mut o, mut d) = match self.projection {
            Projection::Perspective { .. } => (Vec3::ZERO, p.normalize()),
            Projection::Orthographic => (p, Vec3::Z),
        };
        if self.lens_radius > 0.0 {
            let lens = self.lens_radius * sampling::concentric_disk(u_lens);
            let focus = o + d * (self.focal_distance / d.z);
            o += Vec3::new(lens.x, lens.y, 0.0);
            d = (focus - o).normalize();
        }
        CameraRay {
            ray: Ray::new(
                self.world_from_camera.point(o),
                self.world_from_camera.vector(d).normalize(),
            ),
            weight: 1.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(fov_deg: f32, res: (u32, u32)) -> ProjectiveCamera {
        ProjectiveCamera {
            projection: Projection::Perspective {
                tan_half_fov: (fov_deg.to_radians() / 2.0).tan(),
            },
            world_from_camera: Transform::IDENTITY,
            screen_window: default_screen_window(res),
            resolution: res,
            lens_radius: 0.0,
            focal_distance: 1.0,
        }
    }

    #[test]
    fn fov_spans_the_shorter_axis_and_orientation_follows_pbrt() {
        let c = camera(90.0, (200, 100));
        // Top edge centre: 45 degrees up.
        let top = c.generate_ray(Vec2::new(100.0, 0.0), Vec2::ZERO).ray.d;
        assert!((top.y / top.z - 1.0).abs() < 1e-5);
        // Right edge: aspect 2 -> tan = 2, and raster right is camera +x.
        let right = c.generate_ray(Vec2::new(200.0, 50.0), Vec2::ZERO).ray.d;
        assert!((right.x / right.z - 2.0).abs() < 1e-5);
    }

    /// The sampler skips the aperture draw of cameras that say they do not read it.
    #[test]
    fn only_a_lens_reads_the_aperture_sample() {
        let mut c = camera(40.0, (64, 64));
        let rays = |c: &ProjectiveCamera| {
            [Vec2::ZERO, Vec2::new(0.1, 0.9), Vec2::new(0.8, 0.3)].map(|u| {
                let r = c.generate_ray(Vec2::new(10.0, 50.0), u).ray;
                (r.o, r.d)
            })
        };
        let pinhole = rays(&c);
        assert!(!crate::camera::Camera::Projective(c.clone()).uses_lens_sample());
        assert!(pinhole.iter().all(|r| *r == pinhole[0]));
        c.lens_radius = 0.5;
        let lens = rays(&c);
        assert!(crate::camera::Camera::Projective(c).uses_lens_sample());
        assert!(lens[1] != lens[2]);
    }

    #[test]
    fn thin_lens_rays_converge_on_the_focal_plane() {
        let mut c = camera(40.0, (64, 64));
        c.lens_radius = 0.5;
        c.focal_distance = 7.0;
        let pin = c.generate_ray(Vec2::new(10.0, 50.0), Vec2::splat(0.5)).ray;
        let focus = pin.at(7.0 / pin.d.z);
        for u in [Vec2::new(0.1, 0.9), Vec2::new(0.8, 0.3)] {
            let r = c.generate_ray(Vec2::new(10.0, 50.0), u).ray;
            let q = r.at((7.0 - r.o.z) / r.d.z);
            assert!((q - focus).length() < 1e-4);
        }
    }
}
