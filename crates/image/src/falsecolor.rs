//! False-colour error images: a per-pixel error mapped through a colour ramp whose
//! lightness rises linearly, so equal steps in error read as equal steps in brightness.
//!
//! The ramp is our own construction (no third-party colormap table): a path in Oklab
//! (Björn Ottosson, "A perceptual color space for image processing", 2020) with lightness
//! L rising linearly from 0.25 to 0.95 while the hue turns from violet through blue, teal
//! and green to yellow — the shape of viridis (van der Walt & Smith, 2015) but derived
//! from the colour space, not copied. Chroma follows a hand-picked spline that stays
//! inside the sRGB gamut, which makes neighbouring colours about equally far apart in
//! Oklab (±8%); should a colour still fall outside the gamut, its chroma is reduced at
//! constant L and hue, so lightness stays exactly linear.

use std::sync::OnceLock;

use super::metrics::{RELMSE_EPSILON, check_same_size};
use super::{Image, ImageError};
use radiant_math::color::Rgb;

/// Which per-pixel error the false-colour image shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ErrorMetric {
    /// Mean over channels of `(a-b)^2 / (b^2 + 0.01)`: each pixel's share of relMSE.
    #[default]
    RelativeSquared,
    /// `|Y(a) - Y(b)|`, the absolute difference of Rec.709 luminance.
    AbsoluteLuminance,
}

/// Colour given to pixels whose test value is NaN or infinite (not on the ramp).
pub const NONFINITE_COLOR: Rgb = Rgb::new(1.0, 0.0, 1.0);

/// A false-colour error image (linear RGB, ready for `write_png` at exposure 0) and the
/// error value that maps to the top of the ramp.
#[derive(Clone, Debug)]
pub struct FalseColor {
    pub image: Image,
    pub scale: f32,
}

/// Maps the per-pixel error between `test` and `reference` through [`colormap`], with 0 at
/// the bottom of the ramp and `scale` (default: the largest finite error) at the top.
pub fn false_color_error(
    test: &Image,
    reference: &Image,
    metric: ErrorMetric,
    scale: Option<f32>,
) -> Result<FalseColor, ImageError> {
    check_same_size(test, reference)?;
    let errors: Vec<Option<f32>> = test
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(&t, &r)| pixel_error(t, r, metric))
        .collect();
    let scale = scale.unwrap_or_else(|| errors.iter().flatten().fold(0.0f32, |m, &e| m.max(e)));
    let pixels = errors
        .iter()
        .map(|e| match e {
            None => NONFINITE_COLOR,
            Some(_) if scale <= 0.0 => colormap(0.0),
            Some(e) => colormap(e / scale),
        })
        .collect();
    Ok(FalseColor {
        image: Image {
            width: test.width,
            height: test.height,
            pixels,
        },
        scale,
    })
}

/// The error of one pixel, `None` when the test pixel is not finite.
fn pixel_error(t: Rgb, r: Rgb, metric: ErrorMetric) -> Option<f32> {
    if !t.is_finite() {
        return None;
    }
    let e = match metric {
        ErrorMetric::RelativeSquared => {
            let mut s = 0.0f64;
            for c in 0..3 {
                let d = t[c] as f64 - r[c] as f64;
                let b = r[c] as f64;
                s += d * d / (b * b + RELMSE_EPSILON);
            }
            (s / 3.0) as f32
        }
        ErrorMetric::AbsoluteLuminance => (t.luminance() - r.luminance()).abs(),
    };
    Some(e)
}

/// Lightness at the bottom and top of the ramp.
const L_RANGE: (f32, f32) = (0.25, 0.95);
/// Oklab hue (degrees) at the bottom and top: violet → yellow, turning through blue,
/// cyan and green.
const HUE_RANGE: (f32, f32) = (305.0, 100.0);
/// Requested chroma at t = 0, 1/4, 1/2, 3/4, 1, joined by a Catmull-Rom spline. Chosen
/// by hand to stay inside the sRGB gamut along the whole path (whose boundary dips to
/// C ≈ 0.1 around teal and at the light yellow end), so the ramp has no kinks where
/// chroma would otherwise hit the gamut boundary.
const CHROMA_KNOTS: [f32; 5] = [0.115, 0.11, 0.09, 0.15, 0.10];
const LUT_SIZE: usize = 256;

