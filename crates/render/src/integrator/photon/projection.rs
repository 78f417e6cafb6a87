//! Projection maps (Jensen 1996, "Global Illumination using Photon Maps", §2.1; Jensen
//! 2001, §5.3): aim caustic photons only where they can reach a specular object.
//!
//! Choice made here: the map lives in each light's *sample space*. A light turns two
//! uniform pairs (u_pos, u_dir) ∈ [0,1)² × [0,1)² into a photon ray whose power is
//! Le cos / (pdf_pos pdf_dir) for uniform u. Cutting that square into a grid of cells —
//! P × P cells over u_pos, D × D over u_dir — and marking every cell whose rays *can*
//! hit the bounds of a specular object, we sample u uniformly over the marked cells
//! only. The density of u then rises by 1/f, where f is the marked fraction of the
//! sample space, so the photon's power is multiplied by f — the solid angle (times
//! area) covered, exactly the weighting Jensen prescribes — and the estimate stays
//! unbiased as long as marking is conservative. One mechanism serves every light:
//!
//! - point and spot lights: P = 1 (one position), D × D cells of the direction square
//!   (Jensen's cell grid over directions);
//! - area triangles and disks (each emitting triangle is its own light): P × P cells
//!   of the area parametrisation, each with its own D × D direction cells;
//! - distant lights: P × P cells of the disk the parallel rays start from, D = 1;
//! - spherical and curved-patch area lights and the infinite light: no map (f = 1) — the emission
//!   direction depends on the position, and a marking would cover nearly everything.
//!
//! A cell is marked when the bundle of rays from a ball around the cell's positions,
//! within a cone around the cell's directions, can meet the bounding sphere of any
//! specular object. Balls and cones come from the images of points along the cell's
//! boundary, enlarged by half the largest gap between neighbouring images (enough for
//! the piecewise-linear and smooth maps the lights use).

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::geometry::Aabb;
use crate::light::{Light, LightShape, SceneSphere};
use crate::world::World;
use radiant_math::{Distribution1D, ONE_MINUS_EPSILON};

/// Cells per axis of the direction square (point, spot, area lights).
const DIR_RES: u32 = 32;
/// Cells per axis of the position square of area lights.
const AREA_POS_RES: u32 = 8;
/// Cells per axis of the position disk of distant lights.
const DISTANT_POS_RES: u32 = 64;
/// Upper bound on cells over all lights (memory and build time).
const CELL_BUDGET: u64 = 1 << 22;
/// Boundary samples per cell edge.
const EDGE_SAMPLES: u32 = 8;
/// At most this many specular bounding spheres (more are merged along an axis).
const MAX_TARGETS: usize = 64;

/// The marked cells of one light.
#[derive(Clone, Debug)]
pub struct LightProjection {
    pos_res: u32,
    dir_res: u32,
    /// Marked cells, as `pos_cell * dir_res² + dir_cell`.
    marked: Vec<u32>,
}

impl LightProjection {
    /// Fraction of the light's sample space covered by marked cells.
    pub fn fraction(&self) -> f32 {
        let cells = (self.pos_res * self.pos_res * self.dir_res * self.dir_res) as f64;
        (self.marked.len() as f64 / cells) as f32
    }
}

/// Projection maps of every light, and the distribution choosing lights by the power
/// they send towards specular objects.
#[derive(Clone, Debug)]
pub struct ProjectionMaps {
    lights: Vec<LightProjection>,
    fractions: Vec<f32>,
    distribution: Distribution1D,
    /// Power-weighted mean of the fractions: the share of all emitted power aimed at
    /// specular objects.
    pub covered_power_fraction: f32,
}

