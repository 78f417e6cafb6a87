//! Clarberg's equal-area octahedral mapping between the unit square and the unit
//! sphere (P. Clarberg, "Fast Equal-Area Mapping of the (Hemi)Sphere using SIMD",
//! Journal of Graphics Tools 13(3), 2008), the parameterisation of pbrt-v4's
//! environment images.
//!
//! With `(u, v)` the square point moved to [-1,1]² and `r = 1 - |1 - |u| - |v||`, the
//! diamond `|u| + |v| <= 1` holds the +z hemisphere and the four corner triangles the
//! -z one: `z = ±(1 - r²)`, and along each ring of constant `r` the azimuth in a
//! quadrant is linear in `|v| - |u|`. The region `r <= r0` of either hemisphere has
//! area `2 r0²` of the square's 4 and the cap it maps to has solid angle `2π r0²`, and
//! the azimuth is uniform along each ring, so the map multiplies areas by exactly π:
//! a unit of the [0,1]² square is 4π steradians.

use glam::{Vec2, Vec3};

use crate::PI;

/// Solid angle per unit area of the [0,1]² square.
pub const SOLID_ANGLE_PER_AREA: f32 = 4.0 * PI;

/// The unit direction of the point `p` of [0,1]².
pub fn square_to_sphere(p: Vec2) -> Vec3 {
    let u = 2.0 * p.x - 1.0;
    let v = 2.0 * p.y - 1.0;
    let (au, av) = (u.abs(), v.abs());
    // Signed distance from the diamond's edge: positive inside (+z).
    let sd = 1.0 - (au + av);
    let r = 1.0 - sd.abs();
    // Azimuth within the quadrant, [0, π/2]; at the poles (r = 0) any value will do.
    let phi = if r == 0.0 {
        PI / 4.0
    } else {
        (PI / 4.0) * ((av - au) / r + 1.0)
    };
    let z = (1.0 - r * r).copysign(sd);
    let sin_theta = r * (2.0 - r * r).max(0.0).sqrt();
    let x = (phi.cos() * sin_theta).copysign(u);
    let y = (phi.sin() * sin_theta).copysign(v);
    Vec3::new(x, y, z).normalize()
}

/// The point of [0,1]² whose direction is the unit vector `d` (the inverse of
/// [`square_to_sphere`]).
pub fn sphere_to_square(d: Vec3) -> Vec2 {
    let (ax, ay, az) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - az).max(0.0).sqrt();
    // t = (|v| - |u|) / r in [-1, 1].
    let phi = ay.atan2(ax);
    let t = phi * (4.0 / PI) - 1.0;
    let (mut au, mut av) = ((1.0 - t) * 0.5 * r, (1.0 + t) * 0.5 * r);
    if d.z < 0.0 {
        // Folded into the corner triangle: |u| + |v| = 2 - r.
        (au, av) = (1.0 - av, 1.0 - au);
    }
    let u = au.copysign(d.x);
    let v = av.copysign(d.y);
    Vec2::new(
        (0.5 * (u + 1.0)).clamp(0.0, 1.0),
        (0.5 * (v + 1.0)).clamp(0.0, 1.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hash::Pcg32;

    #[test]
    fn round_trips_both_ways() {
        let mut rng = Pcg32::new(3, 5);
        for _ in 0..20_000 {
            let p = Vec2::new(rng.uniform(), rng.uniform());
            let d = square_to_sphere(p);
            assert!((d.length() - 1.0).abs() < 1e-5);
            let q = sphere_to_square(d);
            assert!((p - q).length() < 2e-4, "{p} -> {d} -> {q}");
            let back = square_to_sphere(q);
            assert!((back - d).length() < 2e-4);
        }
        // Poles and the equator's corners of the diamond.
        assert!((square_to_sphere(Vec2::splat(0.5)) - Vec3::Z).length() < 1e-6);
        assert!((square_to_sphere(Vec2::ZERO) + Vec3::Z).length() < 1e-6);
        assert!((square_to_sphere(Vec2::new(1.0, 0.5)) - Vec3::X).length() < 1e-6);
        assert!((square_to_sphere(Vec2::new(0.5, 1.0)) - Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn cells_of_a_grid_have_equal_solid_angle() {
        // Solid angle of each cell of an 8x8 grid by the spherical excess of its
        // (finely subdivided) boundary is hard; instead count uniform sphere points per
        // cell: each must hold 1/64 of them within binomial noise.
        let n = 8usize;
        let samples = 640_000usize;
        let mut counts = vec![0usize; n * n];
        let mut rng = Pcg32::new(9, 1);
        for _ in 0..samples {
            let d = crate::sampling::uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
            let p = sphere_to_square(d);
            let (x, y) = (
                ((p.x * n as f32) as usize).min(n - 1),
                ((p.y * n as f32) as usize).min(n - 1),
            );
            counts[y * n + x] += 1;
        }
        let expected = samples as f64 / (n * n) as f64;
        let sigma = (expected * (1.0 - 1.0 / (n * n) as f64)).sqrt();
        for (i, &c) in counts.iter().enumerate() {
            assert!(
                (c as f64 - expected).abs() < 5.0 * sigma,
                "cell {i}: {c} vs {expected}"
            );
        }
    }
}
