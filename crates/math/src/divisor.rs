//! Division of 32-bit integers by a divisor known ahead of time, by multiplication.
//!
//! A hardware division takes tens of cycles and does not pipeline well; a sampler that
//! takes the digits of an index in a prime base divides several times per digit. With
//! the divisor's 64-bit reciprocal M = ⌊(2⁶⁴ − 1) / d⌋ + 1 computed once, the quotient
//! is the high word of M·n and the remainder the high word of d times the low word of
//! M·n, exact for every 32-bit n and d (Lemire, Kaser & Kurz, "Faster remainder by
//! direct computation", Software: Practice and Experience 49(6), 2019).

/// A divisor d ≥ 2 with its reciprocal, for exact quotients and remainders of u32s.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Divisor {
    d: u32,
    reciprocal: u64,
}

impl Divisor {
    /// The divisor `d`; `d` must be at least 2 (the reciprocal of 1 needs 65 bits).
    pub const fn new(d: u32) -> Divisor {
        assert!(d >= 2, "a divisor by multiplication needs d >= 2");
        Divisor {
            d,
            reciprocal: u64::MAX / d as u64 + 1,
        }
    }

    /// d.
    #[inline(always)]
    pub const fn get(self) -> u32 {
        self.d
    }

    /// n mod d.
    #[inline(always)]
    pub const fn remainder(self, n: u32) -> u32 {
        let low = self.reciprocal.wrapping_mul(n as u64);
        ((low as u128 * self.d as u128) >> 64) as u32
    }

    /// (⌊n / d⌋, n mod d), from one product.
    #[inline(always)]
    pub const fn div_rem(self, n: u32) -> (u32, u32) {
        let product = self.reciprocal as u128 * n as u128;
        let low = product as u64;
        (
            (product >> 64) as u32,
            ((low as u128 * self.d as u128) >> 64) as u32,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hash::Pcg32;

    /// Against the hardware's division: every small divisor and numerator, the edges of
    /// the range, and random pairs over the whole of it.
    #[test]
    fn quotients_and_remainders_equal_the_hardware_division() {
        let check = |d: u32, n: u32| {
            let divisor = Divisor::new(d);
            assert_eq!(divisor.remainder(n), n % d, "{n} % {d}");
            assert_eq!(divisor.div_rem(n), (n / d, n % d), "{n} divrem {d}");
        };
        for d in 2..300 {
            for n in 0..2000 {
                check(d, n);
            }
        }
        let edges = [
            0,
            1,
            2,
            3,
            7,
            1 << 16,
            (1 << 31) - 1,
            1 << 31,
            u32::MAX - 1,
            u32::MAX,
        ];
        for d in edges.into_iter().filter(|&d| d >= 2) {
            for n in edges {
                check(d, n);
                check(d, n.wrapping_add(d / 2));
            }
        }
        let mut rng = Pcg32::new(41, 7);
        for _ in 0..1_000_000 {
            let d = (rng.next_u32() >> (rng.next_u32() % 31)).max(2);
            check(d, rng.next_u32());
        }
    }
}
