//! Randomised Halton points (Halton 1960): coordinate d of point i is the radical inverse
//! of i in the d-th prime base. Each pixel gets its own randomisation of the digits, so
//! pixels are decorrelated and every point is uniformly distributed while the points of
//! one pixel keep the sequence's stratification: in base b, any b^k consecutive indices
//! starting at a multiple of b^k put one point in each interval [j/b^k, (j+1)/b^k).
//!
//! Digits are permuted by affine maps d ↦ (a·d + c) mod b (b prime, a ≠ 0: a bijection).
//! With c uniform every output digit is uniform, which is what makes the estimate
//! unbiased; Faure's (1992) permutations and Owen's (1995) nested scrambling differ in
//! what the map depends on: the digit position alone, or the position and every digit
//! before it. Either way the index's trailing zero digits are permuted too, so a
//! scrambled point has a random tail down to 2^-32 instead of trailing zeros: Owen's
//! scrambling draws it digit by digit from hashes, Faure's in closed form (see
//! [`permuted_radical_inverse`]).

use radiant_math::ONE_MINUS_EPSILON;
use radiant_math::divisor::Divisor;
use radiant_math::hash::{mix64, u32_to_unit_f32};
use radiant_scene::DigitRandomization;

use super::sobol::{scrambled_sobol, sobol_u32};

/// How many primes the sampler knows: dimension pairs past `PRIMES.len() / 2` are
/// independent random numbers (their bases would be too large to stratify anything at
/// practical sample counts anyway).
pub const PRIME_COUNT: usize = 1024;

/// The first [`PRIME_COUNT`] primes, by trial division at compile time.
pub static PRIMES: [u32; PRIME_COUNT] = first_primes();

const fn first_primes() -> [u32; PRIME_COUNT] {
    let mut primes = [0u32; PRIME_COUNT];
    let mut count = 0;
    let mut candidate = 2u32;
    while count < PRIME_COUNT {
        let mut is_prime = true;
        let mut j = 0;
        while j < count && primes[j] * primes[j] <= candidate {
            if candidate.is_multiple_of(primes[j]) {
                is_prime = false;
                break;
            }
            j += 1;
        }
        if is_prime {
            primes[count] = candidate;
            count += 1;
        }
        candidate += 1;
    }
    primes
}

/// The radical inverse of `index` in base `PRIMES[prime]`, its digits randomised as
/// `randomization` says with the hash `key` (one key per pixel and dimension).
pub fn randomized_radical_inverse(
    index: u32,
    prime: usize,
    key: u64,
    randomization: DigitRandomization,
) -> f32 {
    if prime == 0 {
        // Base 2 is the van der Corput sequence, Sobol's first dimension: its scrambles
        // are bit operations on the reversed index.
        let bits = match randomization {
            DigitRandomization::None => sobol_u32(0, index),
            DigitRandomization::PermuteDigits => sobol_u32(0, index) ^ (key >> 32) as u32,
            DigitRandomization::Owen => scrambled_sobol(0, index, (key >> 32) as u32),
        };
        return u32_to_unit_f32(bits);
    }
    let Base {
        divisor: base,
        less_one: base_minus_one,
        inverse: inv_base,
        digits,
    } = BASES[prime];
    if randomization == DigitRandomization::PermuteDigits {
        return permuted_radical_inverse(index, BASES[prime], key);
    }
    let mut rest = index;
    let mut weight = inv_base;
    let mut value = 0.0f64;
    // The hash the next digit's permutation is drawn from: for Owen scrambling it takes
    // in every digit produced so far, so each prefix interval is permuted on its own.
    let mut prefix = key;
    for _ in 0..digits {
        let (next, digit) = base.div_rem(rest);
        rest = next;
        let permuted = match randomization {
            DigitRandomization::Owen => {
                let p = affine_permutation(digit, base, base_minus_one, prefix);
                prefix = mix64(prefix ^ (digit as u64 + 1).wrapping_mul(PHI));
                p
            }
            _ => digit,
        };
        value += permuted as f64 * weight;
        weight *= inv_base;
        if rest == 0 && randomization == DigitRandomization::None {
            break;
        }
    }
    // Rounding must not reach 1.
    (value as f32).min(ONE_MINUS_EPSILON)
}

