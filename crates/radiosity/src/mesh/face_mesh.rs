//! Meshing: planar input faces (triangles and convex quads over welded corner points)
//! split into patches on one shared-vertex mesh, with no T-junctions.
//!
//! Every input edge is split into `n_e = max(subdivision, ceil(length / max_edge))`
//! segments (`sqrt(2) max_edge` for edges of triangles only), a function of the edge alone, so the two faces sharing an edge see the same
//! points and share their indices. The opposite edges of a quad whose lengths differ by
//! less than [`QUAD_RATIO`] are tied to the larger count (a union-find over edges), so
//! rectangles and mild trapezoids become regular grids of quads. A face whose edges end
//! up with different counts keeps a regular core one step inside its boundary and is
//! stitched to each boundary edge by a strip of triangles, the scheme of hardware
//! tessellators with independent edge levels (Moreton, "Watertight Tessellation using
//! Forward Differencing", Graphics Hardware 2001).
//!
//! Triangle pairs of one surface that form a planar convex quad (a quad exported as two
//! triangles) are merged back first, so they subdivide into quads. A curved bilinear
//! patch is a quad face too: its grid points are bilinear in the corners, so they lie on
//! the patch, and its cells (not planar) become two triangles each.

use std::collections::HashMap;

use glam::DVec3;

use super::patch::{PatchSet, polygon_shape};
use super::tessellation::{EdgeTable, FaceBuilder};

/// Opposite quad edges are tied to one segment count when the longer is at most this
/// many times the shorter (otherwise each keeps its own and a strip stitches them).
pub const QUAD_RATIO: f64 = 1.5;

/// Off-plane tolerance (fraction of the diameter) for merging two triangles into a quad:
/// half the patch set's own planarity tolerance.
const MERGE_PLANARITY: f64 = 5e-7;

/// One planar input face: corners counter-clockwise seen from the front.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Face {
    pub corners: [u32; 4],
    /// 3 or 4.
    pub count: u8,
    /// The caller's surface tag (material, emission, shape), copied to every patch.
    pub tag: u32,
    /// A quad that is not planar: a bilinear patch, subdivided on its curved surface
    /// (grid points bilinear in the corners, cells split into triangles).
    pub curved: bool,
}

impl Face {
    pub(super) fn used(&self) -> &[u32] {
        &self.corners[..self.count as usize]
    }
}

/// Input faces over welded points: equal positions share one index.
#[derive(Clone, Debug, Default)]
pub struct FaceMesh {
    pub points: Vec<DVec3>,
    pub faces: Vec<Face>,
    weld: HashMap<[u64; 3], u32>,
}

/// The patches made from a [`FaceMesh`].
#[derive(Clone, Debug, Default)]
pub struct Subdivision {
    /// Points: the mesh's own, then edge points, then face interiors.
    pub set: PatchSet,
    /// The input face of every patch.
    pub patch_face: Vec<u32>,
    /// Sub-patches dropped as degenerate (zero area after rounding).
    pub dropped: usize,
}

impl FaceMesh {
    pub fn new() -> FaceMesh {
        FaceMesh::default()
    }

    /// The index of the point at `p`, adding it unless an identical one exists.
    pub fn point(&mut self, p: DVec3) -> u32 {
        // `+ 0.0` turns -0 into +0 so both weld.
        let key = [
            (p.x + 0.0).to_bits(),
            (p.y + 0.0).to_bits(),
            (p.z + 0.0).to_bits(),
        ];
        let next = self.points.len() as u32;
        let index = *self.weld.entry(key).or_insert(next);
        if index == next {
            self.points.push(p);
        }
        index
    }

    /// Adds a triangle or convex planar quad (indices from [`FaceMesh::point`]).
    /// Faces with repeated corners are ignored.
    pub fn add_face(&mut self, corners: &[u32], tag: u32) {
        let count = corners.len();
        if !(3..=4).contains(&count) {
            return;
        }
        for a in 0..count {
            for b in a + 1..count {
                if corners[a] == corners[b] {
                    return;
                }
            }
        }
        let mut c = [0u32; 4];
        c[..count].copy_from_slice(corners);
        self.faces.push(Face {
            corners: c,
            count: count as u8,
            tag,
            curved: false,
        });
    }

