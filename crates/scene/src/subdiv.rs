//! Loop subdivision surfaces (`Shape "loopsubdiv"`): C. Loop, "Smooth Subdivision
//! Surfaces Based on Triangles", MS thesis, University of Utah, 1987.
//!
//! Each level splits every triangle into four. New (odd) vertices on an interior edge
//! get 3/8 of the edge's ends and 1/8 of the two opposite vertices; on a boundary edge
//! the midpoint. Old (even) vertices move to (1 − nβ) v + β Σ neighbours with Loop's
//! β(n) = (5/8 − (3/8 + cos(2π/n)/4)²) / n, boundary vertices to 3/4 v + 1/8 of their
//! two boundary neighbours. After the last level every vertex is pushed to its limit
//! position: v + γ Σ (neighbour − v) with γ = 1 / (n + 3 / (8β)) inside, and
//! 3/5 v + 1/5 of the boundary neighbours on the boundary. Edges not shared by exactly
//! two triangles count as boundary (creases); vertices on more than two such edges
//! stay where they are. Normals are the area-weighted normals of the final mesh at its
//! limit positions (close to the exact limit normal after a few levels).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use glam::{DVec3, Vec3};

/// The subdivided mesh: limit positions, vertex normals and triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct Subdivided {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub indices: Vec<u32>,
}

/// The ring structure of one level: each vertex's neighbours, and the neighbours across
/// its boundary edges.
struct Rings {
    neighbours: Vec<Vec<u32>>,
    boundary: Vec<Vec<u32>>,
}

/// Edges of a triangle list, each once (smaller index first) and numbered in the order
/// the triangles first name them, with how many triangles use them, the first two
/// vertices opposite them (all an interior edge has) and the edges of each triangle.
struct Edges {
    ends: Vec<(u32, u32)>,
    uses: Vec<u32>,
    opposite: Vec<[u32; 2]>,
    /// Edges ab, bc and ca of each triangle abc.
    of_triangle: Vec<[u32; 3]>,
}

fn key(a: u32, b: u32) -> (u32, u32) {
    if a < b { (a, b) } else { (b, a) }
}

/// A hasher for an edge's two vertex indices, packed in one word: std's default
/// (SipHash, built against adversarial keys) took most of a subdivision level's time.
#[derive(Default)]
struct EdgeHasher(u64);

impl Hasher for EdgeHasher {
    fn finish(&self) -> u64 {
        radiant_math::hash::mix64(self.0)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 << 8) ^ b as u64;
        }
    }

    fn write_u64(&mut self, v: u64) {
        self.0 = v;
    }
}

impl Edges {
    fn of(indices: &[u32]) -> Edges {
        let mut index: HashMap<u64, u32, BuildHasherDefault<EdgeHasher>> =
            HashMap::with_capacity_and_hasher(indices.len(), Default::default());
        let mut e = Edges {
            ends: Vec::with_capacity(indices.len()),
            uses: Vec::with_capacity(indices.len()),
            opposite: Vec::with_capacity(indices.len()),
            of_triangle: Vec::with_capacity(indices.len() / 3),
        };
        for t in indices.chunks_exact(3) {
            let mut ids = [0u32; 3];
            for (k, id_out) in ids.iter_mut().enumerate() {
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let (lo, hi) = key(a, b);
                let next = e.ends.len() as u32;
                let id = *index.entry((lo as u64) << 32 | hi as u64).or_insert(next);
                if id == next {
                    e.ends.push((lo, hi));
                    e.uses.push(0);
                    e.opposite.push([0; 2]);
                }
                let i = id as usize;
                if let Some(slot) = e.opposite[i].get_mut(e.uses[i] as usize) {
                    *slot = c;
                }
                e.uses[i] += 1;
                *id_out = id;
            }
            e.of_triangle.push(ids);
        }
        e
    }

    fn is_boundary(&self, id: usize) -> bool {
        self.uses[id] != 2
    }

    fn rings(&self, vertex_count: usize) -> Rings {
        let mut neighbours = vec![Vec::new(); vertex_count];
        let mut boundary = vec![Vec::new(); vertex_count];
        for (id, &(a, b)) in self.ends.iter().enumerate() {
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
            if self.is_boundary(id) {
                boundary[a as usize].push(b);
                boundary[b as usize].push(a);
            }
        }
        Rings {
            neighbours,
            boundary,
        }
    }
}

/// Loop's β for an interior vertex of valence `n`.
fn beta(n: usize) -> f64 {
    let n = n as f64;
    let c = 3.0 / 8.0 + 0.25 * (2.0 * std::f64::consts::PI / n).cos();
    (5.0 / 8.0 - c * c) / n
}

fn sum(points: &[DVec3], ids: &[u32]) -> DVec3 {
    ids.iter().map(|&i| points[i as usize]).sum()
}

