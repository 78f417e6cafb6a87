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
use radiant_math::sampling::SystematicDraw;

/// A photon's surface must face within ~45° of the query's to count.
const NORMAL_COS: f32 = 0.7;

/// The photons for which the photon mapper's estimate on a layered surface evaluates
/// the BSDF, in each map ([`radiance_estimate_sampled`]). Chosen by time to error on a
/// Cornell box of varnished walls (docs/speed.md): from all of them (about 250) to 4,
/// the photon mapper's CPU time falls 5.4× and its error rises 0.5 %; 1 saves little
/// more.
pub const ESTIMATED_EVALS: usize = 4;

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

/// Which photons an estimate gathers and how it weights them.
#[derive(Clone, Copy, Debug)]
pub struct PhotonSearch {
    /// The largest squared radius searched (squared scene units).
    pub max_r2: f32,
    pub kernel: Kernel,
    /// Photons whose flags share a bit with these are left out.
    pub skip_flags: u8,
}

/// Reflected radiance at `at` from `map`: the `nbrs.k()` nearest photons that `search`
/// admits; `f(wi)` is the BSDF for the photon's incoming direction `wi` (world space).
pub fn radiance_estimate(
    map: &PhotonMap,
    at: &EstimatePoint,
    search: PhotonSearch,
    nbrs: &mut Neighbors,
    f: impl Fn(Vec3) -> Rgb,
) -> Rgb {
    match Disc::find(map, at, search, nbrs) {
        Some(disc) => disc.sum(map, nbrs, f),
        None => Rgb::BLACK,
    }
}

/// [`radiance_estimate`] with the BSDF evaluated for at most `evals` of the photons
/// (all of them where they are no more), for BSDFs whose evaluation is itself a Monte
/// Carlo estimate (layered random walks) and costly. The photons are drawn by
/// systematic sampling along their kernel-weighted powers from the one number `u`
/// ([`SystematicDraw`]) and reweighted. The estimate
/// stays unbiased over `u`; what it adds is the variation of f across the photons'
/// directions, of the order of the walks' own noise for the broad BSDFs this serves.
pub fn radiance_estimate_sampled(
    map: &PhotonMap,
    at: &EstimatePoint,
    search: PhotonSearch,
    nbrs: &mut Neighbors,
    evals: usize,
    u: f32,
    f: impl Fn(Vec3) -> Rgb,
) -> Rgb {
    let Some(disc) = Disc::find(map, at, search, nbrs) else {
        return Rgb::BLACK;
    };
    let share = |i: u32, d2: f32| {
        let w = disc.weight(i, d2)?;
        let ph = map.tree().get(i);
        let power = map.power(ph);
        let q = w * (power.r + power.g + power.b);
        (q > 0.0).then_some((ph, power * w, q))
    };
    let (mut total, mut count) = (0.0f32, 0usize);
    for (_, _, q) in nbrs.iter().filter_map(|(i, d2)| share(i, d2)) {
        total += q;
        count += 1;
    }
    if total <= 0.0 || !total.is_finite() {
        return Rgb::BLACK;
    }
    if count <= evals {
        return disc.sum(map, nbrs, f);
    }
    let mut draw = SystematicDraw::new(total, evals, u);
    let mut sum = Rgb::BLACK;
    for (ph, weighted_power, q) in nbrs.iter().filter_map(|(i, d2)| share(i, d2)) {
        let reweight = draw.reweight(q);
        if reweight > 0.0 {
            sum += f(ph.wi()) * weighted_power * reweight;
        }
    }
    sum * disc.scale
}

/// The photons of an estimate's disc, found: its radius and the kernel's weights.
struct Disc {
    kernel: Kernel,
    r2: f32,
    /// The k-th photon, which sets the radius, when k were found.
    boundary: Option<u32>,
    /// 1 / (the kernel's integral over the disc).
    scale: f32,
}

impl Disc {
    /// Finds the photons into `nbrs`; `None` where there are none.
    fn find(
        map: &PhotonMap,
        at: &EstimatePoint,
        search: PhotonSearch,
        nbrs: &mut Neighbors,
    ) -> Option<Disc> {
        if map.is_empty() {
            return None;
        }
        let PhotonSearch {
            max_r2,
            kernel,
            skip_flags,
        } = search;
        map.tree().nearest_where(at.p, max_r2, nbrs, |ph| {
            ph.flags & skip_flags == 0
                && (at.two_sided || ph.arrives_from_side_of(at.n))
                && ph.normal_within(at.n, NORMAL_COS, at.two_sided)
        });
        if nbrs.is_empty() {
            return None;
        }
        // With k photons found the radius is the k-th distance; otherwise the search
        // radius bounded the region.
        let full = nbrs.is_full() && nbrs.k() > 1;
        let r2 = if full { nbrs.max_d2() } else { max_r2 };
        if r2.is_nan() || r2 <= 0.0 {
            return None;
        }
        let norm = match kernel {
            Kernel::Disc => 1.0,
            // ∫ over the disc of (1 − d/r) dA = πr²/3 (Jensen 2001, eq. 7.8 with k = 1).
            Kernel::Cone => 1.0 / 3.0,
            // ∫ over the disc of (1 − d²/r²) dA = πr²/2.
            Kernel::Epanechnikov => 0.5,
        };
        Some(Disc {
            kernel,
            r2,
            boundary: if full { nbrs.farthest() } else { None },
            scale: 1.0 / (norm * PI * r2),
        })
    }