/// The radical inverse with digit k permuted by d ↦ (a_k·d + c_k) mod b (Faure 1992):
/// one permutation per digit position, the same for every index of a pixel's dimension.
///
/// The multipliers a_k − 1 are the base-(b − 1) digits of one random fraction and the
/// offsets c_k the base-b digits of another, both from `key`, read by multiplying the
/// fraction by the base: independent and uniform, as per-position hashes would be. The
/// offsets as digits of one number are what make the point cheap: past the index's
/// last nonzero digit every digit is 0, and permuted it is c_k, so the whole tail,
/// Σ_{k≥m} c_k b^−(k+1), is what is left of the offsets' fraction after m digits,
/// scaled by b^−m. A point costs the index's digits, not the 20 a base-3 coordinate
/// needs to fill 32 bits, and every index shares the same tail digits, so the points
/// of a pixel stratify as the definition says.
#[inline(always)]
fn permuted_radical_inverse(index: u32, base: Base, key: u64) -> f32 {
    let mut offsets = mix64(key ^ OFFSETS);
    let mut multipliers = mix64(key ^ MULTIPLIERS);
    let b = base.divisor.get() as u64;
    let mut rest = index;
    let mut weight = base.inverse;
    let mut value = 0.0f64;
    while rest != 0 {
        let (next, digit) = base.divisor.div_rem(rest);
        rest = next;
        let wide = offsets as u128 * b as u128;
        let c = (wide >> 64) as u32;
        offsets = wide as u64;
        let wide = multipliers as u128 * (b - 1) as u128;
        let a = 1 + (wide >> 64) as u32;
        multipliers = wide as u64;
        let permuted = base.divisor.remainder(a * digit + c);
        value += permuted as f64 * weight;
        weight *= base.inverse;
    }
    // The offsets' remaining fraction, at the weight of the digit before this one.
    value += offsets as f64 * (1.0 / 18_446_744_073_709_551_616.0) * (weight * b as f64);
    (value as f32).min(ONE_MINUS_EPSILON)
}

const OFFSETS: u64 = 0x5851_f42d_4c95_7f2d;
const MULTIPLIERS: u64 = 0x1405_7b7e_f767_814f;

const PHI: u64 = 0x9e37_79b9_7f4a_7c15;

/// d ↦ (a·d + c) mod b with a ∈ [1, b), c ∈ [0, b) taken from `hash`: a permutation of
/// the digits of a prime base, and c makes every digit equally likely. Every operand is
/// below 2³² (a·d + c < b² for the bases here), so the divisions are by multiplication.
#[inline(always)]
fn affine_permutation(digit: u32, base: Divisor, base_minus_one: Divisor, hash: u64) -> u32 {
    let a = 1 + base_minus_one.remainder((hash >> 32) as u32);
    let c = base.remainder(hash as u32);
    base.remainder(a * digit + c)
}

/// What the digit loop needs of a prime base, computed once: the base and the base less
/// one as divisors by multiplication (the digits and the permutations' multipliers),
/// 1/b, and how many digits it takes until b^-k falls to 2^-32.
#[derive(Clone, Copy)]
struct Base {
    divisor: Divisor,
    less_one: Divisor,
    inverse: f64,
    digits: u32,
}

/// Base 2 takes the bitwise path and is never divided by; its entry holds 2 as "the
/// base less one" only because a divisor by multiplication needs d ≥ 2.
static BASES: [Base; PRIME_COUNT] = bases();