/// One level of subdivision: new positions and four triangles per triangle.
fn refine(points: &[DVec3], indices: &[u32]) -> (Vec<DVec3>, Vec<u32>) {
    let edges = Edges::of(indices);
    let rings = edges.rings(points.len());
    let mut out = smoothed(points, &rings, beta, 0.125);
    let first_odd = out.len() as u32;
    for (id, &(a, b)) in edges.ends.iter().enumerate() {
        let (pa, pb) = (points[a as usize], points[b as usize]);
        out.push(if edges.is_boundary(id) {
            0.5 * (pa + pb)
        } else {
            0.375 * (pa + pb) + 0.125 * sum(points, &edges.opposite[id])
        });
    }
    let mut tris = Vec::with_capacity(indices.len() * 4);
    for (t, ids) in indices.chunks_exact(3).zip(&edges.of_triangle) {
        let (a, b, c) = (t[0], t[1], t[2]);
        let [ab, bc, ca] = ids.map(|id| first_odd + id);
        tris.extend_from_slice(&[a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca]);
    }
    (out, tris)
}

/// Each vertex moved to its limit position on the subdivision surface.
fn limit(points: &[DVec3], indices: &[u32]) -> Vec<DVec3> {
    let rings = Edges::of(indices).rings(points.len());
    let gamma = |n: usize| 1.0 / (n as f64 + 3.0 / (8.0 * beta(n)));
    smoothed(points, &rings, gamma, 0.2)
}

/// Every vertex moved by Loop's masks: an interior vertex of valence n to
/// (1 − n w) v + w Σ neighbours with w = `interior(n)`, a boundary vertex to
/// (1 − 2 b) v + b Σ of its two boundary neighbours, others left in place. The even
/// rule and the limit rule differ only in these weights.
fn smoothed(
    points: &[DVec3],
    rings: &Rings,
    interior: impl Fn(usize) -> f64,
    boundary_weight: f64,
) -> Vec<DVec3> {
    points
        .iter()
        .enumerate()
        .map(|(v, &p)| {
            let boundary = &rings.boundary[v];
            let ring = &rings.neighbours[v];
            match boundary.len() {
                0 if ring.len() >= 3 => {
                    let w = interior(ring.len());
                    (1.0 - ring.len() as f64 * w) * p + w * sum(points, ring)
                }
                2 => (1.0 - 2.0 * boundary_weight) * p + boundary_weight * sum(points, boundary),
                _ => p,
            }
        })
        .collect()
}

/// Triangles after `levels` subdivisions of `triangles` triangles.
pub fn triangle_count(triangles: usize, levels: u32) -> u128 {
    triangles as u128 * 4u128.pow(levels)
}

