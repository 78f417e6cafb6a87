//! Jittered stratified sampling: a pixel's n samples fall one per stratum of [0,1)
//! (1D: n strata) or of an x × y grid (2D), jittered within it (Cook, Porter &
//! Carpenter 1984, "Distributed ray tracing"). Each dimension visits its strata in its
//! own random order, drawn per pixel, so dimensions are not correlated (the "padding" of
//! PBR's stratified sampler). Sample indices past n start a new round over the strata
//! with a fresh order, so any sample count stays unbiased.

use glam::Vec2;
use radiant_math::ONE_MINUS_EPSILON;
use radiant_math::hash::{mix64, u32_to_unit_f32};

/// Sample `index`'s 1D value among `n` strata, the order drawn from `key`.
pub fn stratified_1d(index: u32, n: u32, jitter: bool, key: u64) -> f32 {
    let (stratum, key) = stratum(index, n, key);
    let offset = if jitter {
        u32_to_unit_f32(mix64(key ^ index as u64) as u32)
    } else {
        0.5
    };
    ((stratum as f32 + offset) / n as f32).min(ONE_MINUS_EPSILON)
}

/// Sample `index`'s 2D value in an `x` × `y` grid of strata.
pub fn stratified_2d(index: u32, x: u32, y: u32, jitter: bool, key: u64) -> Vec2 {
    let (stratum, key) = stratum(index, x * y, key);
    let (sx, sy) = (stratum % x, stratum / x);
    let (ox, oy) = if jitter {
        let h = mix64(key ^ index as u64);
        (u32_to_unit_f32(h as u32), u32_to_unit_f32((h >> 32) as u32))
    } else {
        (0.5, 0.5)
    };
    Vec2::new(
        ((sx as f32 + ox) / x as f32).min(ONE_MINUS_EPSILON),
        ((sy as f32 + oy) / y as f32).min(ONE_MINUS_EPSILON),
    )
}

/// The stratum of sample `index` and the key of its round: round r = index / n visits
/// the n strata in the order of a permutation drawn from (key, r).
fn stratum(index: u32, n: u32, key: u64) -> (u32, u64) {
    let round_key = mix64(key ^ (index / n) as u64);
    (permute(index % n, n, round_key), round_key)
}

/// A bijection of [0, n) drawn from `key`, uniformly distributed over keys for each i:
/// an invertible hash of the smallest power-of-two range holding n (xor-shifts and odd
/// multiplications modulo 2^k are each invertible), walked along its cycle until it
/// lands below n — fewer than two steps on average, since n exceeds half the range —
/// then rotated by a random offset. The cycle walk is Kensler's idea (2013, "Correlated
/// Multi-Jittered Sampling"); this hash is our own.
pub fn permute(i: u32, n: u32, key: u64) -> u32 {
    if n <= 1 {
        return 0;
    }
    let bits = 32 - (n - 1).leading_zeros();
    let mask = if bits == 32 {
        u32::MAX
    } else {
        (1u32 << bits) - 1
    };
    let (k0, k1) = (key as u32, (key >> 32) as u32);
    let mut v = i;
    loop {
        v ^= k0;
        v = v.wrapping_mul(0x9e37_79b1 | 1) & mask;
        v ^= v >> (bits / 2 + 1);
        v = v.wrapping_add(k1) & mask;
        v = v.wrapping_mul(0x85eb_ca6b | 1) & mask;
        v ^= v >> (bits / 3 + 1);
        v = (v ^ k1.rotate_left(7)) & mask;
        if v < n {
            // The walk alone is a bijection but not uniform over keys for a fixed i;
            // a rotation by a uniform offset makes every stratum equally likely.
            return ((v as u64 + mix64(key) % n as u64) % n as u64) as u32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permutations_are_bijections() {
        for n in [1u32, 2, 3, 5, 16, 17, 100, 1000, 4097] {
            for key in [0u64, 1, 0xdead_beef_1234_5678] {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let p = permute(i, n, key) as usize;
                    assert!(!seen[p], "n {n} key {key}");
                    seen[p] = true;
                }
            }
        }
    }

    /// For a fixed element, the image is uniform over keys (chi-square, n bins): without it the sampler would be biased.
    #[test]
    fn a_fixed_element_lands_uniformly() {
        for (i, n) in [(3u32, 7u32), (0, 5), (6, 7), (12, 13)] {
            let mut counts = vec![0u32; n as usize];
            let keys = 700 * n as u64;
            for key in 0..keys {
                counts[permute(i, n, mix64(key)) as usize] += 1;
            }
            let chi2: f64 = counts
                .iter()
                .map(|&o| (o as f64 - 700.0).powi(2) / 700.0)
                .sum();
            // The 0.999 quantiles for n - 1 degrees of freedom.
            let quantile = match n {
                5 => 18.5,
                7 => 22.5,
                _ => 32.9,
            };
            assert!(chi2 < quantile, "i {i} n {n}: {chi2}");
        }
    }

    #[test]
    fn permutations_differ_between_keys() {
        let order = |key| (0..16).map(|i| permute(i, 16, key)).collect::<Vec<_>>();
        assert_ne!(order(1), order(2));
        assert_ne!(order(1), (0..16).collect::<Vec<_>>());
    }

    #[test]
    fn each_round_puts_one_sample_in_each_stratum() {
        for jitter in [true, false] {
            let (x, y) = (4u32, 3u32);
            for round in 0..3 {
                let mut seen = [false; 12];
                for i in round * 12..(round + 1) * 12 {
                    let p = stratified_2d(i, x, y, jitter, 77);
                    let cell = (p.y * y as f32) as usize * x as usize + (p.x * x as f32) as usize;
                    assert!(!seen[cell]);
                    seen[cell] = true;
                    let q = stratified_1d(i, 12, jitter, 78);
                    assert!((0.0..1.0).contains(&q));
                }
            }
        }
    }

    /// Over keys, a stratified value is uniform: chi-square over 24 bins (4000 keys,
    /// 23 degrees of freedom, the 0.999 quantile is 49.7).
    #[test]
    fn stratified_values_are_uniform_over_keys() {
        for (index, n) in [(0u32, 16u32), (5, 16), (20, 16), (3, 7)] {
            let mut bins = [0u32; 24];
            let keys = 4000;
            for key in 0..keys {
                let v = stratified_1d(index, n, true, mix64(key));
                bins[(v * 24.0) as usize] += 1;
            }
            let e = keys as f64 / 24.0;
            let chi2: f64 = bins.iter().map(|&o| (o as f64 - e).powi(2) / e).sum();
            assert!(chi2 < 49.7, "index {index} n {n}: {chi2}");
        }
    }
}
