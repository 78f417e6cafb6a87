//! The image-based infinite light: radiance from a square environment image in
//! pbrt-v4's equal-area octahedral layout (Clarberg 2008, see
//! `radiant_math::equal_area`), importance sampled by piecewise-constant densities
//! over its pixels (Pharr, Jakob & Humphreys, *Physically Based Rendering*, 4th ed.,
//! §12.5).
//!
//! Lookups are nearest-pixel: the radiance is constant over each pixel's cell of the
//! square, so the density proportional to pixel luminance matches its shape exactly
//! (a grey image is sampled with zero variance in the direction), and what a lookup
//! returns is what the chi-square tests compare against.
//!
//! Because the mapping is equal-area, a density `p` per unit area of the square is
//! `p / 4π` per steradian, without a per-direction Jacobian.
//!
//! Two densities are kept. The plain one, proportional to luminance, serves every
//! estimator that uses light samples alone (photon emission, the photon mappers'
//! direct light, radiosity). Under multiple importance sampling with the BSDF, pbrt-v4
//! samples instead in proportion to `max(0, Y - mean Y)` (its "compensated"
//! distribution, after Karlík et al., "MIS Compensation: Optimizing Sampling
//! Techniques in Multiple Importance Sampling", 2019): the dim directions, which the
//! BSDF samples well, get no light samples, so the bright ones get more. The light's
//! density is then zero where BSDF sampling must cover alone, which the balance or
//! power heuristic handles (the BSDF's weight there is 1).

use glam::{Mat3, Vec2, Vec3};

use super::{LightLeSample, LightLiSample, LightPoint, LightSampleContext, SceneSphere};
use radiant_math::color::Rgb;
use radiant_math::equal_area::{SOLID_ANGLE_PER_AREA, sphere_to_square, square_to_sphere};
use radiant_math::{Distribution2D, PI, Transform};

/// An environment image ready for lookups and sampling.
#[derive(Clone)]
pub struct EnvironmentMap {
    size: usize,
    /// Per pixel, what a direction's lookup reads, side by side: one memory access
    /// for a light sample's radiance and density (the image and the densities'
    /// arrays apart were three, each likely a cache miss in a large image).
    texels: Vec<Texel>,
    /// Rotation from the light's frame to render space, and back (its transpose).
    render_from_light: Mat3,
    light_from_render: Mat3,
    /// Density per unit area of the square in proportion to luminance.
    plain: Distribution2D,
    /// In proportion to `max(0, Y - mean Y)`: for light samples weighted by MIS.
    compensated: Distribution2D,
    /// Mean radiance over the sphere (equal-area pixels: the pixel mean).
    mean: Rgb,
}

impl std::fmt::Debug for EnvironmentMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EnvironmentMap")
            .field("size", &self.size)
            .field("mean", &self.mean)
            .finish_non_exhaustive()
    }
}

/// The rotation nearest to `xf`'s linear part: pbrt-v4 orients environment images by
/// the CTM; a scale is meaningless for directions, and only a rotation (or a
/// reflection) keeps the equal-area densities valid, so columns are orthonormalised
/// (Gram–Schmidt; exact for similarity transforms). Returns whether `xf` was a
/// similarity.
pub fn rotation_of(xf: &Transform) -> (Mat3, bool) {
    let m = Mat3::from_mat4(xf.m);
    let (a, b, c) = (m.x_axis.length(), m.y_axis.length(), m.z_axis.length());
    let tol = 1e-4 * a.max(b).max(c);
    let similar = (a - b).abs() < tol
        && (a - c).abs() < tol
        && m.x_axis.dot(m.y_axis).abs() < tol * a
        && m.x_axis.dot(m.z_axis).abs() < tol * a
        && m.y_axis.dot(m.z_axis).abs() < tol * a;
    let x = m.x_axis.normalize_or(Vec3::X);
    let y = (m.y_axis - x * x.dot(m.y_axis)).normalize_or(x.any_orthonormal_vector());
    let z = if m.determinant() < 0.0 {
        -x.cross(y)
    } else {
        x.cross(y)
    };
    (Mat3::from_cols(x, y, z), similar)
}

