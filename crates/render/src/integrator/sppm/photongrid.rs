//! The photons of one SPPM pass in a spatial hash grid, looked up from the visible
//! points: each pixel sums the photons inside its own radius, so the sums run in
//! parallel over pixels, need no shared writes, and add in photon order — the same
//! numbers at any thread count. This is the gather direction of the original
//! progressive photon mapping (Hachisuka, Ogaki & Jensen 2008, §4: photons are looked
//! up around each hit point); the hashing of integer cell coordinates follows
//! Teschner et al., "Optimized Spatial Hashing for Collision Detection of Deformable
//! Objects", VMV 2003.
//!
//! Cells are as wide as the largest radius, so a query sphere overlaps at most
//! 3 × 3 × 3 cells. A bucket may hold several cells (hash collisions); a query visits
//! each distinct bucket once and the distance test discards the strangers. Buckets
//! are stored flat (a prefix-sum table and one array), filled in photon order.

use glam::{IVec3, Vec3};
use rayon::prelude::*;

use crate::geometry::Aabb;
use radiant_math::color::Rgb;
use radiant_math::hash::mix64;

/// A photon arriving at a non-specular surface.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Deposit {
    pub p: [f32; 3],
    /// Unit direction towards where the photon came from.
    pub wi: [f32; 3],
    pub power: Rgb,
}

/// Photons by grid cell.
#[derive(Clone, Debug, Default)]
pub struct PhotonGrid {
    bounds: Aabb,
    inv_cell: f32,
    /// Bucket `b` holds `photons[starts[b] .. starts[b + 1]]`.
    starts: Vec<u32>,
    /// The photons' positions apart from the rest: most candidates fail the distance
    /// test, and that test then streams 12 bytes a photon, not 36.
    positions: Vec<[f32; 3]>,
    photons: Vec<Deposit>,
    mask: u64,
}

impl PhotonGrid {
    /// Builds the grid for queries of radius at most `max_radius`.
    pub fn build(deposits: Vec<Deposit>, max_radius: f32) -> PhotonGrid {
        if deposits.is_empty() || !(max_radius > 0.0 && max_radius.is_finite()) {
            return PhotonGrid::default();
        }
        let bounds = deposits
            .par_iter()
            .map(|d| Aabb::new(Vec3::from_array(d.p), Vec3::from_array(d.p)))
            .reduce(|| Aabb::EMPTY, |a, b| a.union(&b));
        let table = deposits.len().next_power_of_two();
        let mut grid = PhotonGrid {
            bounds,
            // A little wider than the largest radius: a sphere then spans at most 3 cells
            // per axis despite round-off.
            inv_cell: 1.0 / (max_radius * 1.001),
            starts: vec![0; table + 1],
            positions: Vec::new(),
            photons: Vec::new(),
            mask: table as u64 - 1,
        };
        let buckets: Vec<u32> = deposits
            .par_iter()
            .map(|d| grid.hash(grid.cell(Vec3::from_array(d.p))))
            .collect();
        for &b in &buckets {
            grid.starts[b as usize + 1] += 1;
        }
        for b in 0..table {
            grid.starts[b + 1] += grid.starts[b];
        }
        let mut cursor = grid.starts.clone();
        grid.photons = vec![Deposit::default(); deposits.len()];
        grid.positions = vec![[0.0; 3]; deposits.len()];
        for (d, &b) in deposits.iter().zip(&buckets) {
            let c = &mut cursor[b as usize];
            grid.photons[*c as usize] = *d;
            grid.positions[*c as usize] = d.p;
            *c += 1;
        }
        grid
    }

    /// Number of photons in the grid.
    pub fn len(&self) -> usize {
        self.photons.len()
    }

    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    fn cell(&self, p: Vec3) -> IVec3 {
        ((p - self.bounds.min) * self.inv_cell).floor().as_ivec3()
    }

    fn hash(&self, c: IVec3) -> u32 {
        let key = (c.x as u32 as u64) ^ ((c.y as u32 as u64) << 21) ^ ((c.z as u32 as u64) << 42);
        (mix64(key) & self.mask) as u32
    }

    /// Calls `visit` with every photon closer to `p` than √`r2`, in bucket order and,
    /// within a bucket, in photon order. A radius above the one the grid was built for
    /// is served too, over more cells.
    pub fn for_each_within(&self, p: Vec3, r2: f32, mut visit: impl FnMut(&Deposit)) {
        if self.photons.is_empty() || r2.is_nan() || r2 <= 0.0 {
            return;
        }
        let reach = Vec3::splat(r2.sqrt());
        if (p + reach).cmplt(self.bounds.min).any() || (p - reach).cmpgt(self.bounds.max).any() {
            return;
        }
        let lo = self.cell(p - reach);
        let hi = self.cell(p + reach);
        let mut small = [0u32; 27];
        let mut large = Vec::new();
        let list: &mut [u32] = if (hi - lo).cmple(IVec3::splat(2)).all() {
            let mut k = 0;
            for z in lo.z..=hi.z {
                for y in lo.y..=hi.y {
                    for x in lo.x..=hi.x {
                        small[k] = self.hash(IVec3::new(x, y, z));
                        k += 1;
                    }
                }
            }
            &mut small[..k]
        } else {
            for z in lo.z..=hi.z {
                for y in lo.y..=hi.y {
                    for x in lo.x..=hi.x {
                        large.push(self.hash(IVec3::new(x, y, z)));
                    }
                }
            }
            &mut large
        };
        // A bucket shared by two of the cells is visited once, or its photons would
        // count twice.
        list.sort_unstable();
        for (i, &b) in list.iter().enumerate() {
            if i > 0 && list[i - 1] == b {
                continue;
            }
            let range = self.starts[b as usize] as usize..self.starts[b as usize + 1] as usize;
            let first = range.start;
            for (i, q) in self.positions[range].iter().enumerate() {
                if (Vec3::from_array(*q) - p).length_squared() < r2 {
                    visit(&self.photons[first + i]);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;

    #[test]
    fn every_photon_within_the_radius_is_visited_exactly_once() {
        let mut rng = Pcg32::new(9, 1);
        let deposits: Vec<Deposit> = (0..4000)
            .map(|i| Deposit {
                p: [
                    rng.uniform() * 10.0,
                    rng.uniform() * 10.0,
                    rng.uniform() * 10.0,
                ],
                wi: [0.0, 0.0, 1.0],
                power: Rgb::splat(i as f32),
            })
            .collect();
        // Built for a smaller radius than some queries use: those span more cells.
        let grid = PhotonGrid::build(deposits.clone(), 0.3);
        assert_eq!(grid.len(), deposits.len());
        for _ in 0..3000 {
            let q = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 11.0 - 0.5;
            let r = 0.05 + rng.uniform() * 0.4;
            let mut seen = Vec::new();
            grid.for_each_within(q, r * r, |d| seen.push(d.power.r as usize));
            let mut unique = seen.clone();
            unique.sort_unstable();
            unique.dedup();
            assert_eq!(unique.len(), seen.len(), "a photon visited twice");
            let expected: Vec<usize> = (0..deposits.len())
                .filter(|&i| (Vec3::from_array(deposits[i].p) - q).length_squared() < r * r)
                .collect();
            assert_eq!(unique, expected);
        }
    }

    #[test]
    fn an_empty_grid_visits_nothing() {
        let grid = PhotonGrid::build(Vec::new(), 1.0);
        assert!(grid.is_empty());
        grid.for_each_within(Vec3::ZERO, 1.0, |_| panic!("visited"));
    }
}
