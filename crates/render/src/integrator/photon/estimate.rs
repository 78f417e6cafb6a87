//! Photon maps and the radiance estimate (Jensen 1996, eq. 6; Jensen 2001, §7.1):
//! reflected radiance at x is the sum over the photons near x of f(wo, wi_p) Φ_p,
//! divided by the area they were gathered from. The k nearest photons within a maximum
//! radius are used, counting only photons that arrived on the viewer's side of the
//! surface and lie on a surface facing the same way (so that light does not leak
//! through thin walls or round corners).

use glam::Vec3;
use rayon::prelude::*;

use super::kdtree::{KdTree, Neighbors};
use super::record::{Photon, RawPhoton};
use super::settings::Kernel;
use radiant_math::PI;
use radiant_math::color::Rgb;

/// A photon's surface must face within ~45° of the query's to count.
const NORMAL_COS: f32 = 0.7;

/// A set of stored photons in a kd-tree.
#[derive(Clone, Debug, Default)]
pub struct PhotonMap {
    tree: KdTree<Photon>,
    /// Powers are stored relative to this (the largest component of any photon).
    power_scale: f32,
}

impl PhotonMap {
    /// Compresses the photons and builds the tree.
    pub fn build(raw: Vec<RawPhoton>) -> PhotonMap {
        PhotonMap::build_until(raw, &|| false).expect("never stopped")
    }

    /// [`PhotonMap::build`], giving up (`None`) once `stop` holds.
    pub fn build_until(raw: Vec<RawPhoton>, stop: &(dyn Fn() -> bool + Sync)) -> Option<PhotonMap> {
        if stop() {
            super::kdtree::release(raw);
            return None;
        }
        let scale = raw
            .par_iter()
            .map(|r| r.power.max_component())
            .reduce(|| 0.0, f32::max);
        let scale = if scale > 0.0 && scale.is_finite() {
            scale
        } else {
            1.0
        };
        let inv = 1.0 / scale;
        let photons: Vec<Photon> = raw.par_iter().map(|r| Photon::encode(r, inv)).collect();
        super::kdtree::release(raw);
        Some(PhotonMap {
            tree: KdTree::build_until(photons, stop)?,
            power_scale: scale,
        })
    }

    /// Drops the map without waiting for a large one's memory to be returned.
    pub fn discard(self) {
        self.tree.discard();
    }

    /// Number of stored photons.
    pub fn len(&self) -> usize {
        self.tree.len()
    }

    /// True when no photon was stored.
    pub fn is_empty(&self) -> bool {
        self.tree.is_empty()
    }

    /// The photons in tree order.
    pub fn photons(&self) -> &[Photon] {
        self.tree.items()
    }

    /// The kd-tree, for queries.
    pub fn tree(&self) -> &KdTree<Photon> {
        &self.tree
    }

    /// Power of a stored photon.
    pub fn power(&self, photon: &Photon) -> Rgb {
        photon.power(self.power_scale)
    }

    /// Total power of the photons whose flags include all of `flags`.
    pub fn total_power(&self, flags: u8) -> [f64; 3] {
        self.photons()
            .iter()
            .filter(|p| p.flags & flags == flags)
            .fold([0.0; 3], |acc, p| {
                let c = self.power(p);
                [
                    acc[0] + c.r as f64,
                    acc[1] + c.g as f64,
                    acc[2] + c.b as f64,
                ]
            })
    }
}

/// Where an estimate is taken: position and the unit geometric normal turned towards
/// the viewer.
#[derive(Clone, Copy, Debug)]
pub struct EstimatePoint {
    pub p: Vec3,
    pub n: Vec3,
    /// The BSDF transmits diffusely: photons arriving on the far side count too (the
    /// BSDF, evaluated for them, carries the transmittance).
    pub two_sided: bool,
}

