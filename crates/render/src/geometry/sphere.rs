//! Spheres in object space (centre at the origin), optionally cut to pbrt's partial
//! sphere: `z_min <= z <= z_max` and azimuth `0 <= phi <= phi_max`.
//!
//! Intersection solves the quadratic with the two precision fixes of Haines, Günther &
//! Akenine-Möller, "Precision Improvements for Ray/Sphere Intersection" (Ray Tracing Gems,
//! 2019): the discriminant is computed from the distance of the ray's closest approach to the
//! centre (no catastrophic cancellation in b² − ac), and the roots use the stable form of
//! Press et al., "Numerical Recipes" (q = −(b + sign(b)√Δ), roots q/a and c/q).

// `!(x > 0.0)` is used on purpose: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::Ray;
use super::sample::{AreaSample, ShapeError, SolidAngleSample, area_to_solid_angle_sample};
use glam::{Vec2, Vec3};
use radiant_math::{Frame, PI, safe_sqrt};

/// A sphere of `radius` about the origin, cut to `z_min <= z <= z_max` and
/// `phi <= phi_max` (radians). The full sphere has z range `[-radius, radius]` and 2π.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub radius: f32,
    pub z_min: f32,
    pub z_max: f32,
    pub phi_max: f32,
}

/// A ray–sphere hit in object space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereHit {
    pub t: f32,
    /// Hit point, re-projected onto the surface.
    pub p: Vec3,
    /// Bound on the distance of `p` from the exact surface, per component.
    pub p_error: Vec3,
    /// Unit outward normal.
    pub n: Vec3,
    /// u = phi / phi_max; v runs from 0 at z_min to 1 at z_max (along the polar angle).
    pub uv: Vec2,
}

impl Sphere {
    /// The full sphere.
    pub fn full(radius: f32) -> Result<Sphere, ShapeError> {
        Sphere::partial(radius, -radius, radius, 360.0)
    }

