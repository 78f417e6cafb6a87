//! Shaft culling (Haines & Wallace, "Shaft Culling for Efficient Ray-Cast Radiosity",
//! Eurographics Workshop on Rendering 1991): before a progressive shot, find for each
//! group of receivers the few occluders that can shadow it from the shooter; its shadow
//! rays are then tested against those alone (none, for most groups).
//!
//! In a shot every shadow ray ends at one point, the shooter's centre `a` (lifted off
//! its surface), so each occluder triangle `T` shadows exactly the points inside the
//! pyramid with apex `a` over `T`, beyond `T`'s plane. Receivers are grouped into tiles
//! of one input face, each bounded by a sphere (grown by the lift of ray origins); `T`
//! is a candidate for a tile only if the sphere reaches beyond `T`'s plane (seen from
//! `a`) and is not wholly outside any of the pyramid's three side planes. Both are
//! necessary conditions for a segment from the tile to `a` to cross `T`, so a tile
//! without candidates is truly unshadowed.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use crate::mesh::patch::PatchSet;

/// Receiver tiles are about this many patch edges across.
const TILE_EDGES: f64 = 6.0;

/// An occluder triangle with what the tests need.
#[derive(Clone, Copy, Debug)]
struct Occluder {
    normal: DVec3,
    offset: f64,
    corners: [DVec3; 3],
    /// In-plane inward edge normals and their offsets: inside iff `m_k . p >= d_k`.
    edge_normals: [DVec3; 3],
    edge_offsets: [f64; 3],
}

#[derive(Clone, Copy, Debug)]
struct Tile {
    centre: DVec3,
    radius: f64,
}

/// The candidate occluders of every tile for one shot.
#[derive(Clone, Debug, Default)]
pub struct ShotCull {
    /// The shooter the lists were made for.
    source: usize,
    /// The point every ray of the shot ends at.
    apex: DVec3,
    /// Candidates of tile `t`: `list[start[t]..start[t + 1]]`.
    start: Vec<u32>,
    list: Vec<u32>,
    /// Signed distance of the apex from each occluder's plane.
    apex_height: Vec<f64>,
}

impl ShotCull {
    /// Whether the lists hold for a ray to `point` on patch `patch`.
    pub fn prepared_for(&self, patch: usize, point: DVec3) -> bool {
        !self.start.is_empty() && self.source == patch && self.apex == point
    }
}

/// The sphere about the box centre of a point set through its farthest point.
fn bounding_sphere(points: &[DVec3]) -> (DVec3, f64) {
    let lower = points.iter().copied().fold(DVec3::INFINITY, DVec3::min);
    let upper = points.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
    let centre = 0.5 * (lower + upper);
    let radius = points
        .iter()
        .map(|p| (*p - centre).length())
        .fold(0.0, f64::max);
    (centre, radius)
}

/// Tile-occluder tests between two stop checks of a shot's preparation (tens of
/// milliseconds).
const TILE_BLOCK_WORK: usize = 1 << 22;

/// Tile-occluder tests per patch above which a shot's preparation costs more than the
/// BVH's shadow rays it would save: a shot casts a few rays per patch at about a
/// microsecond each, and a tile-occluder test costs a few nanoseconds.
const TESTS_PER_PATCH: usize = 64;

/// Occluders and receiver tiles.
#[derive(Clone, Debug, Default)]
pub struct ShaftCuller {
    occluders: Vec<Occluder>,
    tiles: Vec<Tile>,
    tile_of: Vec<u32>,
    /// Distances to a plane below this count as on it.
    tolerance: f64,
}

impl ShaftCuller {
    /// `occluders`: the triangles that can block rays; `patch_face`: the input face of
    /// every patch of `set`; `patch_size`: the patches' edge length (tiles are
    /// `TILE_EDGES` of them across).
    pub fn new(
        set: &PatchSet,
        patch_face: &[u32],
        occluders: &[[DVec3; 3]],
        patch_size: f64,
        tolerance: f64,
    ) -> ShaftCuller {
        let occluders = occluders
            .iter()
            .filter_map(|t| {
                let normal = (t[1] - t[0]).cross(t[2] - t[0]).try_normalize()?;
                let edge_normals: [DVec3; 3] =
                    std::array::from_fn(|k| normal.cross(t[(k + 1) % 3] - t[k]));
                let edge_offsets = std::array::from_fn(|k| edge_normals[k].dot(t[k]));
                Some(Occluder {
                    corners: *t,
                    normal,
                    offset: normal.dot(t[0]),
                    edge_normals,
                    edge_offsets,
                })
            })
            .collect();
        let cell = (TILE_EDGES * patch_size).max(f64::MIN_POSITIVE);
        let mut index: HashMap<(u32, i64, i64, i64), u32> = HashMap::new();
        let mut tile_points: Vec<Vec<DVec3>> = Vec::new();
        let mut tile_of = Vec::with_capacity(set.len());
        for (i, patch) in set.patches.iter().enumerate() {
            let c = (patch.centroid / cell).floor();
            let key = (patch_face[i], c.x as i64, c.y as i64, c.z as i64);
            let next = tile_points.len() as u32;
            let t = *index.entry(key).or_insert(next);
            if t == next {
                tile_points.push(Vec::new());
            }
            tile_points[t as usize].extend_from_slice(set.polygon(i).as_slice());
            tile_of.push(t);
        }
        let tiles = tile_points
            .iter()
            .map(|points| {
                let (centre, radius) = bounding_sphere(points);
                Tile { centre, radius }
            })
            .collect();
        ShaftCuller {
            occluders,
            tiles,
            tile_of,
            tolerance,
        }
    }

