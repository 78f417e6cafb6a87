//! Turning pbrt's spectral parameters into radiant's linear RGB.
//!
//! Two conversions, chosen by what the spectrum describes:
//! - **Emission** (`blackbody`, sampled illuminants): the colour the eye sees. The
//!   spectrum is projected on the CIE 1931 colour-matching functions, using the analytic
//!   multi-lobe fit of Wyman, Sloan & Shirley, "Simple Analytic Approximations to the
//!   CIE XYZ Color Matching Functions", JCGT 2(2), 2013, converted to linear sRGB
//!   (IEC 61966-2-1 primaries, D65 white) and normalised to luminance 1. pbrt-v4
//!   divides every non-RGB emission spectrum by its photometric value the same way, so
//!   `scale` alone sets the brightness.
//! - **Material data** (reflectances, `eta`, `k` given as samples or named spectra): the
//!   average of the piecewise-linear spectrum over three bands, blue 400–500 nm,
//!   green 500–600 nm, red 600–700 nm. Crude, but it keeps a metal's colour and needs
//!   no illuminant.

use radiant_math::color::Rgb;

/// Visible range integrated for emission (nm), the CIE tables' range.
const LAMBDA_MIN: f64 = 360.0;
const LAMBDA_MAX: f64 = 830.0;

/// Band edges (nm) for material spectra: blue, green, red.
pub const BANDS: [(f64, f64); 3] = [(400.0, 500.0), (500.0, 600.0), (600.0, 700.0)];

/// Piecewise Gaussian with different widths left and right of the mean.
fn lobe(lambda: f64, mean: f64, sigma_left: f64, sigma_right: f64) -> f64 {
    let sigma = if lambda < mean {
        sigma_left
    } else {
        sigma_right
    };
    let t = (lambda - mean) / sigma;
    (-0.5 * t * t).exp()
}

/// CIE 1931 2° colour-matching functions (x̄, ȳ, z̄) at `lambda` nm, Wyman, Sloan &
/// Shirley 2013, multi-lobe fit (their eq. 2 with Table 1's parameters).
pub fn cie_xyz_bar(lambda: f64) -> [f64; 3] {
    let x = 1.056 * lobe(lambda, 599.8, 37.9, 31.0) + 0.362 * lobe(lambda, 442.0, 16.0, 26.7)
        - 0.065 * lobe(lambda, 501.1, 20.4, 26.2);
    let y = 0.821 * lobe(lambda, 568.8, 46.9, 40.5) + 0.286 * lobe(lambda, 530.9, 16.3, 31.1);
    let z = 1.217 * lobe(lambda, 437.0, 11.8, 36.0) + 0.681 * lobe(lambda, 459.0, 26.0, 13.8);
    [x, y, z]
}

/// CIE XYZ to linear sRGB (IEC 61966-2-1, D65 white).
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    let [x, y, z] = xyz;
    [
        3.2404542 * x - 1.5371385 * y - 0.4985314 * z,
        -0.9692660 * x + 1.8760108 * y + 0.0415560 * z,
        0.0556434 * x - 0.2040259 * y + 1.0572252 * z,
    ]
}

/// Integrates a spectral power distribution against the colour-matching functions
/// (1 nm steps, midpoint rule).
pub fn spectrum_to_xyz(spd: impl Fn(f64) -> f64) -> [f64; 3] {
    let mut xyz = [0.0; 3];
    let steps = (LAMBDA_MAX - LAMBDA_MIN) as usize;
    for i in 0..steps {
        let lambda = LAMBDA_MIN + i as f64 + 0.5;
        let s = spd(lambda);
        let bar = cie_xyz_bar(lambda);
        for c in 0..3 {
            xyz[c] += s * bar[c];
        }
    }
    xyz
}

/// The RGB of an emission spectrum, scaled to luminance 1. Colours outside the sRGB
/// gamut (very low temperatures) lose their negative components before the scaling.
/// `None` when the spectrum has no visible energy.
pub fn emission_rgb(spd: impl Fn(f64) -> f64) -> Option<Rgb> {
    let rgb = xyz_to_linear_srgb(spectrum_to_xyz(spd)).map(|c| c.max(0.0));
    let rgb = Rgb::new(rgb[0] as f32, rgb[1] as f32, rgb[2] as f32);
    let y = rgb.luminance();
    (y > 0.0 && y.is_finite()).then(|| rgb * (1.0 / y))
}

/// Planck's law: spectral radiance of a blackbody at `kelvin`, up to a constant factor
/// (the result is normalised anyway).
pub fn planck(lambda_nm: f64, kelvin: f64) -> f64 {
    const C: f64 = 299_792_458.0;
    const H: f64 = 6.626_070_15e-34;
    const KB: f64 = 1.380_649e-23;
    let l = lambda_nm * 1e-9;
    (2.0 * H * C * C) / (l.powi(5) * ((H * C / (l * KB * kelvin)).exp() - 1.0))
}