    /// pbrt's `sphere` with `zmin`, `zmax` (clamped to the sphere) and `phimax` in degrees.
    pub fn partial(
        radius: f32,
        z_min: f32,
        z_max: f32,
        phi_max_degrees: f32,
    ) -> Result<Sphere, ShapeError> {
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(ShapeError::BadRadius(radius));
        }
        let (lo, hi) = (z_min.min(z_max).max(-radius), z_min.max(z_max).min(radius));
        if !(lo < hi) {
            return Err(ShapeError::EmptyZRange {
                z_min,
                z_max,
                radius,
            });
        }
        if !(phi_max_degrees > 0.0 && phi_max_degrees <= 360.0) {
            return Err(ShapeError::BadPhiMax(phi_max_degrees));
        }
        Ok(Sphere {
            radius,
            z_min: lo,
            z_max: hi,
            phi_max: phi_max_degrees.to_radians(),
        })
    }

    /// True when no cut applies (cone sampling is only valid then).
    pub fn is_full(&self) -> bool {
        self.z_min <= -self.radius && self.z_max >= self.radius && self.phi_max >= 2.0 * PI
    }

    pub fn area(&self) -> f32 {
        self.phi_max * self.radius * (self.z_max - self.z_min)
    }

    /// Closest hit with `0 < t < t_max` on the (possibly cut) surface.
    ///
    /// The quadratic is solved in f64 from the exact f32 inputs: its roots then carry a
    /// relative error near 1e-16, far below the f32 offsets that move a spawned ray's
    /// origin off the surface, so a ray leaving the sphere never finds it again at t ≈ 0
    /// (the sign of the near root is decided correctly even for grazing directions).
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<SphereHit> {
        let r = self.radius as f64;
        let f = ray.o.as_dvec3();
        let d = ray.d.as_dvec3();
        let a = d.length_squared();
        let b = f.dot(d);
        let c = f.length_squared() - r * r;
        let closest = f - (b / a) * d;
        let disc = a * (r * r - closest.length_squared());
        if !(disc >= 0.0) {
            return None;
        }
        let q = -(b + disc.sqrt().copysign(b));
        if q == 0.0 {
            return None;
        }
        let (t0, t1) = {
            let (x, y) = (q / a, c / q);
            (x.min(y), x.max(y))
        };
        for t in [t0, t1] {
            if !(t > 0.0 && t < t_max as f64) {
                continue;
            }
            let t = t as f32;
            let p = self.reproject(ray.at(t));
            if let Some(phi) = self.accepts(p) {
                return Some(SphereHit {
                    t,
                    p,
                    p_error: reprojection_error(p),
                    n: p / self.radius,
                    uv: self.uv_from(p, phi),
                });
            }
        }
        None
    }

    /// Moves a point computed as o + t d onto the surface (shrinks its error to ~1 ulp),
    /// nudging it off the pole axis so that phi is defined.
    fn reproject(&self, p: Vec3) -> Vec3 {
        let mut p = p * (self.radius / p.length());
        if p.x == 0.0 && p.y == 0.0 {
            p.x = 1e-5 * self.radius;
        }
        p
    }

    /// The azimuth of `p` in [0, 2π) if `p` lies inside the cut, else `None`.
    fn accepts(&self, p: Vec3) -> Option<f32> {
        let mut phi = p.y.atan2(p.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let cut_z = (self.z_min > -self.radius && p.z < self.z_min)
            || (self.z_max < self.radius && p.z > self.z_max);
        (!cut_z && phi <= self.phi_max).then_some(phi)
    }

    fn uv_from(&self, p: Vec3, phi: f32) -> Vec2 {
        let r = self.radius;
        let theta = |z: f32| (z / r).clamp(-1.0, 1.0).acos();
        let (th_lo, th_hi) = (theta(self.z_min), theta(self.z_max));
        Vec2::new(phi / self.phi_max, (theta(p.z) - th_lo) / (th_hi - th_lo))
    }

    /// ∂p/∂v at a surface point (v runs along the polar angle θ from θ(z_min) to
    /// θ(z_max)): (θ_max − θ_min) (z cos φ, z sin φ, −r sin θ); zero at the poles,
    /// where φ is undefined.
    pub fn dpdv(&self, p: Vec3) -> Vec3 {
        let r = self.radius;
        let theta = |z: f32| (z / r).clamp(-1.0, 1.0).acos();
        let span = theta(self.z_max) - theta(self.z_min);
        let rho = (p.x * p.x + p.y * p.y).sqrt();
        if !(rho > 0.0) {
            return Vec3::ZERO;
        }
        let (cos_phi, sin_phi) = (p.x / rho, p.y / rho);
        span * Vec3::new(p.z * cos_phi, p.z * sin_phi, -rho)
    }

    /// Unit outward normal at a surface point.
    pub fn normal(&self, p: Vec3) -> Vec3 {
        p / self.radius
    }

    /// Surface parameters of a point on the sphere (phi measured in [0, 2π)).
    pub fn uv(&self, p: Vec3) -> Vec2 {
        let mut phi = p.y.atan2(p.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        self.uv_from(p, phi)
    }

    /// Uniform sampling by area. By Archimedes' hat-box theorem, area on a sphere is
    /// uniform in (z, phi), which also covers the cut sphere exactly.
    pub fn sample_area(&self, u: Vec2) -> AreaSample {
        let z = self.z_min + u.x * (self.z_max - self.z_min);
        let phi = u.y * self.phi_max;
        let rho = safe_sqrt(self.radius * self.radius - z * z);
        let p = self.reproject(Vec3::new(rho * phi.cos(), rho * phi.sin(), z));
        AreaSample {
            p,
            p_error: reprojection_error(p),
            n: p / self.radius,
            pdf: 1.0 / self.area(),
        }
    }

    /// 1 − cos θmax of the cone the full sphere subtends from `reference`, or `None` when
    /// the point is inside (or on) the sphere. Uses 1 − cos = sin² / (1 + cos), which keeps
    /// full precision for distant spheres where cos θmax → 1.
    fn cone_one_minus_cos(&self, reference: Vec3) -> Option<(f32, f32)> {
        let dc2 = reference.length_squared();
        let r2 = self.radius * self.radius;
        if !(dc2 > r2 * 1.0001) {
            return None;
        }
        let sin2 = r2 / dc2;
        let cos_max = safe_sqrt(1.0 - sin2);
        Some((cos_max, sin2 / (1.0 + cos_max)))
    }

    /// Samples a point of the sphere visible from `reference` (object space): uniform in the
    /// cone of directions the full sphere subtends (pdf 1 / (2π(1 − cos θmax)) per solid
    /// angle). Inside the sphere, or for a cut sphere, it falls back to area sampling
    /// converted to solid angle. `None` when no valid sample exists.
    pub fn sample_solid_angle(&self, reference: Vec3, u: Vec2) -> Option<SolidAngleSample> {
        let cone = self
            .cone_one_minus_cos(reference)
            .filter(|_| self.is_full());
        let Some((_, omc)) = cone else {
            return area_to_solid_angle_sample(self.sample_area(u), reference);
        };
        let dc = reference.length();
        let frame = Frame::from_normal(-reference / dc);
        // Sample cos θ uniformly in [cos θmax, 1]; sin² θ from the product form for precision.
        let one_minus_cos = u.x * omc;
        let cos_theta = 1.0 - one_minus_cos;
        let sin2 = one_minus_cos * (1.0 + cos_theta);
        let sin_theta = safe_sqrt(sin2);
        let phi = 2.0 * PI * u.y;
        let wi = frame.to_world(Vec3::new(
            phi.cos() * sin_theta,
            phi.sin() * sin_theta,
            cos_theta,
        ));
        let r = self.radius;
        // Distance to the near intersection along wi (the law of cosines in the triangle
        // reference–centre–hit point).
        let dist = dc * cos_theta - safe_sqrt(r * r - dc * dc * sin2);
        let p = self.reproject(reference + dist * wi);
        Some(SolidAngleSample {
            p,
            p_error: reprojection_error(p),
            n: p / r,
            wi,
            pdf: 1.0 / (2.0 * PI * omc),
        })
    }

    /// The solid-angle density `sample_solid_angle` gives to the point `p` (on the sphere,
    /// visible from `reference`).
    pub fn pdf_solid_angle(&self, reference: Vec3, p: Vec3) -> f32 {
        match self
            .cone_one_minus_cos(reference)
            .filter(|_| self.is_full())
        {
            Some((_, omc)) => 1.0 / (2.0 * PI * omc),
            None => super::sample::area_pdf_to_solid_angle(
                1.0 / self.area(),
                reference,
                p,
                self.normal(p),
            ),
        }
    }
}

/// The error bound of a point scaled onto a sphere, p · (r / |p|): the length (a sum of
/// three squares and a square root), the quotient and the product round about five
/// times, each relative to |p|'s components.
fn reprojection_error(p: Vec3) -> Vec3 {
    super::ray::gamma(5) * p.abs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;

    fn u2(rng: &mut Pcg32) -> Vec2 {
        Vec2::new(rng.uniform(), rng.uniform())
    }

    #[test]
    fn dpdv_moves_along_v_at_the_rate_of_the_parameterisation() {
        let s = Sphere::partial(2.0, -1.2, 1.5, 300.0).unwrap();
        let mut rng = Pcg32::new(5, 1);
        for _ in 0..200 {
            let p = s.sample_area(u2(&mut rng)).p;
            let uv = s.uv(p);
            if !(0.05..0.95).contains(&uv.y) {
                continue;
            }
            // A small step along ∂p/∂v, projected back onto the sphere.
            let h = 1e-3;
            let q = (p + h * s.dpdv(p)).normalize() * s.radius;
            let duv = s.uv(q) - uv;
            assert!((duv.y - h).abs() < 2e-2 * h, "dv {} for step {h}", duv.y);
            assert!(duv.x.abs() < 1e-2 * h, "du {}", duv.x);
        }
    }

    #[test]
    fn hits_match_f64_quadratic() {
        let s = Sphere::full(2.0).unwrap();
        let mut rng = Pcg32::new(3, 7);
        let mut hits = 0;
        for i in 0..20_000 {
            // Origins from near the surface to far away (1e3 radii), inside and outside.
            let scale = 10f32.powf(3.0 * rng.uniform() - 0.5);
            let o = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5) * 2.0 * scale;
            let target = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5) * 5.0;
            let ray = Ray::new(o, (target - o) * (0.5 + i as f32 % 3.0));
            let (od, dd) = (ray.o.as_dvec3(), ray.d.as_dvec3());
            let (a, b, c) = (dd.dot(dd), od.dot(dd), od.dot(od) - 4.0);
            let disc = b * b - a * c;
            let exact = if disc < 0.0 {
                None
            } else {
                [(-b - disc.sqrt()) / a, (-b + disc.sqrt()) / a]
                    .into_iter()
                    .find(|&t| t > 0.0)
            };
            let got = s.intersect(&ray, f32::INFINITY);
            match (exact, got) {
                (Some(te), Some(h)) => {
                    hits += 1;
                    // Relative error of a few ulps of the distance; grazing rays
                    // (tiny discriminant) are ill-conditioned, so allow 1e-3 there.
                    // Error is relative to the distance for far origins, and absolute
                    // (~ulps of |o|) for origins near the surface.
                    let tol = if disc > 1e-3 * b * b { 1e-5 } else { 1e-3 };
                    let scale = te * a.sqrt() + od.length();
                    assert!(
                        (h.t as f64 - te).abs() * a.sqrt() < tol * scale,
                        "{} {te}",
                        h.t
                    );
                    assert!((h.p.length() - 2.0).abs() < 1e-5);
                    assert!((h.n.length() - 1.0).abs() < 1e-5);
                }
                (None, None) => {}
                // Rays tangent to within round-off may go either way.
                _ => assert!(disc.abs() < 1e-4 * b * b, "{exact:?} {got:?}"),
            }
        }
        assert!(hits > 5000, "{hits}");
    }

    #[test]
    fn partial_sphere_respects_cuts_and_uv_spans_unit_square() {
        let s = Sphere::partial(1.0, -0.5, 0.8, 270.0).unwrap();
        let mut rng = Pcg32::new(4, 4);
        let mut hits = 0;
        for _ in 0..20_000 {
            let o = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5) * 6.0;
            let d = radiant_math::sampling::uniform_sphere(u2(&mut rng)) * 0.9 - o;
            if let Some(h) = s.intersect(&Ray::new(o, d), f32::INFINITY) {
                hits += 1;
                assert!(h.p.z >= -0.5 - 1e-5 && h.p.z <= 0.8 + 1e-5);
                assert!(
                    !(h.p.x > 1e-4 && h.p.y < -1e-4),
                    "phi beyond 270°: {:?}",
                    h.p
                );
                assert!(h.uv.min_element() >= -1e-5 && h.uv.max_element() <= 1.0 + 1e-5);
            }
        }
        assert!(hits > 1000);
        // A ray through the cut-away quarter (x > 0, y < 0) reaches the far inside wall.
        let h = s.intersect(&Ray::new(Vec3::new(5.0, -0.3, 0.0), -Vec3::X), 100.0);
        assert!((h.unwrap().t - (5.0 + 0.91f32.sqrt())).abs() < 1e-5);
        assert!(Sphere::partial(1.0, 2.0, 3.0, 360.0).is_err());
        assert!(Sphere::partial(1.0, -1.0, 1.0, 0.0).is_err());
        assert!(Sphere::full(-1.0).is_err());
    }

    #[test]
    fn area_sampling_pdf_integrates_to_area() {
        // pdf is constant, so mean(1/pdf) = area exactly; test the distribution instead:
        // E[z] over area = (z_min + z_max)/2 (uniform in z); std of z <= 1 so 1e5 samples
        // give a standard error < 0.0032, allow 4 sigma.
        for s in [
            Sphere::full(1.0).unwrap(),
            Sphere::partial(1.0, -0.3, 0.9, 120.0).unwrap(),
        ] {
            let mut rng = Pcg32::new(8, 1);
            let n = 100_000;
            let (mut inv, mut mz) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let a = s.sample_area(u2(&mut rng));
                inv += 1.0 / a.pdf as f64;
                mz += a.p.z as f64;
                assert!((a.p.length() - 1.0).abs() < 1e-5);
                assert!(s.accepts(a.p).is_some() || a.p.y.abs() < 1e-5);
            }
            let expect_area = s.phi_max as f64 * (s.z_max - s.z_min) as f64;
            assert!((inv / n as f64 - expect_area).abs() < 1e-4 * expect_area);
            assert!((mz / n as f64 - 0.5 * (s.z_min + s.z_max) as f64).abs() < 0.013);
        }
    }

    #[test]
    fn cone_sampling_solid_angle_agrees_with_area_sampling() {
        // The visible cap's solid angle is 2π(1 − cos θmax). Estimate ∫ g dω over it two
        // ways: with cone samples (g / pdf_ω) and with area samples (g · visibility ·
        // cos / d² / pdf_A), for g = 1 and a non-constant g. Area sampling wastes half its
        // samples on the hidden side, its relative std is ~1 at d = 3, so 2e5 samples give
        // a relative error ~0.3 %; allow 1.5 %.
        let s = Sphere::full(1.0).unwrap();
        let reference = Vec3::new(0.5, -1.0, 2.7);
        let d = reference.length();
        let exact = 2.0 * PI as f64 * (1.0 - (1.0 - 1.0 / (d * d) as f64).sqrt());
        let g = |p: Vec3| 2.0 + p.x as f64 - 0.5 * p.z as f64;
        let n = 200_000;
        let mut rng = Pcg32::new(1, 2);
        let (mut cone1, mut coneg, mut area1, mut areag) = (0.0, 0.0, 0.0, 0.0);
        for _ in 0..n {
            let c = s.sample_solid_angle(reference, u2(&mut rng)).unwrap();
            assert!((c.p.length() - 1.0).abs() < 1e-5);
            assert!(c.n.dot(c.wi) <= 1e-4, "sampled a hidden point");
            assert!(((c.p - reference).normalize() - c.wi).length() < 1e-3);
            assert_eq!(c.pdf, s.pdf_solid_angle(reference, c.p));
            cone1 += 1.0 / c.pdf as f64;
            coneg += g(c.p) / c.pdf as f64;
            let a = s.sample_area(u2(&mut rng));
            let w = a.p - reference;
            if a.n.dot(w) < 0.0 {
                let geo = (a.n.dot(-w) / w.length().powi(3)) as f64;
                area1 += geo / a.pdf as f64;
                areag += g(a.p) * geo / a.pdf as f64;
            }
        }
        let n = n as f64;
        assert!((cone1 / n - exact).abs() < 1e-4 * exact);
        assert!(
            (area1 / n - exact).abs() < 0.015 * exact,
            "{} {exact}",
            area1 / n
        );
        assert!(
            (coneg / n - areag / n).abs() < 0.015 * (coneg / n),
            "{} {}",
            coneg / n,
            areag / n
        );
        // A tiny, distant sphere keeps its pdf finite and accurate (1 − cos ≈ sin²/2).
        let far = Vec3::new(0.0, 0.0, 1e4);
        let pdf = s.pdf_solid_angle(far, Vec3::Z) as f64;
        assert!((pdf * 2.0 * PI as f64 * 0.5e-8 - 1.0).abs() < 1e-4, "{pdf}");
    }
}
