//! The exact form factor from a differential area to a polygon (Lambert's contour
//! formula), and the cheap disk approximation used in the far field.
//!
//! Derivation. From a point `x` with unit normal `n`, the factor to a surface `A` is
//! `F = (1/pi) Integral_A cos(theta) cos(theta') / r^2 dA = (1/pi) Integral_Omega (n . w) dw`,
//! the projected solid angle over pi (Nusselt's analogue). The integrand `n . w` is the
//! curl-free part of a field on the unit sphere, and Stokes' theorem turns the solid
//! angle integral into a sum over the polygon's edges (Lambert 1760; see Baum, Rushmeier
//! & Winget, "Improving Radiosity Solutions Through the Use of Analytically Determined
//! Form-Factors", SIGGRAPH 1989, and Siegel & Howell, "Thermal Radiation Heat Transfer"):
//!
//! `F = (1 / 2 pi) * sum_k gamma_k * n . (R_k x R_k+1) / |R_k x R_k+1|`
//!
//! with `R_k = v_k - x` and `gamma_k = atan2(|R_k x R_k+1|, R_k . R_k+1)` the angle the
//! edge subtends at `x`. The formula is exact for any planar polygon, but only for the
//! part above the tangent plane of `x` (below it `n . w < 0` would count negatively), so
//! the polygon is first clipped to the half-space `n . (p - x) >= 0` (Sutherland &
//! Hodgman, "Reentrant Polygon Clipping", CACM 1974). Edges lying in the tangent plane are
//! part of the clipped boundary and contribute correctly (they trace the horizon).
//! Polygons are counter-clockwise seen from their front; seen from a point in front of
//! them the sum above is negative, hence the sign below.

use glam::DVec3;

/// Heights above a polygon's plane, relative to the size of the configuration, below
/// which a point counts as lying in the plane: far above the rounding of points shared
/// by a patch and its back twin (1e-15 relative), far below the heights graded
/// quadrature reaches next to a shared edge (1e-7 of a patch), where a perpendicular
/// neighbour still fills half the hemisphere.
const IN_PLANE: f64 = 1e-9;

/// Exact form factor from a differential area at `x` with unit normal `n` to the planar
/// polygon `corners` (counter-clockwise seen from the side `polygon_normal` points to).
/// Zero when `x` is behind or in the polygon's plane. Visibility is not considered.
pub fn point_polygon_factor(x: DVec3, n: DVec3, corners: &[DVec3], polygon_normal: DVec3) -> f64 {
    if corners.len() < 3 {
        return 0.0;
    }
    // A point in the polygon's plane sees none of it. The test must allow for
    // rounding: a point on the back twin of a two-sided patch (the same corners in
    // reverse order) lies in the plane only up to rounding, and with a positive height
    // of 1e-13 the clipped contour closes around the whole polygon and gives F = 1,
    // so every two-sided patch sent all its light to its own back side (a row sum of
    // about 2 and a diverging solve). Distinct faces that meet in a plane up to the
    // f32 rounding of their input (a box's bottom on the floor) are cut off as
    // contacts by the visibility instead (`visibility::contact`).
    if !in_front_of(x, corners, polygon_normal) {
        return 0.0;
    }
    let mut contour = ContourSum::new(n);
    let m = corners.len();
    let mut a = corners[m - 1] - x;
    let mut height_a = n.dot(a);
    for corner in corners {
        let b = *corner - x;
        let height_b = n.dot(b);
        // Sutherland-Hodgman against the tangent plane, streamed: emit the crossing
        // point of edge a->b if it crosses, then b if it is above.
        if (height_a >= 0.0) != (height_b >= 0.0) {
            let t = height_a / (height_a - height_b);
            contour.push(a + (b - a) * t);
        }
        if height_b >= 0.0 {
            contour.push(b);
        }
        a = b;
        height_a = height_b;
    }
    (-contour.finish() / std::f64::consts::TAU).clamp(0.0, 1.0)
}

/// True when `x` lies in front of the plane of the polygon `corners` (at least three,
/// facing `polygon_normal`) by more than rounding: heights under [`IN_PLANE`] of the
/// configuration's size count as in the plane, so a point on a patch's back twin does
/// not see its front.
pub(crate) fn in_front_of(x: DVec3, corners: &[DVec3], polygon_normal: DVec3) -> bool {
    let offset = x - corners[0];
    let scale = offset.length() + (corners[1] - corners[0]).length();
    offset.dot(polygon_normal) > IN_PLANE * scale
}

