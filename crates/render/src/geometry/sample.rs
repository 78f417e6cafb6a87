//! What every shape's sampling routine returns, and the change of measure between
//! area and solid angle that light sampling needs.

use glam::Vec3;

/// A point sampled on a surface with density `pdf` per unit area.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaSample {
    pub p: Vec3,
    /// Bound on the error of `p` per component (for moving ray ends off the surface).
    pub p_error: Vec3,
    /// Unit geometric normal at `p` (the shape's outward / +z side).
    pub n: Vec3,
    /// Density with respect to surface area.
    pub pdf: f32,
}

/// A point sampled on a surface as seen from a reference point, with density `pdf`
/// per unit solid angle at the reference point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolidAngleSample {
    pub p: Vec3,
    /// Bound on the error of `p` per component.
    pub p_error: Vec3,
    /// Unit geometric normal at `p`.
    pub n: Vec3,
    /// Unit direction from the reference point towards `p`.
    pub wi: Vec3,
    /// Density with respect to solid angle at the reference point.
    pub pdf: f32,
}

/// Converts a density per unit area at `p` (normal `n`) into a density per unit solid
/// angle seen from `reference`: dω = |cos θ| dA / r², so p_ω = p_A r² / |cos θ|.
/// Returns 0 where the conversion is degenerate (coincident points, grazing sample),
/// i.e. where the sample cannot carry any contribution.
///
/// With |cos θ| = |n · w| / r for w = p − reference, that is p_A r² · (r / |n · w|):
/// one division after the square root instead of two (a light sample's direction waits
/// on this density).
pub fn area_pdf_to_solid_angle(pdf_area: f32, reference: Vec3, p: Vec3, n: Vec3) -> f32 {
    let w = p - reference;
    let dist2 = w.length_squared();
    let n_dot_w = n.dot(w).abs();
    if dist2 == 0.0 || n_dot_w == 0.0 {
        return 0.0;
    }
    let pdf = (pdf_area * dist2) * (dist2.sqrt() / n_dot_w);
    if pdf.is_finite() { pdf } else { 0.0 }
}

/// Turns an area sample into a solid-angle sample as seen from `reference`
/// (`None` when the conversion is degenerate).
pub fn area_to_solid_angle_sample(s: AreaSample, reference: Vec3) -> Option<SolidAngleSample> {
    let pdf = area_pdf_to_solid_angle(s.pdf, reference, s.p, s.n);
    if pdf == 0.0 {
        return None;
    }
    Some(SolidAngleSample {
        p: s.p,
        p_error: s.p_error,
        n: s.n,
        wi: (s.p - reference).normalize(),
        pdf,
    })
}

/// Errors in shape parameters, for the scene parser to report with a location.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ShapeError {
    #[error("radius must be positive and finite, got {0}")]
    BadRadius(f32),
    #[error("inner radius {inner} must lie in [0, radius {radius})")]
    BadInnerRadius { inner: f32, radius: f32 },
    #[error("zmin {z_min} and zmax {z_max} leave no part of a sphere of radius {radius}")]
    EmptyZRange { z_min: f32, z_max: f32, radius: f32 },
    #[error("phimax must lie in (0, 360] degrees, got {0}")]
    BadPhiMax(f32),
}

#[cfg(test)]
mod tests {
    use super::*;

    /// p_A r² / |cos θ| at points seen head-on, obliquely and from behind, at scales
    /// from 10⁻³ to 10⁶, against the same formula in f64; 0 where degenerate.
    #[test]
    fn area_density_becomes_solid_angle_density() {
        for scale in [1e-3f32, 1.0, 1e6] {
            let reference = Vec3::new(0.3, -0.2, 0.1) * scale;
            for (offset, n) in [
                (Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 0.0, -1.0)),
                (Vec3::new(1.0, 0.5, 2.0), Vec3::new(0.6, 0.0, -0.8)),
                (Vec3::new(-3.0, 1.0, 0.5), Vec3::new(0.0, 1.0, 0.0)),
            ] {
                let p = reference + offset * scale;
                let pdf_area = 0.25 / (scale * scale);
                let w = (p - reference).as_dvec3();
                let r2 = w.length_squared();
                let cos = n.as_dvec3().dot(w).abs() / r2.sqrt();
                let expected = pdf_area as f64 * r2 / cos;
                let got = area_pdf_to_solid_angle(pdf_area, reference, p, n) as f64;
                assert!(
                    (got - expected).abs() <= 1e-5 * expected,
                    "scale {scale}, offset {offset}: {got} against {expected}"
                );
            }
            let grazing = reference + Vec3::new(1.0, 0.0, 0.0) * scale;
            assert_eq!(
                area_pdf_to_solid_angle(1.0, reference, grazing, Vec3::Z),
                0.0
            );
            assert_eq!(
                area_pdf_to_solid_angle(1.0, reference, reference, Vec3::Z),
                0.0
            );
        }
    }
}
