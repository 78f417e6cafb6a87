//! Hemi-cube form factors (Cohen & Greenberg, "The Hemi-Cube: A Radiosity Solution for
//! Complex Environments", SIGGRAPH 1985).
//!
//! Half a cube is placed over the receiving point: a top face of `res x res` cells and
//! four side faces of `res x res/2`. Every patch is clipped to each face's viewing
//! pyramid (which includes the hemisphere boundary, so nothing below the tangent plane
//! survives), projected, and scan-converted with cell-centre sampling into an item
//! buffer with a depth buffer, so only the nearest patch owns a cell. Each cell carries a
//! precomputed delta form factor; a patch's factor is the sum over the cells it owns.
//!
//! The delta form factors here are the exact factors of the cells (the contour integral
//! over each cell's rectangle) rather than the classical cell-centre approximation
//! `dA / (pi (x^2 + y^2 + 1)^2)`, so they sum to 1 to rounding at every resolution; the
//! remaining error is the rasterisation (aliasing) error of the patch outlines.
//!
//! Depth: the plane `m . q = h` of a patch (face coordinates) meets the cell ray
//! `q = t (u, v, 1)` at `1/t = (m . (u, v, 1)) / h`, affine in `(u, v)`, so the inverse
//! depth is exact at every cell centre and larger means nearer.

use glam::DVec3;
use rayon::prelude::*;
use thiserror::Error;

use super::contour_integral::{in_front_of, point_polygon_factor};
use super::matrix::FormFactorMatrix;
use crate::mesh::patch::{PatchSet, tangent_frame};
use crate::visibility::Visibility;

#[derive(Debug, Error, PartialEq)]
pub enum HemiCubeError {
    #[error("hemi-cube resolution must be even and at least 2, got {0}")]
    Resolution(usize),
}

/// The delta form-factor tables for one resolution.
#[derive(Clone, Debug)]
pub struct HemiCube {
    resolution: usize,
    /// `res x res`, row-major over (v, u).
    top_delta: Vec<f64>,
    /// `res/2` rows (row 0 at the horizon) of `res` cells, shared by the four sides.
    side_delta: Vec<f64>,
}

/// Per-thread scratch: inverse depth and item per cell, top face then four sides.
#[derive(Clone, Debug)]
pub struct HemiCubeBuffers {
    inverse_depth: Vec<f64>,
    item: Vec<u32>,
}

const NO_ITEM: u32 = u32::MAX;

/// One face of the hemi-cube: how local coordinates `(a, b, c)` (tangent, bitangent,
/// normal) map to face coordinates `(right, up, forward)`, and its cell rows.
#[derive(Clone, Copy)]
struct Face {
    map: fn(DVec3) -> DVec3,
    top: bool,
}

const FACES: [Face; 5] = [
    Face {
        map: |q| q,
        top: true,
    },
    Face {
        map: |q| DVec3::new(q.y, q.z, q.x),
        top: false,
    },
    Face {
        map: |q| DVec3::new(-q.y, q.z, -q.x),
        top: false,
    },
    Face {
        map: |q| DVec3::new(-q.x, q.z, q.y),
        top: false,
    },
    Face {
        map: |q| DVec3::new(q.x, q.z, -q.y),
        top: false,
    },
];

/// Most vertices a quad can have after clipping by four planes.
const MAX_CLIPPED: usize = 8;

impl HemiCube {
    /// Precomputes the delta form factors for `resolution` cells across the top face.
    pub fn new(resolution: usize) -> Result<HemiCube, HemiCubeError> {
        if resolution < 2 || !resolution.is_multiple_of(2) {
            return Err(HemiCubeError::Resolution(resolution));
        }
        let cell = 2.0 / resolution as f64;
        let half = resolution / 2;
        let mut top_delta = vec![0.0; resolution * resolution];
        for (row, chunk) in top_delta.chunks_mut(resolution).enumerate() {
            let v0 = -1.0 + row as f64 * cell;
            for (col, delta) in chunk.iter_mut().enumerate() {
                let u0 = -1.0 + col as f64 * cell;
                let (u1, v1) = (u0 + cell, v0 + cell);
                // Counter-clockwise seen from the eye below (normal -z).
                let corners = [
                    DVec3::new(u0, v0, 1.0),
                    DVec3::new(u0, v1, 1.0),
                    DVec3::new(u1, v1, 1.0),
                    DVec3::new(u1, v0, 1.0),
                ];
                *delta = point_polygon_factor(DVec3::ZERO, DVec3::Z, &corners, -DVec3::Z);
            }
        }
        let mut side_delta = vec![0.0; half * resolution];
        for (row, chunk) in side_delta.chunks_mut(resolution).enumerate() {
            let v0 = row as f64 * cell;
            for (col, delta) in chunk.iter_mut().enumerate() {
                let u0 = -1.0 + col as f64 * cell;
                let (u1, v1) = (u0 + cell, v0 + cell);
                // The face plane x = 1 (u along y, v along the normal z), facing -x.
                let corners = [
                    DVec3::new(1.0, u0, v0),
                    DVec3::new(1.0, u0, v1),
                    DVec3::new(1.0, u1, v1),
                    DVec3::new(1.0, u1, v0),
                ];
                *delta = point_polygon_factor(DVec3::ZERO, DVec3::Z, &corners, -DVec3::X);
            }
        }
        Ok(HemiCube {
            resolution,
            top_delta,
            side_delta,
        })
    }