    /// Whether culling pays: the tile-occluder tests of a shot's preparation grow as
    /// tiles × occluders, quadratically in the input meshes (a tile never spans two
    /// input faces), which on a scanned or subdivided mesh of 10⁵ triangles is 10¹⁰
    /// tests, seconds per shot. Past [`TESTS_PER_PATCH`] tests per patch, shots use the
    /// BVH's shadow rays instead.
    pub fn pays(&self) -> bool {
        self.tiles.len().saturating_mul(self.occluders.len())
            <= TESTS_PER_PATCH.saturating_mul(self.tile_of.len())
    }

    /// Fills `shot` with the candidate occluders of every tile for rays from receivers
    /// (lifted off their patches by at most `lift`) to `apex` on patch `source`.
    /// Returns false, with `shot` left unprepared, when `go_on` (asked between blocks
    /// of tiles) answers false.
    pub fn prepare(
        &self,
        source: usize,
        apex: DVec3,
        lift: f64,
        shot: &mut ShotCull,
        go_on: &mut dyn FnMut() -> bool,
    ) -> bool {
        shot.source = source;
        shot.apex = apex;
        shot.start.clear();
        shot.list.clear();
        shot.apex_height.clear();
        shot.apex_height
            .extend(self.occluders.iter().map(|o| o.normal.dot(apex) - o.offset));
        // Per occluder: the apex's side of its plane and the pyramid's inward side
        // planes (unit normals through the apex); None when the apex lies in the plane.
        let pyramids: Vec<Option<(f64, [DVec3; 3])>> = self
            .occluders
            .iter()
            .zip(&shot.apex_height)
            .map(|(o, &h)| {
                if h.abs() <= self.tolerance {
                    return None;
                }
                let v = o.corners;
                let sides = std::array::from_fn(|k| {
                    let m = (v[k] - apex).cross(v[(k + 1) % 3] - apex);
                    let m = m.try_normalize().unwrap_or(DVec3::ZERO);
                    if m.dot(v[(k + 2) % 3] - apex) < 0.0 {
                        -m
                    } else {
                        m
                    }
                });
                Some((h.signum(), sides))
            })
            .collect();
        // Tiles times occluders is most of a shot's work on large scenes (seconds), so
        // tiles go in parallel blocks with a stop check between them.
        let candidates = |tile: &Tile| -> Vec<u32> {
            let r = tile.radius + lift + self.tolerance;
            let mut list = Vec::new();
            for (k, (o, pyramid)) in self.occluders.iter().zip(&pyramids).enumerate() {
                let Some((side, planes)) = pyramid else {
                    continue;
                };
                // Some point of the tile strictly beyond the plane, seen from the apex.
                let h = (o.normal.dot(tile.centre) - o.offset) * side;
                if h >= r {
                    continue;
                }
                if planes.iter().any(|m| m.dot(tile.centre - apex) < -r) {
                    continue;
                }
                list.push(k as u32);
            }
            list
        };
        let block = (TILE_BLOCK_WORK / self.occluders.len().max(1)).max(16);
        for tiles in self.tiles.chunks(block) {
            let lists: Vec<Vec<u32>> = tiles.par_iter().map(candidates).collect();
            for list in lists {
                shot.start.push(shot.list.len() as u32);
                shot.list.extend(list);
            }
            if shot.start.len() < self.tiles.len() && !go_on() {
                // Unprepared: `prepared_for` must not accept a partial list.
                shot.start.clear();
                shot.list.clear();
                return false;
            }
        }
        shot.start.push(shot.list.len() as u32);
        true
    }

    /// Whether any candidate of `patch`'s tile in `shot` blocks the segment from `o` to
    /// the shot's apex (ends excluded: hits within `far_end` of the apex do not count).
    #[inline]
    pub fn blocked(&self, shot: &ShotCull, patch: usize, o: DVec3, far_end: f64) -> bool {
        let t = self.tile_of[patch] as usize;
        let candidates = &shot.list[shot.start[t] as usize..shot.start[t + 1] as usize];
        let target = shot.apex;
        candidates.iter().any(|&k| {
            let occ = &self.occluders[k as usize];
            let h0 = occ.normal.dot(o) - occ.offset;
            let h1 = shot.apex_height[k as usize];
            if (h0 > 0.0) == (h1 > 0.0) || h0 == h1 {
                return false;
            }
            let t = h0 / (h0 - h1);
            if t <= 0.0 || t >= 1.0 - far_end {
                return false;
            }
            let p = o + (target - o) * t;
            (0..3).all(|e| occ.edge_normals[e].dot(p) >= occ.edge_offsets[e])
        })
    }
}
