//! Disks (and annuli, and sectors of them) in the plane z = height of object space,
//! facing +z: pbrt's `disk` with `height`, `radius`, `innerradius` and `phimax`.

// `!(x > 0.0)` is used on purpose: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::Ray;
use super::sample::{AreaSample, ShapeError};
use glam::{Vec2, Vec3};
use radiant_math::sampling::concentric_disk;
use radiant_math::{PI, safe_sqrt};

/// A disk (annulus, sector) at `height` on the z axis, facing +z, in object space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disk {
    pub height: f32,
    pub radius: f32,
    pub inner_radius: f32,
    /// Azimuth limit in radians, in (0, 2π].
    pub phi_max: f32,
}

/// A ray–disk hit in object space; the normal is always +z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiskHit {
    pub t: f32,
    /// Hit point, exactly in the disk's plane (so its error bound is zero: it is a point of
    /// the surface, though not exactly the ray's).
    pub p: Vec3,
    /// u = phi / phi_max; v = (radius − r) / (radius − inner_radius) (1 at the inner edge).
    pub uv: Vec2,
}

impl Disk {
    /// pbrt's `disk`: `height`, `radius`, `innerradius`, `phimax` in degrees.
    pub fn new(
        height: f32,
        radius: f32,
        inner_radius: f32,
        phi_max_degrees: f32,
    ) -> Result<Disk, ShapeError> {
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(ShapeError::BadRadius(radius));
        }
        if !(inner_radius >= 0.0 && inner_radius < radius) {
            return Err(ShapeError::BadInnerRadius {
                inner: inner_radius,
                radius,
            });
        }
        if !(phi_max_degrees > 0.0 && phi_max_degrees <= 360.0) {
            return Err(ShapeError::BadPhiMax(phi_max_degrees));
        }
        Ok(Disk {
            height,
            radius,
            inner_radius,
            phi_max: phi_max_degrees.to_radians(),
        })
    }

    pub fn normal(&self) -> Vec3 {
        Vec3::Z
    }

    pub fn area(&self) -> f32 {
        0.5 * self.phi_max * (self.radius * self.radius - self.inner_radius * self.inner_radius)
    }

    /// Hit with `0 < t < t_max`. Rays parallel to the plane never hit.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<DiskHit> {
        if ray.d.z == 0.0 {
            return None;
        }
        let t = (self.height - ray.o.z) / ray.d.z;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let p = ray.at(t);
        let r2 = p.x * p.x + p.y * p.y;
        if r2 > self.radius * self.radius || r2 < self.inner_radius * self.inner_radius {
            return None;
        }
        let mut phi = p.y.atan2(p.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        if phi > self.phi_max {
            return None;
        }
        let r = r2.sqrt();
        Some(DiskHit {
            t,
            // Exactly on the plane: the z of o + t d carries round-off.
            p: Vec3::new(p.x, p.y, self.height),
            uv: Vec2::new(
                phi / self.phi_max,
                (self.radius - r) / (self.radius - self.inner_radius),
            ),
        })
    }

    /// ∂p/∂v at a point of the disk: v = (radius − r) / (radius − inner radius)
    /// falls outwards, so ∂p/∂v = −(radius − inner radius) (x, y, 0) / r.
    pub fn dpdv(&self, p: Vec3) -> Vec3 {
        let r = (p.x * p.x + p.y * p.y).sqrt();
        if !(r > 0.0) {
            return Vec3::ZERO;
        }
        -(self.radius - self.inner_radius) * Vec3::new(p.x, p.y, 0.0) / r
    }

    /// Surface parameters of a point on the disk: (phi / phi_max, (radius − r) /
    /// (radius − inner radius)), as hits report them.
    pub fn uv(&self, p: Vec3) -> Vec2 {
        let mut phi = p.y.atan2(p.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let r = (p.x * p.x + p.y * p.y).sqrt();
        Vec2::new(
            (phi / self.phi_max).min(1.0),
            (self.radius - r) / (self.radius - self.inner_radius),
        )
    }

    /// Uniform sampling by area (pdf = 1 / area). The full disk uses the concentric map
    /// (Shirley & Chiu 1997) for low distortion; annuli and sectors use r² uniform in
    /// [inner², radius²] and phi uniform in [0, phi_max], which is also area-uniform.
    pub fn sample_area(&self, u: Vec2) -> AreaSample {
        let xy = if self.inner_radius == 0.0 && self.phi_max >= 2.0 * PI {
            concentric_disk(u) * self.radius
        } else {
            let (ri2, r2) = (
                self.inner_radius * self.inner_radius,
                self.radius * self.radius,
            );
            let r = safe_sqrt(ri2 + u.x * (r2 - ri2));
            let phi = u.y * self.phi_max;
            Vec2::new(r * phi.cos(), r * phi.sin())
        };
        AreaSample {
            p: Vec3::new(xy.x, xy.y, self.height),
            // On the plane exactly.
            p_error: Vec3::ZERO,
            n: Vec3::Z,
            pdf: 1.0 / self.area(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;

    #[test]
    fn dpdv_moves_along_v_at_the_rate_of_the_parameterisation() {
        let d = Disk::new(0.5, 2.0, 0.4, 250.0).unwrap();
        let mut rng = Pcg32::new(6, 1);
        for _ in 0..200 {
            let p = d.sample_area(Vec2::new(rng.uniform(), rng.uniform())).p;
            let uv = d.uv(p);
            let h = 1e-3;
            let duv = d.uv(p + h * d.dpdv(p)) - uv;
            assert!((duv.y - h).abs() < 1e-2 * h, "dv {} for step {h}", duv.y);
            assert!(duv.x.abs() < 1e-6, "du {}", duv.x);
        }
    }

    #[test]
    fn hits_match_analytic_plane_and_annulus() {
        let disk = Disk::new(0.5, 2.0, 0.5, 300.0).unwrap();
        let mut rng = Pcg32::new(2, 2);
        let mut hits = 0;
        for _ in 0..20_000 {
            let o = Vec3::new(
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() + 1.0,
            ) * 4.0;
            let target = Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, 0.0) * 5.0;
            let ray = Ray::new(o, target - o);
            // Analytic, in f64.
            let t = (0.5 - o.z as f64) / ray.d.z as f64;
            let p = ray.o.as_dvec3() + t * ray.d.as_dvec3();
            let r = p.truncate().length();
            let phi = p.y.atan2(p.x).rem_euclid(2.0 * std::f64::consts::PI);
            let inside = (0.5..=2.0).contains(&r) && phi <= 300f64.to_radians();
            // Edge decisions may differ from the f64 answer within round-off only.
            let phi_max = 300f64.to_radians();
            let near_edge = (r - 2.0).abs() < 1e-4
                || (r - 0.5).abs() < 1e-4
                || (phi - phi_max).abs() < 1e-4
                || !(1e-4..=2.0 * std::f64::consts::PI - 1e-4).contains(&phi);
            let got = disk.intersect(&ray, f32::INFINITY);
            assert!(got.is_some() == inside || near_edge, "r={r} phi={phi}");
            if let Some(h) = got {
                hits += 1;
                assert!(((h.t as f64 - t) / t).abs() < 1e-5);
                assert!(h.uv.min_element() >= 0.0 && h.uv.max_element() <= 1.0);
            }
        }
        assert!(hits > 3000, "{hits}");
        let flat = Ray::new(Vec3::new(0.0, 0.0, 0.5), Vec3::X);
        assert!(disk.intersect(&flat, 10.0).is_none());
        assert!(Disk::new(0.0, 1.0, 1.0, 360.0).is_err());
    }

    #[test]
    fn area_sampling_mean_radius_matches_closed_form() {
        // For area-uniform points on an annulus, E[r] = (2/3)(R³ − ri³)/(R² − ri²).
        // std(r) < R = 2, 1e5 samples → standard error < 0.0063; allow 4 sigma.
        for disk in [
            Disk::new(1.0, 2.0, 0.0, 360.0).unwrap(),
            Disk::new(1.0, 2.0, 0.7, 200.0).unwrap(),
        ] {
            let mut rng = Pcg32::new(6, 1);
            let n = 100_000;
            let (mut mean_r, mut inv_pdf) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let s = disk.sample_area(Vec2::new(rng.uniform(), rng.uniform()));
                let r = s.p.truncate().length() as f64;
                assert!(r <= 2.0 + 1e-5 && r >= 0.7 * f64::from(disk.inner_radius > 0.0) - 1e-5);
                assert_eq!(s.p.z, 1.0);
                mean_r += r;
                inv_pdf += 1.0 / s.pdf as f64;
            }
            let (ro, ri) = (2.0f64, disk.inner_radius as f64);
            let expect = 2.0 / 3.0 * (ro.powi(3) - ri.powi(3)) / (ro * ro - ri * ri);
            assert!(
                (mean_r / n as f64 - expect).abs() < 0.025,
                "{} {expect}",
                mean_r / n as f64
            );
            let area = disk.phi_max as f64 * 0.5 * (ro * ro - ri * ri);
            assert!((inv_pdf / n as f64 - area).abs() < 1e-4 * area);
        }
    }
}
