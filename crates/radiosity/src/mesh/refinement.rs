//! Conforming adaptive subdivision of a meshed scene: regular ("red") splits of single
//! elements, a 2:1 balance between neighbours, and "green" closure pieces on the
//! elements next to a split one, so the mesh never has a T-junction (Bank, Sherman &
//! Weiser, "Refinement Algorithms and Data Structures for Regular Local Mesh
//! Refinement", 1983; the red-green scheme of finite-element codes).
//!
//! The elements of the scene's first mesh are the roots of a forest. A red split cuts a
//! quad into four at its edge midpoints and centre, a triangle into four at its edge
//! midpoints. An edge's midpoint is one shared point, found by the edge's end points,
//! so both elements on an edge (across faces too) see the same point. A leaf next to a
//! split neighbour has that neighbour's midpoint on its edge (a hanging point); the
//! balance rule splits any leaf with a twice-split neighbour edge, a triangle with two
//! hanging points and a quad with three, so every remaining leaf has the few patterns
//! that [`Refinement::scene`] fills with closure pieces: a triangle with one hanging
//! point becomes two triangles, a quad with one becomes three triangles, with two
//! opposite ones two quads, with two adjacent ones four triangles. Closure pieces are
//! rebuilt from the leaves every time, never split themselves (a marked closure piece
//! splits its leaf), so element shapes do not degrade with depth.

use std::collections::HashMap;

use glam::DVec3;

use super::contact_grading::ContactFinder;
use super::meshed_scene::{NO_TWIN, RadiosityScene};
use super::patch::PatchSet;

/// No children yet.
const LEAF: u32 = u32::MAX;

/// One element of the refinement forest.
#[derive(Clone, Copy, Debug)]
struct Cell {
    corners: [u32; 4],
    count: u8,
    /// Red splits between this cell and its root.
    level: u8,
    /// Index of the first of four children, or [`LEAF`].
    children: u32,
    /// The cell this one was split from ([`LEAF`] for a root).
    parent: u32,
    /// The front patch of the unrefined scene this cell lies in.
    root: u32,
}

/// The refinement forest over the front patches of one meshed scene.
#[derive(Clone, Debug)]
pub struct Refinement {
    base: RadiosityScene,
    points: Vec<DVec3>,
    cells: Vec<Cell>,
    midpoints: HashMap<(u32, u32), u32>,
}

/// A refined scene and, for every one of its patches, the leaf cell it belongs to.
#[derive(Clone, Debug)]
pub struct RefinedScene {
    pub scene: RadiosityScene,
    /// The cell of every patch (back sides: their front's cell); pass these to
    /// [`Refinement::split`].
    pub patch_cell: Vec<u32>,
}

fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

impl Refinement {
    /// The unrefined forest: one root per front patch of `base`.
    pub fn new(base: RadiosityScene) -> Refinement {
        let cells = base.patches.patches[..base.front_count]
            .iter()
            .enumerate()
            .map(|(i, p)| Cell {
                corners: p.corners,
                count: p.corner_count,
                level: 0,
                children: LEAF,
                parent: LEAF,
                root: i as u32,
            })
            .collect();
        Refinement {
            points: base.patches.points.clone(),
            base,
            cells,
            midpoints: HashMap::new(),
        }
    }

    /// The scene the forest grew from.
    pub fn base(&self) -> &RadiosityScene {
        &self.base
    }

    /// Red splits between `cell` and its root.
    pub fn level(&self, cell: u32) -> u32 {
        self.cells[cell as usize].level as u32
    }

    /// Splits the given leaf cells (those below `max_level`), then restores the balance
    /// the closure pieces need. Returns the number of red splits made.
    pub fn split(&mut self, cells: &[u32], max_level: u32) -> usize {
        let before = self.cells.len();
        for &c in cells {
            let cell = self.cells[c as usize];
            if cell.children == LEAF && (cell.level as u32) < max_level {
                self.split_cell(c as usize);
            }
        }
        self.balance();
        (self.cells.len() - before) / 4
    }

