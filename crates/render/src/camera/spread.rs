//! How wide a pixel is along the paths it starts: the footprint that texture filtering
//! needs at every hit, for every camera.
//!
//! The camera's rays through two neighbouring pixels at the image centre give an
//! angle per pixel and, for orthographic projections, an offset per pixel. A pixel's
//! rays then form a cone (Amanatides 1984; the ray cones of Akenine-Möller et al.,
//! "Texture Level of Detail Strategies for Real-Time Ray Tracing", Ray Tracing Gems
//! 2019): at distance d along the path its width is offset + angle · d. At a hit the
//! cone's cross-section is carried onto the tangent plane along the ray, which
//! stretches it into the ellipse of a grazing view. As in pbrt-v4's approximation of
//! ray differentials, the same spread serves hits after bounces (with the distance
//! travelled), and the width shrinks as 1/√spp (to at most 1/8) since more samples per
//! pixel each need less prefiltering.

use glam::{Vec2, Vec3};
use radiant_math::Frame;

use super::Camera;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RaySpread {
    /// Radians per pixel.
    pub angle: f32,
    /// Scene units per pixel at the camera (orthographic cameras).
    pub offset: f32,
}

impl RaySpread {
    /// None: every lookup is a point lookup.
    pub const NONE: RaySpread = RaySpread {
        angle: 0.0,
        offset: 0.0,
    };

    /// The spread of `camera` at `resolution` with `spp` samples per pixel, measured at
    /// the image centre; `NONE` where the camera makes no ray there.
    pub fn of_camera(camera: &Camera, resolution: (u32, u32), spp: u32) -> RaySpread {
        let (cx, cy) = ((resolution.0 / 2) as f32, (resolution.1 / 2) as f32);
        let u_lens = Vec2::splat(0.5);
        let ray = |x: f32, y: f32| camera.generate_ray(Vec2::new(x, y), u_lens).map(|r| r.ray);
        let (Some(a), Some(bx), Some(by)) = (
            ray(cx + 0.5, cy + 0.5),
            ray(cx + 1.5, cy + 0.5),
            ray(cx + 0.5, cy + 1.5),
        ) else {
            return RaySpread::NONE;
        };
        let da = a.d.normalize();
        let angle_to = |b: Vec3| da.angle_between(b.normalize());
        // The component of the origins' separation across the ray.
        let across = |o: Vec3| {
            let d = o - a.o;
            (d - da * d.dot(da)).length()
        };
        let angle = 0.5 * (angle_to(bx.d) + angle_to(by.d));
        let offset = 0.5 * (across(bx.o) + across(by.o));
        let scale = (1.0 / (spp.max(1) as f32).sqrt()).max(0.125);
        let spread = RaySpread {
            angle: angle * scale,
            offset: offset * scale,
        };
        if spread.angle.is_finite() && spread.offset.is_finite() {
            spread
        } else {
            RaySpread::NONE
        }
    }

    /// Position differentials (∂p/∂x, ∂p/∂y) on the plane through `p` with normal `n`,
    /// for a ray of direction `d` that has travelled `distance` from the camera.
    pub fn differentials(&self, d: Vec3, distance: f32, n: Vec3) -> (Vec3, Vec3) {
        let width = self.offset + self.angle * distance;
        if !(width > 0.0 && width.is_finite()) {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        let d = d.normalize();
        let frame = Frame::from_normal(d);
        // Nearly grazing views would stretch the footprint without bound.
        let cos = n.dot(d);
        let cos = if cos.abs() < 1e-3 {
            1e-3f32.copysign(cos)
        } else {
            cos
        };
        let onto_plane = |e: Vec3| e - d * (n.dot(e) / cos);
        (onto_plane(frame.s * width), onto_plane(frame.t * width))
    }
}