    /// Adds the bilinear patch with boundary `corners` (p00, p10, p11, p01): planar and
    /// convex ones as quads, the others as curved faces.
    pub fn add_bilinear(&mut self, corners: [u32; 4], tag: u32) {
        if self.is_planar_convex(&corners) {
            self.add_face(&corners, tag);
            return;
        }
        let before = self.faces.len();
        self.add_face(&corners, tag);
        if let Some(face) = self.faces.get_mut(before) {
            face.curved = true;
        }
    }

    /// Adds the triangles of one surface, merging pairs that share an edge (with
    /// opposite directions) into a planar convex quad. Each triangle prefers the
    /// partner across its longest edge (the diagonal of a split quad).
    pub fn add_triangles_merging(&mut self, triangles: &[[u32; 3]], tag: u32) {
        let mut by_edge: HashMap<(u32, u32), usize> = HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                by_edge.insert((tri[k], tri[(k + 1) % 3]), t);
            }
        }
        let mut merged = vec![false; triangles.len()];
        for (t, tri) in triangles.iter().enumerate() {
            if merged[t] {
                continue;
            }
            // Edges longest first.
            let mut edges = [0usize, 1, 2];
            let length = |k: usize| {
                (self.points[tri[(k + 1) % 3] as usize] - self.points[tri[k] as usize]).length()
            };
            edges.sort_by(|&a, &b| length(b).total_cmp(&length(a)));
            let mut quad = None;
            for k in edges {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let Some(&u) = by_edge.get(&(b, a)) else {
                    continue;
                };
                if u == t || merged[u] {
                    continue;
                }
                let other = triangles[u];
                let Some(d) = other.iter().copied().find(|&v| v != a && v != b) else {
                    continue;
                };
                // The quad runs b -> (third of t) -> a -> d.
                let c = tri[(k + 2) % 3];
                let candidate = [b, c, a, d];
                if self.is_planar_convex(&candidate) {
                    quad = Some((u, candidate));
                    break;
                }
            }
            match quad {
                Some((u, q)) => {
                    merged[t] = true;
                    merged[u] = true;
                    self.add_face(&q, tag);
                }
                None => {
                    merged[t] = true;
                    self.add_face(tri, tag);
                }
            }
        }
    }

    /// Whether the quad is planar (within half the patch set's tolerance) and convex.
    pub fn is_planar_convex(&self, quad: &[u32; 4]) -> bool {
        let p = quad.map(|i| self.points[i as usize]);
        let Ok(shape) = polygon_shape(&p) else {
            return false;
        };
        let diameter = (p[2] - p[0]).length().max((p[3] - p[1]).length());
        (p[3] - p[0]).dot(shape.normal).abs() <= MERGE_PLANARITY * diameter
    }

    /// Splits every face into patches whose edges are at most `max_edge` long (and
    /// every input edge into at least `min_segments` segments). `material(tag)` gives
    /// the emission and reflectance of a face's patches.
    pub fn subdivide(
        &self,
        max_edge: f64,
        min_segments: u32,
        material: impl Fn(u32) -> ([f64; 3], [f64; 3]),
    ) -> Subdivision {
        let edges = EdgeTable::new(self, max_edge, min_segments.max(1));
        let mut out = Subdivision {
            set: PatchSet {
                points: self.points.clone(),
                patches: Vec::new(),
            },
            patch_face: Vec::new(),
            dropped: 0,
        };
        let edge_points = edges.make_points(&mut out.set);
        for (f, face) in self.faces.iter().enumerate() {
            let (emission, reflectance) = material(face.tag);
            let mut builder = FaceBuilder {
                out: &mut out,
                face: f as u32,
                emission,
                reflectance,
            };
            let boundary: Vec<Vec<u32>> = (0..face.count as usize)
                .map(|k| {
                    let a = face.corners[k];
                    let b = face.corners[(k + 1) % face.count as usize];
                    edges.chain(a, b, &edge_points)
                })
                .collect();
            let corners: Vec<DVec3> = face
                .used()
                .iter()
                .map(|&i| self.points[i as usize])
                .collect();
            if face.count == 4 {
                builder.quad(&corners, &boundary);
            } else {
                builder.triangle(&corners, &boundary);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every interior edge of a conforming mesh is used by exactly two patches in
    /// opposite directions; boundary edges once. A T-junction shows up as an edge used
    /// once that is not on the input boundary.
    fn edge_uses(set: &PatchSet) -> HashMap<(u32, u32), i32> {
        let mut uses = HashMap::new();
        for p in &set.patches {
            let c = &p.corners[..p.corner_count as usize];
            for k in 0..c.len() {
                *uses.entry((c[k], c[(k + 1) % c.len()])).or_insert(0) += 1;
            }
        }
        uses
    }

    #[test]
    fn square_of_two_triangles_becomes_a_grid() {
        let mut mesh = FaceMesh::new();
        let v = [
            DVec3::ZERO,
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(10.0, 4.0, 0.0),
            DVec3::new(0.0, 4.0, 0.0),
        ]
        .map(|p| mesh.point(p));
        mesh.add_triangles_merging(&[[v[0], v[1], v[2]], [v[0], v[2], v[3]]], 0);
        assert_eq!(mesh.faces.len(), 1);
        let sub = mesh.subdivide(1.0, 1, |_| ([0.0; 3], [0.5; 3]));
        assert_eq!(sub.set.len(), 40);
        assert!((sub.set.total_area() - 40.0).abs() < 1e-9);
        assert!(sub.set.patches.iter().all(|p| p.normal.z > 0.999));
    }

    #[test]
    fn mismatched_edges_stay_conforming() {
        // Two triangles of very different sizes sharing an edge, and a trapezoid whose
        // parallel sides differ by more than QUAD_RATIO next to a small square.
        let mut mesh = FaceMesh::new();
        let p = |m: &mut FaceMesh, x: f64, y: f64| m.point(DVec3::new(x, y, 0.0));
        let (a, b, c, d) = (
            p(&mut mesh, 0.0, 0.0),
            p(&mut mesh, 10.0, 0.0),
            p(&mut mesh, 0.0, 3.0),
            p(&mut mesh, -1.0, 1.0),
        );
        mesh.add_face(&[a, b, c], 0);
        mesh.add_face(&[a, c, d], 0);
        let (e, f, g, h) = (
            p(&mut mesh, 20.0, 0.0),
            p(&mut mesh, 30.0, 0.0),
            p(&mut mesh, 26.0, 2.0),
            p(&mut mesh, 24.0, 2.0),
        );
        mesh.add_face(&[e, f, g, h], 0);
        let (i, j) = (p(&mut mesh, 26.0, 4.0), p(&mut mesh, 24.0, 4.0));
        mesh.add_face(&[h, g, i, j], 0);
        let sub = mesh.subdivide(0.7, 1, |_| ([0.0; 3], [0.5; 3]));
        let expected = 15.0 + 1.5 + 12.0 + 4.0;
        assert!((sub.set.total_area() - expected).abs() < 1e-9);
        assert_eq!(sub.dropped, 0);
        // Edges used once (not matched by a neighbour in the opposite direction) must
        // all lie on the outer boundary of the input: their total length is its
        // perimeter. A T-junction would add unmatched length inside.
        let uses = edge_uses(&sub.set);
        let perimeter_length: f64 = uses
            .keys()
            .filter(|(a, b)| !uses.contains_key(&(*b, *a)))
            .map(|&(a, b)| (sub.set.points[a as usize] - sub.set.points[b as usize]).length())
            .sum();
        // Outer boundaries: the two triangles' union and the two quads' union.
        let fan = 10.0 + 109f64.sqrt() + 5f64.sqrt() + 2f64.sqrt();
        let quads = 10.0 + 2.0 * 20f64.sqrt() + 6.0;
        assert!(
            (perimeter_length - fan - quads).abs() < 1e-9,
            "{perimeter_length}"
        );
        assert!(sub.set.patches.iter().all(|p| p.normal.z > 0.999));
        let longest = sub
            .set
            .patches
            .iter()
            .enumerate()
            .map(|(k, _)| {
                let poly = sub.set.polygon(k);
                let c = poly.as_slice();
                (0..c.len())
                    .map(|e| (c[(e + 1) % c.len()] - c[e]).length())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        // Strip triangles span one grid step across and at most one segment along.
        assert!(longest < 2.0, "{longest}");
    }
}