/// A pixel's radiance (scaled) and its densities per unit area of the square under
/// the plain and the compensated distributions.
#[derive(Clone, Copy, Debug)]
struct Texel {
    radiance: Rgb,
    plain: f32,
    compensated: f32,
}

/// An environment image as read: `size * size` linear RGB values, row 0 at v = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentPicture {
    pub size: usize,
    pub pixels: Vec<Rgb>,
}

impl EnvironmentPicture {
    /// Illuminance on a surface facing the image's +z, at scale 1:
    /// E = Σ_{z > 0} Y_i cos θ_i ΔΩ, with ΔΩ = 4π / N for the equal-area pixels.
    pub fn upper_illuminance(&self) -> f64 {
        let size = self.size;
        let d_omega = SOLID_ANGLE_PER_AREA as f64 / (size * size) as f64;
        let mut e = 0.0f64;
        for (k, p) in self.pixels.iter().enumerate() {
            let st = Vec2::new(
                ((k % size) as f32 + 0.5) / size as f32,
                ((k / size) as f32 + 0.5) / size as f32,
            );
            let w = square_to_sphere(st);
            if w.z > 0.0 {
                e += (p.luminance() * w.z) as f64 * d_omega;
            }
        }
        e
    }
}

impl EnvironmentMap {
    /// `pixels`: `size * size` linear RGB values, row 0 at v = 0; each is multiplied
    /// by `scale`. `render_from_light` should be a rotation (see [`rotation_of`]).
    pub fn new(size: usize, pixels: &[Rgb], scale: Rgb, render_from_light: Mat3) -> EnvironmentMap {
        assert!(size > 0 && pixels.len() == size * size);
        let lum: Vec<f32> = pixels
            .iter()
            .map(|&p| (p * scale).luminance().max(0.0))
            .collect();
        let mean_lum = lum.iter().map(|&y| y as f64).sum::<f64>() / lum.len() as f64;
        let compensated: Vec<f32> = lum
            .iter()
            .map(|&y| (y as f64 - mean_lum).max(0.0) as f32)
            .collect();
        let mut sum = [0.0f64; 3];
        for p in pixels.iter() {
            for (s, v) in sum.iter_mut().zip((*p * scale).to_array()) {
                *s += v as f64;
            }
        }
        let n = pixels.len() as f64;
        let plain = Distribution2D::new(&lum, size, size);
        // A constant image has nothing above its mean: all zero, which falls back to
        // uniform sampling — the right density for it.
        let compensated = Distribution2D::new(&compensated, size, size);
        let texels = pixels
            .iter()
            .enumerate()
            .map(|(k, &p)| {
                let center = Vec2::new(
                    ((k % size) as f32 + 0.5) / size as f32,
                    ((k / size) as f32 + 0.5) / size as f32,
                );
                Texel {
                    radiance: p * scale,
                    plain: plain.pdf(center),
                    compensated: compensated.pdf(center),
                }
            })
            .collect();
        EnvironmentMap {
            size,
            texels,
            plain,
            compensated,
            mean: Rgb::new(
                (sum[0] / n) as f32,
                (sum[1] / n) as f32,
                (sum[2] / n) as f32,
            ),
            light_from_render: render_from_light.transpose(),
            render_from_light,
        }
    }

    pub fn size(&self) -> usize {
        self.size
    }

    /// Mean radiance over all directions.
    pub fn mean(&self) -> Rgb {
        self.mean
    }

    fn distribution(&self, ctx: &LightSampleContext) -> &Distribution2D {
        if ctx.mis_with_bsdf {
            &self.compensated
        } else {
            &self.plain
        }
    }

    /// The pixel holding `st`, as [`Distribution2D::cell`] finds it.
    fn texel(&self, st: Vec2) -> &Texel {
        let n = self.size;
        let x = ((st.x * n as f32).max(0.0) as usize).min(n - 1);
        let y = ((st.y * n as f32).max(0.0) as usize).min(n - 1);
        &self.texels[y * n + x]
    }

