//! Adaptive sampling: a render's budget of samples spread over its pixels by their
//! estimated error rather than evenly.
//!
//! A uniform pilot ([`pilot_samples`]) estimates each pixel's relative variance per
//! sample, r = Var[L] / (E[L]² + ε), from the film's second moments, and its cost c,
//! the rays per sample. Minimising the expected relative MSE Σ r_i / n_i at a fixed
//! cost Σ n_i c_i gives n_i ∝ √(r_i / c_i) (a Lagrange multiplier; with equal costs, the
//! allocation behind greedy error minimisation, Rousselle,
//! Knaus & Zwicker, "Adaptive Sampling and Reconstruction using Greedy Error
//! Minimization", SIGGRAPH Asia 2011; survey: Zwicker et al., "Recent Advances in
//! Adaptive Sampling and Reconstruction for Monte Carlo Rendering", EG STAR 2015).
//!
//! A pilot's per-pixel variance is itself noisy, and heavy-tailed where rare bright
//! paths live, so it is averaged over a 5 × 5 window before use. The window also keeps
//! each pixel's count from depending much on its own samples: a count chosen from a
//! pixel's own values biases its mean (a pixel that drew a low value would look quiet
//! and stop early), which the window dilutes 25 times. The pilot's samples count toward
//! the image, so no pixel gets fewer than the pilot; none gets more than
//! [`MAX_RATIO`] times the budget's mean.

use radiant_image::Film;

/// The ε of r = Var / (E² + ε): that of the relative MSE the renders are scored by
/// (`radiant compare`, Rousselle et al. 2011), in the sensor's units. It keeps black
/// pixels from asking for unbounded work.
pub const RELATIVE_EPSILON: f64 = radiant_image::metrics::RELMSE_EPSILON;

/// No pixel takes more than this many times the mean samples per pixel.
pub const MAX_RATIO: f64 = 8.0;

/// Half the side of the window the pilot's variance is averaged over (5 × 5).
const SMOOTHING_RADIUS: i64 = 2;

/// Samples per pixel of the uniform pilot of an adaptive render of `spp` samples per
/// pixel on average: a quarter of the budget, down to a power of two (so the pilot
/// ends on a pass of the uniform schedule), and at least 16 samples, which a variance
/// estimate needs. Budgets under 32 get no adaptive phase (the pilot is all of it).
///
/// Measured on cornell-box (docs/speed.md): a pilot of 32 or 64 of 256 samples gives
/// the same error; the quarter leaves three quarters of the budget to allocate.
pub fn pilot_samples(spp: u32) -> u32 {
    if spp < 32 {
        return spp;
    }
    let quarter = spp / 4;
    (1u32 << (31 - quarter.leading_zeros())).max(16)
}

/// Each pixel's relative variance per sample, r = mean over channels of
/// Var / (E² + ε), as the sensor records the values; `None` when the film keeps no
/// moments.
pub fn relative_variance(film: &Film) -> Option<Vec<f64>> {
    let variance = film.variance()?;
    let image = film.image();
    Some(
        image
            .pixels
            .iter()
            .enumerate()
            .map(|(i, mean)| {
                let mean = mean.to_array();
                (0..3)
                    .map(|c| {
                        let m = mean[c] as f64;
                        variance[c][i] as f64 / (m * m + RELATIVE_EPSILON)
                    })
                    .sum::<f64>()
                    / 3.0
            })
            .collect(),
    )
}

/// `values` (a `width`-wide image) averaged over the (2 r + 1)² window around each
/// pixel, the window cut at the image's edges; by running sums, so any window costs
/// the same.
fn box_smooth(values: &[f64], width: usize, radius: i64) -> Vec<f64> {
    let height = values.len() / width.max(1);
    let horizontal = |row: &[f64], out: &mut [f64]| {
        for (x, o) in out.iter_mut().enumerate() {
            let lo = (x as i64 - radius).max(0) as usize;
            let hi = ((x as i64 + radius) as usize).min(width - 1);
            *o = row[lo..=hi].iter().sum::<f64>() / (hi - lo + 1) as f64;
        }
    };
    let mut rows = vec![0.0; values.len()];
    for (row, out) in values.chunks(width).zip(rows.chunks_mut(width)) {
        horizontal(row, out);
    }
    let mut out = vec![0.0; values.len()];
    for y in 0..height {
        let lo = (y as i64 - radius).max(0) as usize;
        let hi = ((y as i64 + radius) as usize).min(height - 1);
        let n = (hi - lo + 1) as f64;
        for x in 0..width {
            out[y * width + x] = (lo..=hi).map(|yy| rows[yy * width + x]).sum::<f64>() / n;
        }
    }
    out
}