    /// Cells across the top face.
    pub fn resolution(&self) -> usize {
        self.resolution
    }

    /// Sum of all delta form factors (1 up to rounding).
    pub fn delta_form_factor_sum(&self) -> f64 {
        self.top_delta.iter().sum::<f64>() + 4.0 * self.side_delta.iter().sum::<f64>()
    }

    /// Fresh scratch buffers for this resolution.
    pub fn buffers(&self) -> HemiCubeBuffers {
        let cells = 3 * self.resolution * self.resolution;
        HemiCubeBuffers {
            inverse_depth: vec![0.0; cells],
            item: vec![NO_ITEM; cells],
        }
    }

    /// Factors from a differential area at `x` with unit normal `n` to every patch of
    /// `set` (`out[j]`), with occlusion resolved by the depth buffer. `exclude` is the
    /// patch `x` lies on, if any.
    pub fn point_factors(
        &self,
        set: &PatchSet,
        x: DVec3,
        n: DVec3,
        exclude: Option<usize>,
        buffers: &mut HemiCubeBuffers,
        out: &mut [f64],
    ) {
        buffers.inverse_depth.fill(0.0);
        buffers.item.fill(NO_ITEM);
        let (s, t) = tangent_frame(n);
        for j in 0..set.len() {
            if Some(j) == exclude {
                continue;
            }
            let patch = &set.patches[j];
            let polygon = set.polygon(j);
            let corners = polygon.as_slice();
            // Back faces and patches in the eye's own plane are invisible. In the plane
            // up to rounding counts: the back twin of a two-sided patch shares its
            // corners, and at a height of 1e-13 its clipped outline covered the top
            // face's cells, doubling the front's radiosity and shooting it through.
            if !in_front_of(x, corners, patch.normal) {
                continue;
            }
            let mut local = [DVec3::ZERO; 4];
            let mut above = false;
            for (l, c) in local.iter_mut().zip(corners) {
                let d = *c - x;
                *l = DVec3::new(d.dot(s), d.dot(t), d.dot(n));
                above |= l.z > 0.0;
            }
            if !above {
                continue;
            }
            let local_normal = DVec3::new(
                patch.normal.dot(s),
                patch.normal.dot(t),
                patch.normal.dot(n),
            );
            for (face_index, face) in FACES.iter().enumerate() {
                self.rasterise(
                    face_index,
                    face,
                    &local[..corners.len()],
                    local_normal,
                    j as u32,
                    buffers,
                );
            }
        }
        out.fill(0.0);
        let top_cells = self.resolution * self.resolution;
        let side_cells = self.side_delta.len();
        for (cell, &item) in buffers.item.iter().enumerate() {
            if item == NO_ITEM {
                continue;
            }
            let delta = if cell < top_cells {
                self.top_delta[cell]
            } else {
                self.side_delta[(cell - top_cells) % side_cells]
            };
            out[item as usize] += delta;
        }
    }

    /// Row `from`: the hemi-cube at the centroid of patch `from`. The depth buffer
    /// resolves occlusion; pairs that `vis` says are [separated](Visibility::separated)
    /// (a patch covered by a face resting on it) get no factor, as with ray-cast
    /// factors. Without that, a covered patch's centroid, under the box resting on it,
    /// would look into the box: with two-sided patches, its inner faces.
    pub fn row(
        &self,
        set: &PatchSet,
        from: usize,
        vis: &impl Visibility,
        buffers: &mut HemiCubeBuffers,
        out: &mut [f64],
    ) {
        // A covered patch is separated from every patch, itself included.
        if vis.separated(from, from) {
            out.fill(0.0);
            return;
        }
        let patch = &set.patches[from];
        self.point_factors(set, patch.centroid, patch.normal, Some(from), buffers, out);
        for (j, f) in out.iter_mut().enumerate() {
            if *f != 0.0 && vis.separated(from, j) {
                *f = 0.0;
            }
        }
    }

    /// The full matrix, one hemi-cube per patch, rows in parallel (deterministic).
    pub fn matrix(&self, set: &PatchSet, vis: &impl Visibility) -> FormFactorMatrix<f64> {
        let n = set.len();
        let mut values = vec![0.0; n * n];
        if n > 0 {
            values.par_chunks_mut(n).enumerate().for_each_init(
                || self.buffers(),
                |buffers, (i, row)| self.row(set, i, vis, buffers, row),
            );
        }
        FormFactorMatrix::from_row_major(n, values).expect("n x n values")
    }

