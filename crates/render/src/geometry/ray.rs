//! Rays, and where rays leaving a surface start.
//!
//! A computed intersection point is not on the surface: it carries rounding error. A ray
//! started there may find the same surface again at a tiny distance ("shadow acne") or pass
//! through it. Every shape therefore returns, with its hit point `p`, a conservative bound
//! `p_error` on `|p − p_exact|` per component (forward error analysis as in Higham,
//! *Accuracy and Stability of Numerical Algorithms*, §3, with the γₙ bound on n rounded
//! operations). Spawned rays start at `p` moved along the geometric normal just far enough
//! that the whole error box lies behind them — the box's extent along the normal is
//! `|n| · p_error` — and further by a margin that covers the rounding of the moved point
//! itself (a few ulps of its largest coordinate), so the move survives its own rounding.
//! The ray–triangle test then only accepts distances that are provably positive. This is
//! the approach of Pharr, Jakob & Humphreys, *Physically Based Rendering* (4th ed., §6.8);
//! Wächter & Binder (*Ray Tracing Gems*, ch. 6) discuss the same problem. All offsets scale
//! with the coordinates, so nothing depends on the scene's unit of length.

use glam::Vec3;
use radiant_math::Transform;

/// A ray `o + t d`. `d` need not be normalised; hit distances are in units of `|d|`.
/// The valid interval `[0, t_max)` is passed to queries separately.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub o: Vec3,
    pub d: Vec3,
}

impl Ray {
    pub fn new(o: Vec3, d: Vec3) -> Ray {
        Ray { o, d }
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// Where a shadow ray between two points stops, as a fraction of the segment: short of
/// the far end, whose surface must not count as a blocker. The ends are already moved off
/// their surfaces, so this only guards against the far point's own rounding.
pub const SHADOW_EPSILON: f32 = 1e-4;

/// Half an ulp of 1: the relative error of one correctly rounded f32 operation.
pub const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// γₙ = nε / (1 − nε): bounds the relative error accumulated by n rounded operations.
#[inline(always)]
pub const fn gamma(n: i32) -> f32 {
    (n as f32 * MACHINE_EPSILON) / (1.0 - n as f32 * MACHINE_EPSILON)
}

/// A point on a surface (or in free space) as a place rays start from or end at: the
/// computed position, a conservative bound on its error per component, and the geometric
/// normal (either orientation; zero for points in free space, which are not moved).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    pub p: Vec3,
    pub p_error: Vec3,
    pub n: Vec3,
}

impl SurfacePoint {
    pub fn new(p: Vec3, p_error: Vec3, n: Vec3) -> SurfacePoint {
        SurfacePoint { p, p_error, n }
    }

    /// A point in free space (a point light, a camera): rays start exactly there.
    pub fn free(p: Vec3) -> SurfacePoint {
        SurfacePoint {
            p,
            p_error: Vec3::ZERO,
            n: Vec3::ZERO,
        }
    }

    /// A point known only to within the rounding of its own coordinates (half an ulp
    /// each, doubled for the operations that made it): points converted from f64 or
    /// stored positions of vertices and sample points.
    pub fn rounded(p: Vec3, n: Vec3) -> SurfacePoint {
        SurfacePoint {
            p,
            p_error: gamma(2) * p.abs(),
            n,
        }
    }

    /// The origin for a ray leaving towards `w`: on `w`'s side of the surface, outside the
    /// error box.
    #[inline(always)]
    pub fn spawn_origin(&self, w: Vec3) -> Vec3 {
        offset_ray_origin(self.p, self.p_error, self.n, w)
    }

    #[inline(always)]
    pub fn spawn_ray(&self, w: Vec3) -> Ray {
        Ray::new(self.spawn_origin(w), w)
    }

