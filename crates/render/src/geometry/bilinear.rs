//! Bilinear patches p(u,v) = (1−u)(1−v) p00 + u(1−v) p10 + (1−u)v p01 + uv p11.
//!
//! Curved patches are intersected with the geometric method of Reshetov, "Cool Patches:
//! A Geometric Approach to Ray/Bilinear Patch Intersections" (Ray Tracing Gems, 2019): the
//! patch is swept by the segments L(u) from p(u,0) to p(u,1); the ray meets L(u) only where
//! the ray, L(u) and the origin are coplanar, a quadratic in u; the ray–segment closest
//! approach then gives t and v. Planar patches (the common quad of a mesh) are intersected
//! as the two triangles (p00,p10,p11), (p00,p11,p01) with the watertight triangle test, so
//! they give exactly the same hits as a triangulated quad and stay watertight with
//! neighbouring triangles; (u,v) is then recovered by inverting the bilinear map.

// `!(x > 0.0)` is used on purpose: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::Ray;
use super::ray::{barycentric_error, gamma};
use super::sample::AreaSample;
use super::triangle::{WatertightRay, intersect_triangle};
use glam::{DVec2, Vec2, Vec3};

/// A bilinear patch given by its four corners.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BilinearPatch {
    pub p00: Vec3,
    pub p10: Vec3,
    pub p01: Vec3,
    pub p11: Vec3,
}

/// A ray–patch hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BilinearHit {
    pub t: f32,
    /// The hit point on the patch and a bound on its error per component.
    pub p: Vec3,
    pub p_error: Vec3,
    pub uv: Vec2,
    /// Unit normal along ∂p/∂u × ∂p/∂v.
    pub n: Vec3,
}

/// Relative distance of p11 from the plane of the other three below which a patch counts
/// as planar: a few ulps of the patch size, the noise of computing a plane in f32.
const PLANAR_TOLERANCE: f32 = 1e-6;

impl BilinearPatch {
    pub fn new(p00: Vec3, p10: Vec3, p01: Vec3, p11: Vec3) -> BilinearPatch {
        BilinearPatch { p00, p10, p01, p11 }
    }

    pub fn point(&self, uv: Vec2) -> Vec3 {
        let (u, v) = (uv.x, uv.y);
        (1.0 - u) * (1.0 - v) * self.p00
            + u * (1.0 - v) * self.p10
            + (1.0 - u) * v * self.p01
            + u * v * self.p11
    }

    /// [`point`](Self::point) with a bound on its error: four weights of up to three
    /// roundings each, four products and three sums — γ₇ of the absolute terms, which also
    /// covers weights that do not sum exactly to one.
    pub fn point_with_error(&self, uv: Vec2) -> (Vec3, Vec3) {
        let (u, v) = (uv.x, uv.y);
        let terms = ((1.0 - u) * (1.0 - v) * self.p00).abs()
            + (u * (1.0 - v) * self.p10).abs()
            + ((1.0 - u) * v * self.p01).abs()
            + (u * v * self.p11).abs();
        (self.point(uv), gamma(7) * terms)
    }

    /// The partial derivatives (∂p/∂u, ∂p/∂v) at `uv`.
    pub fn tangents(&self, uv: Vec2) -> (Vec3, Vec3) {
        let dpdu = (self.p10 - self.p00).lerp(self.p11 - self.p01, uv.y);
        let dpdv = (self.p01 - self.p00).lerp(self.p11 - self.p10, uv.x);
        (dpdu, dpdv)
    }

    /// Unit normal ∂p/∂u × ∂p/∂v at `uv` (falls back to the corner plane where the
    /// tangents degenerate, e.g. at the apex of a triangle-shaped patch).
    pub fn normal(&self, uv: Vec2) -> Vec3 {
        let (dpdu, dpdv) = self.tangents(uv);
        let n = dpdu.cross(dpdv).normalize_or_zero();
        if n != Vec3::ZERO {
            return n;
        }
        (self.p10 - self.p00)
            .cross(self.p01 - self.p00)
            .normalize_or_zero()
    }

