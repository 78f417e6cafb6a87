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
        tables: Box<[TabulatedAxis; 2]>,
    },
    /// Mitchell & Netravali's cubic ("Reconstruction Filters in Computer Graphics",
    /// SIGGRAPH 1988) with parameters `b` and `c`, its support [-2, 2] stretched over the
    /// radius as pbrt-v4 does, the product over both axes. Negative lobes: see
    /// [`FilterSample::weight`].
    Mitchell {
        radius: Vec2,
        b: f32,
        c: f32,
        tables: Box<[TabulatedAxis; 2]>,
    },
    /// Lanczos' windowed sinc, sinc(x) · sinc(x / τ) truncated at the radius (Turkowski,
    /// "Filters for Common Resampling Tasks", Graphics Gems 1990), per axis; pbrt-v4's
    /// `"sinc"`.
    LanczosSinc {
        radius: Vec2,
        tau: f32,
        tables: Box<[TabulatedAxis; 2]>,
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
    /// Filters with negative lobes (Mitchell, Lanczos) are sampled by |f|, so an offset in
    /// a negative lobe has a negative weight, about −∫|f| / ∫f (the renderer then scales
    /// the sample's radiance by it rather than weighing the sample in the film: see
    /// `has_negative_lobes`).
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
            TabulatedAxis::new(radius.x, Profile::gaussian(radius.x, sigma)),
            TabulatedAxis::new(radius.y, Profile::gaussian(radius.y, sigma)),
        ]);
        Filter::Gaussian {
            radius,
            sigma,
            tables,
        }
    }

    /// Mitchell & Netravali's filter (see the variant); pbrt-v4's defaults are radius 2
    /// and b = c = 1/3. Non-positive or non-finite radii, and non-finite b or c, are
    /// replaced by those defaults.
    pub fn mitchell(radius: Vec2, b: f32, c: f32) -> Filter {
        let fix = |v: f32| if v.is_finite() && v > 0.0 { v } else { 2.0 };
        let radius = Vec2::new(fix(radius.x), fix(radius.y));
        let third = |v: f32| if v.is_finite() { v } else { 1.0 / 3.0 };
        let (b, c) = (third(b), third(c));
        let tables = Box::new([
            TabulatedAxis::new(
                radius.x,
                Profile::Mitchell {
                    b,
                    c,
                    scale: 2.0 / radius.x,
                },
            ),
            TabulatedAxis::new(
                radius.y,
                Profile::Mitchell {
                    b,
                    c,
                    scale: 2.0 / radius.y,
                },
            ),
        ]);
        Filter::Mitchell {
            radius,
            b,
            c,
            tables,
        }
    }

    /// Lanczos' windowed sinc (see the variant); pbrt-v4's defaults are radius 4 and
    /// τ = 3, which replace non-positive or non-finite values.
    pub fn lanczos_sinc(radius: Vec2, tau: f32) -> Filter {
        let fix = |v: f32, default: f32| if v.is_finite() && v > 0.0 { v } else { default };
        let radius = Vec2::new(fix(radius.x, 4.0), fix(radius.y, 4.0));
        let tau = fix(tau, 3.0);
        let tables = Box::new([
            TabulatedAxis::new(radius.x, Profile::LanczosSinc { tau }),
            TabulatedAxis::new(radius.y, Profile::LanczosSinc { tau }),
        ]);
        Filter::LanczosSinc {
            radius,
            tau,
            tables,
        }
    }

    /// The per-axis tables of the tabulated filters.
    fn tables(&self) -> Option<&[TabulatedAxis; 2]> {
        match self {
            Filter::Box { .. } | Filter::Triangle { .. } => None,
            Filter::Gaussian { tables, .. }
            | Filter::Mitchell { tables, .. }
            | Filter::LanczosSinc { tables, .. } => Some(tables),
        }
    }

    /// Whether the filter has negative lobes, so that sample weights may be negative.
    pub fn has_negative_lobes(&self) -> bool {
        matches!(self, Filter::Mitchell { .. } | Filter::LanczosSinc { .. })
    }

    /// ∫ |eval| over the plane: the normalisation of the density offsets are drawn with.
    pub fn abs_integral(&self) -> f32 {
        match self.tables() {
            Some([x, y]) => (x.abs_integral * y.abs_integral) as f32,
            None => self.integral(),
        }
    }

    /// Half-width of the filter's support along each axis.
    pub fn radius(&self) -> Vec2 {
        match self {
            Filter::Box { radius }
            | Filter::Triangle { radius }
            | Filter::Gaussian { radius, .. }
            | Filter::Mitchell { radius, .. }
            | Filter::LanczosSinc { radius, .. } => *radius,
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
            Filter::Gaussian { tables, .. }
            | Filter::Mitchell { tables, .. }
            | Filter::LanczosSinc { tables, .. } => tables[0].eval(p.x) * tables[1].eval(p.y),
        }
    }

    /// ∫ eval over the plane.
    pub fn integral(&self) -> f32 {
        match self {
            Filter::Box { radius } => 4.0 * radius.x * radius.y,
            Filter::Triangle { radius } => radius.x * radius.x * radius.y * radius.y,
            Filter::Gaussian { tables, .. }
            | Filter::Mitchell { tables, .. }
            | Filter::LanczosSinc { tables, .. } => {
                (tables[0].integral * tables[1].integral) as f32
            }
        }
    }

    /// Draws an offset with density ∝ |filter| (approximately, for the tabulated ones)
    /// from `u` in [0,1)².
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
            Filter::Gaussian { tables, .. }
            | Filter::Mitchell { tables, .. }
            | Filter::LanczosSinc { tables, .. } => {
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

/// Segments of each tabulated per-axis density (a power of two; see `sample`).
const TABLE_SEGMENTS: usize = 1024;

/// The one-dimensional profile of a separable tabulated filter.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Profile {
    /// exp(−x²/(2σ²)) − exp(−r²/(2σ²)), at least 0.
    Gaussian { inv_two_sigma2: f32, offset: f32 },
    /// The Mitchell–Netravali cubic at `scale · x`.
    Mitchell { b: f32, c: f32, scale: f32 },
    /// sinc(x) · sinc(x / τ).
    LanczosSinc { tau: f32 },
}