    /// A ray for the segment from this point to `to`, both ends moved off their surfaces
    /// towards each other, and the `t_max` to trace it with (the far end, less
    /// [`SHADOW_EPSILON`]).
    #[inline(always)]
    pub fn spawn_ray_to(&self, to: &SurfacePoint) -> (Ray, f32) {
        let o = self.spawn_origin(to.p - self.p);
        let target = to.spawn_origin(o - to.p);
        (Ray::new(o, target - o), 1.0 - SHADOW_EPSILON)
    }
}

/// `p` moved along `n` (to the side of `w`) past its error box `p_error` and past the
/// rounding of the move itself. Always inlined: every bounce and shadow ray starts here,
/// and as a call its vector arguments went through memory, where reading them back
/// stalled on the stores that had just written them.
///
/// The box's half-extent along n, |n|·p_error, is raised by γ₄ for the rounding of this
/// dot product and for a unit normal whose computed length falls a few ulps short of 1
/// (the move d·n must still cover the box along the true direction of n). Rounding
/// `p + offset` to f32 then moves each coordinate i by at most ε|p_i + offset_i| (ε half
/// an ulp of 1), which along n sums to at most ε (‖n‖₁ ‖p‖_∞ + |n|² d) ≤ ε (√3 ‖p‖_∞ + d)
/// for |n| ≈ 1; the margin 2ε (‖p‖_∞ + d) covers that with room for its own rounding.
/// pbrt-v4 (§6.8.6) steps each moved coordinate one ulp outwards instead; the margin is
/// the same guarantee with no per-coordinate selects. A free point (n = 0) stays put.
#[inline(always)]
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(p_error) * (1.0 + gamma(4));
    let d = d + 2.0 * MACHINE_EPSILON * (p.abs().max_element() + d);
    let offset = if w.dot(n) < 0.0 { -d * n } else { d * n };
    p + offset
}

/// The error bound of `a₀p₀ + a₁p₁ + a₂p₂` for weights in [0, 1] computed in f32
/// (barycentric interpolation): each term and the two sums add a rounding, and weights that
/// were themselves computed (and do not sum exactly to one) shift the point by a few ulps of
/// the largest term; γ₇ of the absolute terms covers both.
pub fn barycentric_error(b: [f32; 3], p: [Vec3; 3]) -> Vec3 {
    gamma(7) * ((b[0] * p[0]).abs() + (b[1] * p[1]).abs() + (b[2] * p[2]).abs())
}

/// An affine transform of a point with error bound `p_error`, and the bound of the result:
/// each output coordinate is three products and three sums (γ₃ of the absolute terms),
/// and the input's error passes through the absolute linear part, itself rounded.
pub fn transform_point_with_error(xf: &Transform, p: Vec3, p_error: Vec3) -> (Vec3, Vec3) {
    let m = &xf.m;
    let (cx, cy, cz, t) = (
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
        m.w_axis.truncate(),
    );
    let terms = (cx * p.x).abs() + (cy * p.y).abs() + (cz * p.z).abs() + t.abs();
    let carried = cx.abs() * p_error.x + cy.abs() * p_error.y + cz.abs() * p_error.z;
    (xf.point(p), gamma(3) * terms + (1.0 + gamma(3)) * carried)
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;

    #[test]
    fn offset_moves_to_the_side_of_w_past_the_error_box() {
        let mut rng = Pcg32::new(3, 7);
        for &p in &[
            Vec3::ZERO,
            Vec3::new(500.0, -3.0, 1e-3),
            Vec3::new(-1e4, 2e4, 7.0),
            Vec3::new(3.0e6, -1.0, 0.5),
        ] {
            for i in 0..300 {
                // Random normals, and axis-aligned ones, where a coordinate moves least.
                let n = match i % 3 {
                    0 => (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5)
                        .normalize_or(Vec3::Z),
                    1 => [Vec3::X, Vec3::NEG_Y, Vec3::Z][i / 3 % 3],
                    _ => Vec3::new(1.0, 1e-4 * rng.uniform(), 0.0).normalize(),
                };
                // A computed point's bound, and an exact point's (zero: only the
                // rounding of the move itself is left to cover).
                let err = if i % 2 == 0 {
                    gamma(7) * p.abs() + Vec3::splat(1e-30)
                } else {
                    Vec3::ZERO
                };
                if err == Vec3::ZERO && p == Vec3::ZERO {
                    continue;
                }
                let sp = SurfacePoint::new(p, err, n);
                let up = sp.spawn_origin(n);
                let down = sp.spawn_origin(-n);
                // Every corner of the error box lies strictly behind the moved origin.
                for k in 0..8 {
                    let s = Vec3::new(
                        if k & 1 == 0 { 1.0 } else { -1.0 },
                        if k & 2 == 0 { 1.0 } else { -1.0 },
                        if k & 4 == 0 { 1.0 } else { -1.0 },
                    );
                    let corner = (p + s * err).as_dvec3();
                    let nd = n.as_dvec3();
                    assert!((up.as_dvec3() - corner).dot(nd) > 0.0);
                    assert!((down.as_dvec3() - corner).dot(nd) < 0.0);
                }
                // Tiny relative to the coordinates.
                assert!((up - p).length() < 1e-5 * p.length() + 1e-6);
            }
        }
    }
}
