//! Point lights whose intensity varies with direction by an image (Pharr, Jakob &
//! Humphreys, *Physically Based Rendering*, 4th ed., §12.2.2–12.2.3):
//!
//! - goniometric: the intensity of every direction from a square image in the
//!   equal-area octahedral layout (Clarberg 2008) — the layout of environment images,
//!   so the lookups and the direction sampling are an [`EnvironmentMap`]'s. The light's
//!   frame has its y and z axes exchanged, as pbrt-v4 does (goniometric diagrams put
//!   the polar axis along +y).
//! - projection: an image projected through a pinhole along the light's +z, its
//!   narrower side spanning the field of view `fov`; no light outside the image.
//!
//! Both are delta lights. Lookups are nearest-pixel, so each pixel's intensity is
//! constant over its solid angle: the power is the exact sum of intensity × solid
//! angle, and photon rays sampled in proportion to it carry equal flux per pixel.

use std::sync::Arc;

use glam::{Mat3, Vec2, Vec3};

use super::{EnvironmentMap, LightLeSample, LightLiSample};
use radiant_math::color::Rgb;
use radiant_math::{Distribution2D, PI};

/// Isotropic-frame point light with intensity from an equal-area octahedral image.
#[derive(Clone, Debug)]
pub struct GoniometricLight {
    pub position: Vec3,
    /// Intensity (W/sr) per direction leaving the light, render space.
    map: Arc<EnvironmentMap>,
}

impl GoniometricLight {
    /// `map` holds the intensity per direction (its scale included) in render space.
    pub fn new(position: Vec3, map: Arc<EnvironmentMap>) -> GoniometricLight {
        GoniometricLight { position, map }
    }

    /// Intensity towards the render-space direction `w`.
    pub fn intensity(&self, w: Vec3) -> Rgb {
        self.map.radiance(w)
    }

    /// Φ = ∫ I dω = mean intensity × 4π (the pixels are of equal solid angle).
    pub fn power(&self) -> Rgb {
        self.map.mean() * (4.0 * PI)
    }

    pub fn sample_li(&self, p: Vec3) -> Option<LightLiSample> {
        let mut s = super::point::sample_point(p, self.position, Rgb::WHITE)?;
        s.li *= self.intensity(-s.wi);
        (!s.li.is_black()).then_some(s)
    }

    /// A photon ray by the image's luminance (the map's plain density).
    pub fn sample_le(&self, u_dir: Vec2) -> Option<LightLeSample> {
        let (d, pdf_dir) = self.map.sample_direction(u_dir)?;
        let le = self.intensity(d);
        (!le.is_black()).then(|| LightLeSample::from_point(self.position, d, le, pdf_dir))
    }

    /// Solid-angle density of `sample_le`'s direction `w` (render space).
    pub fn pdf_dir(&self, w: Vec3) -> f32 {
        self.map.plain_pdf(w)
    }
}

/// Solid angle of the rectangle [0, x] × [0, y] on the plane z = 1 seen from the
/// origin (signed with x y): atan(x y / √(1 + x² + y²)).
fn corner_solid_angle(x: f64, y: f64) -> f64 {
    (x * y / (1.0 + x * x + y * y).sqrt()).atan()
}

/// Solid angle of the plane-z=1 rectangle [x0, x1] × [y0, y1].
fn rect_solid_angle(x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    corner_solid_angle(x1, y1) - corner_solid_angle(x0, y1) - corner_solid_angle(x1, y0)
        + corner_solid_angle(x0, y0)
}

/// An image projected from a point through a pinhole.
#[derive(Clone, Debug)]
pub struct ProjectionLight {
    pub position: Vec3,
    render_from_light: Mat3,
    light_from_render: Mat3,
    width: usize,
    height: usize,
    /// Row 0 is the image's top, projected towards the light's +y.
    pixels: Arc<Vec<Rgb>>,
    scale: Rgb,
    /// Half extents of the image on the plane z = 1 of the light's frame.
    half_x: f32,
    half_y: f32,
    /// Photon directions: pixels in proportion to luminance × solid angle, uniform
    /// over the image plane within each.
    distribution: Distribution2D,
    power: Rgb,
}

