//! Pixel reconstruction filters used by *filter importance sampling*: each camera sample
//! is placed at the pixel centre plus an offset drawn from the filter, and contributes to
//! its own pixel only, with weight f(offset)/pdf(offset) normalised so that E(weight) = 1.
//! Pixels stay independent (no splatting into neighbours), so a parallel render writes
//! each pixel from one thread and the result does not depend on scheduling.
//! (Ernst, Stamminger, Greiner, "Filter Importance Sampling", IEEE Symposium on
//! Interactive Ray Tracing 2006.)
//!
//! Offsets are in pixel units relative to the pixel centre; with `Box { radius: 0.5 }`
//! every sample lies uniformly inside its own pixel.

use radiant_math::Vec2;

/// A separable pixel filter. `eval` is unnormalised (the formula of each variant);
/// `integral` gives its integral over the plane.
#[derive(Clone, Debug, PartialEq)]
pub enum Filter {
    /// 1 inside `|x| <= radius.x, |y| <= radius.y`.
    Box { radius: Vec2 },
    /// `max(0, rx - |x|) * max(0, ry - |y|)`.
    Triangle { radius: Vec2 },
    /// Truncated Gaussian shifted to reach 0 at the radius, per axis
    /// `g(x) = max(0, exp(-x²/(2σ²)) - exp(-r²/(2σ²)))`, the product over both axes. Build
    /// with [`Filter::gaussian`], which tabulates the sampling distribution once.
    Gaussian {
        radius: Vec2,
        sigma: f32,
        tables: Box<[GaussianAxis; 2]>,
    },
}

/// An importance-sampled filter offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterSample {
    /// Offset from the pixel centre, in pixels.
    pub offset: Vec2,
    /// f(offset) / (pdf(offset) · ∫f), with expectation 1: exactly 1 for box and
    /// triangle; for the Gaussian, whose pdf is a tabulated approximation of f, within
    /// 1.4e-3 of 1 per axis (measured; 1.5e-5 for |offset| < 1 at the default σ 0.5).
    pub weight: f32,
}

impl Default for Filter {
    /// The Gaussian with radius 1.5 and σ = 0.5.
    fn default() -> Filter {
        Filter::gaussian(Vec2::splat(1.5), 0.5)
    }
}

impl Filter {
    /// A box filter of half-width `radius` (0.5 = exactly one pixel).
    pub fn box_filter(radius: Vec2) -> Filter {
        Filter::Box { radius }
    }

    /// A triangle (tent) filter reaching 0 at `radius`.
    pub fn triangle(radius: Vec2) -> Filter {
        Filter::Triangle { radius }
    }

    /// A Gaussian filter of standard deviation `sigma` truncated at `radius` (see the
    /// variant). Non-positive or non-finite parameters are replaced by the defaults
    /// (radius 1.5, σ 0.5) so that sampling is always defined.
    pub fn gaussian(radius: Vec2, sigma: f32) -> Filter {
        let fix = |v: f32, default: f32| if v.is_finite() && v > 0.0 { v } else { default };
        let radius = Vec2::new(fix(radius.x, 1.5), fix(radius.y, 1.5));
        let sigma = fix(sigma, 0.5);
        let tables = Box::new([
            GaussianAxis::new(radius.x, sigma),
            GaussianAxis::new(radius.y, sigma),
        ]);
        Filter::Gaussian {
            radius,
            sigma,
            tables,
        }
    }

    /// Half-width of the filter's support along each axis.
    pub fn radius(&self) -> Vec2 {
        match self {
            Filter::Box { radius }
            | Filter::Triangle { radius }
            | Filter::Gaussian { radius, .. } => *radius,
        }
    }

    /// The (unnormalised) filter value at offset `p` from the pixel centre.
    pub fn eval(&self, p: Vec2) -> f32 {
        match self {
            Filter::Box { radius } => {
                if p.x.abs() <= radius.x && p.y.abs() <= radius.y {
                    1.0
                } else {
                    0.0
                }
            }
            Filter::Triangle { radius } => {
                (radius.x - p.x.abs()).max(0.0) * (radius.y - p.y.abs()).max(0.0)
            }
            Filter::Gaussian { tables, .. } => tables[0].eval(p.x) * tables[1].eval(p.y),
        }
    }

