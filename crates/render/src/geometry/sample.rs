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
pub fn area_pdf_to_solid_angle(pdf_area: f32, reference: Vec3, p: Vec3, n: Vec3) -> f32 {
    let w = p - reference;
    let dist2 = w.length_squared();
    if dist2 == 0.0 {
        return 0.0;
    }
    let cos = n.dot(w).abs() / dist2.sqrt();
    if cos == 0.0 {
        return 0.0;
    }
    let pdf = pdf_area * dist2 / cos;
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