impl ProjectionMaps {
    /// Builds the maps; `None` when the scene has no specular object (no caustics).
    pub fn build(world: &World) -> Option<ProjectionMaps> {
        let targets = targets(world);
        if targets.is_empty() || world.lights.is_empty() {
            return None;
        }
        let scene = world.scene_sphere();
        let base: Vec<(u32, u32)> = world.lights.iter().map(resolution).collect();
        // Shrink the grids together when many lights would exceed the cell budget.
        let total: u64 = base.iter().map(|&(p, d)| (p * p * d * d) as u64).sum();
        let mut shrink = 1u32;
        while total / (shrink as u64 * shrink as u64).pow(2) > CELL_BUDGET && shrink < 64 {
            shrink *= 2;
        }
        let lights: Vec<LightProjection> = world
            .lights
            .par_iter()
            .zip(&base)
            .map(|(light, &(p, d))| {
                let p = if p > 1 { (p / shrink).max(1) } else { 1 };
                let d = if d > 1 { (d / shrink).max(2) } else { 1 };
                build_light(light, p, d, &targets, scene)
            })
            .collect();
        let fractions: Vec<f32> = lights.iter().map(LightProjection::fraction).collect();
        let powers: Vec<f32> = world
            .lights
            .iter()
            .map(|l| l.power(scene).average())
            .collect();
        let weights: Vec<f32> = powers.iter().zip(&fractions).map(|(p, f)| p * f).collect();
        let total_power: f32 = powers.iter().sum();
        let aimed: f32 = weights.iter().sum();
        if aimed.is_nan() || aimed <= 0.0 {
            return None;
        }
        Some(ProjectionMaps {
            lights,
            fractions,
            distribution: Distribution1D::new(&weights),
            covered_power_fraction: aimed / total_power.max(f32::MIN_POSITIVE),
        })
    }

    /// Chooses lights in proportion to the power they aim at specular objects.
    pub fn distribution(&self) -> &Distribution1D {
        &self.distribution
    }

    /// Marked fraction of a light's sample space (the weight of its aimed photons).
    pub fn fraction(&self, light: usize) -> f32 {
        self.fractions[light]
    }

    /// True when `(u_pos, u_dir)` lies in a marked cell of `light` (for tests of
    /// conservativeness: every ray that hits a specular object first must be marked).
    pub fn contains(&self, light: usize, u_pos: Vec2, u_dir: Vec2) -> bool {
        let lp = &self.lights[light];
        let cell = |u: Vec2, res: u32| -> u32 {
            let c = (u * res as f32).as_uvec2().min(glam::UVec2::splat(res - 1));
            c.y * res + c.x
        };
        let index = cell(u_pos, lp.pos_res) * lp.dir_res * lp.dir_res + cell(u_dir, lp.dir_res);
        lp.marked.binary_search(&index).is_ok()
    }

    /// Maps uniform numbers into a marked cell of `light`: `u_cell` picks the cell,
    /// `u_pos` and `u_dir` the point within it.
    pub fn remap(
        &self,
        light: usize,
        u_cell: f32,
        u_pos: Vec2,
        u_dir: Vec2,
    ) -> Option<(Vec2, Vec2)> {
        let lp = &self.lights[light];
        if lp.marked.is_empty() {
            return None;
        }
        let k = ((u_cell * lp.marked.len() as f32) as usize).min(lp.marked.len() - 1);
        let cell = lp.marked[k];
        let dir_cells = lp.dir_res * lp.dir_res;
        let (pc, dc) = (cell / dir_cells, cell % dir_cells);
        let within = |c: u32, res: u32, u: Vec2| -> Vec2 {
            let (x, y) = ((c % res) as f32, (c / res) as f32);
            let v = (Vec2::new(x, y) + u) / res as f32;
            v.min(Vec2::splat(ONE_MINUS_EPSILON))
        };
        Some((within(pc, lp.pos_res, u_pos), within(dc, lp.dir_res, u_dir)))
    }
}

/// (position cells per axis, direction cells per axis) before the budget; (1, 1)
/// means no map.
fn resolution(light: &Light) -> (u32, u32) {
    match light {
        Light::Point { .. } | Light::Spot { .. } | Light::Goniometric(_) | Light::Projection(_) => {
            (1, DIR_RES)
        }
        Light::Area(a) => match a.shape {
            LightShape::Triangle { .. }
            | LightShape::Parallelogram { .. }
            | LightShape::Mesh(_)
            | LightShape::Disk { .. } => (AREA_POS_RES, DIR_RES),
            LightShape::Sphere { .. } | LightShape::Bilinear { .. } => (1, 1),
        },
        Light::Distant { .. } => (DISTANT_POS_RES, 1),
        Light::Infinite { .. } => (1, 1),
    }
}

