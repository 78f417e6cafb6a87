//! Surfaces in contact: patches covered by another face lying on them (the floor under
//! a box that rests on it, and the box's bottom).
//!
//! Shadow rays start a small lift off their patch (see [`super::bvh`]). A face that
//! lies on the patch closer than that lift is behind the ray's origin and never
//! occludes, so a covered patch would see, and light, whatever lies past the face
//! covering it: with two-sided patches, the inside of the box resting on it. Its row of
//! form factors then sums to about 2, `rho F` expands energy and the solve diverges
//! (the spectral radius of `rho F` must stay below 1 for Jacobi, Gauss-Seidel and
//! shooting to converge; Cohen & Wallace, "Radiosity and Realistic Image Synthesis",
//! sec. 5.3). In contact, no light reaches a covered patch or leaves it: the face lying
//! on it blocks every direction, and the gap between the two has no extent (closer
//! than the f32 rounding of the input, their mutual factor is rounding noise that can
//! exceed 1). So a covered patch exchanges light with no patch at all: that is what
//! [`Contacts::separated`] says.

use std::collections::HashMap;

use glam::DVec3;

use crate::mesh::meshed_scene::RadiosityScene;

/// No covering face.
const NONE: u32 = u32::MAX;

/// Cells of the face grid per side of the scene's bounding box, at most.
const GRID_CELLS: f64 = 32.0;

/// The covering face of every patch, if any.
#[derive(Clone, Debug, Default)]
pub struct Contacts {
    /// Per patch, the face lying on it, or `NONE`.
    cover: Vec<u32>,
    covered: usize,
}

impl Contacts {
    /// Finds, for each patch, a planar face other than its own, parallel to it, whose
    /// plane is within `gap` of the patch's centroid and which contains the centroid.
    /// The face's orientation does not matter: occlusion is two-sided whatever the
    /// side a surface reflects on.
    pub fn new(scene: &RadiosityScene, gap: f64) -> Contacts {
        let points = &scene.faces.points;
        let set = &scene.patches;
        let mut contacts = Contacts {
            cover: vec![NONE; set.len()],
            covered: 0,
        };
        if points.is_empty() || set.is_empty() {
            return contacts;
        }
        let lower = points.iter().copied().fold(DVec3::INFINITY, DVec3::min);
        let upper = points.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
        let cell = ((upper - lower).max_element() / GRID_CELLS).max(gap * 4.0);
        let key = |p: DVec3| {
            let k = ((p - lower) / cell).floor();
            (k.x as i64, k.y as i64, k.z as i64)
        };
        // Planar faces, with their unit normal and the cells their boxes touch.
        let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
        let mut normals = vec![DVec3::ZERO; scene.faces.faces.len()];
        for (f, face) in scene.faces.faces.iter().enumerate() {
            if face.curved {
                continue;
            }
            let corners: Vec<DVec3> = face.corners[..face.count as usize]
                .iter()
                .map(|&c| points[c as usize])
                .collect();
            let n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
            if n.length_squared() == 0.0 {
                continue;
            }
            normals[f] = n.normalize();
            let lo = corners.iter().copied().fold(DVec3::INFINITY, DVec3::min) - gap;
            let hi = corners
                .iter()
                .copied()
                .fold(DVec3::NEG_INFINITY, DVec3::max)
                + gap;
            let (a, b) = (key(lo), key(hi));
            for x in a.0..=b.0 {
                for y in a.1..=b.1 {
                    for z in a.2..=b.2 {
                        grid.entry((x, y, z)).or_default().push(f as u32);
                    }
                }
            }
        }
        for (i, patch) in set.patches.iter().enumerate() {
            let c = patch.centroid;
            let Some(candidates) = grid.get(&key(c)) else {
                continue;
            };
            let own = scene.patch_face[i];
            let found = candidates.iter().copied().find(|&f| {
                let n = normals[f as usize];
                let face = &scene.faces.faces[f as usize];
                if f == own || n.dot(patch.normal).abs() < 0.999 {
                    return false;
                }
                let used = &face.corners[..face.count as usize];
                let p0 = points[used[0] as usize];
                if n.dot(c - p0).abs() > gap {
                    return false;
                }
                // Inside the convex face: on the inner side of every edge.
                (0..used.len()).all(|e| {
                    let a = points[used[e] as usize];
                    let b = points[used[(e + 1) % used.len()] as usize];
                    (b - a).cross(c - a).dot(n) >= 0.0
                })
            });
            if let Some(f) = found {
                contacts.cover[i] = f;
                contacts.covered += 1;
            }
        }
        contacts
    }

    /// Number of covered patches.
    pub fn covered(&self) -> usize {
        self.covered
    }

    /// True when patches `a` and `b` cannot exchange light because one of them is
    /// covered. Points off patches (out-of-range indices) are never covered.
    #[inline]
    pub fn separated(&self, a: usize, b: usize) -> bool {
        if self.covered == 0 {
            return false;
        }
        let covered = |p: usize| self.cover.get(p).is_some_and(|&f| f != NONE);
        covered(a) || covered(b)
    }
}
