//! Binary image data for the page: little-endian f32 or IEEE-754 binary16 arrays, as
//! standard base64 (RFC 4648, with padding) wrapped into lines that the page's `atob`
//! accepts (its "forgiving base64" decoding drops ASCII whitespace).

use crate::study::Precision;

const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 of `bytes` with `=` padding, one unbroken line.
pub fn base64(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        let sextet = |i: u32| ALPHABET[((n >> (18 - 6 * i)) & 63) as usize] as char;
        out.push(sextet(0));
        out.push(sextet(1));
        out.push(if chunk.len() > 1 { sextet(2) } else { '=' });
        out.push(if chunk.len() > 2 { sextet(3) } else { '=' });
    }
    out
}

/// `base64(bytes)` broken into lines of `width` characters, each line prefixed by `indent`.
pub fn base64_lines(bytes: &[u8], width: usize, indent: &str) -> String {
    let encoded = base64(bytes);
    let mut out = String::with_capacity(encoded.len() + encoded.len() / width * (indent.len() + 1));
    // The alphabet is ASCII, so byte chunks are character chunks.
    for line in encoded.as_bytes().chunks(width.max(4)) {
        out.push_str(indent);
        out.push_str(std::str::from_utf8(line).expect("base64 output is ASCII"));
        out.push('\n');
    }
    out
}

/// Nearest binary16 value of `x` (round half to even), as its bit pattern.
///
/// Finite values beyond the half range (±65504) saturate to ±65504 rather than becoming
/// infinite, so a bright HDR pixel stays bright instead of turning into an inf; NaN and
/// ±inf keep their kind.
pub fn f32_to_f16_bits(x: f32) -> u16 {
    let bits = x.to_bits();
    let sign = ((bits >> 16) & 0x8000) as u16;
    let exp = ((bits >> 23) & 0xff) as i32;
    let mantissa = bits & 0x007f_ffff;
    if exp == 0xff {
        // Inf stays inf; NaN becomes a quiet NaN.
        return sign | 0x7c00 | if mantissa != 0 { 0x0200 } else { 0 };
    }
    if x.abs() >= 65504.0 {
        return sign | 0x7bff;
    }
    // Re-bias the exponent: f32 bias 127, f16 bias 15.
    let half_exp = exp - 127 + 15;
    if half_exp >= 1 {
        // Normal half: keep 10 mantissa bits, round the 13 dropped ones to nearest even.
        let base = ((half_exp as u32) << 10) | (mantissa >> 13);
        let rest = mantissa & 0x1fff;
        let round_up = rest > 0x1000 || (rest == 0x1000 && (base & 1) == 1);
        // A carry out of the mantissa correctly bumps the exponent (65504 is excluded above).
        return sign | (base + u32::from(round_up)) as u16;
    }
    if half_exp < -10 {
        // Below half the smallest subnormal (2^-25): rounds to zero.
        return sign;
    }
    // Subnormal half: value = m × 2^-24 with the implicit leading 1 made explicit.
    let full = mantissa | 0x0080_0000;
    let shift = (14 - half_exp) as u32; // 14..=24
    let base = full >> shift;
    let rest = full & ((1 << shift) - 1);
    let halfway = 1 << (shift - 1);
    let round_up = rest > halfway || (rest == halfway && (base & 1) == 1);
    sign | (base + u32::from(round_up)) as u16
}

/// The f32 value of a binary16 bit pattern (exact: every half is an f32).
pub fn f16_bits_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0f32 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1f);
    let mantissa = f32::from(h & 0x03ff);
    match exp {
        0 => sign * mantissa * (2.0f32).powi(-24),
        31 if mantissa == 0.0 => sign * f32::INFINITY,
        31 => f32::NAN,
        _ => sign * (1.0 + mantissa / 1024.0) * (2.0f32).powi(exp - 15),
    }
}

/// Little-endian bytes of `values` at `precision`.
pub fn float_bytes(values: impl Iterator<Item = f32>, precision: Precision) -> Vec<u8> {
    let mut out = Vec::new();
    match precision {
        Precision::F32 => values.for_each(|v| out.extend_from_slice(&v.to_le_bytes())),
        Precision::F16 => {
            values.for_each(|v| out.extend_from_slice(&f32_to_f16_bits(v).to_le_bytes()))
        }
    }
    out
}