    /// Clips the polygon (local coordinates) to one face's pyramid and scan-converts it.
    fn rasterise(
        &self,
        face_index: usize,
        face: &Face,
        local: &[DVec3],
        local_normal: DVec3,
        item: u32,
        buffers: &mut HemiCubeBuffers,
    ) {
        // Face coordinates (right, up, forward); the pyramid is |right| <= forward and
        // -forward <= up <= forward (top) or 0 <= up <= forward (sides).
        let mut polygon = [DVec3::ZERO; MAX_CLIPPED];
        let mut count = local.len();
        for (p, l) in polygon.iter_mut().zip(local) {
            *p = (face.map)(*l);
        }
        let planes = [
            DVec3::new(-1.0, 0.0, 1.0),
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(0.0, -1.0, 1.0),
            if face.top {
                DVec3::new(0.0, 1.0, 1.0)
            } else {
                DVec3::new(0.0, 1.0, 0.0)
            },
        ];
        for plane in planes {
            count = clip_against_plane(&mut polygon, count, plane);
            if count < 3 {
                return;
            }
        }
        let m = (face.map)(local_normal);
        // Plane offset h = m . q for any corner (all corners lie on the plane).
        let h = m.dot((face.map)(local[0]));
        if h >= 0.0 {
            return;
        }
        let res = self.resolution;
        let rows = if face.top { res } else { res / 2 };
        let scale = res as f64 / 2.0;
        let v_offset = if face.top { 1.0 } else { 0.0 };
        let mut pixels = [(0.0f64, 0.0f64); MAX_CLIPPED];
        for (pixel, q) in pixels.iter_mut().zip(&polygon[..count]) {
            if q.z <= 0.0 {
                return;
            }
            let u = q.x / q.z;
            let v = q.y / q.z;
            *pixel = (
                ((u + 1.0) * scale).clamp(0.0, res as f64),
                ((v + v_offset) * scale).clamp(0.0, rows as f64),
            );
        }
        let pixels = &pixels[..count];
        let (y_min, y_max) = pixels
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.1), hi.max(p.1))
            });
        let row_start = ((y_min - 0.5).ceil().max(0.0)) as usize;
        let row_end = ((y_max - 0.5).ceil().max(0.0) as usize).min(rows);
        let base = if face_index == 0 {
            0
        } else {
            res * res + (face_index - 1) * rows * res
        };
        for row in row_start..row_end {
            let yc = row as f64 + 0.5;
            let mut x_left = f64::INFINITY;
            let mut x_right = f64::NEG_INFINITY;
            for k in 0..count {
                let a = pixels[k];
                let b = pixels[(k + 1) % count];
                // Canonical endpoint order, so that two polygons sharing an edge compute
                // bit-identical crossings (no cracks, no double coverage).
                let (lo, hi) = if (a.1, a.0) < (b.1, b.0) {
                    (a, b)
                } else {
                    (b, a)
                };
                if lo.1 == hi.1 || yc < lo.1 || yc >= hi.1 {
                    continue;
                }
                let x = lo.0 + (hi.0 - lo.0) * (yc - lo.1) / (hi.1 - lo.1);
                x_left = x_left.min(x);
                x_right = x_right.max(x);
            }
            if x_left >= x_right {
                continue;
            }
            let col_start = ((x_left - 0.5).ceil().max(0.0)) as usize;
            let col_end = ((x_right - 0.5).ceil().max(0.0) as usize).min(res);
            let v = yc / scale - v_offset;
            let row_base = base + row * res;
            for col in col_start..col_end {
                let u = (col as f64 + 0.5) / scale - 1.0;
                let inverse_depth = (m.x * u + m.y * v + m.z) / h;
                let cell = row_base + col;
                if inverse_depth > buffers.inverse_depth[cell] {
                    buffers.inverse_depth[cell] = inverse_depth;
                    buffers.item[cell] = item;
                }
            }
        }
    }
}

/// Sutherland-Hodgman: keeps the part of the polygon where `plane . q >= 0`. Returns
/// the new vertex count (at most one more than before).
fn clip_against_plane(polygon: &mut [DVec3; MAX_CLIPPED], count: usize, plane: DVec3) -> usize {
    let mut all_inside = true;
    for q in &polygon[..count] {
        all_inside &= plane.dot(*q) >= 0.0;
    }
    if all_inside {
        return count;
    }
    let input = *polygon;
    let mut out = 0;
    let mut a = input[count - 1];
    let mut da = plane.dot(a);
    for &b in &input[..count] {
        let db = plane.dot(b);
        if (da >= 0.0) != (db >= 0.0) && out < MAX_CLIPPED {
            // Interpolate from the lexicographically smaller endpoint, so that the two
            // patches sharing this edge (which traverse it in opposite directions) get
            // bit-identical clip points and hence no crack between them.
            let (p, q, dp, dq) = if (a.x, a.y, a.z) < (b.x, b.y, b.z) {
                (a, b, da, db)
            } else {
                (b, a, db, da)
            };
            polygon[out] = p + (q - p) * (dp / (dp - dq));
            out += 1;
        }
        if db >= 0.0 && out < MAX_CLIPPED {
            polygon[out] = b;
            out += 1;
        }
        a = b;
        da = db;
    }
    out
}