    /// The pixel seen in direction `d` (render space, any length); `None` for d = 0.
    fn texel_towards(&self, d: Vec3) -> Option<&Texel> {
        let w = (self.light_from_render * d).normalize_or_zero();
        (w != Vec3::ZERO).then(|| self.texel(sphere_to_square(w)))
    }

    /// Solid-angle density of a texel under the distribution for `ctx`.
    fn density(ctx: &LightSampleContext, texel: &Texel) -> f32 {
        let per_area = if ctx.mis_with_bsdf {
            texel.compensated
        } else {
            texel.plain
        };
        per_area / SOLID_ANGLE_PER_AREA
    }

    /// Radiance arriving from direction `d` (render space, any length).
    pub fn radiance(&self, d: Vec3) -> Rgb {
        self.texel_towards(d).map_or(Rgb::BLACK, |t| t.radiance)
    }

    /// Solid-angle density of `sample_li` from `ctx` for the unit direction `wi`.
    pub fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32 {
        self.texel_towards(wi)
            .map_or(0.0, |t| Self::density(ctx, t))
    }

    /// A direction of arrival by the density for `ctx`; `None` when it carries nothing.
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        scene: SceneSphere,
    ) -> Option<LightLiSample> {
        let (st, _) = self.distribution(ctx).sample(u);
        let wi = (self.render_from_light * square_to_sphere(st)).normalize();
        // Radiance and density of the direction as `environment` and `pdf_li` see it:
        // on a pixel edge, the round trip through the direction may land in the
        // neighbouring pixel, and sample and lookup must agree there.
        let texel = self.texel_towards(wi)?;
        let (li, pdf) = (texel.radiance, Self::density(ctx, texel));
        if li.is_black() || pdf <= 0.0 {
            return None;
        }
        let p = ctx.p;
        Some(LightLiSample {
            li,
            wi,
            pdf,
            p_light: LightPoint::free(p + wi * (2.0 * scene.radius + (p - scene.center).length())),
            delta: false,
            at_infinity: true,
        })
    }

    /// A direction by the plain density (render space, unit), with its solid-angle
    /// density; `None` when the image is black there.
    pub fn sample_direction(&self, u: Vec2) -> Option<(Vec3, f32)> {
        let (st, _) = self.plain.sample(u);
        let w = (self.render_from_light * square_to_sphere(st)).normalize();
        let pdf = self.plain_pdf(w);
        (pdf > 0.0).then_some((w, pdf))
    }

    /// Solid-angle density of `sample_direction` for the direction `w`.
    pub fn plain_pdf(&self, w: Vec3) -> f32 {
        self.texel_towards(w)
            .map_or(0.0, |t| t.plain / SOLID_ANGLE_PER_AREA)
    }

    /// Flux through the scene's disk: mean radiance × 4π sr × π R².
    pub fn power(&self, scene: SceneSphere) -> Rgb {
        self.mean * (4.0 * PI * PI * scene.radius * scene.radius)
    }

    /// A photon ray: a direction of arrival by the plain density, then a parallel ray
    /// through a uniform point of the disk covering the scene.
    pub fn sample_le(&self, u_pos: Vec2, u_dir: Vec2, scene: SceneSphere) -> Option<LightLeSample> {
        let (st, _) = self.plain.sample(u_dir);
        let wi = (self.render_from_light * square_to_sphere(st)).normalize();
        let le = self.radiance(wi);
        let pdf_dir = self.pdf_li(&LightSampleContext::at_point(scene.center), wi);
        if le.is_black() || pdf_dir <= 0.0 {
            return None;
        }
        let mut e = super::infinite::emit_parallel(-wi, le, u_pos, scene);
        e.pdf_dir = pdf_dir;
        e.power *= 1.0 / pdf_dir;
        Some(e)
    }
}
