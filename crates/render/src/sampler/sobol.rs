//! Sobol dimensions (the first two, and four more for draws that continue a point) and
//! hash-based Owen scrambling.

/// Sobol point `index` in dimension 0 (van der Corput, base 2) or 1, as a 32-bit
/// fixed-point fraction. Dimension 1 uses the primitive polynomial x + 1, whose
/// direction numbers satisfy v_k = v_{k-1} ^ (v_{k-1} >> 1) (Sobol 1967; Joe & Kuo 2008).
pub fn sobol_u32(dim: u32, index: u32) -> u32 {
    match dim {
        0 => index.reverse_bits(),
        _ => digit_image(&SOBOL1_BYTES, index),
    }
}

/// Dimension 1 is linear over GF(2) in the index bits, so the image of each index byte
/// can be tabulated: four lookups and three XORs per point.
static SOBOL1_BYTES: [[u32; 256]; 4] = digit_tables(SOBOL1_DIRECTIONS, false);

/// Dimension 1: the polynomial x + 1, m₁ = 1.
const SOBOL1_DIRECTIONS: [u32; 32] = direction_numbers(1, 0, [1, 0, 0, 0]);

/// The further Sobol dimensions radiant uses: (degree s, coefficients a, initial
/// direction numbers m₁..m_s) of dimensions 2 to 5, with the primitive polynomials
/// x² + x + 1, x³ + x + 1, x³ + x² + 1 and x⁴ + x + 1 and the initial numbers of Joe &
/// Kuo, "Constructing Sobol sequences with better two-dimensional projections" (SIAM J.
/// Sci. Comput. 2008).
const FURTHER_DIMENSIONS: [(usize, u32, [u32; 4]); 4] = [
    (2, 1, [1, 3, 0, 0]),
    (3, 1, [1, 3, 1, 0]),
    (3, 2, [1, 1, 1, 0]),
    (4, 1, [1, 1, 3, 3]),
];

/// Which of [`FURTHER_DIMENSIONS`] a continued pair takes (see [`ContinuedPair`](super::ContinuedPair)).
pub(super) const SECOND_PAIR: [usize; 2] = [0, 1];
pub(super) const THIRD_PAIR: [usize; 2] = [2, 3];

/// The 32 direction numbers v_k = m_k / 2^k (as 32-bit fractions) of a dimension with
/// primitive polynomial x^s + a₁x^{s−1} + … + a_{s−1}x + 1 (a = a₁…a_{s−1} in binary),
/// by Sobol's recurrence m_k = 2a₁m_{k−1} ⊕ … ⊕ 2^{s−1}a_{s−1}m_{k−s+1} ⊕ 2^s m_{k−s} ⊕ m_{k−s}
/// (Bratley & Fox, "Algorithm 659", ACM TOMS 1988).
const fn direction_numbers(s: usize, a: u32, initial: [u32; 4]) -> [u32; 32] {
    let mut m = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        m[k] = if k < s {
            initial[k]
        } else {
            let mut v = m[k - s] ^ (m[k - s] << s);
            let mut j = 1;
            while j < s {
                if (a >> (s - 1 - j)) & 1 == 1 {
                    v ^= m[k - j] << j;
                }
                j += 1;
            }
            v
        };
        k += 1;
    }
    let mut v = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        v[k] = m[k] << (31 - k);
        k += 1;
    }
    v
}

/// The image of each `32 / DIGITS`-bit digit of the index under a dimension's direction
/// numbers (a Sobol point is linear over GF(2) in the index bits, so it is the XOR of its
/// digits' images), bit-reversed where `reversed` for scrambling in the reversed domain.
/// `ENTRIES` is 2 to the digit's bits: bytes (256, 4) or nibbles (16, 8).
const fn digit_tables<const ENTRIES: usize, const DIGITS: usize>(
    directions: [u32; 32],
    reversed: bool,
) -> [[u32; ENTRIES]; DIGITS] {
    let bits = 32 / DIGITS;
    let mut tables = [[0u32; ENTRIES]; DIGITS];
    let mut digit = 0;
    while digit < DIGITS {
        let mut value = 0;
        while value < ENTRIES {
            let mut acc = 0u32;
            let mut bit = 0;
            while bit < bits {
                if value & (1 << bit) != 0 {
                    acc ^= directions[digit * bits + bit];
                }
                bit += 1;
            }
            tables[digit][value] = if reversed { acc.reverse_bits() } else { acc };
            value += 1;
        }
        digit += 1;
    }
    tables
}

/// The point of `index` from a dimension's [`digit_tables`] (or from a table of two
/// dimensions' points side by side): its digits' images XORed.
#[inline(always)]
fn digit_image<T, const ENTRIES: usize, const DIGITS: usize>(
    tables: &[[T; ENTRIES]; DIGITS],
    index: u32,
) -> T
where
    T: Copy + Default + std::ops::BitXorAssign,
{
    let bits = 32 / DIGITS;
    let mut x = T::default();
    for (digit, table) in tables.iter().enumerate() {
        x ^= table[(index >> (bits * digit)) as usize & (ENTRIES - 1)];
    }
    x
}

