//! Precomputed irradiance for final gathering (Christensen, "Faster Photon Map Global
//! Illumination", JGT 4(3), 1999): irradiance is estimated once at every fourth photon
//! of the global map, from the global and caustic maps; a gather ray then reads the
//! nearest precomputed point whose normal agrees instead of running a k-nearest
//! estimate of hundreds of photons. Irradiance rather than radiance is stored, so the
//! reflectance at the gather ray's hit applies.

use glam::Vec3;
use rayon::prelude::*;

use super::estimate::{EstimatePoint, PhotonMap, PhotonSearch, radiance_estimate};
use super::kdtree::{self, KdPoint, KdTree, Neighbors};
use super::record::{oct_cos_exceeds, oct_encode};
use super::settings::Kernel;
use radiant_math::color::Rgb;

/// Every `STRIDE`-th global photon carries a precomputed estimate (Christensen uses 4).
pub const STRIDE: usize = 4;

/// The normal of a precomputed point must lie within ~25° of the query's.
const NORMAL_COS: f32 = 0.9;

/// A point with its irradiance (the photons' flux per area arriving on the side of `n`).
#[derive(Clone, Copy, Debug)]
pub struct IrradiancePoint {
    p: [f32; 3],
    n: [u16; 2],
    e: [f32; 3],
}

impl KdPoint for IrradiancePoint {
    #[inline]
    fn position(&self) -> Vec3 {
        Vec3::from_array(self.p)
    }
}

/// The precomputed irradiance points in a kd-tree.
#[derive(Clone, Debug, Default)]
pub struct IrradianceCache {
    tree: KdTree<IrradiancePoint>,
}

impl IrradianceCache {
    /// Estimates irradiance at every [`STRIDE`]-th photon of `global` from both maps
    /// (`global_k` and `caustic_k` nearest photons within `max_r2`).
    pub fn build(
        global: &PhotonMap,
        caustic: &PhotonMap,
        global_k: u32,
        caustic_k: u32,
        max_r2: f32,
        kernel: Kernel,
    ) -> IrradianceCache {
        IrradianceCache::build_until(
            global,
            caustic,
            global_k,
            caustic_k,
            max_r2,
            kernel,
            &|| false,
        )
        .expect("never stopped")
    }

    /// [`IrradianceCache::build`], giving up (`None`) once `stop` holds; asked once per
    /// chunk of photons (a few thousand estimates, about a millisecond of work).
    pub fn build_until(
        global: &PhotonMap,
        caustic: &PhotonMap,
        global_k: u32,
        caustic_k: u32,
        max_r2: f32,
        kernel: Kernel,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Option<IrradianceCache> {
        let photons = global.photons();
        let search = PhotonSearch {
            max_r2,
            kernel,
            skip_flags: 0,
        };
        let points: Vec<IrradiancePoint> = photons
            .par_chunks(256 * STRIDE)
            .flat_map_iter(|chunk| {
                if stop() {
                    return Vec::new();
                }
                let mut g = Neighbors::new(global_k as usize);
                let mut c = Neighbors::new(caustic_k as usize);
                chunk
                    .iter()
                    .step_by(STRIDE)
                    .map(|ph| {
                        let at = EstimatePoint {
                            p: ph.position(),
                            n: ph.normal(),
                            two_sided: false,
                        };
                        let one = |_| Rgb::WHITE;
                        let e = radiance_estimate(global, &at, search, &mut g, one)
                            + radiance_estimate(caustic, &at, search, &mut c, one);
                        IrradiancePoint {
                            p: ph.p,
                            n: oct_encode(at.n),
                            e: e.to_array(),
                        }
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        if stop() {
            kdtree::release(points);
            return None;
        }
        Some(IrradianceCache {
            tree: KdTree::build_until(points, stop)?,
        })
    }

    /// Number of precomputed points.
    pub fn len(&self) -> usize {
        self.tree.len()
    }

    /// True when no point was precomputed.
    pub fn is_empty(&self) -> bool {
        self.tree.is_empty()
    }

    /// Irradiance at the nearest precomputed point within `max_r2` whose normal agrees
    /// with `at.n`; `nbrs` must ask for one neighbour.
    pub fn lookup(&self, at: &EstimatePoint, max_r2: f32, nbrs: &mut Neighbors) -> Option<Rgb> {
        self.tree.nearest_where(at.p, max_r2, nbrs, |pt| {
            oct_cos_exceeds(pt.n, at.n, NORMAL_COS, false)
        });
        let (i, _) = nbrs.iter().next()?;
        Some(Rgb::from_array(self.tree.get(i).e))
    }
}