    /// True when p11 lies in the plane of p00, p10, p01 (to within [`PLANAR_TOLERANCE`]).
    pub fn is_planar(&self) -> bool {
        let n = (self.p10 - self.p00).cross(self.p01 - self.p00);
        let size = (self.p10 - self.p00)
            .length()
            .max((self.p01 - self.p00).length())
            .max((self.p11 - self.p00).length());
        let len = n.length();
        len > 0.0 && (self.p11 - self.p00).dot(n).abs() <= PLANAR_TOLERANCE * size * len
    }

    /// Closest hit with `0 < t < t_max`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<BilinearHit> {
        if self.is_planar() {
            self.intersect_planar(ray, t_max)
        } else {
            self.intersect_curved(ray, t_max)
        }
    }

    /// Planar case: the two triangles of the quad, uv by inverse bilinear interpolation.
    fn intersect_planar(&self, ray: &Ray, t_max: f32) -> Option<BilinearHit> {
        let wr = WatertightRay::new(ray);
        let h0 = intersect_triangle(&wr, self.p00, self.p10, self.p11, t_max);
        let t_max = h0.map_or(t_max, |h| h.t);
        let h1 = intersect_triangle(&wr, self.p00, self.p11, self.p01, t_max);
        let (h, corners) = match (h0, h1) {
            (_, Some(h)) => (h, [self.p00, self.p11, self.p01]),
            (Some(h), None) => (h, [self.p00, self.p10, self.p11]),
            (None, None) => return None,
        };
        let p = h.b[0] * corners[0] + h.b[1] * corners[1] + h.b[2] * corners[2];
        let uv = self.planar_uv(p);
        Some(BilinearHit {
            t: h.t,
            p,
            p_error: barycentric_error(h.b, corners),
            uv,
            n: self.normal(uv),
        })
    }

    /// (u, v) of a point in the plane of a planar patch. Projecting onto the plane's two
    /// best axes, p = p00 + u e + v f + uv g with e = p10 − p00, f = p01 − p00,
    /// g = p00 − p10 − p01 + p11; crossing with (f + u g) eliminates v and leaves
    /// (e×g) u² + (e×f − h×g) u − h×f = 0 for h = p − p00 (2D cross products), solved in f64.
    fn planar_uv(&self, p: Vec3) -> Vec2 {
        let n = (self.p10 - self.p00).cross(self.p01 - self.p00).abs();
        let (i, j) = if n.x >= n.y && n.x >= n.z {
            (1, 2)
        } else if n.y >= n.z {
            (2, 0)
        } else {
            (0, 1)
        };
        let proj = |q: Vec3| DVec2::new(q[i] as f64, q[j] as f64);
        let a = proj(self.p00);
        let e = proj(self.p10) - a;
        let f = proj(self.p01) - a;
        let g = a - proj(self.p10) - proj(self.p01) + proj(self.p11);
        let h = proj(p) - a;
        let (k2, k1, k0) = (e.perp_dot(g), e.perp_dot(f) - h.perp_dot(g), -h.perp_dot(f));
        let u = if k2.abs() <= 1e-12 * k1.abs() {
            -k0 / k1
        } else {
            let disc = (k1 * k1 - 4.0 * k2 * k0).max(0.0).sqrt();
            let q = -0.5 * (k1 + disc.copysign(k1));
            let roots = [q / k2, if q != 0.0 { k0 / q } else { 0.0 }];
            // The root inside [0,1] (closest to its middle, for round-off at the edges).
            if (roots[0] - 0.5).abs() <= (roots[1] - 0.5).abs() {
                roots[0]
            } else {
                roots[1]
            }
        };
        let den = f + u * g;
        let v = if den.x.abs() >= den.y.abs() {
            (h.x - u * e.x) / den.x
        } else {
            (h.y - u * e.y) / den.y
        };
        Vec2::new(u as f32, v as f32).clamp(Vec2::ZERO, Vec2::ONE)
    }

    /// Reshetov's intersection, valid for any patch (used directly for curved ones).
    pub fn intersect_curved(&self, ray: &Ray, t_max: f32) -> Option<BilinearHit> {
        let (o, d) = (ray.o, ray.d);
        let q00 = self.p00 - o;
        let q10 = self.p10 - o;
        let e00 = self.p01 - self.p00; // L(0) direction
        let e11 = self.p11 - self.p10; // L(1) direction
        // f(u) = [pa(u) × d] · pb(u), pa(u) = lerp(q00, q10, u), pb(u) = lerp(e00, e11, u):
        // f(0) = a, f(1) = a + b + c, and the u² coefficient reduces to qn · d.
        let qn = (self.p10 - self.p00).cross(self.p01 - self.p11);
        let a = q00.cross(d).dot(e00);
        let c = qn.dot(d);
        let b = q10.cross(d).dot(e11) - a - c;
        let roots: [f32; 2] = if c == 0.0 {
            if b == 0.0 {
                return None;
            }
            [-a / b, f32::NAN]
        } else {
            let disc = b * b - 4.0 * a * c;
            if disc < 0.0 {
                return None;
            }
            let q = -0.5 * (b + disc.sqrt().copysign(b));
            [q / c, if q != 0.0 { a / q } else { f32::NAN }]
        };
        let mut best: Option<BilinearHit> = None;
        let mut t_best = t_max;
        for u in roots {
            if !(0.0..=1.0).contains(&u) {
                continue;
            }
            let pa = q00.lerp(q10, u);
            let pb = e00.lerp(e11, u);
            // o + t d = o + pa + v pb: crossing with pb and with d isolates t and v.
            let n = d.cross(pb);
            let det = n.length_squared();
            if det == 0.0 {
                continue;
            }
            let m = n.cross(pa);
            let t = m.dot(pb) / det;
            let v = m.dot(d) / det;
            if t > 0.0 && t < t_best && (0.0..=1.0).contains(&v) {
                t_best = t;
                let uv = Vec2::new(u, v);
                let (p, p_error) = self.point_with_error(uv);
                best = Some(BilinearHit {
                    t,
                    p,
                    p_error,
                    uv,
                    n: self.normal(uv),
                });
            }
        }
        best
    }

    /// |∂p/∂u × ∂p/∂v| at `uv`: the area element of the (u,v) parameterisation.
    pub fn jacobian(&self, uv: Vec2) -> f32 {
        let (dpdu, dpdv) = self.tangents(uv);
        dpdu.cross(dpdv).length()
    }

    /// Surface area: the integral of the area element by Gauss–Legendre quadrature
    /// (exact for parallelograms; the element is smooth, so it converges fast).
    pub fn area(&self) -> f32 {
        radiant_scene::mesh::bilinear_patch_area([self.p00, self.p10, self.p01, self.p11])
    }

    /// Samples (u,v) uniformly in the unit square and maps it onto the patch. This is not
    /// uniform in area, but its density is known exactly: dA = J(u,v) du dv with
    /// J = |∂p/∂u × ∂p/∂v|, so pdf_area = 1 / J(u,v). It is uniform for parallelograms and
    /// mildly non-uniform otherwise (the variance cost grows with how much J varies).
    /// `None` where the patch degenerates (J = 0).
    pub fn sample_area(&self, u: Vec2) -> Option<AreaSample> {
        let j = self.jacobian(u);
        if !(j > 0.0) {
            return None;
        }
        let (p, p_error) = self.point_with_error(u);
        Some(AreaSample {
            p,
            p_error,
            n: self.normal(u),
            pdf: 1.0 / j,
        })
    }

    /// The area density `sample_area` gives to the surface point with parameters `uv`.
    pub fn pdf_area(&self, uv: Vec2) -> f32 {
        let j = self.jacobian(uv);
        if j > 0.0 { 1.0 / j } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;

    fn rv(rng: &mut Pcg32) -> Vec3 {
        Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE
    }

    #[test]
    fn saddle_hits_match_analytic_surface() {
        // p(u,v) = (u, v, uv): the saddle z = xy over the unit square. A ray meets it where
        // oz + t dz = (ox + t dx)(oy + t dy), solved in f64.
        let patch = BilinearPatch::new(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE);
        assert!(!patch.is_planar());
        let mut rng = Pcg32::new(12, 1);
        let mut hits = 0;
        for _ in 0..20_000 {
            let o = Vec3::new(rng.uniform(), rng.uniform(), 2.0) + rv(&mut rng) * 0.8;
            let target = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform() - 0.5) * 1.2
                - Vec3::splat(0.1);
            let ray = Ray::new(o, target - o);
            let (od, dd) = (ray.o.as_dvec3(), ray.d.as_dvec3());
            let qa = dd.x * dd.y;
            let qb = od.x * dd.y + od.y * dd.x - dd.z;
            let qc = od.x * od.y - od.z;
            let disc = qb * qb - 4.0 * qa * qc;
            let mut exact: Option<f64> = None;
            if disc >= 0.0 {
                for t in [
                    (-qb - disc.sqrt()) / (2.0 * qa),
                    (-qb + disc.sqrt()) / (2.0 * qa),
                ] {
                    let p = od + t * dd;
                    if t > 0.0 && (0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y) {
                        exact = Some(exact.map_or(t, |e: f64| e.min(t)));
                    }
                }
            }
            let got = patch.intersect(&ray, f32::INFINITY);
            match (exact, got) {
                (Some(te), Some(h)) => {
                    hits += 1;
                    // f32 round-off through the quadratic: 1e-4 relative, measured max ~1e-5.
                    assert!(((h.t as f64 - te) / te).abs() < 1e-4, "{} {te}", h.t);
                    let p = ray.at(h.t);
                    assert!((h.uv - Vec2::new(p.x, p.y)).length() < 1e-4);
                    let expect_n = Vec3::new(-h.uv.y, -h.uv.x, 1.0).normalize();
                    assert!((h.n - expect_n).length() < 1e-4);
                }
                (None, None) => {}
                (e, g) => {
                    // Only rays grazing the boundary may disagree.
                    let t = e.unwrap_or_else(|| g.unwrap().t as f64);
                    let p = od + t * dd;
                    let edge = p.x.min(p.y).min(1.0 - p.x).min(1.0 - p.y);
                    assert!(edge.abs() < 1e-4, "{e:?} {g:?} {p:?}");
                }
            }
        }
        assert!(hits > 5000, "{hits}");
    }

    fn random_planar_patch(rng: &mut Pcg32) -> BilinearPatch {
        // A convex quad in the plane z = 0 with exactly representable coordinates stays
        // exactly planar; shear it into a random plane z = ax + by with dyadic a, b.
        let a = (rng.uniform() * 8.0).floor() / 4.0 - 1.0;
        let b = (rng.uniform() * 8.0).floor() / 4.0 - 1.0;
        let lift = |x: f32, y: f32| Vec3::new(x, y, a * x + b * y);
        let q = |rng: &mut Pcg32| (rng.uniform() * 64.0).floor() / 128.0;
        BilinearPatch::new(
            lift(q(rng), q(rng)),
            lift(1.0 + q(rng), q(rng)),
            lift(q(rng), 1.0 + q(rng)),
            lift(1.0 + q(rng), 1.0 + q(rng)),
        )
    }

    #[test]
    fn planar_patch_equals_two_triangles() {
        let mut rng = Pcg32::new(21, 5);
        let (mut hits, mut curved_checked) = (0, 0);
        for _ in 0..20_000 {
            let patch = random_planar_patch(&mut rng);
            assert!(patch.is_planar());
            let o = rv(&mut rng) * 3.0 + Vec3::new(0.5, 0.5, 0.0);
            // Aim at the patch's plane, over and somewhat beyond the patch.
            let target = patch.point(Vec2::new(rng.uniform(), rng.uniform()) * 1.4 - 0.2);
            let ray = Ray::new(o, target - o);
            let wr = WatertightRay::new(&ray);
            let t0 = intersect_triangle(&wr, patch.p00, patch.p10, patch.p11, f32::INFINITY);
            let t1 = intersect_triangle(&wr, patch.p00, patch.p11, patch.p01, f32::INFINITY);
            let tri = match (t0, t1) {
                (Some(a), Some(b)) => Some(a.t.min(b.t)),
                (a, b) => a.or(b).map(|h| h.t),
            };
            let got = patch.intersect(&ray, f32::INFINITY);
            assert_eq!(got.map(|h| h.t), tri, "planar patch and triangles disagree");
            let Some(h) = got else { continue };
            hits += 1;
            // The recovered (u,v) maps back to the hit point.
            let p = ray.at(h.t);
            assert!((patch.point(h.uv) - p).length() < 1e-4, "{:?}", h.uv);
            // Reshetov's kernel on the same planar patch agrees away from the border.
            if h.uv.min_element() > 1e-3 && h.uv.max_element() < 1.0 - 1e-3 {
                let c = patch
                    .intersect_curved(&ray, f32::INFINITY)
                    .expect("curved kernel missed");
                // Both are f32 solutions of an intersection whose conditioning degrades as
                // 1/cos(incidence); the measured worst case of err * cos was 4e-7.
                let cos = ray.d.normalize().dot(h.n).abs();
                assert!(
                    (c.t - h.t).abs() / h.t * cos < 4e-6,
                    "{} {} {cos}",
                    c.t,
                    h.t
                );
                assert!((c.uv - h.uv).length() * cos < 1e-5, "{:?} {:?}", c.uv, h.uv);
                curved_checked += 1;
            }
        }
        assert!(
            hits > 3000 && curved_checked > 3000,
            "{hits} {curved_checked}"
        );
    }

    #[test]
    fn area_sampling_pdf_integrates_to_area() {
        // mean(1/pdf) = E[J] = area. J on this twisted patch varies by ~2x, so the relative
        // std of 1/pdf is < 0.5 and 1e5 samples give ~0.16 %; allow 1 %.
        let patch = BilinearPatch::new(
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.5),
            Vec3::new(0.0, 1.5, -0.3),
            Vec3::new(2.5, 2.0, 1.2),
        );
        let area = patch.area() as f64;
        let mut rng = Pcg32::new(4, 2);
        let n = 100_000;
        let mut inv = 0.0;
        for _ in 0..n {
            let uv = Vec2::new(rng.uniform(), rng.uniform());
            let s = patch.sample_area(uv).unwrap();
            assert_eq!(s.pdf, patch.pdf_area(uv));
            assert!((s.n.length() - 1.0).abs() < 1e-5);
            inv += 1.0 / s.pdf as f64;
        }
        assert!(
            (inv / n as f64 - area).abs() < 0.01 * area,
            "{} {area}",
            inv / n as f64
        );
        // Quadrature check against a fine midpoint rule (1e-4 relative).
        let m = 400;
        let mut fine = 0.0f64;
        for i in 0..m {
            for j in 0..m {
                let uv = Vec2::new((i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32);
                fine += patch.jacobian(uv) as f64;
            }
        }
        fine /= (m * m) as f64;
        assert!((fine - area).abs() < 1e-4 * area, "{fine} {area}");
        // A parallelogram's area is exact: |e × f|.
        let par = BilinearPatch::new(
            Vec3::ZERO,
            Vec3::X * 2.0,
            Vec3::Y * 3.0,
            Vec3::new(2.0, 3.0, 0.0),
        );
        assert!((par.area() - 6.0).abs() < 1e-5);
    }
}
