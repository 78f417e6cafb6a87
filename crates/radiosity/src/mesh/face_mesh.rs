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
    fn used(&self) -> &[u32] {
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

/// Segment counts of the unique edges.
struct EdgeTable {
    index: HashMap<(u32, u32), usize>,
    /// (low, high) point index and segment count.
    edges: Vec<(u32, u32, u32)>,
}

fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

impl EdgeTable {
    fn new(mesh: &FaceMesh, max_edge: f64, min_segments: u32) -> EdgeTable {
        let mut index = HashMap::new();
        let mut edges = Vec::new();
        // Edges used by triangles only may be sqrt(2) longer: a triangle with edges
        // up to sqrt(2) max_edge has an area of at most 0.87 max_edge^2 (equilateral),
        // within the max_edge^2 a quad cell may have.
        let mut quad_edge = Vec::new();
        for face in &mesh.faces {
            let used = face.used();
            for k in 0..used.len() {
                let key = edge_key(used[k], used[(k + 1) % used.len()]);
                let e = *index.entry(key).or_insert_with(|| {
                    edges.push((key.0, key.1, 0));
                    quad_edge.push(false);
                    edges.len() - 1
                });
                quad_edge[e] |= face.count == 4;
            }
        }
        for (e, edge) in edges.iter_mut().enumerate() {
            let length = (mesh.points[edge.1 as usize] - mesh.points[edge.0 as usize]).length();
            let target = if quad_edge[e] {
                max_edge
            } else {
                std::f64::consts::SQRT_2 * max_edge
            };
            let needed = (length / target).ceil().clamp(1.0, 1e6) as u32;
            edge.2 = needed.max(min_segments);
        }
        // Tie opposite edges of near-parallelogram quads (union-find, counts = class max).
        let mut parent: Vec<usize> = (0..edges.len()).collect();
        fn find(parent: &mut [usize], mut i: usize) -> usize {
            while parent[i] != i {
                parent[i] = parent[parent[i]];
                i = parent[i];
            }
            i
        }
        for face in mesh.faces.iter().filter(|f| f.count == 4) {
            let c = face.corners;
            for k in 0..2 {
                let e0 = index[&edge_key(c[k], c[k + 1])];
                let e1 = index[&edge_key(c[k + 2], c[(k + 3) % 4])];
                let len = |e: usize| {
                    let (a, b, _) = edges[e];
                    (mesh.points[b as usize] - mesh.points[a as usize]).length()
                };
                let (l0, l1) = (len(e0), len(e1));
                if l0.max(l1) <= QUAD_RATIO * l0.min(l1) {
                    let (r0, r1) = (find(&mut parent, e0), find(&mut parent, e1));
                    parent[r0] = r1;
                }
            }
        }
        let mut class_count = vec![0u32; edges.len()];
        for (e, edge) in edges.iter().enumerate() {
            let r = find(&mut parent, e);
            class_count[r] = class_count[r].max(edge.2);
        }
        for (e, edge) in edges.iter_mut().enumerate() {
            edge.2 = class_count[find(&mut parent, e)];
        }
        EdgeTable { index, edges }
    }

    /// Adds the interior points of every edge (low to high end); returns the first
    /// point index of each edge's run.
    fn make_points(&self, set: &mut PatchSet) -> Vec<u32> {
        let mut first = Vec::with_capacity(self.edges.len());
        for &(a, b, n) in &self.edges {
            first.push(set.points.len() as u32);
            let (pa, pb) = (set.points[a as usize], set.points[b as usize]);
            for k in 1..n {
                set.add_point(pa.lerp(pb, k as f64 / n as f64));
            }
        }
        first
    }

    /// The points along edge `a -> b`, both ends included.
    fn chain(&self, a: u32, b: u32, first: &[u32]) -> Vec<u32> {
        let e = self.index[&edge_key(a, b)];
        let (low, _, n) = self.edges[e];
        let mut out = Vec::with_capacity(n as usize + 1);
        out.push(a);
        for k in 1..n {
            let from_low = if a == low { k } else { n - k };
            out.push(first[e] + from_low - 1);
        }
        out.push(b);
        out
    }
}

/// Emits the patches of one face.
struct FaceBuilder<'a> {
    out: &'a mut Subdivision,
    face: u32,
    emission: [f64; 3],
    reflectance: [f64; 3],
}

