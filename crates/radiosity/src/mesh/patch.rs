//! Patches: the planar elements of the radiosity method, and the set they live in.
//!
//! A patch is a planar convex triangle or quad whose corners are indices into a shared
//! point list, so a meshed surface can share vertices between neighbouring patches
//! (needed later for vertex radiosities and Gouraud display). Geometry is shared by
//! the three colour bands; emission `E` and reflectance `rho` are per band.

use glam::{DVec3, Vec3};
use radiant_render::geometry::SurfacePoint;
use radiant_render::geometry::ray::gamma;
use thiserror::Error;

/// Why a patch was rejected.
#[derive(Debug, Error, PartialEq)]
pub enum PatchError {
    #[error("a patch needs 3 or 4 corners, got {0}")]
    CornerCount(usize),
    #[error("corner index {index} is out of range ({points} points)")]
    CornerIndex { index: u32, points: usize },
    #[error("patch is degenerate (area {0:e})")]
    Degenerate(f64),
    #[error("quad is not planar (corner off the plane by {0:e} of its size)")]
    NonPlanar(f64),
    #[error("quad is not convex or its corners are not in order")]
    NonConvex,
    #[error("emission {0:?} must be finite and non-negative")]
    Emission([f64; 3]),
    #[error("reflectance {0:?} must lie in [0, 1]")]
    Reflectance([f64; 3]),
}

/// One planar patch. Corners are counter-clockwise seen from the front (the side the
/// normal points to); only the front side emits and reflects.
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    /// Indices into [`PatchSet::points`]; the first `corner_count` are used.
    pub corners: [u32; 4],
    /// 3 (triangle) or 4 (quad).
    pub corner_count: u8,
    /// Unit normal, `normalize((v1 - v0) x (v2 - v0))`.
    pub normal: DVec3,
    pub area: f64,
    pub centroid: DVec3,
    /// Exitance E per band (W/m^2, radiance times pi for a Lambertian emitter).
    pub emission: [f64; 3],
    /// Diffuse reflectance rho per band.
    pub reflectance: [f64; 3],
}

/// The corner positions of one patch, copied out of the shared point list.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polygon {
    pub corners: [DVec3; 4],
    pub count: usize,
}

impl Polygon {
    /// The used corners.
    pub fn as_slice(&self) -> &[DVec3] {
        &self.corners[..self.count]
    }
}

/// All patches of a scene with their shared corner points.
#[derive(Clone, Debug, Default)]
pub struct PatchSet {
    pub points: Vec<DVec3>,
    pub patches: Vec<Patch>,
}

/// Relative tolerance for planarity of quads (distance of the fourth corner from the
/// plane of the first three, over the quad's diameter).
const PLANARITY_TOLERANCE: f64 = 1e-6;

impl PatchSet {
    /// An empty set.
    pub fn new() -> PatchSet {
        PatchSet::default()
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.patches.len()
    }

    /// True when there are no patches.
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// Appends a shared point and returns its index.
    pub fn add_point(&mut self, p: DVec3) -> u32 {
        self.points.push(p);
        (self.points.len() - 1) as u32
    }

    /// Adds a patch over existing points (3 or 4 indices, counter-clockwise seen from
    /// the front) and returns its index.
    pub fn add_patch(
        &mut self,
        corner_indices: &[u32],
        emission: [f64; 3],
        reflectance: [f64; 3],
    ) -> Result<usize, PatchError> {
        let count = corner_indices.len();
        if !(3..=4).contains(&count) {
            return Err(PatchError::CornerCount(count));
        }
        let mut corners = [0u32; 4];
        let mut positions = [DVec3::ZERO; 4];
        for (k, &index) in corner_indices.iter().enumerate() {
            let p = self
                .points
                .get(index as usize)
                .ok_or(PatchError::CornerIndex {
                    index,
                    points: self.points.len(),
                })?;
            corners[k] = index;
            positions[k] = *p;
        }
        if !emission.iter().all(|e| e.is_finite() && *e >= 0.0) {
            return Err(PatchError::Emission(emission));
        }
        if !reflectance.iter().all(|r| (0.0..=1.0).contains(r)) {
            return Err(PatchError::Reflectance(reflectance));
        }
        let shape = polygon_shape(&positions[..count])?;
        self.patches.push(Patch {
            corners,
            corner_count: count as u8,
            normal: shape.normal,
            area: shape.area,
            centroid: shape.centroid,
            emission,
            reflectance,
        });
        Ok(self.patches.len() - 1)
    }

