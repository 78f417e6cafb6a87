//! Warps from the unit square to the domains the integrators sample, each with its pdf.
//! Formulas follow Shirley & Chiu, "A Low Distortion Map Between Disk and Square" (1997)
//! and the standard Malley construction for cosine-weighted directions.

use super::{INV_PI, PI, Vec2, Vec3};

/// Concentric map from [0,1)^2 to the unit disk (Shirley & Chiu 1997).
///
/// The larger coordinate of `2u − 1` (in magnitude) is the radius and the ratio of the
/// other to it, t ∈ [−1, 1], the angle φ = πt/4 within its quadrant. Written without
/// branches (which half holds the point is a coin flip per sample, a mispredicted
/// branch half the time), and with sin φ and cos φ from their Taylor series: on
/// |φ| ≤ π/4 the terms through φ⁹ and φ¹⁰ leave a truncation error below 2e-9, far
/// under an f32 ulp, so no general range reduction is needed.
#[inline]
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    let x_major = o.x.abs() > o.y.abs();
    let r = select(x_major, o.x, o.y);
    let other = select(x_major, o.y, o.x);
    // At the centre both are zero; the point is then the origin whatever t is.
    let t = if r != 0.0 { other / r } else { 0.0 };
    let (sin, cos) = sin_cos_quarter_turn(t);
    // x-major: angle φ; y-major: π/2 − φ, whose cosine and sine are sin φ and cos φ.
    r * Vec2::new(select(x_major, cos, sin), select(x_major, sin, cos))
}

/// `a` where `pick`, else `b`, by masking bits: the compiler keeps it a blend, where an
/// `if` on floats may become a branch, and this one is a coin flip per sample.
#[inline(always)]
fn select(pick: bool, a: f32, b: f32) -> f32 {
    let mask = (pick as u32).wrapping_neg();
    f32::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// (sin φ, cos φ) for φ = πt/4, t ∈ [−1, 1], by Horner's rule on the Taylor series.
#[inline(always)]
fn sin_cos_quarter_turn(t: f32) -> (f32, f32) {
    let x = (PI / 4.0) * t;
    let x2 = x * x;
    let sin = x
        * (1.0
            + x2 * (-1.0 / 6.0
                + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362_880.0)))));
    let cos = 1.0
        + x2 * (-0.5
            + x2 * (1.0 / 24.0
                + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40_320.0 + x2 * (-1.0 / 3_628_800.0)))));
    (sin, cos)
}

/// Cosine-weighted direction about +z (Malley's method); pdf = cos(theta)/pi.
#[inline]
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
    fn concentric_disk_matches_the_trigonometric_map() {
        // The map in f64 with the library's sin and cos, as Shirley & Chiu write it.
        let exact = |u: Vec2| {
            let (x, y) = (2.0 * u.x as f64 - 1.0, 2.0 * u.y as f64 - 1.0);
            if x == 0.0 && y == 0.0 {
                return (0.0, 0.0);
            }
            let q = std::f64::consts::FRAC_PI_4;
            let (r, theta) = if x.abs() > y.abs() {
                (x, q * (y / x))
            } else {
                (y, 2.0 * q - q * (x / y))
            };
            (r * theta.cos(), r * theta.sin())
        };
        let mut rng = Pcg32::new(9, 1);
        let mut worst = 0.0f64;
        let edges = [0.0, 0.5, 1.0 - f32::EPSILON, 0.25, 0.75];
        let points = edges
            .iter()
            .flat_map(|&a| edges.iter().map(move |&b| Vec2::new(a, b)))
            .chain((0..100_000).map(|_| Vec2::new(rng.uniform(), rng.uniform())));
        for u in points {
            let d = concentric_disk(u);
            let (ex, ey) = exact(u);
            worst = worst
                .max((d.x as f64 - ex).abs())
                .max((d.y as f64 - ey).abs());
            assert!(d.length_squared() <= 1.0 + 4.0 * f32::EPSILON, "{u}: {d}");
        }
        // A few f32 roundings of numbers at most 1.
        assert!(worst < 4.0 * f32::EPSILON as f64, "worst error {worst:e}");
    }

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
