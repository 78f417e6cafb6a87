//! ꟻLIP, a perceptual difference evaluator for rendered images.
//!
//! - **LDR-ꟻLIP**: Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström, Fairchild,
//!   "ꟻLIP: A Difference Evaluator for Alternating Images", HPG 2020. It approximates
//!   the difference a viewer perceives when flipping between two sRGB images at a given
//!   viewing distance: colour differences after filtering by the contrast sensitivity
//!   of the eye, amplified where edges or points (fireflies) differ.
//! - **HDR-ꟻLIP**: Andersson, Nilsson, Shirley, Akenine-Möller, "Visualizing Errors in
//!   Rendered High Dynamic Range Images", Eurographics 2021. Both linear images are
//!   tone mapped (ACES) at a range of exposures derived from the reference, LDR-ꟻLIP is
//!   run at each, and the per-pixel maximum is kept.
//!
//! Errors are in [0, 1] per pixel; 0 means no perceived difference. Error maps are
//! usually shown with the magma colour map ([`flip_color`]).
//!
//! Images are slices of RGB triples, row-major, row 0 at the top.

mod color;
mod convolve;
mod hdr;
mod kernels;
mod magma;
mod pipeline;

pub use magma::MAGMA;

use pipeline::{Filters, flip_linear};
use rayon::prelude::*;

/// Pixels per degree of visual angle for a viewer `distance_m` metres from a display
/// `width_m` metres wide with `width_px` pixels across (small-angle approximation,
/// ꟻLIP Sec. 4).
pub fn pixels_per_degree(distance_m: f32, width_px: f32, width_m: f32) -> f32 {
    distance_m * (width_px / width_m) * std::f32::consts::PI / 180.0
}

/// The ꟻLIP papers' default viewing condition: a 0.7 m wide 4K (3840 px) monitor seen
/// from 0.7 m, about 67 pixels per degree.
pub const DEFAULT_PIXELS_PER_DEGREE: f32 = 3840.0 * std::f32::consts::PI / 180.0;

/// A per-pixel ꟻLIP error map.
#[derive(Clone, Debug, PartialEq)]
pub struct FlipMap {
    pub width: usize,
    pub height: usize,
    /// Errors in [0, 1], row-major, row 0 at the top.
    pub errors: Vec<f32>,
    /// Mean of `errors`, the single-number summary the ꟻLIP authors recommend.
    pub mean: f64,
    /// HDR-ꟻLIP only: the exposure compensations c (image scaled by 2^c before tone
    /// mapping) that were evaluated, from c_start to c_stop. Empty for LDR-ꟻLIP.
    pub exposures: Vec<f32>,
}

impl FlipMap {
    /// The error at pixel (x, y), y = 0 at the top.
    pub fn error_at(&self, x: usize, y: usize) -> f32 {
        self.errors[y * self.width + x]
    }

    /// The error map coloured with [`flip_color`], row-major.
    pub fn to_magma(&self) -> Vec<[u8; 3]> {
        self.errors.iter().map(|&e| flip_color(e)).collect()
    }
}

/// Why a ꟻLIP evaluation was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FlipError {
    #[error("image has {len} pixels but {width}x{height} needs {expected}")]
    SizeMismatch {
        width: usize,
        height: usize,
        expected: usize,
        len: usize,
    },
    #[error("image is empty ({width}x{height})")]
    EmptyImage { width: usize, height: usize },
    #[error("pixels per degree must be positive and finite, got {0}")]
    InvalidPixelsPerDegree(f32),
    #[error("exposure range must be finite with start <= stop, got ({start}, {stop})")]
    InvalidExposureRange { start: f32, stop: f32 },
}

fn check_inputs(
    test: &[[f32; 3]],
    reference: &[[f32; 3]],
    width: usize,
    height: usize,
    pixels_per_degree: f32,
) -> Result<(), FlipError> {
    if width == 0 || height == 0 {
        return Err(FlipError::EmptyImage { width, height });
    }
    let expected = width * height;
    for len in [test.len(), reference.len()] {
        if len != expected {
            return Err(FlipError::SizeMismatch {
                width,
                height,
                expected,
                len,
            });
        }
    }
    if !(pixels_per_degree.is_finite() && pixels_per_degree > 0.0) {
        return Err(FlipError::InvalidPixelsPerDegree(pixels_per_degree));
    }
    Ok(())
}

