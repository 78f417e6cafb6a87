//! Perlin's gradient noise (Perlin 1985; the quintic fade and the twelve cube-edge
//! gradients of "Improving Noise", SIGGRAPH 2002) and the sums built from it: fractional
//! Brownian motion and turbulence, with the octave count limited by the footprint of the
//! lookup so that frequencies above the sampling rate are left out (Ebert et al.,
//! *Texturing and Modeling*, ch. 2).
//!
//! The permutation is a fixed shuffle made here from a seeded generator; any fixed
//! permutation gives noise with the same statistics.

use std::sync::OnceLock;

use glam::Vec3;
use radiant_math::hash::Pcg32;

const PERIOD: usize = 256;

fn permutation() -> &'static [u8; 2 * PERIOD] {
    static TABLE: OnceLock<[u8; 2 * PERIOD]> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut p: [u8; PERIOD] = std::array::from_fn(|i| i as u8);
        let mut rng = Pcg32::new(0x5eed_7e57, 7);
        for i in (1..PERIOD).rev() {
            let j = (rng.next_u32() as usize) % (i + 1);
            p.swap(i, j);
        }
        std::array::from_fn(|i| p[i % PERIOD])
    })
}

/// Dot product of the lattice gradient chosen by `hash` with the offset (x, y, z): one
/// of the twelve directions to the midpoints of a cube's edges (four repeated to make
/// sixteen), which avoids the clumping of random gradients.
fn grad(hash: u8, x: f32, y: f32, z: f32) -> f32 {
    let h = hash & 15;
    let u = if h < 8 { x } else { y };
    let v = if h < 4 {
        y
    } else if h == 12 || h == 14 {
        x
    } else {
        z
    };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

/// 6t⁵ − 15t⁴ + 10t³: zero first and second derivatives at the lattice.
fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

fn lerp(t: f32, a: f32, b: f32) -> f32 {
    a + t * (b - a)
}

/// Gradient noise at `p`: zero at every integer lattice point, within [−1, 1].
pub fn noise(p: Vec3) -> f32 {
    let perm = permutation();
    let cell = p.floor();
    let f = p - cell;
    // Wrap the lattice period; rem_euclid keeps negative cells in range.
    let [ix, iy, iz] = cell
        .to_array()
        .map(|c| (c as i64).rem_euclid(PERIOD as i64) as usize);
    let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
    let a = perm[ix] as usize + iy;
    let aa = perm[a] as usize + iz;
    let ab = perm[a + 1] as usize + iz;
    let b = perm[ix + 1] as usize + iy;
    let ba = perm[b] as usize + iz;
    let bb = perm[b + 1] as usize + iz;
    let (x, y, z) = (f.x, f.y, f.z);
    let n = lerp(
        w,
        lerp(
            v,
            lerp(u, grad(perm[aa], x, y, z), grad(perm[ba], x - 1.0, y, z)),
            lerp(
                u,
                grad(perm[ab], x, y - 1.0, z),
                grad(perm[bb], x - 1.0, y - 1.0, z),
            ),
        ),
        lerp(
            v,
            lerp(
                u,
                grad(perm[aa + 1], x, y, z - 1.0),
                grad(perm[ba + 1], x - 1.0, y, z - 1.0),
            ),
            lerp(
                u,
                grad(perm[ab + 1], x, y - 1.0, z - 1.0),
                grad(perm[bb + 1], x - 1.0, y - 1.0, z - 1.0),
            ),
        ),
    );
    n.clamp(-1.0, 1.0)
}

/// How many octaves the footprint (`dpdx`, `dpdy`) resolves, with the fractional part
/// of the last: octave i has wavelength 2⁻ⁱ, and one below half the footprint's width
/// would alias.
fn octave_budget(dpdx: Vec3, dpdy: Vec3, octaves: u32) -> f32 {
    let len2 = dpdx.length_squared().max(dpdy.length_squared());
    if len2 <= 0.0 || !len2.is_finite() {
        return octaves as f32;
    }
    (-1.0 - 0.5 * len2.log2()).clamp(0.0, octaves as f32)
}

/// Fractional Brownian motion: Σ ωⁱ noise(2ⁱ p), ω = `roughness`.
pub fn fbm(p: Vec3, dpdx: Vec3, dpdy: Vec3, roughness: f32, octaves: u32) -> f32 {
    octave_sum(p, dpdx, dpdy, roughness, octaves, noise)
}

/// Turbulence: Σ ωⁱ |noise(2ⁱ p)|.
pub fn turbulence(p: Vec3, dpdx: Vec3, dpdy: Vec3, roughness: f32, octaves: u32) -> f32 {
    octave_sum(p, dpdx, dpdy, roughness, octaves, |q| noise(q).abs())
}

fn octave_sum(
    p: Vec3,
    dpdx: Vec3,
    dpdy: Vec3,
    roughness: f32,
    octaves: u32,
    f: impl Fn(Vec3) -> f32,
) -> f32 {
    let budget = octave_budget(dpdx, dpdy, octaves);
    let full = budget.floor() as u32;
    let (mut sum, mut lambda, mut omega) = (0.0, 1.0, 1.0);
    for _ in 0..full {
        sum += omega * f(lambda * p);
        lambda *= 2.0;
        omega *= roughness;
    }
    // The partly resolved octave fades in rather than popping.
    let part = budget - full as f32;
    if part > 0.0 {
        sum += part * omega * f(lambda * p);
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_at_lattice_points_and_bounded() {
        for x in -4..4 {
            for y in -4..4 {
                for z in -3..3 {
                    let n = noise(Vec3::new(x as f32, y as f32, z as f32));
                    assert_eq!(n, 0.0, "({x}, {y}, {z})");
                }
            }
        }
        let mut rng = Pcg32::new(1, 2);
        let (mut lo, mut hi, mut sum) = (f32::MAX, f32::MIN, 0.0f64);
        let n = 100_000;
        for _ in 0..n {
            let p = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 40.0 - 20.0;
            let v = noise(p);
            lo = lo.min(v);
            hi = hi.max(v);
            sum += v as f64;
        }
        assert!((-1.0..=1.0).contains(&lo) && (-1.0..=1.0).contains(&hi));
        // Not degenerate: it spans a good part of its range, and averages near zero.
        assert!(hi - lo > 1.0, "range [{lo}, {hi}]");
        assert!((sum / n as f64).abs() < 0.02, "mean {}", sum / n as f64);
    }

    #[test]
    fn wide_footprints_drop_octaves() {
        let p = Vec3::new(0.3, 0.7, 0.1);
        let fine = fbm(p, Vec3::ZERO, Vec3::ZERO, 0.5, 8);
        // A footprint wider than the first wavelength leaves nothing to sum.
        assert_eq!(fbm(p, Vec3::X * 4.0, Vec3::Y * 4.0, 0.5, 8), 0.0);
        assert_eq!(fine, fbm(p, Vec3::X * 1e-6, Vec3::ZERO, 0.5, 8));
    }
}