/// Bounding spheres of the specular geometry, merged down to [`MAX_TARGETS`].
fn targets(world: &World) -> Vec<(Vec3, f32)> {
    let mut spheres = world.specular_bounds();
    if spheres.len() > MAX_TARGETS {
        // Sort along the axis of largest spread of the centres and merge runs.
        let spread = spheres.iter().fold(Aabb::EMPTY, |b, s| b.grow(s.0));
        let d = spread.diagonal();
        let axis = if d.x >= d.y && d.x >= d.z {
            0
        } else if d.y >= d.z {
            1
        } else {
            2
        };
        spheres.sort_by(|a, b| a.0[axis].total_cmp(&b.0[axis]));
        let per = spheres.len().div_ceil(MAX_TARGETS);
        spheres = spheres
            .chunks(per)
            .map(|run| {
                let b = run.iter().fold(Aabb::EMPTY, |acc, &(c, r)| {
                    acc.grow(c - Vec3::splat(r)).grow(c + Vec3::splat(r))
                });
                (b.center(), 0.5 * b.diagonal().length())
            })
            .collect();
    }
    // A hair of slack for round-off in the hit tests.
    spheres
        .into_iter()
        .map(|(c, r)| (c, r * 1.0001 + 1e-6))
        .collect()
}

/// Points along the boundary of the cell `(cx, cy)` of a `res` × `res` grid.
fn boundary(cx: u32, cy: u32, res: u32) -> impl Iterator<Item = Vec2> {
    let n = EDGE_SAMPLES;
    let (x0, y0) = (cx as f32 / res as f32, cy as f32 / res as f32);
    let s = 1.0 / res as f32;
    (0..4 * n).map(move |i| {
        let t = (i % n) as f32 / n as f32;
        let local = match i / n {
            0 => Vec2::new(t, 0.0),
            1 => Vec2::new(1.0, t),
            2 => Vec2::new(1.0 - t, 1.0),
            _ => Vec2::new(0.0, 1.0 - t),
        };
        (Vec2::new(x0, y0) + local * s).min(Vec2::splat(ONE_MINUS_EPSILON))
    })
}

fn cell_centre(cx: u32, cy: u32, res: u32) -> Vec2 {
    (Vec2::new(cx as f32 + 0.5, cy as f32 + 0.5)) / res as f32
}

/// A ball around the positions of a position cell.
fn position_ball(light: &Light, c: u32, res: u32, scene: SceneSphere) -> Option<(Vec3, f32)> {
    let u_dir = Vec2::splat(0.5);
    let (cx, cy) = (c % res, c / res);
    let centre = light
        .sample_le(cell_centre(cx, cy, res), u_dir, scene)?
        .ray
        .o;
    let pts: Vec<Vec3> = boundary(cx, cy, res)
        .filter_map(|u| light.sample_le(u, u_dir, scene).map(|e| e.ray.o))
        .collect();
    let r = pts
        .iter()
        .map(|p| (*p - centre).length())
        .fold(0.0, f32::max);
    let gap = max_gap(&pts, |a, b| (a - b).length());
    // The origin offset off the surface is scale-relative; 1e-4 of the scene covers it.
    Some((centre, r + 0.5 * gap + 1e-4 * scene.radius))
}

/// A cone (axis, half-angle) around the directions of a direction cell.
fn direction_cone(
    light: &Light,
    c: u32,
    res: u32,
    u_pos: Vec2,
    scene: SceneSphere,
) -> Option<(Vec3, f32)> {
    let (cx, cy) = (c % res, c / res);
    let axis = light
        .sample_le(u_pos, cell_centre(cx, cy, res), scene)?
        .ray
        .d
        .normalize();
    let dirs: Vec<Vec3> = boundary(cx, cy, res)
        .filter_map(|u| {
            light
                .sample_le(u_pos, u, scene)
                .map(|e| e.ray.d.normalize())
        })
        .collect();
    let angle = |a: Vec3, b: Vec3| a.dot(b).clamp(-1.0, 1.0).acos();
    let half = dirs.iter().map(|d| angle(axis, *d)).fold(0.0, f32::max);
    let gap = max_gap(&dirs, angle);
    Some((axis, half + 0.5 * gap + 1e-3))
}