/// Running sum of `gamma_k n . c_k / |c_k|` over the edges of a vertex stream (vertices
/// relative to the receiving point), closed back to the first vertex at the end.
struct ContourSum {
    n: DVec3,
    first: DVec3,
    previous: DVec3,
    started: bool,
    sum: f64,
}

impl ContourSum {
    fn new(n: DVec3) -> ContourSum {
        ContourSum {
            n,
            first: DVec3::ZERO,
            previous: DVec3::ZERO,
            started: false,
            sum: 0.0,
        }
    }

    #[inline]
    fn push(&mut self, r: DVec3) {
        if self.started {
            self.sum += edge_term(self.previous, r, self.n);
        } else {
            self.first = r;
            self.started = true;
        }
        self.previous = r;
    }

    fn finish(self) -> f64 {
        if self.started {
            self.sum + edge_term(self.previous, self.first, self.n)
        } else {
            0.0
        }
    }
}

/// One edge's contribution `gamma n . c / |c|`. A zero cross product means a zero-length
/// edge (duplicate clip vertex) or an edge pointing at `x`; both subtend no angle.
#[inline]
fn edge_term(a: DVec3, b: DVec3, n: DVec3) -> f64 {
    let c = a.cross(b);
    let sin_length = c.length();
    if sin_length == 0.0 {
        return 0.0;
    }
    let gamma = sin_length.atan2(a.dot(b));
    gamma * n.dot(c) / sin_length
}

/// The far-field approximation of the point-to-patch factor by a disk of the same area
/// facing along `source_normal` (Wallace, Elmquist & Haines, "A Ray Tracing Algorithm for
/// Progressive Radiosity", SIGGRAPH 1989): `A cos(theta) cos(theta') / (pi r^2 + A)`.
/// Exact for a coaxial disk; for a patch of size `s` at distance `r` the relative error
/// is O((s/r)^2).
#[inline]
pub fn point_disk_approximation(
    x: DVec3,
    n: DVec3,
    centre: DVec3,
    source_normal: DVec3,
    area: f64,
) -> f64 {
    let d = centre - x;
    let distance_squared = d.length_squared();
    let cos_receiver = n.dot(d);
    let cos_source = -source_normal.dot(d);
    if cos_receiver <= 0.0 || cos_source <= 0.0 {
        return 0.0;
    }
    // cos * cos' = (n.d)(-n'.d) / r^2.
    area * cos_receiver * cos_source
        / (distance_squared * (std::f64::consts::PI * distance_squared + area))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(z: f64, half: f64) -> [DVec3; 4] {
        // Facing down (-z), counter-clockwise seen from below.
        [
            DVec3::new(-half, -half, z),
            DVec3::new(-half, half, z),
            DVec3::new(half, half, z),
            DVec3::new(half, -half, z),
        ]
    }

    #[test]
    fn a_point_on_the_back_twin_sees_nothing_of_its_front() {
        // The back side of a two-sided patch lies in its plane up to rounding: a
        // height of 1e-13 must not make the clipped contour close around the whole
        // polygon (F = 1).
        let front = square(0.0, 0.5);
        let up = DVec3::Z;
        for h in [0.0, 1e-13, 1e-9] {
            let x = DVec3::new(0.1, -0.2, -h);
            assert_eq!(point_polygon_factor(x, up, &front, -up), 0.0, "{h}");
        }
        // Resolvable heights still see the square (nearly all of the hemisphere).
        let f = point_polygon_factor(DVec3::new(0.1, -0.2, -1e-4), up, &front, -up);
        assert!(f > 0.99, "{f}");
    }

    #[test]
    fn whole_hemisphere_sums_to_one() {
        // Square of half-side a at height h centred on the normal: four corner
        // rectangles of the classical element-to-parallel-rectangle factor
        // (1/2pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + (X <-> Y)] with X = Y = a/h,
        // i.e. F = (4/pi) s atan(s), s = a / sqrt(a^2 + h^2). The last case (a >> h)
        // covers nearly the whole hemisphere.
        for &(a, h) in &[(1.0f64, 1.0f64), (0.1, 3.0), (50.0, 0.5)] {
            let s: f64 = a / (a * a + h * h).sqrt();
            let exact = 4.0 / std::f64::consts::PI * s * s.atan();
            let f = point_polygon_factor(DVec3::ZERO, DVec3::Z, &square(h, a), -DVec3::Z);
            assert!((f - exact).abs() < 1e-14, "{f} vs {exact}");
        }
    }

    #[test]
    fn back_side_and_coplanar_give_zero() {
        let sq = square(1.0, 1.0);
        // Point above the square sees its back.
        assert_eq!(
            point_polygon_factor(DVec3::new(0.0, 0.0, 2.0), -DVec3::Z, &sq, -DVec3::Z),
            0.0
        );
        // Point in the square's plane.
        assert_eq!(
            point_polygon_factor(DVec3::new(3.0, 0.0, 1.0), DVec3::X, &sq, -DVec3::Z),
            0.0
        );
    }

    #[test]
    fn clipping_keeps_only_the_part_above_the_horizon() {
        // A vertical wall x = 1 spanning z in [-1, 1], seen from the origin with normal +z:
        // only the upper half counts. The clipped result must equal the factor to the
        // upper half alone, which is the perpendicular-rectangle closed form.
        let wall = [
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(1.0, -1.0, 1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, 1.0, -1.0),
        ];
        let upper = [
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, 1.0, 0.0),
        ];
        let f_clip = point_polygon_factor(DVec3::ZERO, DVec3::Z, &wall, -DVec3::X);
        let f_upper = point_polygon_factor(DVec3::ZERO, DVec3::Z, &upper, -DVec3::X);
        assert!((f_clip - f_upper).abs() < 1e-15);
        // Direct integration: F = (1/pi) Int_{-1}^{1} Int_0^1 z / (1 + y^2 + z^2)^2 dz dy
        // = (1/2pi) Int [1/(1+y^2) - 1/(2+y^2)] dy = (1/pi) [pi/4 - atan(1/sqrt2)/sqrt2].
        let exact = (std::f64::consts::FRAC_PI_4 - (0.5f64).sqrt() * (0.5f64).sqrt().atan())
            / std::f64::consts::PI;
        assert!((f_upper - exact).abs() < 1e-14, "{f_upper} vs {exact}");
    }

    #[test]
    fn disk_approximation_is_exact_on_axis() {
        // Coaxial disk of radius R at height h: F = R^2 / (R^2 + h^2).
        let (radius, h): (f64, f64) = (0.7, 2.0);
        let area = std::f64::consts::PI * radius * radius;
        let f = point_disk_approximation(
            DVec3::ZERO,
            DVec3::Z,
            DVec3::new(0.0, 0.0, h),
            -DVec3::Z,
            area,
        );
        assert!((f - radius * radius / (radius * radius + h * h)).abs() < 1e-15);
    }
}

