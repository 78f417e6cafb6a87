//! Error metrics between a test image and a reference, over all pixels and RGB channels,
//! with the same definitions as `shared/tools/compare.py`:
//!
//! - `rmse   = sqrt(mean((a-b)^2))`
//! - `relmse = mean((a-b)^2 / (b^2 + 0.01))`, b the reference — the relative MSE used to
//!   compare Monte Carlo renderers (e.g. Rousselle, Knaus, Zwicker, "Adaptive Rendering
//!   with Non-Local Means Filtering", 2012); the 0.01 keeps black reference pixels from
//!   dominating.
//! - `mae    = mean(|a-b|)`
//! - `mean_test`, `mean_ref` as a brightness sanity check.
//!
//! Non-finite values (NaN, ±inf) are counted per channel value, in each image apart.
//! A non-finite test value is replaced by 0 before everything else (as `compare.py`
//! does: a renderer's NaN counts against it). A non-finite reference value leaves
//! nothing to measure against: that channel value is left out of every figure, for
//! both images, and `count` says how many were compared. Sums are taken in f64.

use super::{Crop, Image, ImageError};

/// Reference-relative epsilon in the relMSE denominator (as in `compare.py`).
pub const RELMSE_EPSILON: f64 = 1e-2;

/// The figures `radiant compare` prints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    pub rmse: f64,
    pub relmse: f64,
    pub mae: f64,
    pub mean_test: f64,
    pub mean_ref: f64,
    /// Number of non-finite channel values in the test image (each replaced by 0).
    pub nonfinite: usize,
    /// Number of non-finite channel values in the reference (each left out).
    pub nonfinite_ref: usize,
    /// Number of channel values compared (3 × pixels in the crop, less those with a
    /// non-finite reference).
    pub count: usize,
}

/// `SizeMismatch` unless `test` and `reference` have the same size.
pub fn check_same_size(test: &Image, reference: &Image) -> Result<(), ImageError> {
    if (test.width, test.height) == (reference.width, reference.height) {
        return Ok(());
    }
    Err(ImageError::SizeMismatch {
        test_w: test.width,
        test_h: test.height,
        ref_w: reference.width,
        ref_h: reference.height,
    })
}

