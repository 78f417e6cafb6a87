//! Triangles: watertight ray intersection, area and uniform area sampling.
//!
//! The intersection is the algorithm of Woop, Benthin & Wald, "Watertight Ray/Triangle
//! Intersection" (JCGT 2013): the ray is mapped by a permutation and a shear so that it
//! runs along +z from the origin; the triangle's vertices, translated and sheared the same
//! way, are then tested with 2D edge functions. Because an edge shared by two triangles
//! produces bit-identical edge-function values in both (same vertices, same operations),
//! a ray can never slip between them; an edge function that rounds to exactly zero is
//! recomputed in f64 so the sign decision stays consistent.

// `!(x > 0.0)` is used on purpose: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::Ray;
use super::sample::AreaSample;
use glam::{Vec2, Vec3};
use radiant_math::sampling::uniform_triangle;

/// The per-ray part of the watertight test: axis permutation (`kz` is the dominant axis of
/// the direction) and shear constants. Computed once per ray and reused for every triangle.
/// The direction must be non-zero.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    pub o: Vec3,
    pub kx: usize,
    pub ky: usize,
    pub kz: usize,
    pub sx: f32,
    pub sy: f32,
    pub sz: f32,
}

impl WatertightRay {
    /// Always inlined: as a call its result went through memory and was read back
    /// field by field at the start of every traversal.
    #[inline(always)]
    pub fn new(ray: &Ray) -> WatertightRay {
        let a = ray.d.abs();
        let kz = if a.x > a.y {
            if a.x > a.z { 0 } else { 2 }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Keep the winding (and hence the sign of the determinant) consistent.
        let d = ray.d.to_array();
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        WatertightRay {
            o: ray.o,
            kx,
            ky,
            kz,
            sx: d[kx] / d[kz],
            sy: d[ky] / d[kz],
            sz: 1.0 / d[kz],
        }
    }
}

/// A ray–triangle hit: distance `t` (in units of the ray direction) and the barycentric
/// weights `b` of the three vertices (the hit point is `b[0] p0 + b[1] p1 + b[2] p2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub b: [f32; 3],
}

/// Edge functions (U, V, W) of a triangle given its vertices relative to the ray origin,
/// already sheared (`[x, y]` per vertex). Zeros are re-evaluated in f64 (Woop et al. §3).
#[inline(always)]
pub(crate) fn edge_functions(a: [f32; 2], b: [f32; 2], c: [f32; 2]) -> [f32; 3] {
    let mut u = c[0] * b[1] - c[1] * b[0];
    let mut v = a[0] * c[1] - a[1] * c[0];
    let mut w = b[0] * a[1] - b[1] * a[0];
    if u == 0.0 || v == 0.0 || w == 0.0 {
        [u, v, w] = edge_functions_f64(a, b, c);
    }
    [u, v, w]
}

#[cold]
#[inline(never)]
pub(crate) fn edge_functions_f64(a: [f32; 2], b: [f32; 2], c: [f32; 2]) -> [f32; 3] {
    let f = |x: f32| x as f64;
    [
        (f(c[0]) * f(b[1]) - f(c[1]) * f(b[0])) as f32,
        (f(a[0]) * f(c[1]) - f(a[1]) * f(c[0])) as f32,
        (f(b[0]) * f(a[1]) - f(b[1]) * f(a[0])) as f32,
    ]
}

/// A conservative bound on the rounding error of the computed `t`, from the largest
/// magnitudes of the sheared vertex coordinates (`max_x`, `max_y`, unscaled `max_z`) and
/// of the edge functions (`max_e`), and the final factor `sz / det`. A forward error
/// analysis of the kernel's operations (in the manner of pbrt-v4 §6.8.4, redone for the
/// unscaled z used here, so that it holds for unnormalised ray directions):
/// - z = p_z − o_z: one rounding, δz = γ₁ max_z;
/// - x = (p_x − o_x) − s_x z with |s_x| ≤ 1: |p_x − o_x| ≤ |x| + max_z, three roundings
///   and the error of z, δx ≤ γ₅ (max_x + 2 max_z) (likewise y);
/// - e = x_b y_c − y_b x_c: two products and a difference of values carrying δx, δy,
///   δe ≤ 2 (γ₂ max_x max_y + δy max_x + δx max_y);
/// - the sum of three products e z: δ ≤ 3 (γ₃ max_e max_z + δe max_z + δz max_e).
///
/// When the computed t does not exceed this bound times |sz / det| its sign is not
/// certain, and the hit is refused: a ray leaving a surface (its origin moved off the
/// surface past the hit point's error box) cannot find that surface again at t ≈ 0.
/// Written in the same operation order as the four-lane kernel, so both decide alike.
#[inline(always)]
pub(crate) fn t_error_bound(max_x: f32, max_y: f32, max_z: f32, max_e: f32, scale: f32) -> f32 {
    use super::ray::gamma;
    let dz = gamma(1) * max_z;
    let dx = gamma(5) * (max_x + 2.0 * max_z);
    let dy = gamma(5) * (max_y + 2.0 * max_z);
    let de = 2.0 * (gamma(2) * max_x * max_y + dy * max_x + dx * max_y);
    let dt = 3.0 * (gamma(3) * max_e * max_z + de * max_z + dz * max_e);
    dt * scale.abs()
}