/// The image of each 4-bit digit of the index's bit reversal, as the sample-index
/// shuffle leaves it (see [`SOBOL01_OF_REVERSED_INDEX`]), per further dimension,
/// bit-reversed for scrambling in the reversed domain. Nibbles, not bytes: a shuffled
/// sample index has random high bits, so every table entry is as likely as any other,
/// and byte tables (16 KiB for the four dimensions) fell out of the L1 cache where
/// these (2 KiB) stay.
static FURTHER_NIBBLES_OF_REVERSED_INDEX: [[[u32; 16]; 8]; 4] = further_tables(true);

/// [`FURTHER_NIBBLES_OF_REVERSED_INDEX`] indexed by the digits of the index itself:
/// the reference the tests hold the sampler's tables to.
#[cfg(test)]
static FURTHER_NIBBLES_REVERSED: [[[u32; 16]; 8]; 4] = further_tables(false);

const fn further_tables(of_reversed_index: bool) -> [[[u32; 16]; 8]; 4] {
    let mut t = [[[0u32; 16]; 8]; 4];
    let mut d = 0;
    while d < 4 {
        let (s, a, m) = FURTHER_DIMENSIONS[d];
        let v = direction_numbers(s, a, m);
        t[d] = digit_tables(
            if of_reversed_index {
                bit_order_reversed(v)
            } else {
                v
            },
            true,
        );
        d += 1;
    }
    t
}

/// Owen-scrambled Sobol point `index` of further dimension `further` (an index into
/// [`FURTHER_DIMENSIONS`]), scrambled in the reversed domain as [`scrambled_sobol`].
#[cfg(test)]
pub fn scrambled_further_sobol(further: usize, index: u32, seed: u32) -> u32 {
    let reversed = digit_image(&FURTHER_NIBBLES_REVERSED[further], index);
    laine_karras(reversed, seed).reverse_bits()
}

/// Owen-scrambled Sobol points of further dimensions `further` (x, y) at the index
/// whose bit reversal is `index_reversed`, scrambled with `seeds`: what
/// `scrambled_further_sobol` gives for each, with one 64-bit reversal for both.
#[inline(always)]
pub fn scrambled_further_sobol_pair(
    further: [usize; 2],
    index_reversed: u32,
    seeds: [u32; 2],
) -> [u32; 2] {
    let x = digit_image(
        &FURTHER_NIBBLES_OF_REVERSED_INDEX[further[0]],
        index_reversed,
    );
    let y = digit_image(
        &FURTHER_NIBBLES_OF_REVERSED_INDEX[further[1]],
        index_reversed,
    );
    reverse_pair(laine_karras(x, seeds[0]), laine_karras(y, seeds[1]))
}

/// Owen-scrambled Sobol dimensions 0 and 1 at the index whose bit reversal is
/// `index_reversed`, scrambled with `seeds`: [`scrambled_sobol`] of both dimensions at
/// that index.
///
/// The shuffled sample index comes out of its scramble bit-reversed, and x86 has no
/// instruction for a bit reversal (it takes about 17). Both dimensions' reversed-domain
/// values are linear over GF(2) in the index bits, so one table of their pair per byte
/// of the reversed index gives both in four lookups, and the two scrambled values are
/// reversed back together as one 64-bit word: two reversals saved per 2D draw.
#[inline(always)]
pub fn scrambled_sobol_pair(index_reversed: u32, seeds: [u32; 2]) -> [u32; 2] {
    let both = digit_image(&SOBOL01_OF_REVERSED_INDEX, index_reversed);
    reverse_pair(
        laine_karras(both as u32, seeds[0]),
        laine_karras((both >> 32) as u32, seeds[1]),
    )
}

/// Owen-scrambled Sobol dimension 0 at the index whose bit reversal is `index_reversed`
/// ([`scrambled_sobol`]`(0, …)` at that index).
#[inline(always)]
pub fn scrambled_sobol_0(index_reversed: u32, seed: u32) -> u32 {
    let reversed = digit_image(&SOBOL01_OF_REVERSED_INDEX, index_reversed) as u32;
    laine_karras(reversed, seed).reverse_bits()
}

/// The bit reversals of `x` and `y`, by one reversal of the word that holds both.
#[inline(always)]
fn reverse_pair(x: u32, y: u32) -> [u32; 2] {
    let both = (x as u64 | (y as u64) << 32).reverse_bits();
    [(both >> 32) as u32, both as u32]
}