/// The ramp's colour (linear sRGB, in 0..=1) for `t` in 0..=1; `t` is clamped and NaN
/// maps to 0. Interpolates a 256-entry table built once.
pub fn colormap(t: f32) -> Rgb {
    static LUT: OnceLock<Vec<Rgb>> = OnceLock::new();
    let lut = LUT.get_or_init(|| {
        (0..LUT_SIZE)
            .map(|i| ramp_color(i as f32 / (LUT_SIZE - 1) as f32))
            .collect()
    });
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let x = t * (LUT_SIZE - 1) as f32;
    let i = (x as usize).min(LUT_SIZE - 2);
    let f = x - i as f32;
    lut[i] * (1.0 - f) + lut[i + 1] * f
}

/// The ramp evaluated directly (no table): Oklab (L, C, h) along the path, chroma reduced
/// by bisection until the colour fits in the sRGB gamut.
fn ramp_color(t: f32) -> Rgb {
    let lerp = |(a, b): (f32, f32)| a + (b - a) * t;
    let l = lerp(L_RANGE);
    let h = lerp(HUE_RANGE).to_radians();
    let c_max = chroma_at(t);
    let at = |c: f32| oklab_to_linear_srgb(l, c * h.cos(), c * h.sin());
    let in_gamut = |p: Rgb| p.min_component() >= 0.0 && p.max_component() <= 1.0;
    if in_gamut(at(c_max)) {
        return at(c_max);
    }
    // Grey (c = 0) at L in (0,1) is always inside the gamut.
    let (mut lo, mut hi) = (0.0f32, c_max);
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if in_gamut(at(mid)) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    at(lo).map(|v| v.clamp(0.0, 1.0))
}

/// Uniform Catmull-Rom spline through [`CHROMA_KNOTS`] (end knots repeated).
fn chroma_at(t: f32) -> f32 {
    let k = &CHROMA_KNOTS;
    let n = k.len() - 1;
    let x = t.clamp(0.0, 1.0) * n as f32;
    let i = (x as usize).min(n - 1);
    let f = x - i as f32;
    let p = |j: isize| k[j.clamp(0, n as isize) as usize];
    let (p0, p1, p2, p3) = (
        p(i as isize - 1),
        p(i as isize),
        p(i as isize + 1),
        p(i as isize + 2),
    );
    0.5 * (2.0 * p1
        + (p2 - p0) * f
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * f * f
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * f * f * f)
}

/// Oklab to linear sRGB (Ottosson 2020: inverse of M2, cube, inverse of M1).
pub fn oklab_to_linear_srgb(l: f32, a: f32, b: f32) -> Rgb {
    let l_ = l + 0.396_337_78 * a + 0.215_803_76 * b;
    let m_ = l - 0.105_561_346 * a - 0.063_854_17 * b;
    let s_ = l - 0.089_484_18 * a - 1.291_485_5 * b;
    let (l3, m3, s3) = (l_ * l_ * l_, m_ * m_ * m_, s_ * s_ * s_);
    Rgb::new(
        4.076_741_7 * l3 - 3.307_711_6 * m3 + 0.230_969_94 * s3,
        -1.268_438 * l3 + 2.609_757_4 * m3 - 0.341_319_38 * s3,
        -0.004_196_086_3 * l3 - 0.703_418_6 * m3 + 1.707_614_7 * s3,
    )
}