    fn midpoint(&mut self, a: u32, b: u32) -> u32 {
        if let Some(&m) = self.midpoints.get(&edge_key(a, b)) {
            return m;
        }
        let p = 0.5 * (self.points[a as usize] + self.points[b as usize]);
        self.points.push(p);
        let m = self.points.len() as u32 - 1;
        self.midpoints.insert(edge_key(a, b), m);
        m
    }

    fn hanging(&self, a: u32, b: u32) -> Option<u32> {
        self.midpoints.get(&edge_key(a, b)).copied()
    }

    fn split_cell(&mut self, c: usize) {
        let cell = self.cells[c];
        let k = cell.count as usize;
        let corner = cell.corners;
        let mids: Vec<u32> = (0..k)
            .map(|e| self.midpoint(corner[e], corner[(e + 1) % k]))
            .collect();
        let children: Vec<[u32; 4]> = if k == 4 {
            let centre = corner[..4]
                .iter()
                .map(|&i| self.points[i as usize])
                .sum::<DVec3>()
                / 4.0;
            self.points.push(centre);
            let o = self.points.len() as u32 - 1;
            (0..4)
                .map(|e| [corner[e], mids[e], o, mids[(e + 3) % 4]])
                .collect()
        } else {
            let mut t: Vec<[u32; 4]> = (0..3)
                .map(|e| [corner[e], mids[e], mids[(e + 2) % 3], 0])
                .collect();
            t.push([mids[0], mids[1], mids[2], 0]);
            t
        };
        self.cells[c].children = self.cells.len() as u32;
        for corners in children {
            self.cells.push(Cell {
                corners,
                count: cell.count,
                level: cell.level + 1,
                children: LEAF,
                parent: c as u32,
                root: cell.root,
            });
        }
    }

    /// Whether leaf `c` must be split for the closure patterns to cover it: a neighbour
    /// split twice along one of its edges, or too many hanging points.
    fn unbalanced(&self, c: usize) -> bool {
        let cell = &self.cells[c];
        let k = cell.count as usize;
        let mut hanging = 0;
        for e in 0..k {
            let (a, b) = (cell.corners[e], cell.corners[(e + 1) % k]);
            if let Some(m) = self.hanging(a, b) {
                if self.hanging(a, m).is_some() || self.hanging(m, b).is_some() {
                    return true;
                }
                hanging += 1;
            }
        }
        hanging >= k - 1
    }

    fn balance(&mut self) {
        loop {
            let mut changed = false;
            let mut c = 0;
            while c < self.cells.len() {
                if self.cells[c].children == LEAF && self.unbalanced(c) {
                    self.split_cell(c);
                    changed = true;
                }
                c += 1;
            }
            if !changed {
                break;
            }
        }
    }

    /// Splits, `levels` times over, the leaf cells that lie within `reach` times their
    /// longest edge of a contact edge (see [`super::contact_grading`]), so that rows of cells
    /// halve towards every contact line. Returns the number of red splits made.
    pub fn grade_contacts(&mut self, levels: u32, reach: f64) -> usize {
        if levels == 0 {
            return 0;
        }
        let longest = |points: &[DVec3], cell: &Cell| {
            let k = cell.count as usize;
            (0..k)
                .map(|e| {
                    (points[cell.corners[(e + 1) % k] as usize] - points[cell.corners[e] as usize])
                        .length()
                })
                .fold(0.0, f64::max)
        };
        let largest = self
            .cells
            .iter()
            .map(|c| longest(&self.points, c))
            .fold(0.0, f64::max);
        let finder = ContactFinder::new(&self.base.faces, reach * largest);
        let mut splits = 0;
        for _ in 0..levels {
            let touching: Vec<u32> = (0..self.cells.len())
                .filter(|&c| {
                    let cell = &self.cells[c];
                    if cell.children != LEAF {
                        return false;
                    }
                    let root = cell.root as usize;
                    let corners: Vec<DVec3> = cell.corners[..cell.count as usize]
                        .iter()
                        .map(|&i| self.points[i as usize])
                        .collect();
                    finder.touches(
                        self.base.patch_face[root],
                        &corners,
                        self.base.patches.patches[root].normal,
                        reach * longest(&self.points, cell),
                    )
                })
                .map(|c| c as u32)
                .collect();
            if touching.is_empty() {
                break;
            }
            splits += self.split(&touching, u32::MAX);
        }
        splits
    }

