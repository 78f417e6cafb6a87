//! The LDR-FLIP pipeline on linear RGB inputs in [0, 1] (Andersson et al. 2020, Sec. 3).
//!
//! Each image goes through two pipelines: the colour pipeline filters it with the
//! contrast sensitivity functions of the human visual system in YCxCz and converts the
//! result to Hunt-adjusted CIELAB; the feature pipeline measures edge and point
//! strength on its achromatic channel. The two images are then compared per pixel.

use crate::flip::color::{
    hunt_adjust, hyab, linear_rgb_to_lab, linear_rgb_to_ycxcz, ycxcz_to_linear_rgb,
};
use crate::flip::convolve::{Kernel1D, Plane, convolve_columns, convolve_rows};
use crate::flip::kernels::{CsfFilter, FeatureKernels, csf_filters, feature_kernels};
use rayon::prelude::*;

/// Exponent applied to the HyAB colour distance (FLIP Sec. 3.1, q_c).
const COLOR_EXPONENT: f32 = 0.7;
/// Exponent applied to the feature difference (FLIP Sec. 3.2, q_f).
const FEATURE_EXPONENT: f32 = 0.5;
/// The colour distance, as a fraction of the maximum, above which errors are
/// compressed into the top of the range (FLIP Sec. 3.1, p_c).
const COLOR_KNEE: f32 = 0.4;
/// The error value that the knee maps to (FLIP Sec. 3.1, p_t).
const ERROR_AT_KNEE: f32 = 0.95;

/// All filters for one viewing condition; built once per evaluation.
pub struct Filters {
    csf: [CsfFilter; 3],
    features: FeatureKernels,
}

impl Filters {
    pub fn new(pixels_per_degree: f32) -> Filters {
        Filters {
            csf: csf_filters(pixels_per_degree),
            features: feature_kernels(pixels_per_degree),
        }
    }
}

/// What FLIP keeps of one image: its filtered colour in Hunt-adjusted CIELAB and the
/// magnitudes of its edge and point responses.
struct Perceived {
    hunt_lab: Vec<[f32; 3]>,
    edges: Vec<f32>,
    points: Vec<f32>,
}

/// Applies a CSF filter (a weighted sum of separable Gaussians) to `channel`, using
/// `rows` as scratch.
fn apply_csf(channel: &Plane, filter: &CsfFilter, rows: &mut Plane, dst: &mut Plane) {
    for (i, (weight, kernel)) in filter.terms.iter().enumerate() {
        convolve_rows(channel, kernel, rows);
        convolve_columns(rows, kernel, *weight, i > 0, dst);
    }
}

/// Colour pipeline (FLIP Sec. 3.1): CSF filtering of each YCxCz channel, back to linear
/// RGB clamped to the gamut, then Hunt-adjusted CIELAB.
fn color_pipeline(ycxcz: &[Plane; 3], filters: &[CsfFilter; 3]) -> Vec<[f32; 3]> {
    let (width, height) = (ycxcz[0].width, ycxcz[0].height);
    let mut rows = Plane::zeros(width, height);
    let mut filtered = [(); 3].map(|_| Plane::zeros(width, height));
    for c in 0..3 {
        apply_csf(&ycxcz[c], &filters[c], &mut rows, &mut filtered[c]);
    }
    let [y, cx, cz] = &filtered;
    y.data
        .par_iter()
        .zip(cx.data.par_iter())
        .zip(cz.data.par_iter())
        .map(|((&y, &cx), &cz)| {
            // Filtering can leave the RGB gamut; FLIP clamps back into it before CIELAB.
            let rgb = ycxcz_to_linear_rgb([y, cx, cz]).map(|v| v.clamp(0.0, 1.0));
            hunt_adjust(linear_rgb_to_lab(rgb))
        })
        .collect()
}

/// Feature pipeline (FLIP Sec. 3.2): magnitudes of the edge and point responses of
/// the normalised achromatic channel. Each 2-D detector is `detector ⊗ gauss` along one
/// axis and its transpose along the other; the magnitude is √(h² + v²).
fn feature_pipeline(luma: &Plane, k: &FeatureKernels) -> (Vec<f32>, Vec<f32>) {
    let (width, height) = (luma.width, luma.height);
    let mut gauss_rows = Plane::zeros(width, height);
    let mut detector_rows = Plane::zeros(width, height);
    let mut horizontal = Plane::zeros(width, height);
    let mut vertical = Plane::zeros(width, height);
    convolve_rows(luma, &k.gauss, &mut gauss_rows);
    let mut magnitude = |detector: &Kernel1D| -> Vec<f32> {
        convolve_rows(luma, detector, &mut detector_rows);
        convolve_columns(&detector_rows, &k.gauss, 1.0, false, &mut horizontal);
        convolve_columns(&gauss_rows, detector, 1.0, false, &mut vertical);
        horizontal
            .data
            .par_iter()
            .zip(vertical.data.par_iter())
            .map(|(h, v)| (h * h + v * v).sqrt())
            .collect()
    };
    let edges = magnitude(&k.edge);
    let points = magnitude(&k.point);
    (edges, points)
}

