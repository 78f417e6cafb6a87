//! Sampling domains and their equal-measure parameterizations.
//!
//! Every domain is mapped onto a parameter rectangle (column coordinate, row
//! coordinate) in which the domain's own measure has a constant density, so a regular
//! grid in parameter space is a grid of cells whose measure is known exactly:
//!
//! | domain     | column          | row              | measure per parameter area |
//! |------------|-----------------|------------------|----------------------------|
//! | sphere     | φ ∈ [0, 2π)     | cos θ ∈ [-1, 1]  | 1 (dω = d cosθ dφ, Archimedes) |
//! | hemisphere | φ ∈ [0, 2π)     | cos θ ∈ [0, 1]   | 1                          |
//! | disk       | φ ∈ [0, 2π)     | r² ∈ [0, 1]      | 1/2 (dA = r dr dφ)         |
//! | rectangle  | x ∈ [min, max]  | y ∈ [min, max]   | 1                          |
//! | interval   | x ∈ [min, max]  | (one row)        | 1                          |

use glam::{Vec2, Vec3};
use std::f64::consts::TAU;

/// A domain on which a sampling routine distributes its points. Densities are with
/// respect to the domain's natural measure: solid angle for `Sphere` and `Hemisphere`
/// (directions, `Vec3`), area for `Disk` and `Rectangle` (`Vec2`), length for
/// `Interval` (`f32`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Domain {
    /// All unit directions.
    Sphere,
    /// Unit directions with z ≥ 0 (the local shading hemisphere).
    Hemisphere,
    /// The unit disk centred at the origin.
    Disk,
    /// An axis-aligned rectangle in the plane, e.g. pixel-filter offsets in [-r, r]².
    Rectangle { min: Vec2, max: Vec2 },
    /// A closed interval of the real line.
    Interval { min: f32, max: f32 },
}

/// Which point type a domain's samples have.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointKind {
    /// `Vec3` unit directions.
    Direction,
    /// `Vec2` points in the plane.
    Planar,
    /// `f32` values on the line.
    Scalar,
}

/// Directions whose length is off 1 by more than this count as outside the domain:
/// generous for f32 round-off, tight enough to catch a missing normalization.
const DIRECTION_LENGTH_TOLERANCE: f64 = 1e-3;
/// Slack on the hemisphere's horizon and the disk's rim for f32 round-off.
const BOUNDARY_TOLERANCE: f64 = 1e-6;

impl Domain {
    /// Default grid (columns, rows): about 8k cells for directions and the disk, which
    /// 10^6 samples fill with ~120 per cell.
    pub fn default_resolution(&self) -> [usize; 2] {
        match self {
            Domain::Sphere | Domain::Hemisphere | Domain::Disk => [128, 64],
            Domain::Rectangle { .. } => [64, 64],
            Domain::Interval { .. } => [512, 1],
        }
    }

    /// Total measure of the domain (4π, 2π, π, area, length).
    pub fn measure(&self) -> f64 {
        let (c, r) = self.parameter_box();
        (c[1] - c[0]) * (r[1] - r[0]) * self.jacobian()
    }

    pub fn point_kind(&self) -> PointKind {
        match self {
            Domain::Sphere | Domain::Hemisphere => PointKind::Direction,
            Domain::Disk | Domain::Rectangle { .. } => PointKind::Planar,
            Domain::Interval { .. } => PointKind::Scalar,
        }
    }

    /// Names of the (column, row) parameters, for summaries.
    pub fn axis_names(&self) -> [&'static str; 2] {
        match self {
            Domain::Sphere | Domain::Hemisphere => ["phi", "cos theta"],
            Domain::Disk => ["phi", "r^2"],
            Domain::Rectangle { .. } => ["x", "y"],
            Domain::Interval { .. } => ["x", "-"],
        }
    }

    /// Whether the first and last columns are adjacent (the azimuth φ).
    pub(crate) fn wraps_columns(&self) -> bool {
        matches!(self, Domain::Sphere | Domain::Hemisphere | Domain::Disk)
    }

