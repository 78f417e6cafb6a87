//! The first two Sobol dimensions and hash-based Owen scrambling.

/// Sobol point `index` in dimension 0 (van der Corput, base 2) or 1, as a 32-bit
/// fixed-point fraction. Dimension 1 uses the primitive polynomial x + 1, whose
/// direction numbers satisfy v_k = v_{k-1} ^ (v_{k-1} >> 1) (Sobol 1967; Joe & Kuo 2008).
pub fn sobol_u32(dim: u32, index: u32) -> u32 {
    match dim {
        0 => index.reverse_bits(),
        _ => {
            let mut v = 1u32 << 31;
            let mut result = 0u32;
            let mut i = index;
            while i != 0 {
                if i & 1 != 0 {
                    result ^= v;
                }
                v ^= v >> 1;
                i >>= 1;
            }
            result
        }
    }
}

/// Nested uniform (Owen) scrambling of a 32-bit fraction by a hash, after Laine &
/// Karras (2011) and Burley (JCGT 2020): a hash that only propagates bits upward,
/// applied to the bit-reversed value, flips each bit depending only on the bits above
/// it. The constants are N. Vegdahl's improved hash ("Building a Better LK Hash", 2021).
pub fn owen_scramble(v: u32, seed: u32) -> u32 {
    let mut x = v.reverse_bits();
    x ^= x.wrapping_mul(0x3d20_adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x0552_6c56);
    x ^= x.wrapping_mul(0x53a2_2864);
    x.reverse_bits()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_dimension_matches_known_prefix() {
        // Direction numbers m = 1, 3, 5 (v = 1/2, 3/4, 5/8) in binary (not Gray) order.
        let expect = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, e) in expect.iter().enumerate() {
            let v = sobol_u32(1, i as u32) as f64 / 4_294_967_296.0;
            assert_eq!(v, *e, "index {i}");
        }
    }

    #[test]
    fn owen_scrambling_is_a_permutation_of_strata() {
        // Scrambling a full 2^8 van der Corput prefix keeps one point per 1/256 stratum.
        let mut seen = [false; 256];
        for i in 0..256u32 {
            let v = owen_scramble(sobol_u32(0, i), 0xdead_beef) >> 24;
            assert!(!std::mem::replace(&mut seen[v as usize], true));
        }
    }
}
