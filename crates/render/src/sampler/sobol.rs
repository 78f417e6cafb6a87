//! The first two Sobol dimensions and hash-based Owen scrambling.

/// Sobol point `index` in dimension 0 (van der Corput, base 2) or 1, as a 32-bit
/// fixed-point fraction. Dimension 1 uses the primitive polynomial x + 1, whose
/// direction numbers satisfy v_k = v_{k-1} ^ (v_{k-1} >> 1) (Sobol 1967; Joe & Kuo 2008).
pub fn sobol_u32(dim: u32, index: u32) -> u32 {
    match dim {
        0 => index.reverse_bits(),
        _ => {
            let b = index.to_le_bytes();
            SOBOL1_BYTES[0][b[0] as usize]
                ^ SOBOL1_BYTES[1][b[1] as usize]
                ^ SOBOL1_BYTES[2][b[2] as usize]
                ^ SOBOL1_BYTES[3][b[3] as usize]
        }
    }
}

/// Dimension 1 is linear over GF(2) in the index bits, so the image of each index byte
/// can be tabulated: four lookups and three XORs per point.
static SOBOL1_BYTES: [[u32; 256]; 4] = sobol1_byte_tables();

const fn sobol1_byte_tables() -> [[u32; 256]; 4] {
    let mut directions = [0u32; 32];
    let mut v = 1u32 << 31;
    let mut k = 0;
    while k < 32 {
        directions[k] = v;
        v ^= v >> 1;
        k += 1;
    }
    let mut tables = [[0u32; 256]; 4];
    let mut byte = 0;
    while byte < 4 {
        let mut value = 0;
        while value < 256 {
            let mut acc = 0u32;
            let mut bit = 0;
            while bit < 8 {
                if value & (1 << bit) != 0 {
                    acc ^= directions[byte * 8 + bit];
                }
                bit += 1;
            }
            tables[byte][value] = acc;
            value += 1;
        }
        byte += 1;
    }
    tables
}

/// Owen-scrambled Sobol point `index` of dimension `dim` (0 or 1). The scramble works
/// on the bit-reversed fraction, and the reversed Sobol value is cheap to form
/// directly (dimension 0 reversed is the index itself; dimension 1 from reversed
/// tables), which saves two bit reversals per value.
#[inline]
pub fn scrambled_sobol(dim: u32, index: u32, seed: u32) -> u32 {
    let reversed = match dim {
        0 => index,
        _ => {
            let b = index.to_le_bytes();
            SOBOL1_BYTES_REVERSED[0][b[0] as usize]
                ^ SOBOL1_BYTES_REVERSED[1][b[1] as usize]
                ^ SOBOL1_BYTES_REVERSED[2][b[2] as usize]
                ^ SOBOL1_BYTES_REVERSED[3][b[3] as usize]
        }
    };
    laine_karras(reversed, seed).reverse_bits()
}

static SOBOL1_BYTES_REVERSED: [[u32; 256]; 4] = {
    let mut t = sobol1_byte_tables();
    let mut byte = 0;
    while byte < 4 {
        let mut v = 0;
        while v < 256 {
            t[byte][v] = t[byte][v].reverse_bits();
            v += 1;
        }
        byte += 1;
    }
    t
};

/// The Laine–Karras style hash: each output bit depends only on itself and lower bits.
#[inline]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x ^= x.wrapping_mul(0x3d20_adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x0552_6c56);
    x ^= x.wrapping_mul(0x53a2_2864);
    x
}

/// Nested uniform (Owen) scrambling of a 32-bit fraction by a hash, after Laine &
/// Karras (2011) and Burley (JCGT 2020): a hash that only propagates bits upward,
/// applied to the bit-reversed value, flips each bit depending only on the bits above
/// it. The constants are N. Vegdahl's improved hash ("Building a Better LK Hash", 2021).
pub fn owen_scramble(v: u32, seed: u32) -> u32 {
    owen_scramble_reversed(v.reverse_bits(), seed)
}

/// [`owen_scramble`] of the value whose bit reversal is `reversed`: for a caller that
/// scrambles one value under many seeds and reverses it once.
#[inline(always)]
pub fn owen_scramble_reversed(reversed: u32, seed: u32) -> u32 {
    laine_karras(reversed, seed).reverse_bits()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_tables_match_the_direction_number_recurrence() {
        for i in [0u32, 1, 2, 255, 256, 12345, 0xdead_beef, u32::MAX] {
            let mut v = 1u32 << 31;
            let mut expect = 0u32;
            for bit in 0..32 {
                if i & (1 << bit) != 0 {
                    expect ^= v;
                }
                v ^= v >> 1;
            }
            assert_eq!(sobol_u32(1, i), expect);
        }
    }

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
    fn fused_scrambled_sobol_equals_scramble_of_sobol() {
        for dim in 0..2 {
            for i in [0u32, 1, 7, 300, 65_537, 0x8000_0001] {
                for seed in [0u32, 0x1234_5678, u32::MAX] {
                    assert_eq!(
                        scrambled_sobol(dim, i, seed),
                        owen_scramble(sobol_u32(dim, i), seed)
                    );
                }
            }
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