    /// Per-patch values of an earlier mesh of this forest (`old`, e.g. radiosities)
    /// carried to the patches of `new`: each new patch takes the value of the old patch
    /// on the same side that contains its centroid, found among the pieces of the old
    /// leaf its cell descends from (the nearest such piece when rounding puts the
    /// centroid on no piece). A starting guess for solving the new mesh.
    pub fn carry(
        &self,
        old: &RefinedScene,
        values: &[[f64; 3]],
        new: &RefinedScene,
    ) -> Vec<[f64; 3]> {
        let mut pieces: HashMap<u32, Vec<u32>> = HashMap::new();
        for (i, &c) in old.patch_cell.iter().enumerate() {
            pieces.entry(c).or_default().push(i as u32);
        }
        let old_set = &old.scene.patches;
        (0..new.scene.patches.len())
            .map(|i| {
                let patch = &new.scene.patches.patches[i];
                let mut c = new.patch_cell[i];
                while !pieces.contains_key(&c) {
                    // Every new cell descends from a leaf of the old mesh.
                    c = self.cells[c as usize].parent;
                }
                let same_side = pieces[&c]
                    .iter()
                    .copied()
                    .filter(|&j| old_set.patches[j as usize].normal.dot(patch.normal) > 0.0);
                let containing = same_side.clone().find(|&j| {
                    let polygon = old_set.polygon(j as usize);
                    let corners = polygon.as_slice();
                    let n = old_set.patches[j as usize].normal;
                    (0..corners.len()).all(|k| {
                        let (a, b) = (corners[k], corners[(k + 1) % corners.len()]);
                        (b - a).cross(patch.centroid - a).dot(n) >= 0.0
                    })
                });
                let nearest = || {
                    same_side.clone().min_by(|&a, &b| {
                        let d = |j: u32| {
                            (old_set.patches[j as usize].centroid - patch.centroid).length_squared()
                        };
                        d(a).total_cmp(&d(b))
                    })
                };
                containing
                    .or_else(nearest)
                    .map_or([0.0; 3], |j| values[j as usize])
            })
            .collect()
    }

    /// Number of leaf cells.
    pub fn leaves(&self) -> usize {
        self.cells.iter().filter(|c| c.children == LEAF).count()
    }

    /// The conforming patch mesh of the current leaves (closure pieces included), with
    /// the base scene's back sides rebuilt on the new front patches.
    pub fn scene(&self) -> RefinedScene {
        let base = &self.base;
        let mut set = PatchSet {
            points: self.points.clone(),
            patches: Vec::with_capacity(self.cells.len()),
        };
        let mut patch_cell = Vec::with_capacity(self.cells.len());
        let mut dropped = 0;
        for (c, cell) in self.cells.iter().enumerate() {
            if cell.children != LEAF {
                continue;
            }
            let root = &base.patches.patches[cell.root as usize];
            for piece in self.closure(cell) {
                let corners = &piece.0[..piece.1];
                let added = add(&mut set, corners, root.emission, root.reflectance);
                for _ in 0..added {
                    patch_cell.push(c as u32);
                }
                dropped += (added == 0) as usize;
            }
        }
        let front_count = set.len();
        let mut patch_face: Vec<u32> = patch_cell
            .iter()
            .map(|&c| base.patch_face[self.cells[c as usize].root as usize])
            .collect();
        let mut twin = vec![NO_TWIN; front_count];
        for i in 0..front_count {
            let root = self.cells[patch_cell[i] as usize].root as usize;
            let base_twin = base.twin[root];
            if base_twin == NO_TWIN {
                continue;
            }
            let back = &base.patches.patches[base_twin as usize];
            let p = &set.patches[i];
            let mut corners: Vec<u32> = p.corners[..p.corner_count as usize].to_vec();
            corners.reverse();
            if set
                .add_patch(&corners, back.emission, back.reflectance)
                .is_ok()
            {
                twin[i] = set.len() as u32 - 1;
                twin.push(i as u32);
                patch_face.push(patch_face[i]);
                patch_cell.push(patch_cell[i]);
            }
        }
        let mut scene = RadiosityScene {
            patches: set,
            patch_face,
            twin,
            front_count,
            faces: base.faces.clone(),
            tags: base.tags.clone(),
            max_edge: base.max_edge,
            warnings: base.warnings.clone(),
        };
        if dropped > 0 {
            scene.warnings.push(radiant_scene::Warning {
                loc: radiant_scene::FileLoc::builtin("radiosity refinement"),
                message: format!(
                    "radiosity: {dropped} degenerate element(s) dropped while refining"
                ),
            });
        }
        RefinedScene { scene, patch_cell }
    }

