//! How [`FaceMesh::subdivide`] cuts faces into patches: a segment count per unique
//! edge (tied across the opposite sides of near-parallelogram quads), the points along
//! every edge, and per face either a regular grid or a regular core stitched to its
//! boundary edges by strips of triangles (the scheme the [`super::face_mesh`] module
//! describes).

use std::collections::HashMap;

use glam::DVec3;

use super::face_mesh::{FaceMesh, QUAD_RATIO, Subdivision};
use super::patch::PatchSet;

/// Segment counts of the unique edges.
pub(super) struct EdgeTable {
    index: HashMap<(u32, u32), usize>,
    /// (low, high) point index and segment count.
    edges: Vec<(u32, u32, u32)>,
}

fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

impl EdgeTable {
    pub(super) fn new(mesh: &FaceMesh, max_edge: f64, min_segments: u32) -> EdgeTable {
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
    pub(super) fn make_points(&self, set: &mut PatchSet) -> Vec<u32> {
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
    pub(super) fn chain(&self, a: u32, b: u32, first: &[u32]) -> Vec<u32> {
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
pub(super) struct FaceBuilder<'a> {
    pub(super) out: &'a mut Subdivision,
    pub(super) face: u32,
    pub(super) emission: [f64; 3],
    pub(super) reflectance: [f64; 3],
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
    pub(super) fn quad(&mut self, c: &[DVec3], boundary: &[Vec<u32>]) {
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

    pub(super) fn triangle(&mut self, c: &[DVec3], boundary: &[Vec<u32>]) {
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