/// Watertight ray–triangle intersection, two-sided. Reports hits with `0 < t < t_max`
/// whose t is positive beyond its rounding error ([`t_error_bound`]).
/// Degenerate (zero-area) triangles and rays in the triangle's plane never hit.
#[inline]
pub fn intersect_triangle(
    ray: &WatertightRay,
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
    t_max: f32,
) -> Option<TriangleHit> {
    let (kx, ky, kz) = (ray.kx, ray.ky, ray.kz);
    let a = p0 - ray.o;
    let b = p1 - ray.o;
    let c = p2 - ray.o;
    let shear = |p: Vec3| [p[kx] - ray.sx * p[kz], p[ky] - ray.sy * p[kz]];
    let [u, v, w] = edge_functions(shear(a), shear(b), shear(c));
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    // The paper scales each vertex's z by Sz; scaling the sum once is the same
    // t = (U Az + V Bz + W Cz) Sz / det up to rounding, with two fewer multiplies.
    let t = (u * a[kz] + v * b[kz] + w * c[kz]) * (ray.sz / det);
    if !(t > 0.0 && t < t_max) {
        return None;
    }
    let [sa, sb, sc] = [shear(a), shear(b), shear(c)];
    let max_x = sa[0].abs().max(sb[0].abs()).max(sc[0].abs());
    let max_y = sa[1].abs().max(sb[1].abs()).max(sc[1].abs());
    let max_z = a[kz].abs().max(b[kz].abs()).max(c[kz].abs());
    let max_e = u.abs().max(v.abs()).max(w.abs());
    if !(t > t_error_bound(max_x, max_y, max_z, max_e, ray.sz / det)) {
        return None;
    }
    let inv_det = 1.0 / det;
    Some(TriangleHit {
        t,
        b: [u * inv_det, v * inv_det, w * inv_det],
    })
}

/// Triangle area.
pub fn triangle_area(p0: Vec3, p1: Vec3, p2: Vec3) -> f32 {
    0.5 * (p1 - p0).cross(p2 - p0).length()
}

/// Unit geometric normal `(p1 - p0) × (p2 - p0)` normalised (zero for degenerate triangles).
pub fn triangle_normal(p0: Vec3, p1: Vec3, p2: Vec3) -> Vec3 {
    (p1 - p0).cross(p2 - p0).normalize_or_zero()
}