    /// ∫ eval over the plane.
    pub fn integral(&self) -> f32 {
        match self {
            Filter::Box { radius } => 4.0 * radius.x * radius.y,
            Filter::Triangle { radius } => radius.x * radius.x * radius.y * radius.y,
            Filter::Gaussian { tables, .. } => (tables[0].integral * tables[1].integral) as f32,
        }
    }

    /// Draws an offset with density ∝ the filter (approximately, for the Gaussian) from
    /// `u` in [0,1)².
    pub fn sample(&self, u: Vec2) -> FilterSample {
        match self {
            Filter::Box { radius } => FilterSample {
                offset: Vec2::new((2.0 * u.x - 1.0) * radius.x, (2.0 * u.y - 1.0) * radius.y),
                weight: 1.0,
            },
            Filter::Triangle { radius } => FilterSample {
                offset: Vec2::new(sample_tent(u.x) * radius.x, sample_tent(u.y) * radius.y),
                weight: 1.0,
            },
            Filter::Gaussian { tables, .. } => {
                let (x, wx) = tables[0].sample(u.x);
                let (y, wy) = tables[1].sample(u.y);
                FilterSample {
                    offset: Vec2::new(x, y),
                    weight: wx * wy,
                }
            }
        }
    }
}

/// Inverse CDF of the unit tent `1 - |x|` on [-1, 1]: the CDF is `(1+x)²/2` left of 0 and
/// `1 - (1-x)²/2` right of it.
fn sample_tent(u: f32) -> f32 {
    if u < 0.5 {
        (2.0 * u).sqrt() - 1.0
    } else {
        1.0 - (2.0 - 2.0 * u).max(0.0).sqrt()
    }
}

/// Segments of the tabulated per-axis Gaussian density (a power of two; see `sample`).
const GAUSSIAN_SEGMENTS: usize = 1024;

/// One axis of the Gaussian filter, sampled by inverting a piecewise-*linear*
/// interpolant of g on a uniform grid over [-r, r]. The interpolant tracks g closely (also
/// near ±r, where g reaches 0 with non-zero slope), so the weight g(x) / interpolant(x)
/// stays within ~1.4e-3 of 1 (worst in the last grid cell, where the relative
/// interpolation error is g''·h / (2|g'|)) instead of swinging near the edges as a
/// piecewise-constant table's would.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussianAxis {
    radius: f32,
    /// 1 / (2σ²)
    inv_two_sigma2: f32,
    /// exp(-r²/(2σ²)), subtracted so that g(±r) = 0.
    offset: f32,
    /// g at the grid nodes x_i = -r + i·h, i = 0..=N.
    node_values: Vec<f32>,
    /// Cumulative trapezoid areas, `cdf[0] = 0`, unnormalised (total = cdf[N]).
    cdf: Vec<f64>,
    /// `guide[k]` = the last segment i with `cdf[i] <= k/N · total`: sampling starts there
    /// and scans forward a step or two instead of binary-searching the whole CDF.
    guide: Vec<u32>,
    /// ∫ g over [-r, r] (composite Simpson, f64).
    integral: f64,
}