/// Largest distance between cyclically consecutive points.
fn max_gap<T: Copy>(pts: &[T], dist: impl Fn(T, T) -> f32) -> f32 {
    (0..pts.len())
        .map(|i| dist(pts[i], pts[(i + 1) % pts.len()]))
        .fold(0.0, f32::max)
}

/// Can a ray from the ball (c_b, r_b) in a direction within the cone (axis, half) meet
/// the sphere (c, r)? Directions from the ball to the sphere lie within
/// asin((r + r_b) / |c − c_b|) of c − c_b.
fn bundle_meets(c_b: Vec3, r_b: f32, axis: Vec3, half: f32, c: Vec3, r: f32) -> bool {
    let v = c - c_b;
    let dist = v.length();
    if dist <= r + r_b {
        return true;
    }
    let spread = ((r + r_b) / dist).asin();
    let angle = axis.dot(v / dist).clamp(-1.0, 1.0).acos();
    angle <= half + spread
}

fn build_light(
    light: &Light,
    pos_res: u32,
    dir_res: u32,
    targets: &[(Vec3, f32)],
    scene: SceneSphere,
) -> LightProjection {
    let dir_cells = dir_res * dir_res;
    if pos_res * dir_res == 1 {
        return LightProjection {
            pos_res: 1,
            dir_res: 1,
            marked: vec![0],
        };
    }
    // Directions do not depend on the position for these lights (flat emitters,
    // point-like and distant ones): compute the cones once.
    let cones: Vec<Option<(Vec3, f32)>> = if dir_res == 1 {
        let d = light
            .sample_le(Vec2::splat(0.5), Vec2::splat(0.5), scene)
            .map(|e| (e.ray.d.normalize(), 0.0));
        vec![d]
    } else {
        (0..dir_cells)
            .map(|c| direction_cone(light, c, dir_res, Vec2::splat(0.5), scene))
            .collect()
    };
    let mut marked = Vec::new();
    for pc in 0..pos_res * pos_res {
        let Some((cb, rb)) = position_ball(light, pc, pos_res, scene) else {
            continue;
        };
        for (dc, cone) in cones.iter().enumerate() {
            let hit = match cone {
                // A cell that produced no direction at all emits nothing.
                None => false,
                Some((axis, half)) => targets
                    .iter()
                    .any(|&(c, r)| bundle_meets(cb, rb, *axis, *half, c, r)),
            };
            if hit {
                marked.push(pc * dir_cells + dc as u32);
            }
        }
    }
    LightProjection {
        pos_res,
        dir_res,
        marked,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bundle_test_is_exact_for_a_point_and_a_ray() {
        // A ray from the origin along +z meets the unit sphere at (0, 0.9, 10).
        assert!(bundle_meets(
            Vec3::ZERO,
            0.0,
            Vec3::Z,
            0.0,
            Vec3::new(0.0, 0.9, 10.0),
            1.0
        ));
        assert!(!bundle_meets(
            Vec3::ZERO,
            0.0,
            Vec3::Z,
            0.0,
            Vec3::new(0.0, 1.1, 10.0),
            1.0
        ));
        // Widening the cone or the ball reaches it again.
        assert!(bundle_meets(
            Vec3::ZERO,
            0.0,
            Vec3::Z,
            0.03,
            Vec3::new(0.0, 1.1, 10.0),
            1.0
        ));
        assert!(bundle_meets(
            Vec3::ZERO,
            0.2,
            Vec3::Z,
            0.0,
            Vec3::new(0.0, 1.1, 10.0),
            1.0
        ));
        // Behind the apex.
        assert!(!bundle_meets(
            Vec3::ZERO,
            0.0,
            Vec3::Z,
            0.1,
            Vec3::new(0.0, 0.0, -10.0),
            1.0
        ));
    }
}
