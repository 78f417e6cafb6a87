//! Contact edges: where one surface rests on or touches another that it does not share
//! an edge with (a block standing on the floor, a box against a wall), the two meet at a
//! concave angle and exchange light at close range. Radiosity there changes over every
//! scale down to the contact line (the dark strip at the base of a block), so elements
//! next to it are split a priori, in rows that halve towards the line (geometric
//! grading, as finite-element meshes are graded towards a corner singularity; Babuska &
//! Guo, "The h-p version of the finite element method", 1986). Faces that share an edge
//! (the walls of a room meeting at its corners) are joined surfaces, not contacts, and
//! are left to the solution-driven refinement.
//!
//! A face counts as touching an element when the two face each other (each has a
//! point strictly in front of the other's plane) and the distance between the element
//! and the face polygon is below a fraction of the element's size.

use std::collections::{HashMap, HashSet};

use glam::DVec3;

use super::face_mesh::FaceMesh;

/// A planar face as a convex polygon with its plane.
#[derive(Clone, Debug)]
struct Polygon {
    corners: Vec<DVec3>,
    normal: DVec3,
    lower: DVec3,
    upper: DVec3,
}

/// The planar faces of a scene, bucketed in a uniform grid for proximity queries.
#[derive(Clone, Debug)]
pub struct ContactFinder {
    faces: Vec<Option<Polygon>>,
    /// Unordered pairs of faces that share a point.
    adjacent: HashSet<(u32, u32)>,
    cell: f64,
    grid: HashMap<[i64; 3], Vec<u32>>,
    /// Faces too large for the grid, tested by every query.
    large: Vec<u32>,
    /// Heights below this count as in a plane.
    tolerance: f64,
}

/// A face covering more grid cells than this is kept out of the grid.
const MAX_CELLS_PER_FACE: i64 = 4096;

impl ContactFinder {
    /// Indexes the planar faces of `mesh`; queries reach at most `reach` (scene units).
    pub fn new(mesh: &FaceMesh, reach: f64) -> ContactFinder {
        let lower = mesh
            .points
            .iter()
            .copied()
            .fold(DVec3::INFINITY, DVec3::min);
        let upper = mesh
            .points
            .iter()
            .copied()
            .fold(DVec3::NEG_INFINITY, DVec3::max);
        let size = (upper - lower).length().max(f64::MIN_POSITIVE);
        let cell = (2.0 * reach).max(1e-6 * size);
        let mut finder = ContactFinder {
            faces: Vec::with_capacity(mesh.faces.len()),
            adjacent: HashSet::new(),
            cell,
            grid: HashMap::new(),
            large: Vec::new(),
            tolerance: 1e-7 * size,
        };
        let mut by_point: HashMap<u32, Vec<u32>> = HashMap::new();
        for (f, face) in mesh.faces.iter().enumerate() {
            let used = &face.corners[..face.count as usize];
            for &a in used {
                by_point.entry(a).or_default().push(f as u32);
            }
            if face.curved {
                finder.faces.push(None);
                continue;
            }
            let corners: Vec<DVec3> = used.iter().map(|&i| mesh.points[i as usize]).collect();
            let normal = (corners[1] - corners[0])
                .cross(corners[2] - corners[0])
                .normalize_or_zero();
            if normal == DVec3::ZERO {
                finder.faces.push(None);
                continue;
            }
            let lo = corners.iter().copied().fold(DVec3::INFINITY, DVec3::min);
            let hi = corners
                .iter()
                .copied()
                .fold(DVec3::NEG_INFINITY, DVec3::max);
            let (a, b) = (
                finder.key(lo - DVec3::splat(reach)),
                finder.key(hi + DVec3::splat(reach)),
            );
            let count = (0..3).map(|k| b[k] - a[k] + 1).product::<i64>();
            if count > MAX_CELLS_PER_FACE {
                finder.large.push(f as u32);
            } else {
                for x in a[0]..=b[0] {
                    for y in a[1]..=b[1] {
                        for z in a[2]..=b[2] {
                            finder.grid.entry([x, y, z]).or_default().push(f as u32);
                        }
                    }
                }
            }
            finder.faces.push(Some(Polygon {
                corners,
                normal,
                lower: lo,
                upper: hi,
            }));
        }
        for faces in by_point.values() {
            for (i, &f) in faces.iter().enumerate() {
                for &g in &faces[i + 1..] {
                    finder.adjacent.insert((f.min(g), f.max(g)));
                }
            }
        }
        finder
    }