impl GaussianAxis {
    fn new(radius: f32, sigma: f32) -> GaussianAxis {
        let inv_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
        let offset = (-radius * radius * inv_two_sigma2).exp();
        let mut axis = GaussianAxis {
            radius,
            inv_two_sigma2,
            offset,
            node_values: Vec::with_capacity(GAUSSIAN_SEGMENTS + 1),
            cdf: Vec::with_capacity(GAUSSIAN_SEGMENTS + 1),
            guide: Vec::with_capacity(GAUSSIAN_SEGMENTS),
            integral: 0.0,
        };
        let h = 2.0 * radius / GAUSSIAN_SEGMENTS as f32;
        for i in 0..=GAUSSIAN_SEGMENTS {
            let v = axis.eval(-radius + i as f32 * h);
            axis.node_values.push(v);
        }
        axis.node_values[0] = 0.0;
        axis.node_values[GAUSSIAN_SEGMENTS] = 0.0;
        let mut acc = 0.0f64;
        axis.cdf.push(0.0);
        for w in axis.node_values.windows(2) {
            acc += 0.5 * h as f64 * (w[0] as f64 + w[1] as f64);
            axis.cdf.push(acc);
        }
        // Simpson on 8N intervals: error ~ (h/8)^4, far below f32 precision.
        let n = 8 * GAUSSIAN_SEGMENTS;
        let hs = 2.0 * radius as f64 / n as f64;
        let g = |x: f64| ((-x * x * inv_two_sigma2 as f64).exp() - offset as f64).max(0.0);
        let mut s = g(-radius as f64) + g(radius as f64);
        for i in 1..n {
            s += g(-radius as f64 + i as f64 * hs) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        axis.integral = s * hs / 3.0;
        let total = acc;
        for k in 0..GAUSSIAN_SEGMENTS {
            let level = k as f64 / GAUSSIAN_SEGMENTS as f64 * total;
            let i = axis.cdf.partition_point(|&c| c <= level).saturating_sub(1);
            axis.guide.push(i.min(GAUSSIAN_SEGMENTS - 1) as u32);
        }
        axis
    }

    /// g(x), zero outside [-r, r].
    fn eval(&self, x: f32) -> f32 {
        if x.abs() >= self.radius {
            return 0.0;
        }
        ((-x * x * self.inv_two_sigma2).exp() - self.offset).max(0.0)
    }

    /// Returns (x, g(x) / interpolant(x)).
    fn sample(&self, u: f32) -> (f32, f32) {
        let total = self.cdf[GAUSSIAN_SEGMENTS];
        let u = u.clamp(0.0, 1.0) as f64;
        let target = u * total;
        // Last segment i with cdf[i] <= target. N is a power of two, so k/N·total <= target
        // holds exactly for k = floor(u·N) and the guide never starts past the answer.
        let k = ((u * GAUSSIAN_SEGMENTS as f64) as usize).min(GAUSSIAN_SEGMENTS - 1);
        let mut i = self.guide[k] as usize;
        while i + 1 < GAUSSIAN_SEGMENTS && self.cdf[i + 1] <= target {
            i += 1;
        }
        let area = self.cdf[i + 1] - self.cdf[i];
        let (a, b) = (self.node_values[i] as f64, self.node_values[i + 1] as f64);
        let local = if area > 0.0 {
            ((target - self.cdf[i]) / area).clamp(0.0, 1.0)
        } else {
            0.0
        };
        // Invert (a·t + (b-a)·t²/2) / ((a+b)/2) = local for t in [0,1]; this form of the
        // quadratic root has no cancellation when a ≈ b.
        let denom = a + (a * a + local * (b * b - a * a)).max(0.0).sqrt();
        let t = if denom > 0.0 {
            local * (a + b) / denom
        } else {
            local
        };
        let h = 2.0 * self.radius as f64 / GAUSSIAN_SEGMENTS as f64;
        let x = (-(self.radius as f64) + (i as f64 + t) * h) as f32;
        let interpolant = a + (b - a) * t;
        let weight = if interpolant > 0.0 {
            // Normalise by ∫g / ∫interpolant so that E[weight] = 1 exactly.
            (self.eval(x) as f64 / interpolant * total / self.integral) as f32
        } else {
            // Only at x = ±r (u = 0 or 1), where g/interpolant → 1 in the limit.
            1.0
        };
        (x, weight)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;

    // Chi-square tests of the sampled offsets, with the shared harness, are in
    // tests/filter_sampling.rs.

    #[test]
    fn box_half_pixel_stays_in_pixel() {
        let f = Filter::box_filter(Vec2::splat(0.5));
        let mut rng = Pcg32::new(3, 1);
        for _ in 0..10_000 {
            let s = f.sample(Vec2::new(rng.uniform(), rng.uniform()));
            // Pixel (0,0) spans [0,1)²; its centre is 0.5.
            let p = Vec2::splat(0.5) + s.offset;
            assert!(
                (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y),
                "{p}"
            );
            assert_eq!(s.weight, 1.0);
        }
        assert_eq!(f.sample(Vec2::ZERO).offset, Vec2::splat(-0.5));
    }

    #[test]
    fn tent_inverse_cdf_hits_known_points() {
        // CDF(-0.5) = 0.125, CDF(0) = 0.5, CDF(0.5) = 0.875.
        assert!((sample_tent(0.125) + 0.5).abs() < 1e-6);
        assert_eq!(sample_tent(0.5), 0.0);
        assert!((sample_tent(0.875) - 0.5).abs() < 1e-6);
        assert_eq!(sample_tent(0.0), -1.0);
    }

    #[test]
    fn gaussian_weights_are_nearly_constant_and_average_one() {
        let f = Filter::default();
        // pbrt-v4 parameterisation: g(0) = 1 - exp(-4.5) per axis.
        let g0 = 1.0 - (-4.5f32).exp();
        assert!((f.eval(Vec2::ZERO) - g0 * g0).abs() < 1e-6);
        assert_eq!(f.eval(Vec2::new(1.5, 0.0)), 0.0);
        // ∫g = σ√(2π)·erf(r/(σ√2)) - 2r·exp(-r²/2σ²); erf(3/√2) = 0.9973002039.
        let g1 =
            0.5 * (2.0 * std::f64::consts::PI).sqrt() * 0.997_300_203_9 - 3.0 * (-4.5f64).exp();
        assert!(
            (f.integral() as f64 - g1 * g1).abs() < 1e-5,
            "{}",
            f.integral()
        );
        let n = 100_000;
        let mut rng = Pcg32::new(11, 2);
        let (mut sum, mut lo, mut hi) = (0.0f64, f32::MAX, 0.0f32);
        for _ in 0..n {
            let w = f.sample(Vec2::new(rng.uniform(), rng.uniform())).weight;
            sum += w as f64;
            lo = lo.min(w);
            hi = hi.max(w);
        }
        // Per axis the weight g/interpolant is within g''·h/(2|g'|) = 0.355·(3/1024)/0.133
        // = 7.8e-3 of 1 in the worst (last) cell and ~1e-5 in the bulk; a scan of u
        // measured [0.99865, 1.000004]. Allow 3e-3 below 1 for the product of two axes.
        assert!(lo > 0.997 && hi < 1.0001, "weights in [{lo}, {hi}]");
        // Spread < 3e-3 → the mean of 1e5 weights is within ~1e-5 of its expectation 1.
        assert!((sum / n as f64 - 1.0).abs() < 1e-4, "{}", sum / n as f64);
        // The extreme u values are finite and in the support.
        for u in [0.0, radiant_math::ONE_MINUS_EPSILON] {
            let s = f.sample(Vec2::splat(u));
            assert!(
                s.weight.is_finite() && s.offset.abs().max_element() <= 1.5,
                "{s:?}"
            );
        }
    }

    #[test]
    fn guide_table_finds_the_same_segment_as_binary_search() {
        let Filter::Gaussian { tables, .. } = Filter::default() else {
            unreachable!()
        };
        let axis = &tables[0];
        let total = axis.cdf[GAUSSIAN_SEGMENTS];
        let mut rng = Pcg32::new(5, 5);
        for j in 0..20_000 {
            let u = if j < 2 {
                j as f32 * radiant_math::ONE_MINUS_EPSILON
            } else {
                rng.uniform()
            };
            let target = u as f64 * total;
            let i = axis
                .cdf
                .partition_point(|&c| c <= target)
                .saturating_sub(1)
                .min(GAUSSIAN_SEGMENTS - 1);
            let h = 2.0 * axis.radius as f64 / GAUSSIAN_SEGMENTS as f64;
            let x = axis.sample(u).0 as f64 + axis.radius as f64;
            // The sample lies in segment i (up to f32 rounding of x).
            assert!(
                x >= i as f64 * h - 1e-6 && x <= (i + 1) as f64 * h + 1e-6,
                "u={u}"
            );
        }
    }

    #[test]
    fn bad_parameters_fall_back_to_defaults() {
        let f = Filter::gaussian(Vec2::new(-1.0, f32::NAN), 0.0);
        assert_eq!(f, Filter::default());
    }
}