/// Compares `test` against `reference` inside `crop` (the whole image when `None`).
pub fn compare(test: &Image, reference: &Image, crop: Option<Crop>) -> Result<Metrics, ImageError> {
    check_same_size(test, reference)?;
    let crop = crop.unwrap_or(Crop::full(test.width, test.height));
    crop.check(test.width, test.height)?;

    let (mut se, mut rel, mut ae, mut st, mut sr) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let (mut nonfinite, mut nonfinite_ref) = (0usize, 0usize);
    for y in crop.y0..crop.y1 {
        let row = y * test.width;
        let t_row = &test.pixels[row + crop.x0..row + crop.x1];
        let r_row = &reference.pixels[row + crop.x0..row + crop.x1];
        for (t, r) in t_row.iter().zip(r_row) {
            for c in 0..3 {
                let mut a = t[c] as f64;
                if !a.is_finite() {
                    nonfinite += 1;
                    a = 0.0;
                }
                let b = r[c] as f64;
                if !b.is_finite() {
                    nonfinite_ref += 1;
                    continue;
                }
                let d = a - b;
                se += d * d;
                rel += d * d / (b * b + RELMSE_EPSILON);
                ae += d.abs();
                st += a;
                sr += b;
            }
        }
    }
    let count = 3 * crop.width() * crop.height() - nonfinite_ref;
    let n = count as f64;
    Ok(Metrics {
        rmse: (se / n).sqrt(),
        relmse: rel / n,
        mae: ae / n,
        mean_test: st / n,
        mean_ref: sr / n,
        nonfinite,
        nonfinite_ref,
        count,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::color::Rgb;

    fn image(w: usize, h: usize, values: &[[f32; 3]]) -> Image {
        Image {
            width: w,
            height: h,
            pixels: values.iter().map(|&v| Rgb::from_array(v)).collect(),
        }
    }

    #[test]
    fn hand_computed_values() {
        // Two pixels, six channel values.
        // test: (1,2,3) (0,0,NaN); ref: (1,1,1) (0.1,0,1)
        // d = 0, 1, 2, -0.1, 0, -1   (the NaN becomes 0)
        // d^2 = 0, 1, 4, 0.01, 0, 1          sum 6.01  → mse 6.01/6
        // b^2+0.01 = 1.01,1.01,1.01,0.02,0.01,1.01
        // rel terms = 0, 1/1.01, 4/1.01, 0.5, 0, 1/1.01 → sum 6/1.01 + 0.5
        // |d| sum = 4.1 → mae 4.1/6
        // mean_test = (6 + 0)/6 = 1, mean_ref = 4.1/6
        let t = image(2, 1, &[[1.0, 2.0, 3.0], [0.0, 0.0, f32::NAN]]);
        let r = image(2, 1, &[[1.0, 1.0, 1.0], [0.1, 0.0, 1.0]]);
        let m = compare(&t, &r, None).unwrap();
        // 0.1 is not exact in f32; the tolerance covers its 1.5e-9 representation error.
        let close = |a: f64, b: f64| (a - b).abs() < 1e-7 * b.abs().max(1.0);
        assert!(close(m.rmse, (6.01f64 / 6.0).sqrt()), "{m:?}");
        assert!(close(m.relmse, (6.0 / 1.01 + 0.5) / 6.0), "{m:?}");
        assert!(close(m.mae, 4.1 / 6.0), "{m:?}");
        assert!(close(m.mean_test, 1.0), "{m:?}");
        assert!(close(m.mean_ref, 4.1 / 6.0), "{m:?}");
        assert_eq!(m.nonfinite, 1);
        assert_eq!(m.count, 6);
    }

    #[test]
    fn non_finite_values_are_counted_in_each_image_and_a_bad_reference_is_left_out() {
        // test: (1,2,NaN) (4,5,6); ref: (1,1,1) (inf,NaN,6)
        // Left out: the reference's inf and NaN (G and R of pixel 2).
        // Compared: d = 0, 1, -1 (the test's NaN becomes 0), 0 → 4 values.
        let t = image(2, 1, &[[1.0, 2.0, f32::NAN], [4.0, 5.0, 6.0]]);
        let r = image(2, 1, &[[1.0, 1.0, 1.0], [f32::INFINITY, f32::NAN, 6.0]]);
        let m = compare(&t, &r, None).unwrap();
        assert_eq!((m.nonfinite, m.nonfinite_ref, m.count), (1, 2, 4));
        assert!((m.rmse - (2.0f64 / 4.0).sqrt()).abs() < 1e-12, "{m:?}");
        assert!((m.mae - 0.5).abs() < 1e-12, "{m:?}");
        assert!((m.mean_test - 9.0 / 4.0).abs() < 1e-12, "{m:?}");
        assert!((m.mean_ref - 9.0 / 4.0).abs() < 1e-12, "{m:?}");
        // Swapped, each count follows its image.
        let m = compare(&r, &t, None).unwrap();
        assert_eq!((m.nonfinite, m.nonfinite_ref, m.count), (2, 1, 5));
        assert!(m.rmse.is_finite() && m.relmse.is_finite(), "{m:?}");
    }

    #[test]
    fn crop_selects_half_open_rectangle() {
        // 3x2 test image all zeros; reference has value 2 only at (1,1).
        let t = Image::new(3, 2);
        let mut r = Image::new(3, 2);
        r.set(1, 1, Rgb::splat(2.0));
        // Crop x 1..3, y 1..2 → pixels (1,1),(2,1): d = -2 three times, 0 three times.
        let crop = Crop {
            x0: 1,
            y0: 1,
            x1: 3,
            y1: 2,
        };
        let m = compare(&t, &r, Some(crop)).unwrap();
        assert_eq!(m.count, 6);
        assert!((m.rmse - (12.0f64 / 6.0).sqrt()).abs() < 1e-12);
        assert!((m.relmse - (3.0 * 4.0 / 4.01) / 6.0).abs() < 1e-12);
        assert!((m.mean_ref - 1.0).abs() < 1e-12);
        // Excluding that pixel gives zero error.
        let m0 = compare(&t, &r, Some(Crop { x1: 1, ..crop })).unwrap_err();
        assert!(matches!(m0, ImageError::BadCrop { .. }));
        let m2 = compare(&t, &r, Some(Crop { x0: 2, ..crop })).unwrap();
        assert_eq!(m2.rmse, 0.0);
        assert_eq!(r.mean_in(crop).unwrap(), 1.0);
        assert_eq!(
            r.crop(crop).unwrap().pixels,
            vec![Rgb::splat(2.0), Rgb::BLACK]
        );
    }

    #[test]
    fn errors_on_size_mismatch_and_bad_crop() {
        let a = Image::new(4, 4);
        let b = Image::new(4, 3);
        let e = compare(&a, &b, None).unwrap_err().to_string();
        assert!(e.contains("4x4") && e.contains("4x3"), "{e}");
        let out = Crop {
            x0: 0,
            y0: 0,
            x1: 5,
            y1: 4,
        };
        assert!(compare(&a, &a, Some(out)).is_err());
    }

    #[test]
    fn identical_images_have_zero_error() {
        let mut a = Image::new(5, 4);
        for (i, p) in a.pixels.iter_mut().enumerate() {
            *p = Rgb::new(i as f32, 0.5, 1e3);
        }
        let m = compare(&a, &a, None).unwrap();
        assert_eq!((m.rmse, m.relmse, m.mae, m.nonfinite), (0.0, 0.0, 0.0, 0));
        assert!((m.mean_test - a.mean()).abs() < 1e-9);
    }
}