/// The reversed-domain values of Sobol dimensions 0 (low half) and 1 (high half) as the
/// image of each byte of the index's bit reversal: 8 KiB.
static SOBOL01_OF_REVERSED_INDEX: [[u64; 256]; 4] = {
    let dim0 = digit_tables::<256, 4>(bit_order_reversed(VAN_DER_CORPUT_DIRECTIONS), true);
    let dim1 = digit_tables::<256, 4>(bit_order_reversed(SOBOL1_DIRECTIONS), true);
    let mut t = [[0u64; 256]; 4];
    let mut digit = 0;
    while digit < 4 {
        let mut value = 0;
        while value < 256 {
            t[digit][value] = dim0[digit][value] as u64 | (dim1[digit][value] as u64) << 32;
            value += 1;
        }
        digit += 1;
    }
    t
};

/// Dimension 0, the van der Corput sequence: index bit k is the fraction's bit 31 − k.
const VAN_DER_CORPUT_DIRECTIONS: [u32; 32] = {
    let mut v = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        v[k] = 1 << (31 - k);
        k += 1;
    }
    v
};

/// Direction numbers indexed by the bits of the index's reversal: bit k of the reversed
/// index is bit 31 − k of the index.
const fn bit_order_reversed(v: [u32; 32]) -> [u32; 32] {
    let mut w = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        w[k] = v[31 - k];
        k += 1;
    }
    w
}

/// Owen-scrambled Sobol point `index` of dimension `dim` (0 or 1). The scramble works
/// on the bit-reversed fraction, and the reversed Sobol value is cheap to form
/// directly (dimension 0 reversed is the index itself; dimension 1 from reversed
/// tables), which saves two bit reversals per value.
#[inline]
pub fn scrambled_sobol(dim: u32, index: u32, seed: u32) -> u32 {
    let reversed = match dim {
        0 => index,
        _ => digit_image(&SOBOL1_BYTES_REVERSED, index),
    };
    laine_karras(reversed, seed).reverse_bits()
}

static SOBOL1_BYTES_REVERSED: [[u32; 256]; 4] = digit_tables(SOBOL1_DIRECTIONS, true);

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
    owen_scramble_reversed(v.reverse_bits(), seed).reverse_bits()
}

/// [`owen_scramble`] of the value whose bit reversal is `reversed`, left bit-reversed:
/// for a caller that reads the scrambled value through tables of its reversal.
#[inline(always)]
pub fn owen_scramble_reversed(reversed: u32, seed: u32) -> u32 {
    laine_karras(reversed, seed)
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

    /// The tabulated further dimensions against the direction numbers applied bit by bit,
    /// and each a (0, 1)-sequence: 2^k consecutive points fill the 2^k intervals of
    /// length 2^−k once each (which valid initial numbers m_k, odd and below 2^k, ensure).
    #[test]
    fn further_dimensions_match_their_direction_numbers_and_stratify() {
        for (further, &(s, a, m)) in FURTHER_DIMENSIONS.iter().enumerate() {
            let v = direction_numbers(s, a, m);
            for i in [0u32, 1, 2, 3, 77, 255, 256, 65_535, 0x8000_0001, u32::MAX] {
                let direct = (0..32)
                    .filter(|k| i & (1 << k) != 0)
                    .fold(0u32, |x, k| x ^ v[k]);
                assert_eq!(
                    scrambled_further_sobol(further, i, 0x1234_5678),
                    owen_scramble(direct, 0x1234_5678),
                    "dimension {further} index {i}"
                );
            }
            for k in [1u32, 4, 8] {
                let mut seen = vec![false; 1 << k];
                for i in 0..1u32 << k {
                    let x = scrambled_further_sobol(further, i, 0) >> (32 - k);
                    assert!(!std::mem::replace(&mut seen[x as usize], true));
                }
            }
        }
    }

    /// The pair draws from a reversed index are the single-dimension scrambles at the
    /// index itself.
    #[test]
    fn pairs_from_the_reversed_index_equal_the_scrambles_of_each_dimension() {
        let mut rng = radiant_math::hash::Pcg32::new(5, 9);
        for n in 0..2000 {
            let i = match n {
                0 => 0,
                1 => u32::MAX,
                2 => 0x8000_0001,
                _ => rng.next_u32(),
            };
            let seeds = [rng.next_u32(), rng.next_u32()];
            let r = i.reverse_bits();
            assert_eq!(
                scrambled_sobol_pair(r, seeds),
                [
                    scrambled_sobol(0, i, seeds[0]),
                    scrambled_sobol(1, i, seeds[1])
                ],
                "index {i:#x}"
            );
            assert_eq!(
                scrambled_sobol_0(r, seeds[0]),
                scrambled_sobol(0, i, seeds[0])
            );
            for further in [[0, 1], [2, 3], [3, 0]] {
                assert_eq!(
                    scrambled_further_sobol_pair(further, r, seeds),
                    [
                        scrambled_further_sobol(further[0], i, seeds[0]),
                        scrambled_further_sobol(further[1], i, seeds[1])
                    ],
                    "index {i:#x}, dimensions {further:?}"
                );
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
