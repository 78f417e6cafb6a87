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
    concentric_disk_and_radius(u).0
}

/// [`concentric_disk`] and the point's signed radius (its distance from the centre, up
/// to sign), which is known before the angle.
#[inline(always)]
fn concentric_disk_and_radius(u: Vec2) -> (Vec2, f32) {
    let o = 2.0 * u - Vec2::ONE;
    let x_major = o.x.abs() > o.y.abs();
    let r = select(x_major, o.x, o.y);
    let other = select(x_major, o.y, o.x);
    // At the centre both are zero; the point is then the origin whatever t is.
    let t = if r != 0.0 { other / r } else { 0.0 };
    let (sin, cos) = sin_cos_quarter_turn(t);
    // x-major: angle φ; y-major: π/2 − φ, whose cosine and sine are sin φ and cos φ.
    let d = r * Vec2::new(select(x_major, cos, sin), select(x_major, sin, cos));
    (d, r)
}

/// `a` where `pick`, else `b`, by masking bits: the compiler keeps it a blend, where an
/// `if` on floats may become a branch, and this one is a coin flip per sample.
#[inline(always)]
fn select(pick: bool, a: f32, b: f32) -> f32 {
    let mask = (pick as u32).wrapping_neg();
    f32::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// (sin φ, cos φ) for φ = πt/4, t ∈ [−1, 1], from the Taylor series in powers of
/// x² grouped by Estrin's scheme (x², x⁴, x⁸ and pairs of terms side by side): four
/// dependent products and sums instead of Horner's ten, as a path's next ray waits on
/// this direction.
#[inline(always)]
fn sin_cos_quarter_turn(t: f32) -> (f32, f32) {
    let x = (PI / 4.0) * t;
    let x2 = x * x;
    let x4 = x2 * x2;
    let x8 = x4 * x4;
    let sin = x
        * ((1.0 - x2 * (1.0 / 6.0))
            + x4 * (1.0 / 120.0 - x2 * (1.0 / 5040.0))
            + x8 * (1.0 / 362_880.0));
    let cos = (1.0 - x2 * 0.5)
        + x4 * (1.0 / 24.0 - x2 * (1.0 / 720.0))
        + x8 * (1.0 / 40_320.0 - x2 * (1.0 / 3_628_800.0));
    (sin, cos)
}

/// Cosine-weighted direction about +z (Malley's method); pdf = cos(theta)/pi.
#[inline]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let (d, r) = concentric_disk_and_radius(u);
    // The height from the radius rather than from the point: the square root then runs
    // beside the angle's division and series instead of after them.
    let z = (1.0 - r * r).max(0.0).sqrt();
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

/// Systematic sampling of `n` items from a stream of nonnegative weights whose total
/// is known beforehand, from one number u ∈ [0, 1): the points (u + j) · total / n,
/// j < n, are laid along the cumulative weights, and an item is taken as many times as
/// points fall in its interval. Item i is then taken n w_i / total times in
/// expectation over u, so that weighing its term by `reweight` (total / (n w_i) per
/// point) keeps a sum estimated from the taken items unbiased (Cochran, *Sampling
/// Techniques*, 1977, §8). Items are offered in a fixed order and nothing is stored.
#[derive(Clone, Copy, Debug)]
pub struct SystematicDraw {
    n: u32,
    u: f32,
    /// total / n, the spacing of the points, and its inverse.
    step: f32,
    inv_step: f32,
    cumulative: f32,
    /// Points below `cumulative`.
    taken: u32,
}

impl SystematicDraw {
    /// `n` points (at least 1) over weights summing to `total` (positive and finite).
    pub fn new(total: f32, n: usize, u: f32) -> SystematicDraw {
        let n = n.max(1) as u32;
        let step = total / n as f32;
        SystematicDraw {
            n,
            u: u.clamp(0.0, 1.0),
            step,
            inv_step: 1.0 / step,
            cumulative: 0.0,
            taken: 0,
        }
    }

    /// Offers the next item, of weight `w`: the factor its term is weighed by, the
    /// number of points that fell in its interval times total / (n w), or 0 where none
    /// did. The points below c number ⌈c / step − u⌉, computed afresh for each item
    /// rather than stepped, so that rounding neither loses nor adds one at the end.
    #[inline]
    pub fn reweight(&mut self, w: f32) -> f32 {
        if w <= 0.0 {
            return 0.0;
        }
        self.cumulative += w;
        let below = ((self.cumulative * self.inv_step - self.u).ceil().max(0.0) as u32).min(self.n);
        let points = below - self.taken;
        self.taken = below;
        if points == 0 {
            0.0
        } else {
            points as f32 * self.step / w
        }
    }
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

    /// The height comes from the disk's radius, not from the point: the direction is
    /// still of unit length to a few roundings.
    #[test]
    fn cosine_hemisphere_directions_are_unit_to_a_few_roundings() {
        let mut rng = Pcg32::new(4, 1);
        let edges = [0.0, 0.5, 1.0 - f32::EPSILON, 0.25, 0.75, 0.5 + f32::EPSILON];
        let points = edges
            .iter()
            .flat_map(|&a| edges.iter().map(move |&b| Vec2::new(a, b)))
            .chain((0..100_000).map(|_| Vec2::new(rng.uniform(), rng.uniform())));
        for u in points {
            let c = cosine_hemisphere(u).as_dvec3();
            let error = (c.length() - 1.0).abs();
            assert!(
                c.z >= 0.0 && error < 4.0 * f32::EPSILON as f64,
                "{u}: {c}, {error:e}"
            );
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
    /// Over u, each item is taken n w_i / total times on average, so that a reweighted
    /// sum of any values is the full sum in expectation; and each draw takes n points.
    #[test]
    fn systematic_draws_are_unbiased_and_take_n_points() {
        let weights = [0.5f32, 0.0, 3.0, 0.01, 1.2, 7.0, 0.3, 0.3, 2.2];
        let values = [1.0f32, 5.0, -2.0, 40.0, 0.7, 0.1, 3.0, 9.0, 1.5];
        let total: f32 = weights.iter().sum();
        let full: f32 = weights.iter().zip(values).map(|(w, v)| w * v).sum();
        for n in [1usize, 3, 4, 20] {
            let draws = 400_000;
            let mut mean = 0.0f64;
            for k in 0..draws {
                let u = (k as f32 + 0.5) / draws as f32;
                let mut draw = SystematicDraw::new(total, n, u);
                let mut points = 0.0f32;
                let mut sum = 0.0f32;
                for (w, v) in weights.iter().zip(values) {
                    let r = draw.reweight(*w);
                    points += r * w / (total / n as f32);
                    sum += r * w * v;
                }
                assert!((points - n as f32).abs() < 1e-3, "n {n}: {points} points");
                mean += sum as f64 / draws as f64;
            }
            assert!(
                (mean / full as f64 - 1.0).abs() < 1e-3,
                "n {n}: {mean} against {full}"
            );
        }
    }
}