    /// The pieces covering leaf `cell`: itself, or the closure pattern of its hanging
    /// points (corner lists with their lengths).
    fn closure(&self, cell: &Cell) -> Vec<([u32; 4], usize)> {
        let k = cell.count as usize;
        let c = cell.corners;
        let mids: Vec<Option<u32>> = (0..k).map(|e| self.hanging(c[e], c[(e + 1) % k])).collect();
        let hanging: Vec<usize> = (0..k).filter(|&e| mids[e].is_some()).collect();
        let tri = |a: u32, b: u32, d: u32| ([a, b, d, 0], 3);
        match (k, hanging.as_slice()) {
            (_, []) => vec![(c, k)],
            (3, &[e]) => {
                let (a, b, d) = (c[e], c[(e + 1) % 3], c[(e + 2) % 3]);
                let m = mids[e].expect("hanging");
                vec![tri(a, m, d), tri(m, b, d)]
            }
            (4, &[e]) => {
                let (a, b, q, d) = (c[e], c[(e + 1) % 4], c[(e + 2) % 4], c[(e + 3) % 4]);
                let m = mids[e].expect("hanging");
                vec![tri(a, m, d), tri(m, b, q), tri(m, q, d)]
            }
            (4, &[e0, e1]) if e1 - e0 == 2 => {
                let (a, b, q, d) = (c[e0], c[e0 + 1], c[(e0 + 2) % 4], c[(e0 + 3) % 4]);
                let (m0, m1) = (mids[e0].expect("hanging"), mids[e1].expect("hanging"));
                vec![([a, m0, m1, d], 4), ([m0, b, q, m1], 4)]
            }
            (4, &[e0, e1]) => {
                // Adjacent edges: e runs into the shared corner b.
                let e = if e1 - e0 == 1 { e0 } else { e1 };
                let (a, b, q, d) = (c[e], c[(e + 1) % 4], c[(e + 2) % 4], c[(e + 3) % 4]);
                let m0 = mids[e].expect("hanging");
                let m1 = mids[(e + 1) % 4].expect("hanging");
                vec![tri(m0, b, m1), tri(a, m0, d), tri(m0, m1, d), tri(m1, q, d)]
            }
            _ => unreachable!("balance() splits leaves with more hanging points"),
        }
    }
}

/// Adds a piece as one patch, or a quad that fails the patch checks as two triangles.
/// Returns the number of patches added.
fn add(set: &mut PatchSet, corners: &[u32], emission: [f64; 3], reflectance: [f64; 3]) -> usize {
    if set.add_patch(corners, emission, reflectance).is_ok() {
        return 1;
    }
    if corners.len() == 4 {
        let halves = [
            [corners[0], corners[1], corners[2]],
            [corners[0], corners[2], corners[3]],
        ];
        return halves
            .iter()
            .map(|t| set.add_patch(t, emission, reflectance).is_ok() as usize)
            .sum();
    }
    0
}
