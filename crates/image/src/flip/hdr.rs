//! HDR-FLIP (Andersson, Nilsson, Shirley, Akenine-Möller, EG 2021): tone map both images
//! at a range of exposures chosen from the reference, run LDR-FLIP at each, keep the
//! per-pixel maximum.

use crate::flip::color::luminance;

/// The ACES filmic curve as fitted by Narkowicz (2015), with his 0.6 input scale folded
/// into the coefficients, as a ratio of quadratics
/// y(x) = (k₀x² + k₁x + k₂) / (k₃x² + k₄x + k₅). The HDR-FLIP paper writes every tone
/// mapper in this form so that it can be inverted in closed form.
const ACES: [f64; 6] = [
    0.6 * 0.6 * 2.51,
    0.6 * 0.03,
    0.0,
    0.6 * 0.6 * 2.43,
    0.6 * 0.59,
    0.14,
];

/// The display value that the brightest reference pixel reaches at the start exposure
/// and the median pixel reaches at the stop exposure (HDR-FLIP Sec. 3).
const EXPOSURE_TARGET: f64 = 0.85;

/// Tone maps one linear channel with the ACES curve, clamped to [0, 1].
#[inline]
pub fn tone_map(x: f32) -> f32 {
    let x = x.max(0.0);
    let k = ACES.map(|v| v as f32);
    let y = (k[0] * x * x + k[1] * x + k[2]) / (k[3] * x * x + k[4] * x + k[5]);
    y.clamp(0.0, 1.0)
}

/// The input that the (unclamped) curve maps to `target`: the non-negative root of
/// (t·k₃ − k₀)x² + (t·k₄ − k₁)x + (t·k₅ − k₂) = 0.
fn inverse_tone_map(target: f64) -> f64 {
    let k = ACES;
    let a = target * k[3] - k[0];
    let b = target * k[4] - k[1];
    let c = target * k[5] - k[2];
    if a.abs() < 1e-12 {
        return -c / b;
    }
    let root = (b * b - 4.0 * a * c).max(0.0).sqrt();
    let x1 = (-b + root) / (2.0 * a);
    let x2 = (-b - root) / (2.0 * a);
    x1.max(x2)
}

/// The exposure range [c_start, c_stop] of HDR-FLIP for a reference image: at
/// 2^c_start the brightest pixel's luminance tone maps to 0.85, at 2^c_stop the median
/// luminance does, so the range covers everything from the highlights to the typical
/// content.
///
/// The median is the element at index ⌊n/2⌋ of the sorted luminances (the upper middle
/// one for an even count, as the reference implementation takes it). A reference whose
/// median luminance is 0 uses its smallest positive luminance instead, and one without
/// any positive luminance gives (0, 0); the paper leaves those cases open.
pub fn exposure_range(reference: &[[f32; 3]]) -> (f32, f32) {
    let mut lum: Vec<f32> = reference
        .iter()
        .map(|p| luminance(p.map(|v| v.max(0.0))))
        .collect();
    if lum.is_empty() {
        return (0.0, 0.0);
    }
    let max = lum.iter().copied().fold(0.0f32, f32::max);
    if max <= 0.0 {
        return (0.0, 0.0);
    }
    let mid = lum.len() / 2;
    let (_, median, _) = lum.select_nth_unstable_by(mid, f32::total_cmp);
    let mut median = *median;
    if median <= 0.0 {
        median = lum
            .iter()
            .copied()
            .filter(|v| *v > 0.0)
            .fold(f32::INFINITY, f32::min);
    }
    let x = inverse_tone_map(EXPOSURE_TARGET);
    let start = (x / max as f64).log2();
    let stop = (x / median as f64).log2();
    (start as f32, stop as f32)
}

/// The exposures evaluated for a range: N = max(2, ⌈c_stop − c_start⌉) evenly spaced
/// values from c_start to c_stop inclusive, about one per stop.
pub fn exposures(start: f32, stop: f32) -> Vec<f32> {
    let n = ((stop - start).ceil() as usize).max(2);
    let step = (stop - start) / (n - 1) as f32;
    (0..n).map(|i| start + i as f32 * step).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_tone_map_inverts() {
        for t in [0.1, 0.5, 0.85, 0.95] {
            let x = inverse_tone_map(t);
            assert!(x > 0.0);
            assert!((tone_map(x as f32) as f64 - t).abs() < 1e-5, "{t}");
        }
    }

    #[test]
    fn tone_map_is_monotone_from_zero() {
        assert_eq!(tone_map(0.0), 0.0);
        let mut prev = 0.0;
        for i in 1..1000 {
            let y = tone_map(i as f32 * 0.05);
            assert!(y >= prev);
            prev = y;
        }
        assert!(prev > 0.99);
    }

    #[test]
    fn exposure_range_of_known_image() {
        // Luminances 1, 2, 4, 0.5 (grey pixels): upper median 2, max 4.
        let img = [[1.0; 3], [4.0; 3], [2.0; 3], [0.5; 3]];
        let (start, stop) = exposure_range(&img);
        let x = inverse_tone_map(EXPOSURE_TARGET);
        assert!((start as f64 - (x / 4.0).log2()).abs() < 1e-5);
        assert!((stop as f64 - (x / 2.0).log2()).abs() < 1e-5);
        assert!((stop - start - 1.0).abs() < 1e-5);
    }

    #[test]
    fn exposure_count_and_spacing() {
        let e = exposures(-2.5, 5.2);
        assert_eq!(e.len(), 8);
        assert!((e[0] + 2.5).abs() < 1e-6 && (e[7] - 5.2).abs() < 1e-5);
        assert_eq!(exposures(1.0, 1.0), vec![1.0, 1.0]);
    }
}