    /// Adds a patch with its own (unshared) corner points.
    pub fn add_polygon(
        &mut self,
        corners: &[DVec3],
        emission: [f64; 3],
        reflectance: [f64; 3],
    ) -> Result<usize, PatchError> {
        if !(3..=4).contains(&corners.len()) {
            return Err(PatchError::CornerCount(corners.len()));
        }
        let first = self.points.len() as u32;
        self.points.extend_from_slice(corners);
        let indices: Vec<u32> = (first..first + corners.len() as u32).collect();
        let added = self.add_patch(&indices, emission, reflectance);
        if added.is_err() {
            self.points.truncate(first as usize);
        }
        added
    }

    /// Patch `i`'s point `p` (with normal `n`) as a place rays start from or end at, in
    /// the renderer's f32, with the error bound [`point_error`](Self::point_error).
    pub fn surface_point(&self, i: usize, p: DVec3, n: Vec3) -> SurfacePoint {
        SurfacePoint::new(p.as_vec3(), self.point_error(i), n)
    }

    /// How far a point of patch `i` rounded to f32 may lie off the renderer's surface, per
    /// component. The renderer's triangles are the patch's faces rounded to f32, and the
    /// point is rounded once more, so it may lie off them by a few ulps of the largest
    /// corner coordinate (not of the point's own, which may be near zero on a tilted
    /// face): γ₄ of the corners' magnitudes, which also bound every point inside.
    pub fn point_error(&self, i: usize) -> Vec3 {
        let reach = self
            .polygon(i)
            .as_slice()
            .iter()
            .fold(DVec3::ZERO, |m, c| m.max(c.abs()));
        gamma(4) * reach.as_vec3()
    }

    /// The corner positions of patch `i`.
    #[inline]
    pub fn polygon(&self, i: usize) -> Polygon {
        let patch = &self.patches[i];
        let mut corners = [DVec3::ZERO; 4];
        for (k, corner) in corners
            .iter_mut()
            .enumerate()
            .take(patch.corner_count as usize)
        {
            *corner = self.points[patch.corners[k] as usize];
        }
        Polygon {
            corners,
            count: patch.corner_count as usize,
        }
    }

    /// Sum of the patch areas.
    pub fn total_area(&self) -> f64 {
        self.patches.iter().map(|p| p.area).sum()
    }

    /// Total emitted power per band, sum of `A_i E_i`.
    pub fn emitted_power(&self) -> [f64; 3] {
        let mut power = [0.0; 3];
        for p in &self.patches {
            for (b, pw) in power.iter_mut().enumerate() {
                *pw += p.area * p.emission[b];
            }
        }
        power
    }
}

/// Normal, area and centroid of a planar polygon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolygonShape {
    pub normal: DVec3,
    pub area: f64,
    pub centroid: DVec3,
}

/// Validates a triangle or convex planar quad and returns its shape. The normal follows
/// the convention `normalize((v1 - v0) x (v2 - v0))`; the area and centroid come from
/// the fan of triangles around `v0`.
pub fn polygon_shape(corners: &[DVec3]) -> Result<PolygonShape, PatchError> {
    let count = corners.len();
    if !(3..=4).contains(&count) {
        return Err(PatchError::CornerCount(count));
    }
    let v0 = corners[0];
    let mut area_vector = DVec3::ZERO;
    let mut weighted_centre = DVec3::ZERO;
    for k in 1..count - 1 {
        let doubled = (corners[k] - v0).cross(corners[k + 1] - v0);
        // Triangles of the fan must all turn the same way for a convex quad.
        if k > 1 && doubled.dot(area_vector) <= 0.0 {
            return Err(PatchError::NonConvex);
        }
        area_vector += doubled;
        weighted_centre += doubled.length() * (v0 + corners[k] + corners[k + 1]) / 3.0;
    }
    let doubled_area = area_vector.length();
    let diameter = corners
        .iter()
        .map(|c| (*c - v0).length())
        .fold(0.0, f64::max);
    // Written so that a NaN area is rejected too.
    let large_enough = doubled_area > 1e-14 * diameter * diameter;
    if !large_enough || !doubled_area.is_finite() {
        return Err(PatchError::Degenerate(doubled_area / 2.0));
    }
    let normal = (corners[1] - v0).cross(corners[2] - v0).normalize();
    if count == 4 {
        let off_plane = (corners[3] - v0).dot(normal).abs() / diameter;
        if off_plane > PLANARITY_TOLERANCE {
            return Err(PatchError::NonPlanar(off_plane));
        }
        // Convexity at every corner: consecutive edges turn the same way as the normal.
        for k in 0..4 {
            let a = corners[k];
            let b = corners[(k + 1) % 4];
            let c = corners[(k + 2) % 4];
            if (b - a).cross(c - b).dot(normal) <= 0.0 {
                return Err(PatchError::NonConvex);
            }
        }
    }
    Ok(PolygonShape {
        normal,
        area: doubled_area / 2.0,
        centroid: weighted_centre / doubled_area,
    })
}