/// Runs the colour and feature pipelines on one linear RGB image.
fn perceive(linear: &[[f32; 3]], width: usize, height: usize, filters: &Filters) -> Perceived {
    let mut ycxcz = [(); 3].map(|_| Plane::zeros(width, height));
    let [y, cx, cz] = &mut ycxcz;
    y.data
        .par_iter_mut()
        .zip(cx.data.par_iter_mut())
        .zip(cz.data.par_iter_mut())
        .zip(linear.par_iter())
        .for_each(|(((y, cx), cz), rgb)| {
            let c = linear_rgb_to_ycxcz(rgb.map(|v| v.clamp(0.0, 1.0)));
            (*y, *cx, *cz) = (c[0], c[1], c[2]);
        });
    let hunt_lab = color_pipeline(&ycxcz, &filters.csf);
    // The feature pipeline sees the unfiltered achromatic channel normalised to
    // [0, 1], (Y + 16) / 116 = Y / Y_white.
    let [mut luma, _, _] = ycxcz;
    luma.data
        .par_iter_mut()
        .for_each(|y| *y = (*y + 16.0) / 116.0);
    let (edges, points) = feature_pipeline(&luma, &filters.features);
    Perceived {
        hunt_lab,
        edges,
        points,
    }
}

/// FLIP's largest colour distance: HyAB between Hunt-adjusted pure green and pure blue,
/// raised to q_c. Colour errors are expressed relative to it.
fn max_color_distance() -> f32 {
    let green = hunt_adjust(linear_rgb_to_lab([0.0, 1.0, 0.0]));
    let blue = hunt_adjust(linear_rgb_to_lab([0.0, 0.0, 1.0]));
    hyab(green, blue).powf(COLOR_EXPONENT)
}

/// Maps a colour distance (already raised to q_c) to [0, 1]: linear up to the knee
/// p_c·c_max, where it reaches p_t, then linear again to 1 at c_max. This spreads the
/// perceptually small distances over most of the error range (FLIP Sec. 3.1).
#[inline]
fn remap_color_error(distance: f32, max_distance: f32) -> f32 {
    let knee = COLOR_KNEE * max_distance;
    if distance < knee {
        distance * ERROR_AT_KNEE / knee
    } else {
        ERROR_AT_KNEE + (distance - knee) / (max_distance - knee) * (1.0 - ERROR_AT_KNEE)
    }
}

/// The LDR-FLIP error map of two linear RGB images in [0, 1] (values outside are
/// clamped), written into `errors`.
pub fn flip_linear(
    test: &[[f32; 3]],
    reference: &[[f32; 3]],
    width: usize,
    height: usize,
    filters: &Filters,
    errors: &mut [f32],
) {
    let t = perceive(test, width, height, filters);
    let r = perceive(reference, width, height, filters);
    let max_distance = max_color_distance();
    errors.par_iter_mut().enumerate().for_each(|(i, e)| {
        let color = remap_color_error(
            hyab(t.hunt_lab[i], r.hunt_lab[i]).powf(COLOR_EXPONENT),
            max_distance,
        );
        let edge_diff = (t.edges[i] - r.edges[i]).abs();
        let point_diff = (t.points[i] - r.points[i]).abs();
        // Both magnitudes are at most √2 for inputs in [0, 1], hence the 1/√2.
        let feature =
            (edge_diff.max(point_diff) * std::f32::consts::FRAC_1_SQRT_2).powf(FEATURE_EXPONENT);
        // Feature differences amplify colour differences: e = ΔE_c^(1 − ΔE_f).
        *e = color.powf(1.0 - feature).clamp(0.0, 1.0);
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn remap_is_continuous_and_spans_unit_interval() {
        let m = max_color_distance();
        assert_eq!(remap_color_error(0.0, m), 0.0);
        let knee = COLOR_KNEE * m;
        let below = remap_color_error(knee * (1.0 - 1e-6), m);
        let above = remap_color_error(knee, m);
        assert!((below - ERROR_AT_KNEE).abs() < 1e-4 && (above - ERROR_AT_KNEE).abs() < 1e-6);
        assert!((remap_color_error(m, m) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn green_versus_blue_flat_images_give_error_one() {
        let (w, h) = (8, 8);
        let green = vec![[0.0, 1.0, 0.0]; w * h];
        let blue = vec![[0.0, 0.0, 1.0]; w * h];
        let mut errors = vec![0.0; w * h];
        flip_linear(&green, &blue, w, h, &Filters::new(67.0), &mut errors);
        for e in errors {
            assert!((e - 1.0).abs() < 1e-4, "{e}");
        }
    }
}