/// Linear sRGB to Oklab (Ottosson 2020: M1, cube root, M2); returns (L, a, b).
pub fn linear_srgb_to_oklab(c: Rgb) -> (f32, f32, f32) {
    let l = 0.412_221_46 * c.r + 0.536_332_55 * c.g + 0.051_445_995 * c.b;
    let m = 0.211_903_5 * c.r + 0.680_699_5 * c.g + 0.107_396_96 * c.b;
    let s = 0.088_302_46 * c.r + 0.281_718_85 * c.g + 0.629_978_7 * c.b;
    let (l_, m_, s_) = (l.cbrt(), m.cbrt(), s.cbrt());
    (
        0.210_454_26 * l_ + 0.793_617_8 * m_ - 0.004_072_047 * s_,
        1.977_998_5 * l_ - 2.428_592_2 * m_ + 0.450_593_7 * s_,
        0.025_904_037 * l_ + 0.782_771_77 * m_ - 0.808_675_77 * s_,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn oklab_white_and_round_trip() {
        // Oklab is normalised so that sRGB white has L = 1, a = b = 0.
        let (l, a, b) = linear_srgb_to_oklab(Rgb::WHITE);
        assert!((l - 1.0).abs() < 1e-4 && a.abs() < 1e-4 && b.abs() < 1e-4);
        for c in [
            Rgb::new(0.2, 0.5, 0.9),
            Rgb::new(0.9, 0.1, 0.05),
            Rgb::splat(0.18),
        ] {
            let (l, a, b) = linear_srgb_to_oklab(c);
            let back = oklab_to_linear_srgb(l, a, b);
            assert!(
                (back - c).map(f32::abs).max_component() < 1e-4,
                "{c:?} {back:?}"
            );
        }
    }

    #[test]
    fn ramp_lightness_is_linear_and_in_gamut() {
        for i in 0..LUT_SIZE {
            let t = i as f32 / (LUT_SIZE - 1) as f32;
            let c = colormap(t);
            assert!(
                c.min_component() >= 0.0 && c.max_component() <= 1.0,
                "{t} {c:?}"
            );
            let (l, _, _) = linear_srgb_to_oklab(c);
            // Gamut clamping happens only at bisection precision, so L is on the line to
            // well within a thousandth.
            let want = L_RANGE.0 + (L_RANGE.1 - L_RANGE.0) * t;
            assert!((l - want).abs() < 1e-3, "t={t}: L={l}, want {want}");
        }
        // Perceptual uniformity: Oklab distances between neighbouring table entries are
        // equal to within 20% (measured spread 0.0193 .. 0.0224 per 1/40 step).
        let steps: Vec<f32> = (0..40)
            .map(|i| {
                let (l0, a0, b0) = linear_srgb_to_oklab(colormap(i as f32 / 40.0));
                let (l1, a1, b1) = linear_srgb_to_oklab(colormap((i + 1) as f32 / 40.0));
                ((l1 - l0).powi(2) + (a1 - a0).powi(2) + (b1 - b0).powi(2)).sqrt()
            })
            .collect();
        let mean = steps.iter().sum::<f32>() / steps.len() as f32;
        for (i, d) in steps.iter().enumerate() {
            assert!((d / mean - 1.0).abs() < 0.2, "step {i}: {d} vs mean {mean}");
        }
        // The ends look as intended: dark violet-blue, bright yellow (red and green above blue).
        let (lo, hi) = (colormap(0.0), colormap(1.0));
        assert!(lo.b > lo.g && lo.r > lo.g, "{lo:?}");
        assert!(hi.r > hi.b && hi.g > hi.b, "{hi:?}");
    }

    #[test]
    fn error_image_scale_and_markers() {
        let mut reference = Image::new(3, 1);
        reference.set(0, 0, Rgb::splat(1.0));
        reference.set(1, 0, Rgb::splat(1.0));
        let mut test = reference.clone();
        test.set(1, 0, Rgb::splat(2.0));
        test.set(2, 0, Rgb::new(f32::NAN, 0.0, 0.0));
        let fc = false_color_error(&test, &reference, ErrorMetric::RelativeSquared, None).unwrap();
        // Pixel 1: (2-1)^2/(1+0.01) in each channel.
        assert!((fc.scale - 1.0 / 1.01).abs() < 1e-6, "{}", fc.scale);
        assert_eq!(fc.image.get(0, 0), colormap(0.0));
        assert_eq!(fc.image.get(1, 0), colormap(1.0));
        assert_eq!(fc.image.get(2, 0), NONFINITE_COLOR);
        let fc = false_color_error(&test, &reference, ErrorMetric::AbsoluteLuminance, Some(2.0))
            .unwrap();
        assert_eq!(fc.scale, 2.0);
        assert_eq!(fc.image.get(1, 0), colormap(0.5));
        assert!(false_color_error(&test, &Image::new(2, 1), ErrorMetric::default(), None).is_err());
    }
}
