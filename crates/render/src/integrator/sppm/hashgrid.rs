//! A spatial hash grid over the visible points of an iteration (Hachisuka & Jensen
//! 2009, §4: "we use a spatial hash ... to store visible points"; hashing of integer
//! cell coordinates in the spirit of Teschner et al., "Optimized Spatial Hashing for
//! Collision Detection of Deformable Objects", VMV 2003).
//!
//! Cells are as wide as the largest radius, so each point's sphere overlaps at most
//! 3 × 3 × 3 cells and a photon looks in one bucket only. Buckets are stored flat (a
//! prefix-sum table and one entry array), built in point order — deterministic.

use glam::{IVec3, Vec3, Vec4};
use rayon::prelude::*;

use crate::geometry::Aabb;
use radiant_math::hash::mix64;

/// An item in a bucket: its sphere (centre, squared radius) and index.
#[derive(Clone, Copy, Debug, Default)]
pub struct GridEntry {
    pub centre: [f32; 3],
    pub r2: f32,
    pub index: u32,
}

/// Visible points by grid cell.
#[derive(Clone, Debug, Default)]
pub struct HashGrid {
    bounds: Aabb,
    inv_cell: f32,
    /// Bucket `b` holds `entries[starts[b] .. starts[b + 1]]`.
    starts: Vec<u32>,
    /// Each entry carries its sphere, so that a lookup reads one bucket sequentially.
    entries: Vec<GridEntry>,
    mask: u64,
}

impl HashGrid {
    /// Builds the grid over spheres given as (centre, squared radius); a negative
    /// squared radius marks an item without a visible point this iteration.
    pub fn build(spheres: &[Vec4]) -> HashGrid {
        let (bounds, max_r, count) = spheres
            .par_iter()
            .filter(|s| s.w >= 0.0)
            .map(|s| {
                let (p, r) = (s.truncate(), s.w.sqrt());
                (Aabb::new(p - Vec3::splat(r), p + Vec3::splat(r)), r, 1usize)
            })
            .reduce(
                || (Aabb::EMPTY, 0.0f32, 0usize),
                |a, b| (a.0.union(&b.0), a.1.max(b.1), a.2 + b.2),
            );
        if count == 0 || max_r.is_nan() || max_r <= 0.0 {
            return HashGrid::default();
        }
        let table = count.next_power_of_two();
        let mut grid = HashGrid {
            bounds,
            // A little wider than the largest radius: a sphere then spans at most 3 cells
            // per axis despite round-off.
            inv_cell: 1.0 / (max_r * 1.001),
            starts: vec![0; table + 1],
            entries: Vec::new(),
            mask: table as u64 - 1,
        };
        // Hashing in parallel; counting and filling in item order (deterministic).
        let buckets: Vec<([u32; 27], u8)> = spheres
            .par_iter()
            .map(|s| {
                let mut out = [0u32; 27];
                let k = if s.w >= 0.0 {
                    grid.buckets_of(s.truncate(), s.w.sqrt(), &mut out).len()
                } else {
                    0
                };
                (out, k as u8)
            })
            .collect();
        for (list, k) in &buckets {
            for &b in &list[..*k as usize] {
                grid.starts[b as usize + 1] += 1;
            }
        }
        for b in 0..table {
            grid.starts[b + 1] += grid.starts[b];
        }
        let mut cursor = grid.starts.clone();
        grid.entries = vec![GridEntry::default(); grid.starts[table] as usize];
        for (i, (list, k)) in buckets.iter().enumerate() {
            let s = spheres[i];
            for &b in &list[..*k as usize] {
                let c = &mut cursor[b as usize];
                grid.entries[*c as usize] = GridEntry {
                    centre: s.truncate().to_array(),
                    r2: s.w,
                    index: i as u32,
                };
                *c += 1;
            }
        }
        grid
    }

    fn cell(&self, p: Vec3) -> IVec3 {
        ((p - self.bounds.min) * self.inv_cell).floor().as_ivec3()
    }

    fn hash(&self, c: IVec3) -> u32 {
        let key = (c.x as u32 as u64) ^ ((c.y as u32 as u64) << 21) ^ ((c.z as u32 as u64) << 42);
        (mix64(key) & self.mask) as u32
    }

    /// The distinct buckets of the cells a sphere overlaps (a point whose cells share a
    /// bucket must be listed there once, or photons would count twice).
    fn buckets_of<'a>(&self, p: Vec3, r: f32, out: &'a mut [u32; 27]) -> &'a [u32] {
        let lo = self.cell(p - Vec3::splat(r));
        let hi = self.cell(p + Vec3::splat(r)).min(lo + IVec3::splat(2));
        let mut k = 0;
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    out[k] = self.hash(IVec3::new(x, y, z));
                    k += 1;
                }
            }
        }
        let list = &mut out[..k];
        list.sort_unstable();
        let mut unique = 0;
        for i in 0..k {
            if i == 0 || list[i] != list[unique - 1] {
                list[unique] = list[i];
                unique += 1;
            }
        }
        &out[..unique]
    }

    /// Items whose sphere may contain `p` (a superset; callers test the distance).
    pub fn candidates(&self, p: Vec3) -> &[GridEntry] {
        if self.entries.is_empty() || !inside(&self.bounds, p) {
            return &[];
        }
        let b = self.hash(self.cell(p)) as usize;
        &self.entries[self.starts[b] as usize..self.starts[b + 1] as usize]
    }
}

fn inside(b: &Aabb, p: Vec3) -> bool {
    p.cmpge(b.min).all() && p.cmple(b.max).all()
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;

    #[test]
    fn every_containing_sphere_is_a_candidate_exactly_once() {
        let mut rng = Pcg32::new(9, 1);
        let items: Vec<(Vec3, f32)> = (0..2000)
            .map(|_| {
                let p = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 10.0;
                (p, 0.05 + rng.uniform() * 0.4)
            })
            .collect();
        let spheres: Vec<Vec4> = items
            .iter()
            .enumerate()
            .map(|(i, &(p, r))| {
                if i % 7 != 3 {
                    p.extend(r * r)
                } else {
                    Vec4::new(0.0, 0.0, 0.0, -1.0)
                }
            })
            .collect();
        let grid = HashGrid::build(&spheres);
        for _ in 0..5000 {
            let q = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 10.0;
            let found = grid.candidates(q);
            let mut seen = std::collections::HashSet::new();
            for e in found {
                assert!(seen.insert(e.index), "item {} listed twice", e.index);
                assert_eq!(
                    spheres[e.index as usize],
                    Vec3::from_array(e.centre).extend(e.r2)
                );
            }
            for (i, &(p, r)) in items.iter().enumerate() {
                if i % 7 != 3 && (p - q).length_squared() < r * r {
                    assert!(seen.contains(&(i as u32)), "item {i} missing");
                }
            }
        }
    }
}