/// A regular `sides`-gon with the same area as the disk of `radius` about `centre`
/// (counter-clockwise seen from the side `normal` points to). Disks are not patches;
/// this helper stands in for them in tests against disk form factors.
pub fn equal_area_disk_polygon(
    centre: DVec3,
    normal: DVec3,
    radius: f64,
    sides: usize,
) -> Vec<DVec3> {
    let n = normal.normalize();
    let (s, t) = tangent_frame(n);
    let wedge = std::f64::consts::TAU / sides as f64;
    // Area of a regular polygon with circumradius R: (sides/2) R^2 sin(wedge).
    let circumradius = radius * (std::f64::consts::TAU / (sides as f64 * wedge.sin())).sqrt();
    (0..sides)
        .map(|k| {
            let phi = wedge * k as f64;
            centre + circumradius * (phi.cos() * s + phi.sin() * t)
        })
        .collect()
}

/// An orthonormal tangent pair `(s, t)` with `s x t = n`, chosen from the world axis
/// least aligned with `n` so that axis-aligned normals get axis-aligned tangents
/// (keeps hemi-cube grids aligned with axis-aligned walls).
pub fn tangent_frame(n: DVec3) -> (DVec3, DVec3) {
    let a = n.abs();
    let axis = if a.x <= a.y && a.x <= a.z {
        DVec3::X
    } else if a.y <= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let s = (axis - n * n.dot(axis)).normalize();
    (s, n.cross(s))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_shape_matches_hand_computation() {
        // Trapezoid with parallel sides a = 2 (bottom) and b = 1, height h = 1: area
        // 1.5, centroid h (a + 2b) / (3 (a + b)) = 4/9 above the bottom side.
        let quad = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(1.5, 1.0, 0.0),
            DVec3::new(0.5, 1.0, 0.0),
        ];
        let shape = polygon_shape(&quad).unwrap();
        assert!((shape.area - 1.5).abs() < 1e-15);
        assert!((shape.normal - DVec3::Z).length() < 1e-15);
        assert!((shape.centroid - DVec3::new(1.0, 4.0 / 9.0, 0.0)).length() < 1e-15);
    }

    #[test]
    fn bad_patches_are_rejected() {
        let mut set = PatchSet::new();
        let square = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        assert!(set.add_polygon(&square, [0.0; 3], [0.5; 3]).is_ok());
        let bowtie = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
        assert_eq!(
            set.add_polygon(&bowtie, [0.0; 3], [0.5; 3]),
            Err(PatchError::NonConvex)
        );
        let warped = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.1), DVec3::Y];
        assert!(matches!(
            set.add_polygon(&warped, [0.0; 3], [0.5; 3]),
            Err(PatchError::NonPlanar(_))
        ));
        let line = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
        assert!(matches!(
            set.add_polygon(&line, [0.0; 3], [0.5; 3]),
            Err(PatchError::Degenerate(_))
        ));
        assert_eq!(
            set.add_polygon(&square, [0.0; 3], [1.5, 0.0, 0.0]),
            Err(PatchError::Reflectance([1.5, 0.0, 0.0]))
        );
        assert_eq!(
            set.add_patch(&[0, 1, 9], [0.0; 3], [0.5; 3]),
            Err(PatchError::CornerIndex {
                index: 9,
                points: 4
            })
        );
        // Failed additions leave no stray points behind.
        assert_eq!(set.points.len(), 4);
        assert_eq!(set.len(), 1);
    }

    #[test]
    fn disk_polygon_has_the_disk_area() {
        let poly = equal_area_disk_polygon(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0), 2.0, 64);
        let mut doubled = DVec3::ZERO;
        for k in 0..poly.len() {
            doubled += poly[k].cross(poly[(k + 1) % poly.len()]);
        }
        assert!((doubled.length() / 2.0 - std::f64::consts::PI * 4.0).abs() < 1e-12);
        // Counter-clockwise about the requested normal.
        assert!(doubled.z < 0.0);
    }
}
