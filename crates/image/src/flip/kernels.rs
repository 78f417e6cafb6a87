//! The spatial filters of FLIP (Andersson et al. 2020, Sec. 3.1 and 3.2), built as
//! 1-D factors for separable convolution.

use crate::flip::convolve::Kernel1D;
use std::f64::consts::PI;

/// One term a·√(π/b)·exp(−π²x²/b) of a contrast sensitivity function in the spatial
/// domain, x in degrees of visual angle. It is the inverse Fourier transform of the
/// frequency-domain Gaussian a·exp(−b·ρ²) that FLIP fits to each channel's CSF
/// (Sec. 3.1, following Johnson & Fairchild).
#[derive(Clone, Copy, Debug)]
struct CsfTerm {
    a: f64,
    b: f64,
}

/// CSF parameters per YCxCz channel (FLIP Table 1): achromatic, red–green, blue–yellow.
/// The achromatic and red–green CSFs are single Gaussians (their second amplitude is 0).
const CSF_TERMS: [[CsfTerm; 2]; 3] = [
    [CsfTerm { a: 1.0, b: 0.0047 }, CsfTerm { a: 0.0, b: 1e-5 }],
    [CsfTerm { a: 1.0, b: 0.0053 }, CsfTerm { a: 0.0, b: 1e-5 }],
    [CsfTerm { a: 34.1, b: 0.04 }, CsfTerm { a: 13.5, b: 0.025 }],
];

/// The widest Gaussian among all CSF terms; it sets one common filter radius.
const CSF_B_MAX: f64 = 0.04;

/// Width of the feature detectors in degrees (FLIP Sec. 3.2): σ = ½·w·ppd pixels.
const FEATURE_WIDTH_DEGREES: f64 = 0.082;

/// A 2-D CSF filter as a weighted sum of separable Gaussians: Σ wᵢ·(kᵢ ⊗ kᵢ), with
/// each kᵢ summing to 1 and Σ wᵢ = 1, so that the 2-D filter has unit DC gain and a
/// flat image passes unchanged.
#[derive(Clone, Debug)]
pub struct CsfFilter {
    pub terms: Vec<(f32, Kernel1D)>,
}

/// The CSF filters for the Y, Cx and Cz channels at the given pixels per degree.
pub fn csf_filters(pixels_per_degree: f32) -> [CsfFilter; 3] {
    let ppd = pixels_per_degree as f64;
    // Three standard deviations of the widest Gaussian, σ = √(b/(2π²)) degrees.
    let radius = (3.0 * (CSF_B_MAX / (2.0 * PI * PI)).sqrt() * ppd).ceil() as usize;
    CSF_TERMS.map(|terms| {
        let mut parts: Vec<(f64, Vec<f64>)> = Vec::new();
        for term in terms.iter().filter(|t| t.a > 0.0) {
            let samples: Vec<f64> = (-(radius as isize)..=radius as isize)
                .map(|i| {
                    let x = i as f64 / ppd;
                    (-PI * PI * x * x / term.b).exp()
                })
                .collect();
            let sum: f64 = samples.iter().sum();
            // Weight of this term in the 2-D kernel before normalisation:
            // amplitude times the 2-D sum of its samples.
            let mass = term.a * (PI / term.b).sqrt() * sum * sum;
            parts.push((mass, samples.iter().map(|s| s / sum).collect()));
        }
        let total: f64 = parts.iter().map(|(m, _)| m).sum();
        CsfFilter {
            terms: parts
                .into_iter()
                .map(|(mass, k)| {
                    let weights = k.into_iter().map(|v| v as f32).collect();
                    ((mass / total) as f32, Kernel1D { weights })
                })
                .collect(),
        }
    })
}