/// `"blackbody" [T]`: the colour of a blackbody at `kelvin`, luminance 1.
pub fn blackbody_rgb(kelvin: f32) -> Option<Rgb> {
    if !(kelvin.is_finite() && kelvin > 0.0) {
        return None;
    }
    emission_rgb(|l| planck(l, f64::from(kelvin)))
}

/// Linear interpolation in a table of (wavelength, value) pairs sorted by wavelength;
/// constant beyond the ends.
pub fn interpolate(samples: &[(f64, f64)], lambda: f64) -> f64 {
    match samples {
        [] => 0.0,
        [(_, v)] => *v,
        _ => {
            let i = samples.partition_point(|s| s.0 <= lambda);
            if i == 0 {
                samples[0].1
            } else if i == samples.len() {
                samples[samples.len() - 1].1
            } else {
                let (l0, v0) = samples[i - 1];
                let (l1, v1) = samples[i];
                let t = if l1 > l0 {
                    (lambda - l0) / (l1 - l0)
                } else {
                    0.0
                };
                v0 + t * (v1 - v0)
            }
        }
    }
}

/// Average of the piecewise-linear spectrum over each band of [`BANDS`], as (r, g, b).
/// Integrated with 1 nm trapezoids, exact to well below the data's own precision.
pub fn band_average(samples: &[(f64, f64)]) -> Rgb {
    let avg = |(lo, hi): (f64, f64)| {
        let n = (hi - lo) as usize;
        let mut sum = 0.0;
        for i in 0..n {
            let a = lo + i as f64;
            sum += 0.5 * (interpolate(samples, a) + interpolate(samples, a + 1.0));
        }
        (sum / n as f64) as f32
    };
    Rgb::new(avg(BANDS[2]), avg(BANDS[1]), avg(BANDS[0]))
}

/// (wavelength, value) pairs from pbrt's flat list `[λ0 v0 λ1 v1 …]`, sorted by
/// wavelength. `None` when the list has an odd length or non-finite entries.
pub fn pairs_from_flat(values: &[f32]) -> Option<Vec<(f64, f64)>> {
    if values.is_empty() || !values.len().is_multiple_of(2) || values.iter().any(|v| !v.is_finite())
    {
        return None;
    }
    let mut pairs: Vec<(f64, f64)> = values
        .chunks_exact(2)
        .map(|c| (f64::from(c[0]), f64::from(c[1])))
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    Some(pairs)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CIE 1931 ȳ integrates to 106.857 over 360–830 nm (1 nm table sum). The
    /// multi-lobe fit's stated error is below 1 % of the peak, so its integral must
    /// agree to within 1 %.
    #[test]
    fn fitted_y_bar_has_the_cie_integral() {
        let y = spectrum_to_xyz(|_| 1.0)[1];
        assert!((y - 106.857).abs() / 106.857 < 0.01, "∫ȳ = {y}");
    }

    /// Equal-energy white has chromaticity (1/3, 1/3); the fit reproduces it within
    /// 0.005 (its chromaticity error is of that order).
    #[test]
    fn equal_energy_white_is_at_one_third() {
        let [x, y, z] = spectrum_to_xyz(|_| 1.0);
        let s = x + y + z;
        assert!((x / s - 1.0 / 3.0).abs() < 0.005 && (y / s - 1.0 / 3.0).abs() < 0.005);
    }

    /// Planckian locus at 6500 K: (x, y) = (0.3135, 0.3237) (CIE 15 tables); 2856 K
    /// (illuminant A): (0.4476, 0.4074). Tolerance 0.003 covers the fit error.
    #[test]
    fn blackbody_chromaticities_match_the_planckian_locus() {
        for (t, cx, cy) in [(6500.0, 0.3135, 0.3237), (2856.0, 0.4476, 0.4074)] {
            let [x, y, z] = spectrum_to_xyz(|l| planck(l, t));
            let s = x + y + z;
            assert!((x / s - cx).abs() < 0.003, "T={t}: x={}", x / s);
            assert!((y / s - cy).abs() < 0.003, "T={t}: y={}", y / s);
        }
    }

    #[test]
    fn blackbody_rgb_has_unit_luminance_and_warms_with_lower_temperature() {
        let warm = blackbody_rgb(3000.0).unwrap();
        let daylight = blackbody_rgb(6500.0).unwrap();
        for c in [warm, daylight] {
            assert!((c.luminance() - 1.0).abs() < 1e-5);
        }
        assert!(warm.r > warm.g && warm.g > warm.b);
        // 6500 K is close to the sRGB white point: channels within 10 % of each other.
        assert!(daylight.max_component() / daylight.min_component() < 1.1);
        assert!(blackbody_rgb(-5.0).is_none());
    }

    #[test]
    fn band_average_of_a_ramp_is_the_band_centre() {
        let ramp = [(300.0, 300.0), (800.0, 800.0)];
        let c = band_average(&ramp);
        assert!((c.b - 450.0).abs() < 1e-3 && (c.g - 550.0).abs() < 1e-3);
        assert!((c.r - 650.0).abs() < 1e-3);
    }
}