/// Subdivides a triangle mesh `levels` times (in f64, so that deep levels do not
/// accumulate rounding) and returns the limit surface's mesh.
pub fn loop_subdivide(positions: &[Vec3], indices: &[u32], levels: u32) -> Subdivided {
    let mut points: Vec<DVec3> = positions.iter().map(|p| p.as_dvec3()).collect();
    let mut tris = indices.to_vec();
    for _ in 0..levels {
        (points, tris) = refine(&points, &tris);
    }
    let points = limit(&points, &tris);
    let mut normals = vec![DVec3::ZERO; points.len()];
    for t in tris.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
        let n = (points[b] - points[a]).cross(points[c] - points[a]);
        for v in [a, b, c] {
            normals[v] += n;
        }
    }
    Subdivided {
        positions: points.iter().map(|p| p.as_vec3()).collect(),
        normals: normals
            .iter()
            .map(|n| n.try_normalize().unwrap_or(DVec3::Z).as_vec3())
            .collect(),
        indices: tris,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A regular octahedron around the origin.
    fn octahedron() -> (Vec<Vec3>, Vec<u32>) {
        let p = vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        let t = vec![
            0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5,
        ];
        (p, t)
    }

    #[test]
    fn counts_grow_by_four_per_level_and_closed_surfaces_stay_closed() {
        let (p, t) = octahedron();
        for levels in 0..4 {
            let s = loop_subdivide(&p, &t, levels);
            assert_eq!(s.indices.len() / 3, 8 * 4usize.pow(levels));
            // Euler characteristic of a sphere: V − E + F = 2, with E = 3F/2.
            let f = s.indices.len() as i64 / 3;
            assert_eq!(s.positions.len() as i64 - 3 * f / 2 + f, 2);
        }
    }

    /// The limit surface of a symmetric octahedron is symmetric and inside its hull,
    /// with outward normals; the limit position of an original vertex is the same from
    /// any level, and it is where plain subdivision converges to.
    #[test]
    fn the_limit_surface_is_symmetric_and_where_subdivision_converges() {
        let (p, t) = octahedron();
        let s3 = loop_subdivide(&p, &t, 3);
        let s1 = loop_subdivide(&p, &t, 1);
        let r_axis = s3.positions[0].length();
        // Old vertices keep their indices; vertex 0 stays on the +x axis.
        assert!(s3.positions[0].y.abs() < 1e-6 && s3.positions[0].z.abs() < 1e-6);
        assert!((s1.positions[0].length() - r_axis).abs() < 1e-6);
        for k in 0..6 {
            assert!((s3.positions[k].length() - r_axis).abs() < 1e-6);
        }
        for (q, n) in s3.positions.iter().zip(&s3.normals) {
            let r = q.length();
            assert!(r > 0.3 && r < 1.0, "radius {r}");
            // Outward normals, close to radial on this rounded surface.
            assert!(n.dot(*q / r) > 0.85, "normal {n} at {q}");
        }
        // Seven plain levels (no limit step) bring vertex 0 close to its limit: the
        // distance shrinks by the subdominant eigenvalue (3/8 at valence 4) per level.
        let mut points: Vec<DVec3> = p.iter().map(|q| q.as_dvec3()).collect();
        let mut tris = t.clone();
        for _ in 0..7 {
            (points, tris) = refine(&points, &tris);
        }
        let gap = (points[0].length() - r_axis as f64).abs();
        assert!(
            gap < 1e-3,
            "limit {r_axis} vs subdivided {}",
            points[0].length()
        );
    }

    /// A flat patch stays flat and inside its boundary, and regular vertices of a planar
    /// grid (inside, and on a straight stretch of boundary) do not move.
    #[test]
    fn planar_meshes_stay_planar_with_fixed_boundary() {
        // A 3×3 grid of vertices (two triangles per cell) in z = 0.
        let p: Vec<Vec3> = (0..9)
            .map(|i| Vec3::new((i % 3) as f32, (i / 3) as f32, 0.0))
            .collect();
        let mut t = Vec::new();
        for cy in 0..2u32 {
            for cx in 0..2u32 {
                let v = cy * 3 + cx;
                t.extend_from_slice(&[v, v + 1, v + 4, v, v + 4, v + 3]);
            }
        }
        let s = loop_subdivide(&p, &t, 2);
        for (q, n) in s.positions.iter().zip(&s.normals) {
            assert!(q.z.abs() < 1e-6);
            assert!((n.z - 1.0).abs() < 1e-6, "{n}");
            assert!(q.x >= -1e-6 && q.x <= 2.0 + 1e-6 && q.y >= -1e-6 && q.y <= 2.0 + 1e-6);
        }
        // The centre vertex has valence 6 in a regular planar grid: a fixed point.
        assert!((s.positions[4] - Vec3::new(1.0, 1.0, 0.0)).length() < 1e-6);
        // The middle of the bottom edge has collinear boundary neighbours: it stays.
        assert!(
            (s.positions[1] - Vec3::X).length() < 1e-6,
            "{}",
            s.positions[1]
        );
    }

    /// An edge two triangles share gets Loop's interior odd rule; one that a single
    /// triangle or three triangles use (a fin: not a 2-manifold there) gets the boundary
    /// midpoint. Each triangle's four children name the odd vertices of its own edges.
    #[test]
    fn odd_vertices_follow_how_many_triangles_use_the_edge() {
        let p = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.5, 1.0, 0.0),
            DVec3::new(0.5, -1.0, 0.0),
            DVec3::new(0.5, 0.0, 1.0),
        ];
        let odd_of = |indices: &[u32], a: u32, b: u32| {
            let (points, tris) = refine(&p, indices);
            // The child triangle at corner a of the first triangle is (a, ab, ca).
            let t = &tris[..3];
            assert_eq!(t[0], indices[0]);
            let ab = if (indices[0], indices[1]) == (a, b) {
                t[1]
            } else {
                t[2]
            };
            points[ab as usize]
        };
        // Two triangles on edge 0–1: 3/8 of its ends, 1/8 of vertices 2 and 3.
        let two = [0, 1, 2, 1, 0, 3];
        let expected = 0.375 * (p[0] + p[1]) + 0.125 * (p[2] + p[3]);
        assert!((odd_of(&two, 0, 1) - expected).length() < 1e-15);
        // A third triangle on the same edge: the midpoint.
        let three = [0, 1, 2, 1, 0, 3, 0, 1, 4];
        assert!((odd_of(&three, 0, 1) - 0.5 * (p[0] + p[1])).length() < 1e-15);
        // Every child names an odd vertex of an edge of its parent: 3 corners + 3 odd.
        let (points, tris) = refine(&p, &three);
        assert_eq!(tris.len(), 4 * three.len());
        assert_eq!(points.len(), p.len() + 7);
    }

    #[test]
    fn loop_beta_is_three_sixteenths_at_valence_three_and_regular_at_six() {
        // Loop's β at n = 6 is 1/16 (the regular case); at n = 3 it is 3/16.
        assert!((beta(6) - 1.0 / 16.0).abs() < 1e-12);
        assert!((beta(3) - 3.0 / 16.0).abs() < 1e-12);
    }
}