/// Mean in f64, summed in a fixed order so the value does not depend on thread count.
fn mean(errors: &[f32]) -> f64 {
    errors.iter().map(|&e| e as f64).sum::<f64>() / errors.len() as f64
}

/// LDR-ꟻLIP of an sRGB-encoded `test` image against `reference`, both with channels in
/// [0, 1] (values outside are clamped).
pub fn flip_ldr(
    test: &[[f32; 3]],
    reference: &[[f32; 3]],
    width: usize,
    height: usize,
    pixels_per_degree: f32,
) -> Result<FlipMap, FlipError> {
    check_inputs(test, reference, width, height, pixels_per_degree)?;
    let decode = |img: &[[f32; 3]]| -> Vec<[f32; 3]> {
        img.par_iter()
            .map(|p| p.map(|v| color::srgb_to_linear(v.clamp(0.0, 1.0))))
            .collect()
    };
    let (t, r) = (decode(test), decode(reference));
    let mut errors = vec![0.0; width * height];
    flip_linear(
        &t,
        &r,
        width,
        height,
        &Filters::new(pixels_per_degree),
        &mut errors,
    );
    Ok(FlipMap {
        width,
        height,
        mean: mean(&errors),
        errors,
        exposures: Vec::new(),
    })
}

/// The automatic HDR-ꟻLIP exposure range (c_start, c_stop) of a linear reference
/// image: at 2^c_start its brightest luminance tone maps to 0.85, at 2^c_stop its median
/// luminance does.
pub fn hdr_exposure_range(reference: &[[f32; 3]]) -> (f32, f32) {
    hdr::exposure_range(reference)
}

/// HDR-ꟻLIP of a linear-RGB `test` image against `reference` (non-negative values;
/// negative ones count as 0). `exposure` is the range (c_start, c_stop) in stops;
/// `None` derives it from the reference ([`hdr_exposure_range`]). The range is
/// sampled at max(2, ⌈c_stop − c_start⌉) evenly spaced exposures.
pub fn flip_hdr(
    test: &[[f32; 3]],
    reference: &[[f32; 3]],
    width: usize,
    height: usize,
    pixels_per_degree: f32,
    exposure: Option<(f32, f32)>,
) -> Result<FlipMap, FlipError> {
    check_inputs(test, reference, width, height, pixels_per_degree)?;
    let (start, stop) = match exposure {
        Some((start, stop)) => {
            if !(start.is_finite() && stop.is_finite() && start <= stop) {
                return Err(FlipError::InvalidExposureRange { start, stop });
            }
            (start, stop)
        }
        None => hdr::exposure_range(reference),
    };
    let exposures = hdr::exposures(start, stop);
    let filters = Filters::new(pixels_per_degree);
    let n = width * height;
    let mut t = vec![[0.0f32; 3]; n];
    let mut r = vec![[0.0f32; 3]; n];
    let mut at_exposure = vec![0.0f32; n];
    let mut errors = vec![0.0f32; n];
    for &c in &exposures {
        let scale = c.exp2();
        let expose = |src: &[[f32; 3]], dst: &mut [[f32; 3]]| {
            dst.par_iter_mut()
                .zip(src.par_iter())
                .for_each(|(d, s)| *d = s.map(|v| hdr::tone_map(scale * v)));
        };
        expose(test, &mut t);
        expose(reference, &mut r);
        // The tone-mapped values are linear display values, so no sRGB decode here.
        flip_linear(&t, &r, width, height, &filters, &mut at_exposure);
        errors
            .par_iter_mut()
            .zip(at_exposure.par_iter())
            .for_each(|(e, &v)| *e = e.max(v));
    }
    Ok(FlipMap {
        width,
        height,
        mean: mean(&errors),
        errors,
        exposures,
    })
}

/// The magma colour of an error in [0, 1] (clamped; NaN maps to 0), as 8-bit sRGB.
pub fn flip_color(error: f32) -> [u8; 3] {
    let e = if error.is_nan() {
        0.0
    } else {
        error.clamp(0.0, 1.0)
    };
    MAGMA[(e * 255.0).round() as usize]
}
