//! Warps from the unit square to the domains the integrators sample, each with its pdf.
//! Formulas follow Shirley & Chiu, "A Low Distortion Map Between Disk and Square" (1997)
//! and the standard Malley construction for cosine-weighted directions.

use super::{INV_PI, PI, Vec2, Vec3};

/// Concentric map from [0,1)^2 to the unit disk (Shirley & Chiu 1997).
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, (PI / 4.0) * (o.y / o.x))
    } else {
        (o.y, PI / 2.0 - (PI / 4.0) * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Cosine-weighted direction about +z (Malley's method); pdf = cos(theta)/pi.
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d.x * d.x - d.y * d.y).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * INV_PI
}

/// Uniform direction on the unit sphere; pdf = 1/(4 pi).
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Uniform direction on the +z hemisphere; pdf = 1/(2 pi).
pub fn uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

pub const UNIFORM_HEMISPHERE_PDF: f32 = 1.0 / (2.0 * PI);

/// Uniform direction in the cone around +z with half-angle acos(cos_max); pdf = 1/(2 pi (1 - cos_max)).
pub fn uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    let cos_theta = (1.0 - u.x) + u.x * cos_max;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = u.y * 2.0 * PI;
    Vec3::new(phi.cos() * sin_theta, phi.sin() * sin_theta, cos_theta)
}

pub fn uniform_cone_pdf(cos_max: f32) -> f32 {
    1.0 / (2.0 * PI * (1.0 - cos_max))
}

/// Barycentric coordinates (b0, b1, b2) uniformly distributed over a triangle,
/// using the area-preserving square-to-triangle map of Heitz (2019), low distortion.
pub fn uniform_triangle(u: Vec2) -> [f32; 3] {
    let (b0, b1) = if u.x < u.y {
        let b0 = u.x / 2.0;
        (b0, u.y - b0)
    } else {
        let b1 = u.y / 2.0;
        (u.x - b1, b1)
    };
    [b0, b1, 1.0 - b0 - b1]
}

/// Veach's power heuristic with beta = 2 for two strategies taking one sample each.
pub fn power_heuristic(pdf_f: f32, pdf_g: f32) -> f32 {
    let f = pdf_f * pdf_f;
    let g = pdf_g * pdf_g;
    if f.is_infinite() {
        return 1.0;
    }
    if f + g == 0.0 { 0.0 } else { f / (f + g) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hash::Pcg32;

    #[test]
    fn warps_stay_in_their_domains() {
        let mut rng = Pcg32::new(1, 1);
        for _ in 0..10_000 {
            let u = Vec2::new(rng.uniform(), rng.uniform());
            assert!(concentric_disk(u).length() <= 1.0 + 1e-6);
            let c = cosine_hemisphere(u);
            assert!(c.z >= 0.0 && (c.length() - 1.0).abs() < 1e-5);
            assert!((uniform_sphere(u).length() - 1.0).abs() < 1e-5);
            let b = uniform_triangle(u);
            assert!(b.iter().all(|&x| (-1e-6..=1.0 + 1e-6).contains(&x)));
            let d = uniform_cone(u, 0.9);
            assert!(d.z >= 0.9 - 1e-6);
        }
    }

    #[test]
    fn cosine_hemisphere_mean_cosine_is_two_thirds() {
        // E[cos] under pdf cos/pi is (1/pi) * integral cos^2 dw = 2/3.
        let mut rng = Pcg32::new(2, 1);
        let n = 200_000;
        let mean: f64 = (0..n)
            .map(|_| cosine_hemisphere(Vec2::new(rng.uniform(), rng.uniform())).z as f64)
            .sum::<f64>()
            / n as f64;
        assert!((mean - 2.0 / 3.0).abs() < 3e-3, "{mean}");
    }
}