/// The values a page will decode from `float_bytes(values, precision)`.
pub fn stored_value(v: f32, precision: Precision) -> f32 {
    match precision {
        Precision::F32 => v,
        Precision::F16 => f16_bits_to_f32(f32_to_f16_bits(v)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648_vectors() {
        // Test vectors from RFC 4648 section 10.
        let cases = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (plain, coded) in cases {
            assert_eq!(base64(plain.as_bytes()), coded, "{plain:?}");
        }
        // All 64 sextets appear in this byte pattern.
        let bytes: Vec<u8> = (0..=255).collect();
        let s = base64(&bytes);
        assert!(s.starts_with("AAECAwQFBgcICQoLDA0ODxAREhMUFRYXGBkaGxwdHh8g"));
        assert!(s.ends_with("+/w=="), "{}", &s[s.len() - 8..]);
    }

    #[test]
    fn base64_lines_rejoin_to_one_line() {
        let bytes: Vec<u8> = (0..1000u32).map(|i| (i * 7 % 251) as u8).collect();
        let lines = base64_lines(&bytes, 76, "  ");
        assert!(lines.lines().all(|l| l.len() <= 78 && l.starts_with("  ")));
        let joined: String = lines.split_whitespace().collect();
        assert_eq!(joined, base64(&bytes));
    }

    #[test]
    fn f16_known_bit_patterns() {
        let cases: [(f32, u16); 12] = [
            (0.0, 0x0000),
            (-0.0, 0x8000),
            (1.0, 0x3c00),
            (-2.0, 0xc000),
            (0.5, 0x3800),
            (65504.0, 0x7bff),
            (1e6, 0x7bff),
            (f32::INFINITY, 0x7c00),
            (f32::NEG_INFINITY, 0xfc00),
            (6.103_515_6e-5, 0x0400), // smallest normal 2^-14
            (5.960_464_5e-8, 0x0001), // smallest subnormal 2^-24
            (0.333_333_34, 0x3555),
        ];
        for (x, bits) in cases {
            assert_eq!(f32_to_f16_bits(x), bits, "{x}");
        }
        assert!(f16_bits_to_f32(f32_to_f16_bits(f32::NAN)).is_nan());
        // Half of the smallest subnormal is a tie and rounds to even (zero); just above rounds up.
        assert_eq!(f32_to_f16_bits(2.0f32.powi(-25)), 0);
        assert_eq!(f32_to_f16_bits(2.0f32.powi(-25) * 1.01), 1);
        // 1 + 2^-11 is halfway between 1 and the next half: ties to even gives 1.
        assert_eq!(f32_to_f16_bits(1.0 + 2.0f32.powi(-11)), 0x3c00);
        assert_eq!(f32_to_f16_bits(1.0 + 3.0 * 2.0f32.powi(-11)), 0x3c02);
    }

    #[test]
    fn every_half_round_trips_through_f32() {
        for h in 0..=u16::MAX {
            let x = f16_bits_to_f32(h);
            if x.is_nan() {
                continue;
            }
            assert_eq!(f32_to_f16_bits(x), h, "{h:#06x} -> {x}");
        }
    }

    #[test]
    fn f16_relative_error_is_below_half_an_ulp() {
        // Over the normal range the rounding error is at most 2^-11 relative.
        let mut x = 1e-4f32;
        while x < 6e4 {
            let back = f16_bits_to_f32(f32_to_f16_bits(x));
            assert!(
                ((back - x) / x).abs() <= 2.0f32.powi(-11) * 1.0001,
                "{x} -> {back}"
            );
            x *= 1.013;
        }
    }

    #[test]
    fn float_bytes_are_little_endian() {
        let b = float_bytes([1.0f32, -2.0].into_iter(), Precision::F32);
        assert_eq!(b, [0, 0, 0x80, 0x3f, 0, 0, 0, 0xc0]);
        let h = float_bytes([1.0f32, -2.0].into_iter(), Precision::F16);
        assert_eq!(h, [0x00, 0x3c, 0x00, 0xc0]);
    }
}