/// 1-D factors of the feature detectors: the 2-D edge filter is `edge ⊗ gauss` (and
/// its transpose), the 2-D point filter is `point ⊗ gauss` (and its transpose).
#[derive(Clone, Debug)]
pub struct FeatureKernels {
    /// Gaussian, summing to 1.
    pub gauss: Kernel1D,
    /// First derivative of the Gaussian, positive and negative weights each summing to ±1.
    pub edge: Kernel1D,
    /// Second derivative of the Gaussian, positive and negative weights each summing to ±1.
    pub point: Kernel1D,
}

/// Scales the positive weights to sum to 1 and the negative ones to sum to −1, as FLIP
/// does for its detectors, so that responses are comparable across resolutions.
fn normalize_signed(v: &[f64]) -> Kernel1D {
    let pos: f64 = v.iter().filter(|x| **x > 0.0).sum();
    let neg: f64 = -v.iter().filter(|x| **x < 0.0).sum::<f64>();
    Kernel1D {
        weights: v
            .iter()
            .map(|&x| {
                if x > 0.0 {
                    (x / pos) as f32
                } else if x < 0.0 {
                    (x / neg) as f32
                } else {
                    0.0
                }
            })
            .collect(),
    }
}

/// Edge and point detector factors at the given pixels per degree.
pub fn feature_kernels(pixels_per_degree: f32) -> FeatureKernels {
    let sigma = 0.5 * FEATURE_WIDTH_DEGREES * pixels_per_degree as f64;
    let radius = (3.0 * sigma).ceil() as isize;
    let xs: Vec<f64> = (-radius..=radius).map(|i| i as f64).collect();
    let g: Vec<f64> = xs
        .iter()
        .map(|x| (-x * x / (2.0 * sigma * sigma)).exp())
        .collect();
    let g_sum: f64 = g.iter().sum();
    let gauss = Kernel1D {
        weights: g.iter().map(|v| (v / g_sum) as f32).collect(),
    };
    let edge: Vec<f64> = xs.iter().zip(&g).map(|(x, g)| -x * g).collect();
    let point: Vec<f64> = xs
        .iter()
        .zip(&g)
        .map(|(x, g)| (x * x / (sigma * sigma) - 1.0) * g)
        .collect();
    FeatureKernels {
        gauss,
        edge: normalize_signed(&edge),
        point: normalize_signed(&point),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csf_filters_have_unit_gain() {
        for filter in csf_filters(67.0) {
            let w: f32 = filter.terms.iter().map(|(w, _)| w).sum();
            assert!((w - 1.0).abs() < 1e-6);
            for (_, k) in &filter.terms {
                let s: f32 = k.weights.iter().sum();
                assert!((s - 1.0).abs() < 1e-5);
                assert_eq!(k.weights.len() % 2, 1);
            }
        }
    }

    #[test]
    fn csf_radius_at_67_ppd() {
        // 3·√(0.04/(2π²))·67 = 9.05 → 10 pixels.
        let f = csf_filters(67.0);
        assert_eq!(f[0].terms[0].1.radius(), 10);
        assert_eq!(f[2].terms.len(), 2);
    }

    #[test]
    fn feature_kernels_are_normalized() {
        let k = feature_kernels(67.0);
        // σ = 0.5·0.082·67 = 2.747 → radius 9.
        assert_eq!(k.gauss.radius(), 9);
        for kern in [&k.edge, &k.point] {
            let pos: f32 = kern.weights.iter().filter(|w| **w > 0.0).sum();
            let neg: f32 = kern.weights.iter().filter(|w| **w < 0.0).sum();
            assert!((pos - 1.0).abs() < 1e-5 && (neg + 1.0).abs() < 1e-5);
        }
        // The edge filter is odd, the point filter even.
        let n = k.edge.weights.len();
        for i in 0..n {
            assert!((k.edge.weights[i] + k.edge.weights[n - 1 - i]).abs() < 1e-6);
            assert!((k.point.weights[i] - k.point.weights[n - 1 - i]).abs() < 1e-6);
        }
    }
}