    /// Parameter ranges (column, row).
    pub(crate) fn parameter_box(&self) -> ([f64; 2], [f64; 2]) {
        match *self {
            Domain::Sphere => ([0.0, TAU], [-1.0, 1.0]),
            Domain::Hemisphere => ([0.0, TAU], [0.0, 1.0]),
            Domain::Disk => ([0.0, TAU], [0.0, 1.0]),
            Domain::Rectangle { min, max } => {
                ([min.x as f64, max.x as f64], [min.y as f64, max.y as f64])
            }
            Domain::Interval { min, max } => ([min as f64, max as f64], [0.0, 1.0]),
        }
    }

    /// Domain measure per unit parameter area (constant by construction).
    pub(crate) fn jacobian(&self) -> f64 {
        match self {
            Domain::Disk => 0.5,
            _ => 1.0,
        }
    }

    /// Whether the row axis carries information (false for the 1D interval).
    pub(crate) fn has_rows(&self) -> bool {
        !matches!(self, Domain::Interval { .. })
    }

    /// Describes why the domain cannot be gridded, if so.
    pub(crate) fn validate(&self) -> Result<(), String> {
        let ok = |a: f32, b: f32| a.is_finite() && b.is_finite() && a < b;
        match *self {
            Domain::Rectangle { min, max } if !(ok(min.x, max.x) && ok(min.y, max.y)) => Err(
                format!("rectangle needs finite min < max on both axes, got {min} .. {max}"),
            ),
            Domain::Interval { min, max } if !ok(min, max) => Err(format!(
                "interval needs finite min < max, got {min} .. {max}"
            )),
            _ => Ok(()),
        }
    }
}

fn azimuth(x: f64, y: f64) -> f64 {
    let phi = y.atan2(x);
    if phi < 0.0 { phi + TAU } else { phi }
}

/// Clamps `v` into [lo, hi] when it lies within `slack` outside; None when further out.
fn clamp_with_slack(v: f64, lo: f64, hi: f64, slack: f64) -> Option<f64> {
    if v < lo - slack || v > hi + slack {
        None
    } else {
        Some(v.clamp(lo, hi))
    }
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for glam::Vec3 {}
    impl Sealed for glam::Vec2 {}
    impl Sealed for f32 {}
}

/// The point types a sampler may return: `Vec3` for directions, `Vec2` for planar
/// domains, `f32` for intervals. Implemented for exactly those three types.
pub trait DomainPoint: Copy + std::fmt::Debug + sealed::Sealed {
    const KIND: PointKind;

    /// Parameter coordinates (column, row) of the point, or None when it lies outside
    /// the domain (or the domain has another point type).
    #[doc(hidden)]
    fn parameters(self, domain: &Domain) -> Option<[f64; 2]>;

    /// The point at parameter coordinates (column, row).
    #[doc(hidden)]
    fn at_parameters(domain: &Domain, p: [f64; 2]) -> Self;
}

impl DomainPoint for Vec3 {
    const KIND: PointKind = PointKind::Direction;

    fn parameters(self, domain: &Domain) -> Option<[f64; 2]> {
        let lower = match domain {
            Domain::Sphere => -1.0,
            Domain::Hemisphere => 0.0,
            _ => return None,
        };
        let d = self.as_dvec3();
        let len = d.length();
        if !len.is_finite() || (len - 1.0).abs() > DIRECTION_LENGTH_TOLERANCE {
            return None;
        }
        let z = clamp_with_slack(d.z / len, lower, 1.0, BOUNDARY_TOLERANCE)?;
        Some([azimuth(d.x, d.y), z])
    }

    fn at_parameters(_domain: &Domain, p: [f64; 2]) -> Vec3 {
        let [phi, z] = p;
        let s = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32)
    }
}

impl DomainPoint for Vec2 {
    const KIND: PointKind = PointKind::Planar;

    fn parameters(self, domain: &Domain) -> Option<[f64; 2]> {
        let p = self.as_dvec2();
        if !p.is_finite() {
            return None;
        }
        match *domain {
            Domain::Disk => {
                let r2 = clamp_with_slack(p.length_squared(), 0.0, 1.0, BOUNDARY_TOLERANCE)?;
                Some([azimuth(p.x, p.y), r2])
            }
            Domain::Rectangle { .. } => {
                let (c, r) = domain.parameter_box();
                let x = clamp_with_slack(p.x, c[0], c[1], BOUNDARY_TOLERANCE * (c[1] - c[0]))?;
                let y = clamp_with_slack(p.y, r[0], r[1], BOUNDARY_TOLERANCE * (r[1] - r[0]))?;
                Some([x, y])
            }
            _ => None,
        }
    }