impl ProjectionLight {
    /// `fov` in degrees spans the narrower side of the `width` × `height` image;
    /// `render_from_light` should be a rotation. Pixels are multiplied by `scale`.
    pub fn new(
        position: Vec3,
        render_from_light: Mat3,
        fov: f32,
        width: usize,
        height: usize,
        pixels: Arc<Vec<Rgb>>,
        scale: Rgb,
    ) -> ProjectionLight {
        assert!(width > 0 && height > 0 && pixels.len() == width * height);
        let t = (0.5 * fov.to_radians()).tan();
        let aspect = width as f32 / height as f32;
        let (half_x, half_y) = if aspect > 1.0 {
            (t * aspect, t)
        } else {
            (t, t / aspect)
        };
        let omega = Self::pixel_solid_angles(width, height, half_x, half_y);
        let weights: Vec<f32> = pixels
            .iter()
            .zip(&omega)
            .map(|(p, &o)| ((*p * scale).luminance().max(0.0) as f64 * o) as f32)
            .collect();
        let mut sum = [0.0f64; 3];
        for (p, &o) in pixels.iter().zip(&omega) {
            for (s, v) in sum.iter_mut().zip((*p * scale).to_array()) {
                *s += v as f64 * o;
            }
        }
        ProjectionLight {
            position,
            light_from_render: render_from_light.transpose(),
            render_from_light,
            distribution: Distribution2D::new(&weights, width, height),
            power: Rgb::new(sum[0] as f32, sum[1] as f32, sum[2] as f32),
            width,
            height,
            pixels,
            scale,
            half_x,
            half_y,
        }
    }

    /// Each pixel's solid angle, row-major.
    pub fn pixel_solid_angles(width: usize, height: usize, half_x: f32, half_y: f32) -> Vec<f64> {
        let xs: Vec<f64> = (0..=width)
            .map(|i| (-1.0 + 2.0 * i as f64 / width as f64) * half_x as f64)
            .collect();
        // Row 0 at the top (+y).
        let ys: Vec<f64> = (0..=height)
            .map(|j| (1.0 - 2.0 * j as f64 / height as f64) * half_y as f64)
            .collect();
        ys.windows(2)
            .flat_map(|y| {
                xs.windows(2)
                    .map(move |x| rect_solid_angle(x[0], x[1], y[1], y[0]))
            })
            .collect()
    }

    /// The image square point (u right, v down from the top) that the light-frame
    /// direction `w` passes through; `None` behind the light or outside the image.
    fn image_point(&self, w: Vec3) -> Option<Vec2> {
        if w.z <= 0.0 {
            return None;
        }
        let x = w.x / w.z;
        let y = w.y / w.z;
        let u = 0.5 * (x / self.half_x + 1.0);
        let v = 0.5 * (1.0 - y / self.half_y);
        ((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v)).then_some(Vec2::new(u, v))
    }

    fn direction_of(&self, st: Vec2) -> Vec3 {
        let x = (2.0 * st.x - 1.0) * self.half_x;
        let y = (1.0 - 2.0 * st.y) * self.half_y;
        Vec3::new(x, y, 1.0)
    }

    /// Intensity towards the render-space direction `w` (any length).
    pub fn intensity(&self, w: Vec3) -> Rgb {
        let l = (self.light_from_render * w).normalize_or_zero();
        match self.image_point(l) {
            Some(st) => {
                let (x, y) = self.distribution.cell(st);
                self.pixels[y * self.width + x] * self.scale
            }
            None => Rgb::BLACK,
        }
    }

    pub fn power(&self) -> Rgb {
        self.power
    }

    /// The render-space axis, and the cosine of the widest direction (the image's
    /// corners) from it.
    pub fn cone(&self) -> (Vec3, f32) {
        let corner = Vec3::new(self.half_x, self.half_y, 1.0).normalize();
        ((self.render_from_light * Vec3::Z).normalize(), corner.z)
    }

    pub fn sample_li(&self, p: Vec3) -> Option<LightLiSample> {
        let mut s = super::point::sample_point(p, self.position, Rgb::WHITE)?;
        s.li *= self.intensity(-s.wi);
        (!s.li.is_black()).then_some(s)
    }

    /// Solid-angle density of `sample_le`'s direction `w` (render space): the image
    /// plane's density over its area, times the plane-to-sphere Jacobian
    /// dA/dω = 1 / cos³θ (distance 1 along the axis).
    pub fn pdf_dir(&self, w: Vec3) -> f32 {
        let l = (self.light_from_render * w).normalize_or_zero();
        let Some(st) = self.image_point(l) else {
            return 0.0;
        };
        let plane_area = 4.0 * self.half_x * self.half_y;
        self.distribution.pdf(st) / (plane_area * l.z * l.z * l.z)
    }

    pub fn sample_le(&self, u_dir: Vec2) -> Option<LightLeSample> {
        let (st, _) = self.distribution.sample(u_dir);
        let d = (self.render_from_light * self.direction_of(st)).normalize();
        let le = self.intensity(d);
        let pdf_dir = self.pdf_dir(d);
        (!le.is_black() && pdf_dir > 0.0)
            .then(|| LightLeSample::from_point(self.position, d, le, pdf_dir))
    }

    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_solid_angles_sum_to_the_rectangle() {
        // A 90° field of view on a square image is one face of a cube: 4π / 6.
        let o = ProjectionLight::pixel_solid_angles(7, 7, 1.0, 1.0);
        let total: f64 = o.iter().sum();
        assert!(
            (total - 4.0 * std::f64::consts::PI / 6.0).abs() < 1e-9,
            "{total}"
        );
        assert!(o.iter().all(|&x| x > 0.0));
    }
}