impl FaceBuilder<'_> {
    fn point(&mut self, p: DVec3) -> u32 {
        self.out.set.add_point(p)
    }

    fn patch(&mut self, corners: &[u32]) {
        let set = &mut self.out.set;
        if set
            .add_patch(corners, self.emission, self.reflectance)
            .is_ok()
        {
            self.out.patch_face.push(self.face);
            return;
        }
        // A cell that is not planar or convex enough as a quad: two triangles.
        if corners.len() == 4 {
            self.patch(&[corners[0], corners[1], corners[2]]);
            self.patch(&[corners[0], corners[2], corners[3]]);
        } else {
            self.out.dropped += 1;
        }
    }

    /// `boundary[k]` runs from corner k to corner k + 1.
    fn quad(&mut self, c: &[DVec3], boundary: &[Vec<u32>]) {
        let counts: Vec<usize> = boundary.iter().map(|b| b.len() - 1).collect();
        let (nu, nv) = (counts[0].max(counts[2]), counts[1].max(counts[3]));
        let at = |i: usize, j: usize| {
            let (s, t) = (i as f64 / nu as f64, j as f64 / nv as f64);
            (1.0 - s) * (1.0 - t) * c[0]
                + s * (1.0 - t) * c[1]
                + s * t * c[2]
                + (1.0 - s) * t * c[3]
        };
        let regular = counts[0] == counts[2] && counts[1] == counts[3];
        if regular {
            // Grid (i, j): boundary points from the shared edges, the rest new.
            let mut grid = vec![0u32; (nu + 1) * (nv + 1)];
            for j in 0..=nv {
                for i in 0..=nu {
                    grid[j * (nu + 1) + i] = if j == 0 {
                        boundary[0][i]
                    } else if i == nu {
                        boundary[1][j]
                    } else if j == nv {
                        boundary[2][nu - i]
                    } else if i == 0 {
                        boundary[3][nv - j]
                    } else {
                        self.point(at(i, j))
                    };
                }
            }
            for j in 0..nv {
                for i in 0..nu {
                    let g = |i: usize, j: usize| grid[j * (nu + 1) + i];
                    self.patch(&[g(i, j), g(i + 1, j), g(i + 1, j + 1), g(i, j + 1)]);
                }
            }
            return;
        }
        if nu < 2 || nv < 2 {
            self.centre_fan(c, boundary);
            return;
        }
        // Regular core (i, j) in [1, nu-1] x [1, nv-1], then a strip per side.
        let (cu, cv) = (nu - 1, nv - 1);
        let mut core = vec![0u32; cu * cv];
        for j in 1..nv {
            for i in 1..nu {
                core[(j - 1) * cu + (i - 1)] = self.point(at(i, j));
            }
        }
        let g = |i: usize, j: usize| core[(j - 1) * cu + (i - 1)];
        for j in 1..nv - 1 {
            for i in 1..nu - 1 {
                self.patch(&[g(i, j), g(i + 1, j), g(i + 1, j + 1), g(i, j + 1)]);
            }
        }
        let sides: [Vec<u32>; 4] = [
            (1..nu).map(|i| g(i, 1)).collect(),
            (1..nv).map(|j| g(nu - 1, j)).collect(),
            (1..nu).rev().map(|i| g(i, nv - 1)).collect(),
            (1..nv).rev().map(|j| g(1, j)).collect(),
        ];
        for (outer, inner) in boundary.iter().zip(&sides) {
            self.zipper(outer, inner);
        }
    }

    fn triangle(&mut self, c: &[DVec3], boundary: &[Vec<u32>]) {
        let counts: Vec<usize> = boundary.iter().map(|b| b.len() - 1).collect();
        let m = counts[0].max(counts[1]).max(counts[2]);
        let at = |i: usize, j: usize| {
            c[0] + (c[1] - c[0]) * (i as f64 / m as f64) + (c[2] - c[0]) * (j as f64 / m as f64)
        };
        // Point (i, j) of the level-m barycentric grid; i along c0->c1, j along c0->c2.
        let row_start = |j: usize| j * (m + 1) - j * (j.saturating_sub(1)) / 2;
        if counts.iter().all(|&n| n == m) {
            let mut grid = vec![0u32; (m + 1) * (m + 2) / 2];
            for j in 0..=m {
                for i in 0..=m - j {
                    grid[row_start(j) + i] = if j == 0 {
                        boundary[0][i]
                    } else if i + j == m {
                        boundary[1][j]
                    } else if i == 0 {
                        boundary[2][m - j]
                    } else {
                        self.point(at(i, j))
                    };
                }
            }
            self.grid_patches(m, |i, j| grid[row_start(j) + i]);
            return;
        }
        if m < 4 {
            self.centre_fan(c, boundary);
            return;
        }
        // Core: the points with i, j, k >= 1 (a level m-3 triangle), then strips.
        let level = m - 3;
        let core_start = |j: usize| j * (level + 1) - j * (j.saturating_sub(1)) / 2;
        let mut core = vec![0u32; (level + 1) * (level + 2) / 2];
        for j in 0..=level {
            for i in 0..=level - j {
                core[core_start(j) + i] = self.point(at(i + 1, j + 1));
            }
        }
        let g = |i: usize, j: usize| core[core_start(j) + i];
        self.grid_patches(level, g);
        let sides: [Vec<u32>; 3] = [
            (0..=level).map(|i| g(i, 0)).collect(),
            (0..=level).map(|j| g(level - j, j)).collect(),
            (0..=level).rev().map(|j| g(0, j)).collect(),
        ];
        for (outer, inner) in boundary.iter().zip(&sides) {
            self.zipper(outer, inner);
        }
    }

    /// Triangulates the strip between an outer chain and an inner chain running the
    /// same way (inner on the left, i.e. inside a counter-clockwise face), always
    /// taking the shorter new diagonal.
    fn zipper(&mut self, outer: &[u32], inner: &[u32]) {
        let (mut s, mut k) = (0, 0);
        while s + 1 < outer.len() || k + 1 < inner.len() {
            let advance_outer = if s + 1 == outer.len() {
                false
            } else if k + 1 == inner.len() {
                true
            } else {
                let p = |i: u32| self.out.set.points[i as usize];
                (p(outer[s + 1]) - p(inner[k])).length_squared()
                    <= (p(inner[k + 1]) - p(outer[s])).length_squared()
            };
            if advance_outer {
                self.patch(&[outer[s], outer[s + 1], inner[k]]);
                s += 1;
            } else {
                self.patch(&[outer[s], inner[k + 1], inner[k]]);
                k += 1;
            }
        }
    }

    /// The patches of a triangular grid of `m` steps per side whose point (i, j),
    /// i + j <= m, is `g(i, j)`: per row, upright triangles and the inverted ones between.
    fn grid_patches(&mut self, m: usize, g: impl Fn(usize, usize) -> u32) {
        for j in 0..m {
            for i in 0..m - j {
                self.patch(&[g(i, j), g(i + 1, j), g(i, j + 1)]);
                if i + j + 1 < m {
                    self.patch(&[g(i + 1, j), g(i + 1, j + 1), g(i, j + 1)]);
                }
            }
        }
    }

    /// A fan from the face centre to every boundary segment (small faces whose edges
    /// have different counts).
    fn centre_fan(&mut self, c: &[DVec3], boundary: &[Vec<u32>]) {
        let centre = c.iter().copied().sum::<DVec3>() / c.len() as f64;
        let centre = self.point(centre);
        for chain in boundary {
            for w in chain.windows(2) {
                self.patch(&[w[0], w[1], centre]);
            }
        }
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