/// Reflected radiance at `at` from `map`: the `nbrs.k()` nearest photons within
/// `max_r2` (squared scene units) whose flags share nothing with `skip_flags`;
/// `f(wi)` is the BSDF for the photon's incoming direction `wi` (world space).
pub fn radiance_estimate(
    map: &PhotonMap,
    at: &EstimatePoint,
    max_r2: f32,
    kernel: Kernel,
    skip_flags: u8,
    nbrs: &mut Neighbors,
    f: impl Fn(Vec3) -> Rgb,
) -> Rgb {
    if map.is_empty() {
        return Rgb::BLACK;
    }
    map.tree().nearest_where(at.p, max_r2, nbrs, |ph| {
        ph.flags & skip_flags == 0
            && if at.two_sided {
                ph.normal().dot(at.n).abs() > NORMAL_COS
            } else {
                ph.wi().dot(at.n) > 0.0 && ph.normal().dot(at.n) > NORMAL_COS
            }
    });
    if nbrs.is_empty() {
        return Rgb::BLACK;
    }
    // With k photons found the radius is the k-th distance; otherwise the search
    // radius bounded the region.
    let full = nbrs.is_full() && nbrs.k() > 1;
    let r2 = if full { nbrs.max_d2() } else { max_r2 };
    if r2.is_nan() || r2 <= 0.0 {
        return Rgb::BLACK;
    }
    let farthest = nbrs.farthest();
    let mut sum = Rgb::BLACK;
    for (i, d2) in nbrs.iter() {
        let w = match kernel {
            // The boundary photon defines r: counting it would bias by k/(k−1).
            Kernel::Disc if full && Some(i) == farthest => continue,
            Kernel::Disc => 1.0,
            Kernel::Cone => 1.0 - (d2 / r2).sqrt(),
            Kernel::Epanechnikov => 1.0 - d2 / r2,
        };
        let ph = map.tree().get(i);
        sum += f(ph.wi()) * map.power(ph) * w;
    }
    let norm = match kernel {
        Kernel::Disc => 1.0,
        // ∫ over the disc of (1 − d/r) dA = πr²/3 (Jensen 2001, eq. 7.8 with k = 1).
        Kernel::Cone => 1.0 / 3.0,
        // ∫ over the disc of (1 − d²/r²) dA = πr²/2.
        Kernel::Epanechnikov => 0.5,
    };
    sum * (1.0 / (norm * PI * r2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;

    /// Photons of equal power spread uniformly over a plane: the estimate of irradiance
    /// (f = 1) converges to the density for every kernel.
    #[test]
    fn kernels_are_normalised_for_a_uniform_density() {
        let mut rng = Pcg32::new(5, 6);
        let side = 100.0f32;
        let n = 400_000;
        let raw: Vec<RawPhoton> = (0..n)
            .map(|_| RawPhoton {
                p: Vec3::new(rng.uniform() * side, 0.0, rng.uniform() * side),
                power: Rgb::splat(1.0),
                wi: Vec3::Y,
                n: Vec3::Y,
                bounces: 1,
                flags: 0,
            })
            .collect();
        let map = PhotonMap::build(raw);
        let density = n as f32 / (side * side);
        for kernel in [Kernel::Disc, Kernel::Cone, Kernel::Epanechnikov] {
            let mut nbrs = Neighbors::new(200);
            let mut sum = 0.0f64;
            let queries = 400;
            for _ in 0..queries {
                let p = Vec3::new(
                    20.0 + rng.uniform() * 60.0,
                    0.0,
                    20.0 + rng.uniform() * 60.0,
                );
                let at = EstimatePoint {
                    p,
                    n: Vec3::Y,
                    two_sided: false,
                };
                sum += radiance_estimate(&map, &at, 100.0, kernel, 0, &mut nbrs, |_| Rgb::WHITE).g
                    as f64;
            }
            let mean = sum / queries as f64;
            // Each estimate has relative noise ~1/sqrt(k) = 7 %; the mean of 400 partly
            // overlapping estimates is good to ~1 %; 2.5 % leaves room.
            assert!(
                (mean / density as f64 - 1.0).abs() < 0.025,
                "{kernel:?}: {mean} vs {density}"
            );
        }
    }

    #[test]
    fn photons_from_behind_or_other_surfaces_do_not_count() {
        let raw = vec![
            RawPhoton {
                p: Vec3::ZERO,
                power: Rgb::WHITE,
                wi: -Vec3::Y,
                n: -Vec3::Y,
                bounces: 1,
                flags: 0,
            },
            RawPhoton {
                p: Vec3::X * 0.1,
                power: Rgb::WHITE,
                wi: Vec3::X,
                n: Vec3::X,
                bounces: 1,
                flags: 0,
            },
        ];
        let map = PhotonMap::build(raw);
        let mut nbrs = Neighbors::new(10);
        let at = EstimatePoint {
            p: Vec3::ZERO,
            n: Vec3::Y,
            two_sided: false,
        };
        assert_eq!(
            radiance_estimate(&map, &at, 1.0, Kernel::Disc, 0, &mut nbrs, |_| Rgb::WHITE),
            Rgb::BLACK
        );
    }
}