/// A point uniformly distributed over the triangle's area (pdf = 1 / area), with the
/// geometric normal. `None` for a degenerate triangle, which has no density.
pub fn sample_triangle(p0: Vec3, p1: Vec3, p2: Vec3, u: Vec2) -> Option<AreaSample> {
    let area = triangle_area(p0, p1, p2);
    if !(area > 0.0) {
        return None;
    }
    let b = uniform_triangle(u);
    Some(AreaSample {
        p: b[0] * p0 + b[1] * p1 + b[2] * p2,
        p_error: super::ray::barycentric_error(b, [p0, p1, p2]),
        n: triangle_normal(p0, p1, p2),
        pdf: 1.0 / area,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;

    fn rand_vec(rng: &mut Pcg32) -> Vec3 {
        Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE
    }

    #[test]
    fn rays_at_shared_edges_and_vertices_never_fall_through() {
        // Rays from points inside a closed mesh, aimed exactly at vertices and at
        // points on shared edges (where non-watertight tests leak), must hit something.
        // A closed geodesic sphere with shared vertices (320 triangles).
        let mesh = crate::accel::displaced_sphere::geodesic_sphere(4);
        let (v, f) = (mesh.vertices, mesh.triangles);
        let mut rng = Pcg32::new(11, 3);
        let mut misses = 0;
        let mut rays = 0;
        for k in 0..40 {
            let o = rand_vec(&mut rng) * 0.5 * (k as f32 / 40.0);
            for tri in &f {
                let p = tri.map(|i| v[i as usize]);
                let targets = [
                    p[0],
                    p[1],
                    0.5 * (p[0] + p[1]),
                    0.25 * p[1] + 0.75 * p[2],
                    p[2] + (p[0] - p[2]) * rng.uniform(),
                ];
                for target in targets {
                    let ray = Ray::new(o, target - o);
                    let wr = WatertightRay::new(&ray);
                    rays += 1;
                    let hit = f.iter().any(|t| {
                        let q = t.map(|i| v[i as usize]);
                        intersect_triangle(&wr, q[0], q[1], q[2], f32::INFINITY).is_some()
                    });
                    misses += usize::from(!hit);
                }
            }
        }
        assert!(rays > 30_000);
        assert_eq!(misses, 0, "{misses} of {rays} rays leaked through the mesh");
    }

    #[test]
    fn hit_matches_plane_intersection_and_barycentrics_reconstruct_point() {
        let mut rng = Pcg32::new(5, 1);
        let mut hits = 0;
        for _ in 0..20_000 {
            let p = [rand_vec(&mut rng), rand_vec(&mut rng), rand_vec(&mut rng)];
            let o = rand_vec(&mut rng) * 3.0;
            let target = p[0] * 0.3 + p[1] * 0.3 + p[2] * 0.4 + rand_vec(&mut rng) * 0.5;
            let ray = Ray::new(o, target - o);
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            let wr = WatertightRay::new(&ray);
            let Some(h) = intersect_triangle(&wr, p[0], p[1], p[2], f32::INFINITY) else {
                continue;
            };
            hits += 1;
            // Analytic plane distance, in f64.
            let t_plane =
                (p[0] - o).as_dvec3().dot(n.as_dvec3()) / ray.d.as_dvec3().dot(n.as_dvec3());
            let cos = (ray.d.normalize().dot(n.normalize())).abs() as f64;
            // Relative error grows like 1/cos for grazing rays; 1e-5 covers f32 round-off.
            assert!(
                ((h.t as f64 - t_plane) / t_plane).abs() < 1e-5 / cos.max(1e-2),
                "{} vs {}",
                h.t,
                t_plane
            );
            let q = h.b[0] * p[0] + h.b[1] * p[1] + h.b[2] * p[2];
            assert!((q - ray.at(h.t)).length() < 1e-4 / cos.max(1e-2) as f32);
            assert!(h.b.iter().all(|&b| b >= 0.0) && (h.b.iter().sum::<f32>() - 1.0).abs() < 1e-5);
        }
        assert!(hits > 2000, "{hits}");
    }

    #[test]
    fn degenerate_and_parallel_cases_miss() {
        let o = Vec3::new(0.2, 0.2, -1.0);
        let wr = WatertightRay::new(&Ray::new(o, Vec3::Z));
        // Zero-area: collinear and coincident vertices.
        let a = Vec3::new(0.0, 0.0, 0.0);
        let b = Vec3::new(1.0, 1.0, 0.0);
        assert!(intersect_triangle(&wr, a, b, 0.5 * b, 10.0).is_none());
        assert!(intersect_triangle(&wr, a, a, a, 10.0).is_none());
        // Ray in the triangle's plane.
        let wr = WatertightRay::new(&Ray::new(Vec3::new(-1.0, 0.1, 0.0), Vec3::X));
        let c = Vec3::new(1.0, 0.0, 0.0);
        let d = Vec3::new(0.0, 1.0, 0.0);
        assert!(intersect_triangle(&wr, a, c, d, 10.0).is_none());
        // Behind the origin and beyond t_max.
        let wr = WatertightRay::new(&Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::Z));
        assert!(intersect_triangle(&wr, a, c, d, 10.0).is_none());
        let wr = WatertightRay::new(&Ray::new(o, Vec3::Z));
        assert!(intersect_triangle(&wr, a, c, d, 1.0).is_none());
        assert_eq!(
            intersect_triangle(&wr, a, c, d, 1.001).map(|h| h.t),
            Some(1.0)
        );
    }

    #[test]
    fn area_sampling_recovers_area() {
        // E[1/pdf] = area exactly (pdf is constant); also the sample mean must be the centroid
        // within Monte Carlo error: the std of one coordinate is < 1, so 1e5 samples give
        // a standard error < 0.0032; allow 4 sigma.
        let p = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 1.0),
            Vec3::new(0.5, 3.0, 0.0),
        ];
        let area = triangle_area(p[0], p[1], p[2]);
        let mut rng = Pcg32::new(9, 9);
        let n = 100_000;
        let mut inv_pdf = 0.0f64;
        let mut mean = Vec3::ZERO.as_dvec3();
        for _ in 0..n {
            let s =
                sample_triangle(p[0], p[1], p[2], Vec2::new(rng.uniform(), rng.uniform())).unwrap();
            inv_pdf += 1.0 / s.pdf as f64;
            mean += s.p.as_dvec3();
            assert!((s.p - p[0]).dot(s.n).abs() < 1e-5);
        }
        assert!((inv_pdf / n as f64 - area as f64).abs() < 1e-4 * area as f64);
        let centroid = ((p[0] + p[1] + p[2]) / 3.0).as_dvec3();
        assert!((mean / n as f64 - centroid).length() < 0.013);
        assert!(sample_triangle(p[0], p[1], p[0], Vec2::splat(0.5)).is_none());
    }
}