const fn bases() -> [Base; PRIME_COUNT] {
    let mut table = [Base {
        divisor: Divisor::new(2),
        less_one: Divisor::new(2),
        inverse: 0.5,
        digits: 32,
    }; PRIME_COUNT];
    let mut i = 1;
    while i < PRIME_COUNT {
        let inverse = 1.0 / PRIMES[i] as f64;
        // The weights as the loop forms them, by repeated products.
        let (mut weight, mut digits) = (inverse, 0);
        while weight > 1.0 / 4_294_967_296.0 {
            weight *= inverse;
            digits += 1;
        }
        table[i] = Base {
            divisor: Divisor::new(PRIMES[i]),
            less_one: Divisor::new(PRIMES[i] - 1),
            inverse,
            digits,
        };
        i += 1;
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The radical inverse as first written, with the hardware's divisions and the
    /// loop ending on the weight: the reference for the tables and the division by
    /// multiplication.
    fn by_division(index: u32, prime: usize, key: u64, randomization: DigitRandomization) -> f32 {
        let base = PRIMES[prime] as u64;
        let permute = |digit: u64, hash: u64| {
            let a = 1 + (hash >> 32) % (base - 1);
            let c = (hash & 0xffff_ffff) % base;
            (a * digit + c) % base
        };
        let inv_base = 1.0 / base as f64;
        let (mut rest, mut weight, mut value) = (index as u64, inv_base, 0.0f64);
        let mut prefix = key;
        // Faure's permutations: digit k of the two fractions, one at a time.
        let (mut offsets, mut multipliers) = (mix64(key ^ OFFSETS), mix64(key ^ MULTIPLIERS));
        let digit_of = |fraction: &mut u64, b: u64| {
            let wide = *fraction as u128 * b as u128;
            *fraction = wide as u64;
            (wide >> 64) as u64
        };
        // The closed-form tail is exact: sum the digits until what is dropped, less
        // than the last weight times b, is below 2^-32.
        let faure = randomization == DigitRandomization::PermuteDigits;
        let last = if faure { base as f64 } else { 1.0 };
        while weight * last > 1.0 / 4_294_967_296.0 {
            let digit = rest % base;
            rest /= base;
            let permuted = match randomization {
                DigitRandomization::None => digit,
                DigitRandomization::PermuteDigits => {
                    let c = digit_of(&mut offsets, base);
                    let a = 1 + digit_of(&mut multipliers, base - 1);
                    (a * digit + c) % base
                }
                DigitRandomization::Owen => {
                    let p = permute(digit, prefix);
                    prefix = mix64(prefix ^ (digit + 1).wrapping_mul(PHI));
                    p
                }
            };
            value += permuted as f64 * weight;
            weight *= inv_base;
            if rest == 0 && randomization == DigitRandomization::None {
                break;
            }
        }
        (value as f32).min(ONE_MINUS_EPSILON)
    }

    /// Plain division gives the same points; Faure's permutations, whose tail the
    /// sampler sums in closed form, to within one f32 rounding step of the digits summed
    /// one by one.
    #[test]
    fn the_tables_give_the_points_of_plain_division() {
        let mut rng = radiant_math::hash::Pcg32::new(3, 9);
        for randomization in [
            DigitRandomization::None,
            DigitRandomization::PermuteDigits,
            DigitRandomization::Owen,
        ] {
            for prime in [1, 2, 3, 4, 10, 100, 511, 512, PRIME_COUNT - 1] {
                for i in 0..3000u32 {
                    let index = match i % 3 {
                        0 => i,
                        1 => rng.next_u32(),
                        _ => u32::MAX - i,
                    };
                    let key = mix64(i as u64 ^ (prime as u64) << 32);
                    let fast = randomized_radical_inverse(index, prime, key, randomization);
                    let plain = by_division(index, prime, key, randomization);
                    if randomization == DigitRandomization::PermuteDigits {
                        assert!(
                            (fast - plain).abs() <= f32::EPSILON * fast.max(plain) + 2f32.powi(-32),
                            "{randomization:?} prime {prime} index {index}: {fast} {plain}"
                        );
                    } else {
                        assert_eq!(
                            fast.to_bits(),
                            plain.to_bits(),
                            "{randomization:?} prime {prime} index {index}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn the_prime_table_holds_the_primes() {
        assert_eq!(&PRIMES[..10], &[2, 3, 5, 7, 11, 13, 17, 19, 23, 29]);
        // The 1024th prime.
        assert_eq!(PRIMES[PRIME_COUNT - 1], 8161);
    }

    #[test]
    fn unscrambled_points_are_the_radical_inverse() {
        let r = |i, p| randomized_radical_inverse(i, p, 0, DigitRandomization::None);
        // 6 = 110 in base 2 → 0.011 = 3/8; 5 = 12 in base 3 → 0.21 = 2/3 + 1/9;
        // 7 = 12 in base 5 → 0.21 = 2/5 + 1/25.
        assert_eq!(r(6, 0), 0.375);
        assert!((r(5, 1) - (2.0 / 3.0 + 1.0 / 9.0)).abs() < 1e-6);
        assert!((r(7, 2) - (2.0 / 5.0 + 1.0 / 25.0)).abs() < 1e-6);
        assert_eq!(r(0, 5), 0.0);
    }

    /// b^k consecutive points from a multiple of b^k fill the b^k intervals once each,
    /// with every randomisation, in several bases.
    #[test]
    fn every_randomisation_keeps_the_intervals_stratified() {
        for randomization in [
            DigitRandomization::None,
            DigitRandomization::PermuteDigits,
            DigitRandomization::Owen,
        ] {
            for (prime, k) in [(0usize, 8u32), (1, 5), (2, 3), (9, 2), (100, 1)] {
                let b = PRIMES[prime];
                let n = b.pow(k);
                for start in [0, n, 7 * n] {
                    let mut seen = vec![false; n as usize];
                    for i in start..start + n {
                        let v = randomized_radical_inverse(
                            i,
                            prime,
                            0xabc ^ prime as u64,
                            randomization,
                        );
                        // The unscrambled points lie on the interval ends, where the
                        // f32 rounding may fall just short.
                        let slack = if randomization == DigitRandomization::None {
                            1e-3
                        } else {
                            0.0
                        };
                        let cell = (v as f64 * n as f64 + slack) as usize;
                        assert!(!seen[cell], "{randomization:?} base {b} index {i}");
                        seen[cell] = true;
                    }
                }
            }
        }
    }

    /// Over many keys a scrambled coordinate is uniform: Pearson's chi-square over 32
    /// bins for a fixed index, in bases 2, 3 and 7919 (4000 keys, 31 degrees of freedom,
    /// the 0.999 quantile is 61.1).
    #[test]
    fn scrambled_points_are_uniform_over_keys() {
        for randomization in [DigitRandomization::PermuteDigits, DigitRandomization::Owen] {
            for prime in [0usize, 1, 999] {
                for index in [0u32, 5, 1000] {
                    let n = 4000;
                    let mut bins = [0u32; 32];
                    for key in 0..n {
                        let v = randomized_radical_inverse(index, prime, mix64(key), randomization);
                        bins[(v * 32.0) as usize] += 1;
                    }
                    let expected = n as f64 / 32.0;
                    let chi2: f64 = bins
                        .iter()
                        .map(|&o| (o as f64 - expected).powi(2) / expected)
                        .sum();
                    assert!(
                        chi2 < 61.1,
                        "{randomization:?} prime {prime} index {index}: {chi2}"
                    );
                }
            }
        }
    }
}
