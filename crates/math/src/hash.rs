//! Integer hashing and a small counter-based generator.
//!
//! Every random number in radiant is a pure function of (pixel, sample index,
//! dimension, seed), never of the thread or of time, so images are bit-identical at
//! any thread count. These hashes provide that mapping.

/// A strong 64-bit mixer (the finaliser of MurmurHash3 / SplitMix64 variant by Stafford, "Mix13").
#[inline]
pub fn mix64(mut v: u64) -> u64 {
    v ^= v >> 31;
    v = v.wrapping_mul(0x7fb5_d329_728e_a185);
    v ^= v >> 27;
    v = v.wrapping_mul(0x81da_def4_bc2d_d44d);
    v ^= v >> 33;
    v
}

/// Hashes a list of integers into one 64-bit value.
#[inline]
pub fn hash_u64s(values: &[u64]) -> u64 {
    let mut h = 0x9e37_79b9_7f4a_7c15u64;
    for &v in values {
        h = mix64(h ^ v.wrapping_add(0x9e37_79b9_7f4a_7c15).wrapping_add(h << 6));
    }
    h
}

/// Maps the top 24 bits of a hash to a float in [0, 1).
#[inline]
pub fn u32_to_unit_f32(v: u32) -> f32 {
    (v >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// A PCG32 generator (O'Neill 2014). Used where a sequential stream is natural
/// (photon tracing, tests); it is always seeded from a hash of the work item, never
/// from OS entropy.
#[derive(Clone, Debug)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
}

impl Pcg32 {
    pub fn new(seed: u64, stream: u64) -> Pcg32 {
        let mut rng = Pcg32 {
            state: 0,
            inc: (stream << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform float in [0, 1).
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        u32_to_unit_f32(self.next_u32())
    }

    /// Uniform f64 in [0, 1) with 53 random bits.
    pub fn uniform_f64(&mut self) -> f64 {
        let hi = (self.next_u32() as u64) << 21;
        let lo = (self.next_u32() >> 11) as u64;
        (hi | lo) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pcg_uniform_is_in_unit_interval_and_reproducible() {
        let mut a = Pcg32::new(7, 3);
        let mut b = Pcg32::new(7, 3);
        let mut sum = 0.0;
        for _ in 0..10_000 {
            let x = a.uniform();
            assert_eq!(x, b.uniform());
            assert!((0.0..1.0).contains(&x));
            sum += x as f64;
        }
        assert!((sum / 10_000.0 - 0.5).abs() < 0.02);
    }
}