impl Profile {
    fn gaussian(radius: f32, sigma: f32) -> Profile {
        let inv_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
        Profile::Gaussian {
            inv_two_sigma2,
            offset: (-radius * radius * inv_two_sigma2).exp(),
        }
    }

    /// The profile at `x`, ignoring the support.
    fn at(&self, x: f32) -> f32 {
        match *self {
            Profile::Gaussian {
                inv_two_sigma2,
                offset,
            } => ((-x * x * inv_two_sigma2).exp() - offset).max(0.0),
            Profile::Mitchell { b, c, scale } => {
                // Mitchell & Netravali's piecewise cubic on |x| ≤ 1 and 1 < |x| ≤ 2.
                let x = (scale * x).abs();
                if x <= 1.0 {
                    ((12.0 - 9.0 * b - 6.0 * c) * x * x * x
                        + (-18.0 + 12.0 * b + 6.0 * c) * x * x
                        + (6.0 - 2.0 * b))
                        / 6.0
                } else if x <= 2.0 {
                    ((-b - 6.0 * c) * x * x * x
                        + (6.0 * b + 30.0 * c) * x * x
                        + (-12.0 * b - 48.0 * c) * x
                        + (8.0 * b + 24.0 * c))
                        / 6.0
                } else {
                    0.0
                }
            }
            Profile::LanczosSinc { tau } => sinc(x) * sinc(x / tau),
        }
    }
}

/// sin(πx) / (πx), 1 at 0.
fn sinc(x: f32) -> f32 {
    let px = std::f32::consts::PI * x;
    if px.abs() < 1e-5 { 1.0 } else { px.sin() / px }
}

/// One axis of a tabulated filter, sampled by inverting a piecewise-*linear*
/// interpolant of |f| on a uniform grid over [-r, r]. The interpolant tracks |f| closely
/// (also near ±r, where the Gaussian reaches 0 with non-zero slope), so the weight
/// f(x) / interpolant(x) stays within ~1.4e-3 of ±1 for the Gaussian (worst in the last
/// grid cell, where the relative interpolation error is f''·h / (2|f'|)) instead of
/// swinging near the edges as a piecewise-constant table's would.
#[derive(Clone, Debug, PartialEq)]
pub struct TabulatedAxis {
    radius: f32,
    profile: Profile,
    /// |f| at the grid nodes x_i = -r + i·h, i = 0..=N.
    node_values: Vec<f32>,
    /// Cumulative trapezoid areas, `cdf[0] = 0`, unnormalised (total = cdf[N]).
    cdf: Vec<f64>,
    /// `guide[k]` = the last segment i with `cdf[i] <= k/N · total`: sampling starts there
    /// and scans forward a step or two instead of binary-searching the whole CDF.
    guide: Vec<u32>,
    /// ∫ f over [-r, r] (composite Simpson, f64).
    integral: f64,
    /// ∫ |f| over [-r, r], the same way.
    abs_integral: f64,
}

