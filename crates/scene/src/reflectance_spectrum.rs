//! Smooth reflectance spectra for RGB values, for the places where a reflectance enters
//! light transport non-linearly and an RGB renderer and a spectral one part ways.
//!
//! A reflectance given as RGB stands for a whole spectrum. pbrt-v4 takes the smooth
//! one of Jakob & Hanika, "A Low-Dimensional Function Space for Efficient Spectral
//! Upsampling" (Computer Graphics Forum 38(2), 2019): the sigmoid of a quadratic in
//! wavelength, R(λ) = s(c0 x² + c1 x + c2) with s(z) = 1/2 + z / (2 √(1 + z²)), which
//! stays in [0, 1] and is fitted so that its colour under the D65 illuminant is the
//! RGB. One bounce gives the same colour either way; light that meets the reflectance
//! k times carries R(λ)^k, whose colour is not the RGB to the k-th power. Here x is the
//! wavelength mapped to [0, 1] over 360–830 nm, and colours are linear sRGB through
//! the CIE 1931 observer (the analytic fit of [`crate::spectrum::cie_xyz_bar`]), each
//! channel's weights normalised so that a flat spectrum projects to itself.

use std::sync::OnceLock;

use crate::spectrum::{cie_xyz_bar, xyz_to_linear_srgb};

/// CIE standard illuminant D65, relative spectral power every 10 nm from 360 to 830 nm
/// (CIE 015:2018, table 5).
const D65: [f64; 48] = [
    46.6383, 52.0891, 49.9755, 54.6482, 82.7549, 91.4860, 93.4318, 86.6823, 104.8650, 117.0080,
    117.8120, 114.8610, 115.9230, 108.8110, 109.3540, 107.8020, 104.7900, 107.6890, 104.4050,
    104.0460, 100.0000, 96.3342, 95.7880, 88.6856, 90.0062, 89.5991, 87.6987, 83.2886, 83.6992,
    80.0268, 80.2146, 82.2778, 78.2842, 69.7213, 71.6091, 74.3490, 61.6040, 69.8856, 75.0870,
    63.5927, 46.4182, 66.8054, 63.3828, 64.3040, 59.4519, 51.9590, 57.4406, 60.3125,
];
const LAMBDA_MIN: f64 = 360.0;
const LAMBDA_MAX: f64 = 830.0;
/// Wavelength nodes of the projection (midpoints of 2 nm steps).
const NODES: usize = 235;

/// The sigmoid of the quadratic with coefficients `c` (in x = (λ − 360) / 470).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothReflectance {
    pub c: [f64; 3],
}

fn sigmoid(z: f64) -> f64 {
    if z.is_infinite() {
        return if z > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + z / (2.0 * (1.0 + z * z).sqrt())
}

/// s⁻¹(y) for y in (0, 1).
fn inverse_sigmoid(y: f64) -> f64 {
    let t = 2.0 * y - 1.0;
    t / (1.0 - t * t).sqrt()
}

impl SmoothReflectance {
    /// The reflectance at `x` in [0, 1] (360–830 nm).
    pub fn at(&self, x: f64) -> f64 {
        let [a, b, c] = self.c;
        sigmoid((a * x + b) * x + c)
    }

    /// The RGB of `f(R(λ))` under D65: the colour of light that met the reflectance
    /// as `f` says (f = identity: the reflectance's own RGB).
    pub fn project(&self, f: impl Fn(f64) -> f64) -> [f64; 3] {
        let table = projection();
        let mut rgb = [0.0; 3];
        for (x, w) in table.x.iter().zip(&table.weights) {
            let v = f(self.at(*x));
            for k in 0..3 {
                rgb[k] += w[k] * v;
            }
        }
        rgb
    }

    /// The smooth spectrum whose RGB is `rgb` (each channel in [0, 1]), fitted by
    /// damped Gauss–Newton from a few starting shapes; `None` where no fit comes
    /// within 1e-5 of it (colours no reflectance of this family reaches).
    pub fn fit(rgb: [f64; 3]) -> Option<SmoothReflectance> {
        if rgb.iter().any(|v| !(0.0..=1.0).contains(v)) {
            return None;
        }
        let mean = (rgb[0] + rgb[1] + rgb[2]) / 3.0;
        if (rgb[0] - rgb[1]).abs() < 1e-9 && (rgb[1] - rgb[2]).abs() < 1e-9 {
            // Grey: a flat spectrum (the sigmoid's limits for 0 and 1).
            let z = if mean <= 0.0 {
                f64::NEG_INFINITY
            } else if mean >= 1.0 {
                f64::INFINITY
            } else {
                inverse_sigmoid(mean)
            };
            return Some(SmoothReflectance { c: [0.0, 0.0, z] });
        }
        let flat = inverse_sigmoid(mean.clamp(1e-3, 1.0 - 1e-3));
        let starts = [
            [0.0, 0.0, flat],
            [-50.0, 60.0, -10.0],
            [-100.0, 150.0, -40.0],
            [50.0, -10.0, -5.0],
            [-20.0, 40.0, -15.0],
            [20.0, -40.0, 10.0],
        ];
        let mut best: Option<(f64, SmoothReflectance)> = None;
        for start in starts {
            let (cost, fit) = gauss_newton(rgb, start);
            if best.is_none_or(|(b, _)| cost < b) {
                best = Some((cost, fit));
            }
            if cost < 1e-14 {
                break;
            }
        }
        best.filter(|(cost, _)| cost.sqrt() < 1e-5).map(|(_, f)| f)
    }
}

/// Squared residual of the fit and the fit, from `start`.
fn gauss_newton(rgb: [f64; 3], start: [f64; 3]) -> (f64, SmoothReflectance) {
    let table = projection();
    let residual = |c: [f64; 3]| {
        let got = SmoothReflectance { c }.project(|r| r);
        [got[0] - rgb[0], got[1] - rgb[1], got[2] - rgb[2]]
    };
    let cost_of = |r: [f64; 3]| r.iter().map(|v| v * v).sum::<f64>();
    let mut c = start;
    let mut r = residual(c);
    let mut cost = cost_of(r);
    let mut damping = 1e-3;
    for _ in 0..200 {
        if cost < 1e-16 {
            break;
        }
        // J[k][j] = ∂ channel k / ∂ c_j = Σ w_k s'(z) x^(2−j).
        let mut jac = [[0.0f64; 3]; 3];
        for (x, w) in table.x.iter().zip(&table.weights) {
            let z = (c[0] * x + c[1]) * x + c[2];
            let ds = 0.5 / (1.0 + z * z).powf(1.5);
            let dz = [x * x, *x, 1.0];
            for k in 0..3 {
                for j in 0..3 {
                    jac[k][j] += w[k] * ds * dz[j];
                }
            }
        }
        // (JᵀJ + λ diag(JᵀJ)) δ = −Jᵀ r (Levenberg–Marquardt).
        let mut a = [[0.0f64; 3]; 3];
        let mut g = [0.0f64; 3];
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] = (0..3).map(|k| jac[k][i] * jac[k][j]).sum();
            }
            g[i] = -(0..3).map(|k| jac[k][i] * r[k]).sum::<f64>();
        }
        let mut accepted = false;
        for _ in 0..12 {
            let mut m = a;
            for (i, row) in m.iter_mut().enumerate() {
                row[i] += damping * a[i][i].max(1e-12);
            }
            let Some(step) = solve3(m, g) else {
                damping *= 10.0;
                continue;
            };
            let next = [c[0] + step[0], c[1] + step[1], c[2] + step[2]];
            let rn = residual(next);
            let cn = cost_of(rn);
            if cn < cost {
                (c, r, cost) = (next, rn, cn);
                damping = (damping / 3.0).max(1e-9);
                accepted = true;
                break;
            }
            damping *= 4.0;
        }
        if !accepted {
            break;
        }
    }
    (cost, SmoothReflectance { c })
}

