//! Procedural test geometry for the ray benchmark: a geodesic sphere with deterministic
//! noise displacement, and the Cornell box walls.

use glam::Vec3;
use radiant_math::hash::{hash_u64s, u32_to_unit_f32};
use std::collections::HashMap;

/// An indexed triangle mesh.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub vertices: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

const ICOSAHEDRON_FACES: [[u32; 3]; 20] = [
    [0, 11, 5],
    [0, 5, 1],
    [0, 1, 7],
    [0, 7, 10],
    [0, 10, 11],
    [1, 5, 9],
    [5, 11, 4],
    [11, 10, 2],
    [10, 7, 6],
    [7, 1, 8],
    [3, 9, 4],
    [3, 4, 2],
    [3, 2, 6],
    [3, 6, 8],
    [3, 8, 9],
    [4, 9, 5],
    [2, 4, 11],
    [6, 2, 10],
    [8, 6, 7],
    [9, 8, 1],
];

fn icosahedron_vertices() -> [Vec3; 12] {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    [
        Vec3::new(-1.0, t, 0.0),
        Vec3::new(1.0, t, 0.0),
        Vec3::new(-1.0, -t, 0.0),
        Vec3::new(1.0, -t, 0.0),
        Vec3::new(0.0, -1.0, t),
        Vec3::new(0.0, 1.0, t),
        Vec3::new(0.0, -1.0, -t),
        Vec3::new(0.0, 1.0, -t),
        Vec3::new(t, 0.0, -1.0),
        Vec3::new(t, 0.0, 1.0),
        Vec3::new(-t, 0.0, -1.0),
        Vec3::new(-t, 0.0, 1.0),
    ]
    .map(Vec3::normalize)
}

/// A closed geodesic unit sphere: every icosahedron face split into `k²` triangles on a
/// barycentric grid and projected onto the sphere (20 k² triangles, outward winding).
/// Vertices on shared edges are shared, and computed from the edge's endpoints in a
/// canonical order, so the mesh has no cracks.
pub fn geodesic_sphere(k: u32) -> Mesh {
    let k = k.max(1);
    let corners = icosahedron_vertices();
    let mut mesh = Mesh {
        vertices: corners.to_vec(),
        triangles: Vec::with_capacity(20 * (k * k) as usize),
    };
    let mut edge_vertex: HashMap<(u32, u32, u32), u32> = HashMap::new();
    let kf = k as f32;
    let row = |i: u32, j: u32| (i * (2 * k + 3 - i) / 2 + j) as usize; // (i, j), j <= k - i
    let mut ids = vec![0u32; row(k, 0) + 1];
    for face in ICOSAHEDRON_FACES {
        let [a, b, c] = face;
        let (pa, pb, pc) = (
            corners[a as usize],
            corners[b as usize],
            corners[c as usize],
        );
        for i in 0..=k {
            for j in 0..=k - i {
                // Vertex at a + i/k (b − a) + j/k (c − a); edge vertices are keyed by
                // (lower corner, higher corner, steps from the lower corner).
                let mut edge = |u: u32, v: u32, step: u32| {
                    let key = if u < v {
                        (u, v, step)
                    } else {
                        (v, u, k - step)
                    };
                    *edge_vertex.entry(key).or_insert_with(|| {
                        let (lo, hi, s) = key;
                        let p = corners[lo as usize].lerp(corners[hi as usize], s as f32 / kf);
                        mesh.vertices.push(p.normalize());
                        mesh.vertices.len() as u32 - 1
                    })
                };
                let id = if i == 0 && j == 0 {
                    a
                } else if i == k {
                    b
                } else if j == k {
                    c
                } else if j == 0 {
                    edge(a, b, i)
                } else if i == 0 {
                    edge(a, c, j)
                } else if i + j == k {
                    edge(b, c, j)
                } else {
                    let p = pa * ((k - i - j) as f32 / kf)
                        + pb * (i as f32 / kf)
                        + pc * (j as f32 / kf);
                    mesh.vertices.push(p.normalize());
                    mesh.vertices.len() as u32 - 1
                };
                ids[row(i, j)] = id;
            }
        }
        for i in 0..k {
            for j in 0..k - i {
                let (p00, p10, p01) = (ids[row(i, j)], ids[row(i + 1, j)], ids[row(i, j + 1)]);
                mesh.triangles.push([p00, p10, p01]);
                if i + j + 1 < k {
                    mesh.triangles.push([p10, ids[row(i + 1, j + 1)], p01]);
                }
            }
        }
    }
    mesh
}

