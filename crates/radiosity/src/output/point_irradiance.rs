//! Irradiance at an arbitrary point from a solved scene: `H(x) = sum_j B_j F(x -> j)
//! V_j(x)` with the exact point-to-polygon factor of every patch (Lambert's contour
//! integral) and the visible fraction of each patch from shadow rays. Used to compare a
//! solution with point measurements (sensors) without interpolating patch values, and
//! as a per-point final gather.

use glam::DVec3;

use crate::formfactor::contour_integral::point_polygon_factor;
use crate::formfactor::quadrature::PatchRule;
use crate::mesh::patch::PatchSet;
use crate::visibility::Visibility;
use crate::visibility::bvh::NO_PATCH;
use radiant_math::hash::{Pcg32, hash_u64s};

/// Shadow rays per patch for [`irradiance_at`]: `per_side^2` stratified points per
/// triangle (quads are two triangles), more on emitters, whose partial visibility
/// (penumbrae) decides the direct light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GatherSettings {
    pub rays_per_side: usize,
    pub emitter_rays_per_side: usize,
    pub seed: u64,
}

impl Default for GatherSettings {
    fn default() -> Self {
        GatherSettings {
            rays_per_side: 2,
            emitter_rays_per_side: 16,
            seed: 0,
        }
    }
}

/// Irradiance per band at `x` (unit normal `n`, not on any patch) from the radiosities
/// `radiosity` of `set`. The visible fraction of each patch weights its rays by the
/// point-to-point kernel `cos cos' / r^2`, so it tends to the factor of the visible part.
pub fn irradiance_at<V: Visibility>(
    set: &PatchSet,
    radiosity: &[[f64; 3]],
    x: DVec3,
    n: DVec3,
    vis: &V,
    settings: GatherSettings,
) -> [f64; 3] {
    let mut h = [0.0; 3];
    for (j, patch) in set.patches.iter().enumerate() {
        let b = radiosity[j];
        if b == [0.0; 3] {
            continue;
        }
        let polygon = set.polygon(j);
        let f = point_polygon_factor(x, n, polygon.as_slice(), patch.normal);
        if f == 0.0 {
            continue;
        }
        let visible = if vis.always_visible() {
            1.0
        } else {
            let per_side = if patch.emission.iter().any(|&e| e > 0.0) {
                settings.emitter_rays_per_side
            } else {
                settings.rays_per_side
            };
            let rule = PatchRule::Stratified {
                per_side: per_side.max(1),
            };
            let mut rng = Pcg32::new(
                hash_u64s(&[
                    settings.seed,
                    j as u64,
                    x.x.to_bits(),
                    x.y.to_bits(),
                    x.z.to_bits(),
                ]),
                0,
            );
            let (mut seen, mut total) = (0.0, 0.0);
            rule.for_each_point(polygon.as_slice(), &mut rng, |y, w| {
                let d = y - x;
                let d2 = d.length_squared();
                let kernel = w * n.dot(d).max(0.0) * (-patch.normal.dot(d)).max(0.0) / (d2 * d2);
                if kernel > 0.0 {
                    total += kernel;
                    if vis.visible(x, y, NO_PATCH, j) {
                        seen += kernel;
                    }
                }
            });
            if total > 0.0 { seen / total } else { 0.0 }
        };
        for k in 0..3 {
            h[k] += b[k] * f * visible;
        }
    }
    h
}