    fn key(&self, p: DVec3) -> [i64; 3] {
        [0, 1, 2].map(|k| (p[k] / self.cell).floor() as i64)
    }

    /// Whether the convex element `corners` (normal `normal`) of face `face` lies within
    /// `reach` of a face it does not share a point with, the two facing each other.
    pub fn touches(&self, face: u32, corners: &[DVec3], normal: DVec3, reach: f64) -> bool {
        let lo = corners.iter().copied().fold(DVec3::INFINITY, DVec3::min) - DVec3::splat(reach);
        let hi = corners
            .iter()
            .copied()
            .fold(DVec3::NEG_INFINITY, DVec3::max)
            + DVec3::splat(reach);
        let (a, b) = (self.key(lo), self.key(hi));
        let centroid = corners.iter().copied().sum::<DVec3>() / corners.len() as f64;
        let mut seen: Vec<u32> = Vec::new();
        let mut candidates = self.large.clone();
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    if let Some(list) = self.grid.get(&[x, y, z]) {
                        candidates.extend_from_slice(list);
                    }
                }
            }
        }
        candidates.sort_unstable();
        candidates.dedup();
        for g in candidates {
            if g == face || self.adjacent.contains(&(face.min(g), face.max(g))) || seen.contains(&g)
            {
                continue;
            }
            seen.push(g);
            let Some(other) = &self.faces[g as usize] else {
                continue;
            };
            if other.upper.cmplt(lo).any() || other.lower.cmpgt(hi).any() {
                continue;
            }
            // Facing each other: part of the face in front of the element's plane, and
            // the element's centre in front of the face's plane.
            let in_front = other
                .corners
                .iter()
                .any(|p| normal.dot(*p - corners[0]) > self.tolerance);
            if !in_front || other.normal.dot(centroid - other.corners[0]) <= self.tolerance {
                continue;
            }
            if polygon_distance(corners, normal, &other.corners, other.normal) < reach {
                return true;
            }
        }
        false
    }
}

/// Distance from `p` to the convex planar polygon `corners` (normal `normal`).
fn point_polygon_distance(p: DVec3, corners: &[DVec3], normal: DVec3) -> f64 {
    let height = normal.dot(p - corners[0]);
    let q = p - height * normal;
    let inside = (0..corners.len()).all(|k| {
        let (a, b) = (corners[k], corners[(k + 1) % corners.len()]);
        (b - a).cross(q - a).dot(normal) >= 0.0
    });
    if inside {
        return height.abs();
    }
    (0..corners.len())
        .map(|k| point_segment_distance(p, corners[k], corners[(k + 1) % corners.len()]))
        .fold(f64::INFINITY, f64::min)
}

fn point_segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let d = b - a;
    let t = ((p - a).dot(d) / d.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
    (a + t * d - p).length()
}