/// Smooth value noise in [-1, 1]: hashed lattice values, trilinear with quintic fade
/// (Perlin, "Improving Noise", SIGGRAPH 2002, for the fade curve).
fn value_noise(p: Vec3, seed: u64) -> f32 {
    let cell = p.floor();
    let f = p - cell;
    let fade = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    let c = cell.as_ivec3();
    let lattice = |dx: i32, dy: i32, dz: i32| {
        let h = hash_u64s(&[
            (c.x + dx) as u64,
            (c.y + dy) as u64,
            (c.z + dz) as u64,
            seed,
        ]);
        2.0 * u32_to_unit_f32(h as u32) - 1.0
    };
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = lerp(lattice(0, 0, 0), lattice(1, 0, 0), fade.x);
    let x10 = lerp(lattice(0, 1, 0), lattice(1, 1, 0), fade.x);
    let x01 = lerp(lattice(0, 0, 1), lattice(1, 0, 1), fade.x);
    let x11 = lerp(lattice(0, 1, 1), lattice(1, 1, 1), fade.x);
    lerp(lerp(x00, x10, fade.y), lerp(x01, x11, fade.y), fade.z)
}

/// Fractal sum of 5 octaves of value noise, roughly in [-1, 1].
fn fbm(p: Vec3, seed: u64) -> f32 {
    let (mut sum, mut amp, mut freq) = (0.0, 0.5, 1.0);
    for octave in 0..5 {
        sum += amp * value_noise(p * freq, seed.wrapping_add(octave));
        amp *= 0.5;
        freq *= 2.0;
    }
    sum / 0.97
}

/// A geodesic sphere (`k` as in [`geodesic_sphere`]) with its radius displaced by
/// `amplitude · fbm(4 · direction)`, centred at `center`. Deterministic in `seed`.
pub fn displaced_sphere(k: u32, center: Vec3, radius: f32, amplitude: f32, seed: u64) -> Mesh {
    let mut mesh = geodesic_sphere(k);
    for v in &mut mesh.vertices {
        let r = radius * (1.0 + amplitude * fbm(*v * 4.0, seed));
        *v = center + *v * r;
    }
    mesh
}

/// The Cornell box walls (floor, ceiling, back, right and left walls; open at z = 0) as
/// measured (see shared/scenes.md), two triangles per quad, normals into the room.
pub fn cornell_box_walls() -> Vec<[Vec3; 3]> {
    let quads: [[[f32; 3]; 4]; 5] = [
        [
            [552.8, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 559.2],
            [549.6, 0.0, 559.2],
        ],
        [
            [556.0, 548.8, 0.0],
            [556.0, 548.8, 559.2],
            [0.0, 548.8, 559.2],
            [0.0, 548.8, 0.0],
        ],
        [
            [549.6, 0.0, 559.2],
            [0.0, 0.0, 559.2],
            [0.0, 548.8, 559.2],
            [556.0, 548.8, 559.2],
        ],
        [
            [0.0, 0.0, 559.2],
            [0.0, 0.0, 0.0],
            [0.0, 548.8, 0.0],
            [0.0, 548.8, 559.2],
        ],
        [
            [552.8, 0.0, 0.0],
            [549.6, 0.0, 559.2],
            [556.0, 548.8, 559.2],
            [556.0, 548.8, 0.0],
        ],
    ];
    quads
        .iter()
        .flat_map(|q| {
            let v = q.map(Vec3::from);
            [[v[0], v[1], v[2]], [v[0], v[2], v[3]]]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geodesic_sphere_is_closed_and_sized() {
        // Closed 2-manifold: every edge is used exactly twice, in opposite directions,
        // and Euler's formula V − E + F = 2 holds.
        let k = 7;
        let m = geodesic_sphere(k);
        assert_eq!(m.triangles.len(), 20 * 49);
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for t in &m.triangles {
            for e in 0..3 {
                *edges.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1);
            assert_eq!(edges.get(&(b, a)), Some(&1), "open edge {a}-{b}");
        }
        let (v, e, f) = (
            m.vertices.len() as i64,
            edges.len() as i64 / 2,
            m.triangles.len() as i64,
        );
        assert_eq!(v - e + f, 2);
        // Outward winding: the signed volume is positive and close to 4π/3.
        let vol: f32 = m
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.vertices[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        assert!(vol > 0.95 * 4.18879 && vol < 4.18879, "{vol}");
    }
}