impl TabulatedAxis {
    fn new(radius: f32, profile: Profile) -> TabulatedAxis {
        let mut axis = TabulatedAxis {
            radius,
            profile,
            node_values: Vec::with_capacity(TABLE_SEGMENTS + 1),
            cdf: Vec::with_capacity(TABLE_SEGMENTS + 1),
            guide: Vec::with_capacity(TABLE_SEGMENTS),
            integral: 0.0,
            abs_integral: 0.0,
        };
        let h = 2.0 * radius / TABLE_SEGMENTS as f32;
        for i in 0..=TABLE_SEGMENTS {
            let v = axis.eval(-radius + i as f32 * h).abs();
            axis.node_values.push(v);
        }
        // The end nodes take the profile's value at the rim from inside: 0 for the
        // Gaussian, not for a sinc truncated between its zeros, whose weights would
        // otherwise grow without bound towards the rim.
        let rim = profile.at(radius).abs();
        axis.node_values[0] = rim;
        axis.node_values[TABLE_SEGMENTS] = rim;
        let mut acc = 0.0f64;
        axis.cdf.push(0.0);
        for w in axis.node_values.windows(2) {
            acc += 0.5 * h as f64 * (w[0] as f64 + w[1] as f64);
            axis.cdf.push(acc);
        }
        // Simpson on 8N intervals: error ~ (h/8)^4, far below f32 precision where f is
        // smooth (|f| has kinks at a sign change, where the rule is first-order there).
        let n = 8 * TABLE_SEGMENTS;
        let hs = 2.0 * radius as f64 / n as f64;
        let f = |x: f64| profile.at(x as f32) as f64;
        let (mut s, mut s_abs) = (0.0, 0.0);
        for i in 0..=n {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let v = f(-radius as f64 + i as f64 * hs);
            s += w * v;
            s_abs += w * v.abs();
        }
        axis.integral = s * hs / 3.0;
        axis.abs_integral = s_abs * hs / 3.0;
        let total = acc;
        for k in 0..TABLE_SEGMENTS {
            let level = k as f64 / TABLE_SEGMENTS as f64 * total;
            let i = axis.cdf.partition_point(|&c| c <= level).saturating_sub(1);
            axis.guide.push(i.min(TABLE_SEGMENTS - 1) as u32);
        }
        axis
    }

    /// f(x), zero outside [-r, r].
    fn eval(&self, x: f32) -> f32 {
        if x.abs() >= self.radius {
            return 0.0;
        }
        self.profile.at(x)
    }

    /// Returns (x, f(x) / interpolant(x), normalised so that its expectation is 1).
    fn sample(&self, u: f32) -> (f32, f32) {
        let total = self.cdf[TABLE_SEGMENTS];
        let u = u.clamp(0.0, 1.0) as f64;
        let target = u * total;
        // Last segment i with cdf[i] <= target. N is a power of two, so k/N·total <= target
        // holds exactly for k = floor(u·N) and the guide never starts past the answer.
        let k = ((u * TABLE_SEGMENTS as f64) as usize).min(TABLE_SEGMENTS - 1);
        let mut i = self.guide[k] as usize;
        while i + 1 < TABLE_SEGMENTS && self.cdf[i + 1] <= target {
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
        let h = 2.0 * self.radius as f64 / TABLE_SEGMENTS as f64;
        let x = (-(self.radius as f64) + (i as f64 + t) * h) as f32;
        let interpolant = a + (b - a) * t;
        let weight = if interpolant > 0.0 {
            // Normalise by ∫f / ∫interpolant so that E[weight] = 1 exactly.
            (self.eval(x) as f64 / interpolant * total / self.integral) as f32
        } else {
            // Only where |f| vanishes on a whole cell's ends (the Gaussian's rim, u = 0
            // or 1), where f / interpolant → 1 in the limit.
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

    /// A drawn offset x inverts the interpolant's distribution: the trapezoids' area
    /// left of x is u of the whole, to the f32 rounding of x, at every tabulated
    /// filter's axis, in cells where the profile rises, falls or is negative.
    #[test]
    fn a_drawn_offset_inverts_the_interpolants_distribution() {
        let filters = [
            Filter::gaussian(Vec2::new(1.5, 2.0), 0.5),
            Filter::mitchell(Vec2::splat(2.0), 1.0 / 3.0, 1.0 / 3.0),
            Filter::lanczos_sinc(Vec2::new(4.0, 3.0), 3.0),
        ];
        let mut rng = Pcg32::new(17, 4);
        for f in &filters {
            for axis in f.tables().unwrap() {
                let total = axis.cdf[TABLE_SEGMENTS];
                let r = axis.radius as f64;
                let h = 2.0 * r / TABLE_SEGMENTS as f64;
                let peak = axis.node_values.iter().fold(0.0f32, |m, &v| m.max(v)) as f64;
                for _ in 0..20_000 {
                    let u = rng.uniform();
                    let x = axis.sample(u).0 as f64;
                    let cell = ((x + r) / h)
                        .floor()
                        .clamp(0.0, (TABLE_SEGMENTS - 1) as f64);
                    let i = cell as usize;
                    let t = (x + r) / h - cell;
                    let (a, b) = (axis.node_values[i] as f64, axis.node_values[i + 1] as f64);
                    let left = axis.cdf[i] + h * (a * t + 0.5 * (b - a) * t * t);
                    // x is an f32: its rounding moves the area by up to peak · ulp(r).
                    let tolerance = 1e-9 + peak * r * f32::EPSILON as f64 / total;
                    assert!(
                        (left / total - u as f64).abs() <= tolerance,
                        "{f:?}: u {u}, x {x}: area left of x {}",
                        left / total
                    );
                }
            }
        }
    }

    #[test]
    fn guide_table_finds_the_same_segment_as_binary_search() {
        let Filter::Gaussian { tables, .. } = Filter::default() else {
            unreachable!()
        };
        let axis = &tables[0];
        let total = axis.cdf[TABLE_SEGMENTS];
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
                .min(TABLE_SEGMENTS - 1);
            let h = 2.0 * axis.radius as f64 / TABLE_SEGMENTS as f64;
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