/// Distance between segments `p0 p1` and `q0 q1` (closest points by clamped
/// parameters; Ericson, "Real-Time Collision Detection", 2005, sec. 5.1.9).
fn segment_distance(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> f64 {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    let tiny = f64::MIN_POSITIVE;
    if a <= tiny {
        return point_segment_distance(p0, q0, q1);
    }
    if e <= tiny {
        return point_segment_distance(q0, p0, p1);
    }
    let (b, c) = (d1.dot(d2), d1.dot(r));
    let denominator = a * e - b * b;
    let mut s = if denominator > tiny * a * e {
        ((b * f - c * e) / denominator).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    (p0 + s * d1 - (q0 + t * d2)).length()
}

/// Whether segment `a b` crosses the convex polygon `corners` (normal `normal`).
fn segment_crosses(a: DVec3, b: DVec3, corners: &[DVec3], normal: DVec3) -> bool {
    let (ha, hb) = (normal.dot(a - corners[0]), normal.dot(b - corners[0]));
    if (ha > 0.0) == (hb > 0.0) || ha == hb {
        return false;
    }
    let q = a + (b - a) * (ha / (ha - hb));
    (0..corners.len()).all(|k| {
        let (u, v) = (corners[k], corners[(k + 1) % corners.len()]);
        (v - u).cross(q - u).dot(normal) >= 0.0
    })
}

/// Distance between two convex planar polygons: zero when an edge of one crosses the
/// other, else the least of the vertex-to-polygon and edge-to-edge distances.
fn polygon_distance(a: &[DVec3], na: DVec3, b: &[DVec3], nb: DVec3) -> f64 {
    let edges = |p: &[DVec3]| -> Vec<(DVec3, DVec3)> {
        (0..p.len()).map(|k| (p[k], p[(k + 1) % p.len()])).collect()
    };
    let (ea, eb) = (edges(a), edges(b));
    if ea.iter().any(|&(u, v)| segment_crosses(u, v, b, nb))
        || eb.iter().any(|&(u, v)| segment_crosses(u, v, a, na))
    {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    for &p in a {
        best = best.min(point_polygon_distance(p, b, nb));
    }
    for &p in b {
        best = best.min(point_polygon_distance(p, a, na));
    }
    for &(u, v) in &ea {
        for &(s, t) in &eb {
            best = best.min(segment_distance(u, v, s, t));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_on_a_floor_touches_it_and_the_room_corner_does_not() {
        // A floor quad, a back wall sharing its far edge, and one face of a block
        // standing on the floor's interior (facing -z, towards the viewer).
        let mut mesh = FaceMesh::new();
        let p = |m: &mut FaceMesh, x: f64, y: f64, z: f64| m.point(DVec3::new(x, y, z));
        let floor = [
            p(&mut mesh, 10.0, 0.0, 0.0),
            p(&mut mesh, 0.0, 0.0, 0.0),
            p(&mut mesh, 0.0, 0.0, 10.0),
            p(&mut mesh, 10.0, 0.0, 10.0),
        ];
        mesh.add_face(&floor, 0);
        let top = [
            p(&mut mesh, 0.0, 10.0, 10.0),
            p(&mut mesh, 10.0, 10.0, 10.0),
        ];
        mesh.add_face(&[floor[3], floor[2], top[0], top[1]], 0);
        let block = [
            p(&mut mesh, 6.0, 0.0, 5.0),
            p(&mut mesh, 3.0, 0.0, 5.0),
            p(&mut mesh, 3.0, 3.0, 5.0),
            p(&mut mesh, 6.0, 3.0, 5.0),
        ];
        mesh.add_face(&block, 0);
        let finder = ContactFinder::new(&mesh, 1.0);
        let up = DVec3::Y;
        let floor_element = |x: f64, z: f64| {
            [
                DVec3::new(x + 1.0, 0.0, z),
                DVec3::new(x, 0.0, z),
                DVec3::new(x, 0.0, z + 1.0),
                DVec3::new(x + 1.0, 0.0, z + 1.0),
            ]
        };
        // In front of the block, touching its base: a contact.
        assert!(finder.touches(0, &floor_element(4.0, 4.0), up, 0.5));
        // Half a unit in front of it: within a reach of 0.6, not of 0.4.
        assert!(finder.touches(0, &floor_element(4.0, 3.5), up, 0.6));
        assert!(!finder.touches(0, &floor_element(4.0, 3.5), up, 0.4));
        // Behind the block's face (inside the block): not facing it.
        assert!(!finder.touches(0, &floor_element(4.0, 5.5), up, 0.5));
        // In the corner with the back wall: joined surfaces, no contact.
        assert!(!finder.touches(0, &floor_element(0.0, 9.0), up, 0.5));
        // The block face's lowest element touches the floor.
        let block_element = [
            DVec3::new(4.0, 0.0, 5.0),
            DVec3::new(3.0, 0.0, 5.0),
            DVec3::new(3.0, 1.0, 5.0),
            DVec3::new(4.0, 1.0, 5.0),
        ];
        assert!(finder.touches(2, &block_element, -DVec3::Z, 0.5));
    }
}