    /// The estimate with the BSDF `f` evaluated for every photon found into `nbrs`.
    fn sum(&self, map: &PhotonMap, nbrs: &Neighbors, f: impl Fn(Vec3) -> Rgb) -> Rgb {
        let mut sum = Rgb::BLACK;
        for (i, d2) in nbrs.iter() {
            let Some(w) = self.weight(i, d2) else {
                continue;
            };
            let ph = map.tree().get(i);
            sum += f(ph.wi()) * map.power(ph) * w;
        }
        sum * self.scale
    }

    /// The kernel's weight of photon `i` at squared distance `d2`; `None` for the
    /// boundary photon of the disc kernel, which defines r: counting it would bias by
    /// k / (k − 1).
    #[inline(always)]
    fn weight(&self, i: u32, d2: f32) -> Option<f32> {
        Some(match self.kernel {
            Kernel::Disc if Some(i) == self.boundary => return None,
            Kernel::Disc => 1.0,
            Kernel::Cone => 1.0 - (d2 / self.r2).sqrt(),
            Kernel::Epanechnikov => 1.0 - d2 / self.r2,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;

    /// Every photon within `sqrt(max_r2)`, weighted by `kernel`.
    fn search(max_r2: f32, kernel: Kernel) -> PhotonSearch {
        PhotonSearch {
            max_r2,
            kernel,
            skip_flags: 0,
        }
    }

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
                sum += radiance_estimate(&map, &at, search(100.0, kernel), &mut nbrs, |_| {
                    Rgb::WHITE
                })
                .g as f64;
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

    /// The estimate that evaluates f for a sample of the photons is unbiased: over its
    /// number u it averages to the estimate that evaluates f for all of them, for every
    /// kernel, with photons of unequal powers and an f that varies with direction; and
    /// with as many evaluations as photons it differs from it only where the draw takes
    /// a photon twice.
    #[test]
    fn sampling_the_photons_whose_bsdf_is_evaluated_keeps_the_estimate() {
        let mut rng = Pcg32::new(11, 3);
        let raw: Vec<RawPhoton> = (0..5000)
            .map(|_| {
                let wi = Vec3::new(rng.uniform() - 0.5, 1.0, rng.uniform() - 0.5).normalize();
                RawPhoton {
                    p: Vec3::new(rng.uniform() * 10.0, 0.0, rng.uniform() * 10.0),
                    power: Rgb::new(rng.uniform(), 0.2 + rng.uniform(), 3.0 * rng.uniform()),
                    wi,
                    n: Vec3::Y,
                    bounces: 1,
                    flags: 0,
                }
            })
            .collect();
        let map = PhotonMap::build(raw);
        // Peaked towards +x, and coloured, as a glossy layered BSDF is.
        let f = |wi: Vec3| Rgb::new(1.0 + 8.0 * wi.x.max(0.0).powi(2), 0.5, 0.1 + wi.z.abs());
        let at = EstimatePoint {
            p: Vec3::new(5.0, 0.0, 5.0),
            n: Vec3::Y,
            two_sided: false,
        };
        for kernel in [Kernel::Disc, Kernel::Cone, Kernel::Epanechnikov] {
            let mut nbrs = Neighbors::new(200);
            let whole = radiance_estimate(&map, &at, search(4.0, kernel), &mut nbrs, f);
            let draws = 4096;
            let mut mean = [0.0f64; 3];
            for j in 0..draws {
                let u = (j as f32 + 0.5) / draws as f32;
                let e =
                    radiance_estimate_sampled(&map, &at, search(4.0, kernel), &mut nbrs, 16, u, f);
                for (m, c) in mean.iter_mut().zip([e.r, e.g, e.b]) {
                    *m += c as f64 / draws as f64;
                }
            }
            for (m, w) in mean.into_iter().zip([whole.r, whole.g, whole.b]) {
                assert!(
                    (m / w as f64 - 1.0).abs() < 2e-3,
                    "{kernel:?}: {mean:?} against {whole:?}"
                );
            }
            // One draw of 16 evaluations is off by the spread of f, not by orders.
            let one =
                radiance_estimate_sampled(&map, &at, search(4.0, kernel), &mut nbrs, 16, 0.3, f);
            assert!(
                (one.r / whole.r - 1.0).abs() < 0.5,
                "{one:?} against {whole:?}"
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
            radiance_estimate(&map, &at, search(1.0, Kernel::Disc), &mut nbrs, |_| {
                Rgb::WHITE
            }),
            Rgb::BLACK
        );
    }
}