/// Cramer's rule for a 3 × 3 system; `None` when singular.
fn solve3(m: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    if d.abs() <= 1e-300 || !d.is_finite() {
        return None;
    }
    let mut out = [0.0; 3];
    for (i, o) in out.iter_mut().enumerate() {
        let mut mi = m;
        for row in 0..3 {
            mi[row][i] = b[row];
        }
        *o = det(&mi) / d;
    }
    Some(out)
}

struct Projection {
    /// Node positions in [0, 1].
    x: Vec<f64>,
    /// Linear sRGB weights of each node under D65, each channel summing to 1.
    weights: Vec<[f64; 3]>,
}

fn d65(lambda: f64) -> f64 {
    let t = ((lambda - LAMBDA_MIN) / 10.0).clamp(0.0, (D65.len() - 1) as f64);
    let i = (t.floor() as usize).min(D65.len() - 2);
    let f = t - i as f64;
    D65[i] * (1.0 - f) + D65[i + 1] * f
}

fn projection() -> &'static Projection {
    static TABLE: OnceLock<Projection> = OnceLock::new();
    TABLE.get_or_init(|| {
        let step = (LAMBDA_MAX - LAMBDA_MIN) / NODES as f64;
        let mut x = Vec::with_capacity(NODES);
        let mut weights = Vec::with_capacity(NODES);
        let mut sums = [0.0f64; 3];
        for i in 0..NODES {
            let lambda = LAMBDA_MIN + (i as f64 + 0.5) * step;
            let e = d65(lambda);
            let bar = cie_xyz_bar(lambda);
            let w = xyz_to_linear_srgb([bar[0] * e, bar[1] * e, bar[2] * e]);
            for k in 0..3 {
                sums[k] += w[k];
            }
            x.push((lambda - LAMBDA_MIN) / (LAMBDA_MAX - LAMBDA_MIN));
            weights.push(w);
        }
        for w in &mut weights {
            for k in 0..3 {
                w[k] /= sums[k];
            }
        }
        Projection { x, weights }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_reproduce_their_rgb() {
        for rgb in [
            [1.0, 0.378676, 0.013473],
            [0.05, 0.6, 0.1],
            [0.2, 0.3, 0.9],
            [0.8, 0.8, 0.1],
            [0.5, 0.5, 0.5],
            [0.0, 0.0, 0.0],
            [0.7, 0.2, 0.6],
        ] {
            let fit = SmoothReflectance::fit(rgb).unwrap_or_else(|| panic!("{rgb:?}"));
            let got = fit.project(|r| r);
            for k in 0..3 {
                assert!((got[k] - rgb[k]).abs() < 1e-5, "{rgb:?} -> {got:?}");
            }
            for i in 0..=100 {
                let r = fit.at(i as f64 / 100.0);
                assert!((0.0..=1.0).contains(&r), "{rgb:?}: R = {r}");
            }
        }
        assert!(SmoothReflectance::fit([1.2, 0.0, 0.0]).is_none());
    }

    #[test]
    fn a_flat_spectrum_projects_to_itself_whatever_the_transfer() {
        let fit = SmoothReflectance::fit([0.3, 0.3, 0.3]).unwrap();
        let got = fit.project(|r| r * r);
        for v in got {
            assert!((v - 0.09).abs() < 1e-12, "{got:?}");
        }
    }
}