#[cfg(test)]
mod far_field_tests {
    use super::*;
    use radiant_math::hash::Pcg32;

    #[test]
    fn disk_approximation_error_shrinks_with_distance() {
        // Unit squares in random orientations facing a point at distance r (measured
        // from the centre; both cosines >= 0.2): the relative error of the disk
        // approximation against the exact contour factor, worst case over 2000
        // orientations, must fall like area / r^2.
        let mut rng = Pcg32::new(3, 4);
        let mut random_unit = || {
            let z = 2.0 * rng.uniform_f64() - 1.0;
            let phi = std::f64::consts::TAU * rng.uniform_f64();
            let r = (1.0 - z * z).sqrt();
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        };
        for ratio in [4.0f64, 16.0, 64.0] {
            let distance = ratio.sqrt();
            let mut worst = 0.0f64;
            for _ in 0..2000 {
                let direction = random_unit();
                let mut normal = random_unit();
                // Face the point with cosines at least 0.2 each way.
                if normal.dot(-direction) < 0.0 {
                    normal = -normal;
                }
                let receiver_normal = random_unit();
                if normal.dot(-direction) < 0.2 || receiver_normal.dot(direction) < 0.2 {
                    continue;
                }
                let centre = direction * distance;
                let (s, t) = crate::mesh::patch::tangent_frame(normal);
                let square = [
                    centre - 0.5 * s - 0.5 * t,
                    centre + 0.5 * s - 0.5 * t,
                    centre + 0.5 * s + 0.5 * t,
                    centre - 0.5 * s + 0.5 * t,
                ];
                let exact = point_polygon_factor(DVec3::ZERO, receiver_normal, &square, normal);
                let approx =
                    point_disk_approximation(DVec3::ZERO, receiver_normal, centre, normal, 1.0);
                worst = worst.max((approx / exact - 1.0).abs());
            }
            // Measured: 0.23, 0.070, 0.018, i.e. about 1.1 / ratio.
            assert!(worst < 1.5 / ratio, "ratio {ratio}: {worst}");
        }
    }
}
