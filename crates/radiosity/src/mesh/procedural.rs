//! Meshed test scenes built in code: subdivided rectangles with shared corner points,
//! a Cornell-like box and the inside of a sphere. Used by tests and benchmarks.

use glam::DVec3;

use thiserror::Error;

use super::patch::{PatchError, PatchSet};

/// Cornell box white reflectance (RGB), as in `enclosures.json`.
pub const CORNELL_WHITE: [f64; 3] = [0.885809, 0.698859, 0.666422];
/// Cornell box red reflectance (RGB).
pub const CORNELL_RED: [f64; 3] = [0.570068, 0.0430135, 0.0443706];
/// Cornell box green reflectance (RGB).
pub const CORNELL_GREEN: [f64; 3] = [0.105421, 0.37798, 0.076425];
/// The Cornell light's exitance `pi L` with `L = (18.387, 13.9873, 6.75357)`.
pub const CORNELL_LIGHT: [f64; 3] = [57.76446412155553, 43.94239892355651, 21.21696589750442];

/// Adds the rectangle `origin + s u + t v` (`s, t` in [0, 1]) as `nu x nv` quads sharing
/// their corner points; the front is the side `u x v` points to. `emission(s, t)` gives
/// the exitance of the quad centred at `(s, t)`. Returns the index of the first patch;
/// patches follow row by row (`t` outer, `s` inner).
#[allow(clippy::too_many_arguments)]
pub fn add_grid(
    set: &mut PatchSet,
    origin: DVec3,
    u: DVec3,
    v: DVec3,
    nu: usize,
    nv: usize,
    reflectance: [f64; 3],
    emission: impl Fn(f64, f64) -> [f64; 3],
) -> Result<usize, PatchError> {
    let first_point = set.points.len() as u32;
    for row in 0..=nv {
        for col in 0..=nu {
            set.add_point(origin + u * (col as f64 / nu as f64) + v * (row as f64 / nv as f64));
        }
    }
    let index = |col: usize, row: usize| first_point + (row * (nu + 1) + col) as u32;
    let first_patch = set.len();
    for row in 0..nv {
        for col in 0..nu {
            let centre = (
                (col as f64 + 0.5) / nu as f64,
                (row as f64 + 0.5) / nv as f64,
            );
            set.add_patch(
                &[
                    index(col, row),
                    index(col + 1, row),
                    index(col + 1, row + 1),
                    index(col, row + 1),
                ],
                emission(centre.0, centre.1),
                reflectance,
            )?;
        }
    }
    Ok(first_patch)
}

/// A unit cube seen from inside, each wall split into `divisions x divisions` patches:
/// white floor (y = 0), ceiling (y = 1) and back (z = 1), red wall at x = 1, green at
/// x = 0, and a white front wall at z = 0 unless `open_front`. The ceiling patches whose
/// centres lie within `light_half_width` of the ceiling's centre emit [`CORNELL_LIGHT`].
pub fn cornell_like_box(
    divisions: usize,
    open_front: bool,
    light_half_width: f64,
) -> Result<PatchSet, PatchError> {
    let mut set = PatchSet::new();
    let n = divisions;
    let dark = |_: f64, _: f64| [0.0; 3];
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    // Floor, normal +y = z x x.
    add_grid(&mut set, DVec3::ZERO, z, x, n, n, CORNELL_WHITE, dark)?;
    // Ceiling, normal -y = x x z.
    add_grid(&mut set, y, x, z, n, n, CORNELL_WHITE, |s, t| {
        if (s - 0.5).abs() < light_half_width && (t - 0.5).abs() < light_half_width {
            CORNELL_LIGHT
        } else {
            [0.0; 3]
        }
    })?;
    // Back, normal -z = y x x.
    add_grid(&mut set, z, y, x, n, n, CORNELL_WHITE, dark)?;
    // Red wall x = 1, normal -x = z x y.
    add_grid(&mut set, x, z, y, n, n, CORNELL_RED, dark)?;
    // Green wall x = 0, normal +x = y x z.
    add_grid(&mut set, DVec3::ZERO, y, z, n, n, CORNELL_GREEN, dark)?;
    if !open_front {
        // Front z = 0, normal +z = x x y.
        add_grid(&mut set, DVec3::ZERO, x, y, n, n, CORNELL_WHITE, dark)?;
    }
    Ok(set)
}

/// Why a shape could not be built.
#[derive(Debug, Error, PartialEq)]
pub enum ShapeError {
    #[error(transparent)]
    Patch(#[from] PatchError),
    #[error("sphere ring heights must rise strictly from -radius to radius (at least 3)")]
    RingHeights,
}

/// Ring heights `-R + 2R k / rings` (`k = 0..=rings`): every ring then has the same area
/// on the sphere (Archimedes), but rings near the poles are wide in angle.
pub fn uniform_z_rings(radius: f64, rings: usize) -> Vec<f64> {
    (0..=rings)
        .map(|k| radius * (-1.0 + 2.0 * k as f64 / rings as f64))
        .collect()
}

/// The inside of a sphere of `radius` about the origin, cut by the planes
/// `z = ring_heights[k]` (rising from `-radius` to `radius`) and by `segments`
/// meridians. Patches are planar trapezoids (triangles at the poles) facing the
/// centre, ordered ring by ring from the bottom, `segments` per ring; every patch of
/// ring `k` gets `material(k)`, which returns `(emission, reflectance)`.
pub fn sphere_interior(
    radius: f64,
    ring_heights: &[f64],
    segments: usize,
    material: impl Fn(usize) -> ([f64; 3], [f64; 3]),
) -> Result<PatchSet, ShapeError> {
    let rings = ring_heights.len().saturating_sub(1);
    let rising = ring_heights.windows(2).all(|w| w[0] < w[1]);
    if rings < 2 || !rising || ring_heights[0] != -radius || ring_heights[rings] != radius {
        return Err(ShapeError::RingHeights);
    }
    let mut set = PatchSet::new();
    // The poles are single points.
    let mut ring_start = Vec::with_capacity(rings + 1);
    for (k, &z) in ring_heights.iter().enumerate() {
        ring_start.push(set.points.len() as u32);
        if k == 0 || k == rings {
            set.add_point(DVec3::new(0.0, 0.0, z));
            continue;
        }
        let r = (radius * radius - z * z).max(0.0).sqrt();
        for s in 0..segments {
            let phi = std::f64::consts::TAU * s as f64 / segments as f64;
            set.add_point(DVec3::new(r * phi.cos(), r * phi.sin(), z));
        }
    }
    let point = |k: usize, s: usize| {
        if k == 0 || k == rings {
            ring_start[k]
        } else {
            ring_start[k] + (s % segments) as u32
        }
    };
    for k in 0..rings {
        let (emission, reflectance) = material(k);
        for s in 0..segments {
            // Counter-clockwise seen from inside: up the meridian, then back along phi.
            let corners = [
                point(k, s),
                point(k + 1, s),
                point(k + 1, s + 1),
                point(k, s + 1),
            ];
            let used: Vec<u32> = if k == 0 {
                vec![corners[0], corners[1], corners[2]]
            } else if k + 1 == rings {
                vec![corners[0], corners[1], corners[3]]
            } else {
                corners.to_vec()
            };
            set.add_patch(&used, emission, reflectance)?;
        }
    }
    Ok(set)
}