    fn at_parameters(domain: &Domain, p: [f64; 2]) -> Vec2 {
        match domain {
            Domain::Disk => {
                let r = p[1].max(0.0).sqrt();
                Vec2::new((r * p[0].cos()) as f32, (r * p[0].sin()) as f32)
            }
            _ => Vec2::new(p[0] as f32, p[1] as f32),
        }
    }
}

impl DomainPoint for f32 {
    const KIND: PointKind = PointKind::Scalar;

    fn parameters(self, domain: &Domain) -> Option<[f64; 2]> {
        match domain {
            Domain::Interval { .. } => {
                let (c, _) = domain.parameter_box();
                let x = self as f64;
                if !x.is_finite() {
                    return None;
                }
                let x = clamp_with_slack(x, c[0], c[1], BOUNDARY_TOLERANCE * (c[1] - c[0]))?;
                Some([x, 0.5])
            }
            _ => None,
        }
    }

    fn at_parameters(_domain: &Domain, p: [f64; 2]) -> f32 {
        p[0] as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn measures_are_the_textbook_ones() {
        let pi = std::f64::consts::PI;
        assert!((Domain::Sphere.measure() - 4.0 * pi).abs() < 1e-12);
        assert!((Domain::Hemisphere.measure() - 2.0 * pi).abs() < 1e-12);
        assert!((Domain::Disk.measure() - pi).abs() < 1e-12);
        let rect = Domain::Rectangle {
            min: Vec2::new(-1.0, -0.5),
            max: Vec2::new(2.0, 0.5),
        };
        assert!((rect.measure() - 3.0).abs() < 1e-12);
        let interval = Domain::Interval {
            min: -1.0,
            max: 3.0,
        };
        assert!((interval.measure() - 4.0).abs() < 1e-12);
    }

    #[test]
    fn parameters_round_trip() {
        let domains = [Domain::Sphere, Domain::Hemisphere];
        for d in domains {
            for &p in &[[0.3, 0.2], [5.0, 0.9], [3.1, 0.01]] {
                let v = Vec3::at_parameters(&d, p);
                let q = v.parameters(&d).unwrap();
                assert!((q[0] - p[0]).abs() < 1e-5 && (q[1] - p[1]).abs() < 1e-6);
            }
        }
        let v = Vec2::at_parameters(&Domain::Disk, [4.0, 0.25]);
        assert!((v.length() - 0.5).abs() < 1e-6);
        let q = v.parameters(&Domain::Disk).unwrap();
        assert!((q[0] - 4.0).abs() < 1e-5 && (q[1] - 0.25).abs() < 1e-6);
    }

    #[test]
    fn points_outside_are_rejected() {
        assert!(
            Vec3::new(0.0, 0.6, -0.8)
                .parameters(&Domain::Hemisphere)
                .is_none()
        );
        assert!(
            Vec3::new(0.0, 0.6, 0.8)
                .parameters(&Domain::Hemisphere)
                .is_some()
        );
        assert!(
            Vec3::new(0.0, 0.0, 1.1)
                .parameters(&Domain::Sphere)
                .is_none()
        );
        assert!(
            Vec3::new(f32::NAN, 0.0, 1.0)
                .parameters(&Domain::Sphere)
                .is_none()
        );
        assert!(Vec2::new(0.8, 0.8).parameters(&Domain::Disk).is_none());
        let rect = Domain::Rectangle {
            min: Vec2::splat(-1.0),
            max: Vec2::splat(1.0),
        };
        assert!(Vec2::new(1.0, -1.0).parameters(&rect).is_some());
        assert!(Vec2::new(1.01, 0.0).parameters(&rect).is_none());
        let interval = Domain::Interval { min: 0.0, max: 1.0 };
        assert!(1.5f32.parameters(&interval).is_none());
        assert!(Vec2::ZERO.parameters(&Domain::Sphere).is_none());
    }

    #[test]
    fn degenerate_boxes_are_invalid() {
        let bad = Domain::Rectangle {
            min: Vec2::ONE,
            max: Vec2::new(2.0, 1.0),
        };
        assert!(bad.validate().is_err());
        assert!(
            Domain::Interval {
                min: 1.0,
                max: f32::NAN
            }
            .validate()
            .is_err()
        );
        assert!(Domain::Sphere.validate().is_ok());
    }
}
