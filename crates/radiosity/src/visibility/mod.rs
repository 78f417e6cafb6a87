//! Visibility between points on patches, abstract so the renderer's BVH can be plugged
//! in; a brute-force ray-polygon test serves tests and small scenes.
//!
//! - [`bvh`]: shadow rays through the renderer's BVHs, against the render world or the
//!   unsubdivided faces the patches were cut from.
//! - [`shaft`]: shaft culling, the few occluders that matter per progressive shot.

pub mod bvh;
pub mod contact;
pub mod shaft;

use glam::DVec3;

pub use self::shaft::ShotCull;
use crate::mesh::patch::PatchSet;

/// Answers whether the open segment between two points on two patches is unobstructed.
pub trait Visibility: Sync {
    /// True when nothing blocks the segment `from -> to`; the patches the endpoints lie
    /// on are excluded from the test.
    fn visible(&self, from: DVec3, to: DVec3, from_patch: usize, to_patch: usize) -> bool;

    /// True when every pair of points is mutually visible (a convex enclosure, or a
    /// deliberate no-occlusion run), so callers may skip shadow rays altogether.
    fn always_visible(&self) -> bool {
        false
    }

    /// True when patches `a` and `b` exchange no light at all, whatever the points:
    /// one of them is covered by a face lying on it (see [`contact`]). Form factors
    /// that resolve occlusion without this trait (the hemi-cube's depth buffer) ask
    /// this, so that every method treats surfaces in contact alike. The default: never.
    fn separated(&self, _a: usize, _b: usize) -> bool {
        false
    }

    /// Optional speed-up for the many queries of one progressive shot (rays between
    /// patch `source` and every receiver): prepares `shot` (e.g. the occluders that can
    /// matter per group of receivers). The default prepares nothing.
    /// `go_on` is asked between blocks of the work (it can take seconds on large
    /// scenes); when it answers false the preparation stops and this returns false.
    fn prepare_shot(
        &self,
        _set: &PatchSet,
        _source: usize,
        _shot: &mut ShotCull,
        _go_on: &mut dyn FnMut() -> bool,
    ) -> bool {
        true
    }

    /// [`Visibility::visible`] for a query of the shot `shot` was prepared for.
    fn visible_in_shot(
        &self,
        _shot: &ShotCull,
        from: DVec3,
        to: DVec3,
        from_patch: usize,
        to_patch: usize,
    ) -> bool {
        self.visible(from, to, from_patch, to_patch)
    }
}

/// A visibility restricted to the queries of one prepared shot.
pub struct InShot<'a, V: Visibility> {
    pub vis: &'a V,
    pub shot: &'a ShotCull,
}

impl<V: Visibility> Visibility for InShot<'_, V> {
    #[inline]
    fn visible(&self, from: DVec3, to: DVec3, from_patch: usize, to_patch: usize) -> bool {
        self.vis
            .visible_in_shot(self.shot, from, to, from_patch, to_patch)
    }

    fn always_visible(&self) -> bool {
        self.vis.always_visible()
    }

    fn separated(&self, a: usize, b: usize) -> bool {
        self.vis.separated(a, b)
    }
}

/// No occlusion: exact for the inside of a convex enclosure.
#[derive(Clone, Copy, Debug, Default)]
pub struct AlwaysVisible;

impl Visibility for AlwaysVisible {
    fn visible(&self, _: DVec3, _: DVec3, _: usize, _: usize) -> bool {
        true
    }

    fn always_visible(&self) -> bool {
        true
    }
}

/// Tests a segment against every patch (with a bounding-box rejection first): O(N) per
/// query, meant for tests and scenes of a few hundred patches.
#[derive(Clone, Debug)]
pub struct BruteForceVisibility {
    blockers: Vec<Blocker>,
}

#[derive(Clone, Debug)]
struct Blocker {
    corners: [DVec3; 4],
    count: usize,
    normal: DVec3,
    lower: DVec3,
    upper: DVec3,
}

/// Hits closer than this fraction of the segment to either end are ignored: they are
/// the endpoints' own surfaces or neighbours touching them, not occluders.
const END_TOLERANCE: f64 = 1e-9;

impl BruteForceVisibility {
    /// Copies the patch polygons with their planes and bounding boxes.
    pub fn new(set: &PatchSet) -> BruteForceVisibility {
        let blockers = (0..set.len())
            .map(|i| {
                let polygon = set.polygon(i);
                let used = polygon.as_slice();
                let lower = used.iter().copied().fold(DVec3::INFINITY, DVec3::min);
                let upper = used.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
                Blocker {
                    corners: polygon.corners,
                    count: polygon.count,
                    normal: set.patches[i].normal,
                    lower,
                    upper,
                }
            })
            .collect();
        BruteForceVisibility { blockers }
    }
}

impl Visibility for BruteForceVisibility {
    fn visible(&self, from: DVec3, to: DVec3, from_patch: usize, to_patch: usize) -> bool {
        let d = to - from;
        let seg_lower = from.min(to);
        let seg_upper = from.max(to);
        for (k, b) in self.blockers.iter().enumerate() {
            if k == from_patch || k == to_patch {
                continue;
            }
            if b.lower.cmpgt(seg_upper).any() || b.upper.cmplt(seg_lower).any() {
                continue;
            }
            let denominator = b.normal.dot(d);
            if denominator == 0.0 {
                continue;
            }
            let t = b.normal.dot(b.corners[0] - from) / denominator;
            if t <= END_TOLERANCE || t >= 1.0 - END_TOLERANCE {
                continue;
            }
            let hit = from + t * d;
            // Inside a convex polygon: on the inner side of every edge.
            let inside = (0..b.count).all(|e| {
                let a = b.corners[e];
                let c = b.corners[(e + 1) % b.count];
                (c - a).cross(hit - a).dot(b.normal) >= 0.0
            });
            if inside {
                return false;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_blocks_only_segments_through_it() {
        let mut set = PatchSet::new();
        let blocker = [
            DVec3::new(-1.0, -1.0, 1.0),
            DVec3::new(1.0, -1.0, 1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(-1.0, 1.0, 1.0),
        ];
        set.add_polygon(&blocker, [0.0; 3], [0.5; 3]).unwrap();
        let vis = BruteForceVisibility::new(&set);
        let below = DVec3::ZERO;
        assert!(!vis.visible(below, DVec3::new(0.5, 0.2, 2.0), 7, 8));
        assert!(vis.visible(below, DVec3::new(3.0, 0.0, 2.0), 7, 8));
        // Stops short of the blocker.
        assert!(vis.visible(below, DVec3::new(0.0, 0.0, 0.9), 7, 8));
        // The blocker itself is an endpoint's patch: ignored.
        assert!(vis.visible(below, DVec3::new(0.0, 0.0, 2.0), 0, 8));
    }
}