/// Samples per pixel to reach, for a film that holds the pilot, whose samples traced
/// `pilot_rays` rays in each pixel (empty: cost taken as equal everywhere).
///
/// With c the rays per sample, minimising Σ r / n at a fixed cost Σ n c gives
/// n ∝ √(r / c): pixels whose samples are expensive (long glossy or refracted chains)
/// get fewer than their variance alone would ask for. The counts are clamped to at
/// least `pilot` and at most [`MAX_RATIO`] × `spp`, and spend about the rays of `spp`
/// samples in every pixel (rounding down loses less than a sample per pixel), so an
/// adaptive render takes about the time of a uniform one. Uniform (`spp` everywhere)
/// when the film keeps no moments or the pilot saw no variance. A pure function of the
/// film and counts: the same pilot gives the same targets on any number of threads.
pub fn sample_targets(film: &Film, pilot_rays: &[u32], spp: u32, pilot: u32) -> Vec<u32> {
    let n = film.pixels.len();
    let Some(r) = relative_variance(film) else {
        return vec![spp; n];
    };
    // Rays per sample, at least one (the camera ray), smoothed like the variance.
    let cost: Vec<f64> = if pilot_rays.len() == n {
        let per_sample: Vec<f64> = pilot_rays
            .iter()
            .zip(&film.pixels)
            .map(|(&rays, p)| rays as f64 / p.samples.max(1) as f64)
            .collect();
        box_smooth(&per_sample, film.width, SMOOTHING_RADIUS)
            .into_iter()
            .map(|c| c.max(1.0))
            .collect()
    } else {
        vec![1.0; n]
    };
    let smoothed = box_smooth(&r, film.width, SMOOTHING_RADIUS);
    let weights: Vec<f64> = smoothed
        .iter()
        .zip(&cost)
        .map(|(&v, &c)| {
            if v.is_finite() {
                (v.max(0.0) / c).sqrt()
            } else {
                0.0
            }
        })
        .collect();
    let (lo, hi) = (pilot as f64, (spp as f64 * MAX_RATIO).max(pilot as f64));
    let budget = spp as f64 * cost.iter().sum::<f64>();
    let spent = |scale: f64| -> f64 {
        weights
            .iter()
            .zip(&cost)
            .map(|(w, c)| (scale * w).clamp(lo, hi) * c)
            .sum()
    };
    let w_max = weights.iter().copied().fold(0.0, f64::max);
    if w_max <= 0.0 {
        // No variance seen: nothing to gain from shifting samples.
        return vec![spp; n];
    }
    // The scale at which the clamped counts spend the budget, by bisection: `spent` is
    // continuous and non-decreasing in it. Its upper end is found by doubling from the
    // scale that brings the largest weight to the cap (a few very noisy pixels make
    // that one small); where even every pixel with a weight at the cap spends less
    // (an image mostly black), they all get the cap.
    let mut above = hi / w_max;
    while spent(above) < budget {
        if above > 1e300 || spent(above * 2.0) == spent(above) {
            return weights
                .iter()
                .map(|&w| if w > 0.0 { hi } else { lo }.floor() as u32)
                .collect();
        }
        above *= 2.0;
    }
    let mut below = 0.0f64;
    for _ in 0..64 {
        let mid = 0.5 * (below + above);
        if spent(mid) > budget {
            above = mid;
        } else {
            below = mid;
        }
    }
    weights
        .iter()
        .map(|w| (below * w).clamp(lo, hi).floor() as u32)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_image::Sensor;
    use radiant_math::color::Rgb;

    /// A film whose pixels have mean `mean(i)` and per-sample variance `var(i)` over
    /// `samples` unit-weight samples.
    fn film(
        width: usize,
        height: usize,
        mean: impl Fn(usize) -> f32,
        var: impl Fn(usize) -> f32,
    ) -> Film {
        let samples = 16u32;
        let mut film = Film::new(width, height, Sensor::UNIT).with_moments();
        let moments = film.moments.as_mut().unwrap();
        for (i, (p, m)) in film.pixels.iter_mut().zip(moments.iter_mut()).enumerate() {
            let (mu, v) = (mean(i) as f64, var(i) as f64);
            for _ in 0..samples {
                p.add(Rgb::splat(mean(i)), 1.0);
            }
            *m = [(v + mu * mu) * samples as f64; 3];
        }
        film
    }

    #[test]
    fn the_pilot_is_a_power_of_two_quarter_of_at_least_16() {
        assert_eq!(pilot_samples(8), 8);
        assert_eq!(pilot_samples(31), 31);
        assert_eq!(pilot_samples(32), 16);
        assert_eq!(pilot_samples(100), 16);
        assert_eq!(pilot_samples(256), 64);
        assert_eq!(pilot_samples(1000), 128);
        assert_eq!(pilot_samples(1024), 256);
    }

    #[test]
    fn smoothing_keeps_constants_and_averages_windows() {
        let flat = vec![3.0; 7 * 5];
        assert!(
            box_smooth(&flat, 7, 2)
                .iter()
                .all(|&v| (v - 3.0).abs() < 1e-12)
        );
        // One spike in a 5x5 image: the centre's 5x5 window holds all 25 pixels.
        let mut spike = vec![0.0; 25];
        spike[12] = 25.0;
        let s = box_smooth(&spike, 5, 2);
        assert!((s[12] - 1.0).abs() < 1e-12);
        // The corner's window is cut to 3x3 and holds the spike.
        assert!((s[0] - 25.0 / 9.0).abs() < 1e-12);
    }

    #[test]
    fn counts_spend_the_budget_within_bounds_and_follow_the_square_root() {
        let (w, h) = (40, 30);
        // Left half four times the relative variance of the right half.
        let f = film(w, h, |_| 0.5, |i| if i % w < w / 2 { 0.4 } else { 0.1 });
        let (spp, pilot) = (256, 64);
        let t = sample_targets(&f, &[], spp, pilot);
        let sum: u64 = t.iter().map(|&n| n as u64).sum();
        let budget = spp as u64 * (w * h) as u64;
        assert!(
            sum <= budget && sum + (w * h) as u64 >= budget,
            "{sum} vs {budget}"
        );
        assert!(
            t.iter()
                .all(|&n| n >= pilot && n as f64 <= MAX_RATIO * spp as f64)
        );
        // Away from the seam (the window blends it), counts go as sqrt(4) = 2.
        let (left, right) = (t[15 * w + 5], t[15 * w + w - 5]);
        assert!(
            (left as f64 / right as f64 - 2.0).abs() < 0.02,
            "{left} {right}"
        );
    }

    #[test]
    fn expensive_pixels_get_fewer_samples_and_the_rays_are_the_budget() {
        let (w, h) = (40, 30);
        let f = film(w, h, |_| 0.5, |_| 0.2);
        // Samples of the right half trace four times the rays: counts go as 1/sqrt(4).
        let rays: Vec<u32> = (0..w * h)
            .map(|i| if i % w < w / 2 { 16 * 3 } else { 16 * 12 })
            .collect();
        let t = sample_targets(&f, &rays, 128, 32);
        let (left, right) = (t[15 * w + 5], t[15 * w + w - 5]);
        assert!(
            (left as f64 / right as f64 - 2.0).abs() < 0.02,
            "{left} {right}"
        );
        let cost = |i: usize| if i % w < w / 2 { 3.0 } else { 12.0 };
        let spent: f64 = t.iter().enumerate().map(|(i, &n)| n as f64 * cost(i)).sum();
        let budget: f64 = (0..w * h).map(|i| 128.0 * cost(i)).sum();
        assert!(
            spent <= budget && spent > 0.99 * budget,
            "{spent} vs {budget}"
        );
    }

    #[test]
    fn the_pilot_floor_and_the_cap_hold_for_extreme_contrast() {
        let (w, h) = (32, 32);
        // One bright, noisy corner block; the rest nearly noiseless.
        let f = film(
            w,
            h,
            |_| 1.0,
            |i| if i % w < 8 && i / w < 8 { 1e4 } else { 1e-6 },
        );
        let t = sample_targets(&f, &[], 64, 16);
        assert!(t.iter().all(|&n| (16..=512).contains(&n)));
        assert_eq!(t[0], 512);
        assert_eq!(t[w * h - 1], 16);
    }

    #[test]
    fn uniform_without_moments_or_variance() {
        let plain = Film::new(4, 4, Sensor::UNIT);
        assert_eq!(sample_targets(&plain, &[], 100, 16), vec![100; 16]);
        let quiet = film(4, 4, |_| 0.3, |_| 0.0);
        assert_eq!(sample_targets(&quiet, &[], 100, 16), vec![100; 16]);
    }

    #[test]
    fn equal_variance_gives_the_budget_everywhere() {
        let f = film(9, 7, |_| 0.2, |_| 0.05);
        let t = sample_targets(&f, &[], 128, 32);
        // Rounding down from exactly the budget may lose one sample per pixel.
        assert!(t.iter().all(|&n| n == 128 || n == 127), "{t:?}");
    }
}
