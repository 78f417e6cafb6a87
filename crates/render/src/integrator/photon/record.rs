//! The compact photon record (28 bytes) and its encodings: power as three IEEE
//! half floats relative to a per-map scale, directions as 16-bit octahedral pairs.
//!
//! Jensen (2001, *Realistic Image Synthesis Using Photon Mapping*, §5) stores power as
//! RGBE and the direction as two angle bytes. Half floats keep 11 significant bits
//! (relative rounding error below 2⁻¹¹ ≈ 0.05 %, unbiased to first order by
//! round-to-nearest-even), which is far below the estimator's noise; a per-map scale
//! (the largest component of any photon in the map) keeps every value within f16's
//! normal range for all but negligible photons. Octahedral unit vectors follow Cigolle
//! et al., "A Survey of Efficient Representations for Independent Unit Vectors"
//! (JCGT 2014): 2 × 16 bits give an angular error below 5e-5 rad.

use glam::{Vec2, Vec3};

use super::kdtree::KdPoint;
use radiant_math::color::Rgb;

/// Flag: the photon's first diffuse hit (direct from the light, or after a purely
/// specular chain).
pub const FIRST_DIFFUSE: u8 = 1;
/// Flag: the path from the light was purely specular before this hit (L S+ D).
pub const CAUSTIC: u8 = 2;
/// Flag: the photon's first scattering event was specular (L S …): light that a camera
/// path can never connect to a point or spot light by next-event estimation.
pub const FROM_SPECULAR: u8 = 4;

/// A stored photon: where it landed, what it carries, where it came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    pub p: [f32; 3],
    /// Power per channel as f16 bits, in units of the map's `power_scale`.
    power: [u16; 3],
    /// Unit direction towards where the photon came from (octahedral).
    wi: [u16; 2],
    /// Surface normal, turned to the side the photon arrived on (octahedral).
    n: [u16; 2],
    /// Scattering events between the light and this hit (0: direct).
    pub bounces: u8,
    /// [`FIRST_DIFFUSE`] | [`CAUSTIC`] | [`FROM_SPECULAR`].
    pub flags: u8,
}

const _: () = assert!(std::mem::size_of::<Photon>() <= 32);

/// A photon as traced, before compression (the scale is known only once a map is
/// complete).
#[derive(Clone, Copy, Debug)]
pub struct RawPhoton {
    pub p: Vec3,
    pub power: Rgb,
    pub wi: Vec3,
    pub n: Vec3,
    pub bounces: u8,
    pub flags: u8,
}

impl Photon {
    /// Compresses a photon; `inv_scale` is 1 / the map's power scale.
    pub fn encode(raw: &RawPhoton, inv_scale: f32) -> Photon {
        let c = raw.power * inv_scale;
        Photon {
            p: raw.p.to_array(),
            power: [f32_to_f16(c.r), f32_to_f16(c.g), f32_to_f16(c.b)],
            wi: oct_encode(raw.wi),
            n: oct_encode(raw.n),
            bounces: raw.bounces,
            flags: raw.flags,
        }
    }

    /// Where the photon landed.
    pub fn position(&self) -> Vec3 {
        Vec3::from_array(self.p)
    }

    /// Power, given the map's scale.
    pub fn power(&self, scale: f32) -> Rgb {
        Rgb::new(
            f16_to_f32(self.power[0]),
            f16_to_f32(self.power[1]),
            f16_to_f32(self.power[2]),
        ) * scale
    }

    /// Unit direction towards where the photon came from.
    pub fn wi(&self) -> Vec3 {
        oct_decode(self.wi)
    }

    /// Surface normal at the photon, on the side it arrived from.
    pub fn normal(&self) -> Vec3 {
        oct_decode(self.n)
    }

    /// Whether the photon came from the side of `n` (a positive cosine with it).
    #[inline]
    pub fn arrives_from_side_of(&self, n: Vec3) -> bool {
        // The sign of the cosine needs no normalisation.
        oct_point(self.wi).dot(n) > 0.0
    }

    /// Whether the cosine between the photon's normal and the unit vector `n` exceeds
    /// `cos` (≥ 0); with `either_side`, its magnitude does.
    #[inline]
    pub fn normal_within(&self, n: Vec3, cos: f32, either_side: bool) -> bool {
        oct_cos_exceeds(self.n, n, cos, either_side)
    }
}

impl KdPoint for Photon {
    #[inline]
    fn position(&self) -> Vec3 {
        Vec3::from_array(self.p)
    }
}

/// IEEE 754 binary16 bits of `x`, rounded to nearest even; overflow gives infinity.
pub fn f32_to_f16(x: f32) -> u16 {
    let bits = x.to_bits();
    let sign = ((bits >> 16) & 0x8000) as u16;
    let exp = ((bits >> 23) & 0xff) as i32;
    let mant = bits & 0x007f_ffff;
    if exp == 0xff {
        return sign | 0x7c00 | if mant != 0 { 0x0200 } else { 0 };
    }
    let e = exp - 127 + 15;
    if e >= 0x1f {
        return sign | 0x7c00;
    }
    let round = |m: u32, shift: u32| -> u32 {
        let half = 1u32 << (shift - 1);
        let rem = m & ((1u32 << shift) - 1);
        let q = m >> shift;
        if rem > half || (rem == half && q & 1 == 1) {
            q + 1
        } else {
            q
        }
    };
    if e <= 0 {
        // Subnormal half: value = m × 2⁻²⁴.
        if e < -10 {
            return sign;
        }
        let m = mant | 0x0080_0000;
        let shift = (14 - e) as u32;
        return sign | round(m, shift) as u16;
    }
    // A carry out of the mantissa correctly bumps the exponent (up to infinity).
    sign | round(((e as u32) << 23) | mant, 13) as u16
}

/// The f32 value of binary16 bits.
pub fn f16_to_f32(h: u16) -> f32 {
    let sign = ((h as u32) & 0x8000) << 16;
    let e = ((h >> 10) & 0x1f) as u32;
    let m = (h & 0x03ff) as u32;
    match e {
        0 => {
            let v = m as f32 * (1.0 / (1u32 << 24) as f32);
            if sign != 0 { -v } else { v }
        }
        0x1f => f32::from_bits(sign | 0x7f80_0000 | (m << 13)),
        _ => f32::from_bits(sign | ((e + 112) << 23) | (m << 13)),
    }
}

fn sign_not_zero(v: f32) -> f32 {
    if v >= 0.0 { 1.0 } else { -1.0 }
}

/// Octahedral encoding of a unit vector into two 16-bit numbers.
pub fn oct_encode(v: Vec3) -> [u16; 2] {
    let l1 = v.x.abs() + v.y.abs() + v.z.abs();
    if l1 == 0.0 {
        return [32768, 32768];
    }
    let mut p = Vec2::new(v.x, v.y) / l1;
    if v.z < 0.0 {
        p = Vec2::new(
            (1.0 - p.y.abs()) * sign_not_zero(p.x),
            (1.0 - p.x.abs()) * sign_not_zero(p.y),
        );
    }
    let q = |c: f32| ((c.clamp(-1.0, 1.0) * 0.5 + 0.5) * 65535.0).round() as u16;
    [q(p.x), q(p.y)]
}

/// Inverse of [`oct_encode`] (a unit vector).
pub fn oct_decode(e: [u16; 2]) -> Vec3 {
    oct_point(e).normalize()
}

/// Whether the cosine between the direction `e` encodes and the unit vector `n` exceeds
/// `cos` (≥ 0); with `either_side`, its magnitude does. Photon searches test this for
/// every candidate, so it skips the square root and division of a normalisation:
/// v·n / |v| > c is (v·n)² > c² |v|² with the sign of v·n.
#[inline]
pub fn oct_cos_exceeds(e: [u16; 2], n: Vec3, cos: f32, either_side: bool) -> bool {
    let v = oct_point(e);
    let d = v.dot(n);
    (either_side || d > 0.0) && d * d > cos * cos * v.length_squared()
}

/// The point of the octahedron |x| + |y| + |z| = 1 that `e` encodes: the direction of
/// [`oct_decode`], not yet normalised.
#[inline]
fn oct_point(e: [u16; 2]) -> Vec3 {
    let x = e[0] as f32 / 65535.0 * 2.0 - 1.0;
    let y = e[1] as f32 / 65535.0 * 2.0 - 1.0;
    let z = 1.0 - x.abs() - y.abs();
    let (x, y) = if z < 0.0 {
        (
            (1.0 - y.abs()) * sign_not_zero(x),
            (1.0 - x.abs()) * sign_not_zero(y),
        )
    } else {
        (x, y)
    };
    Vec3::new(x, y, z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::Pcg32;
    use radiant_math::sampling::uniform_sphere;

    #[test]
    fn every_finite_half_survives_a_round_trip() {
        for h in 0..=u16::MAX {
            let v = f16_to_f32(h);
            if v.is_nan() {
                assert!(f16_to_f32(f32_to_f16(v)).is_nan());
                continue;
            }
            // -0 and +0 keep their sign bits.
            assert_eq!(f32_to_f16(v), h, "half {h:#06x} = {v}");
        }
    }

    #[test]
    fn half_rounding_error_is_below_half_an_ulp() {
        let mut rng = Pcg32::new(1, 2);
        for _ in 0..100_000 {
            // Normal half range: 2^-14 .. 65504.
            let x = (2.0f32).powf(rng.uniform() * 29.0 - 14.0);
            let y = f16_to_f32(f32_to_f16(x));
            assert!(((y - x) / x).abs() <= 1.0 / 2048.0 + 1e-7, "{x} -> {y}");
        }
        assert_eq!(f16_to_f32(f32_to_f16(1e6)), f32::INFINITY);
        assert_eq!(f16_to_f32(f32_to_f16(1e-9)), 0.0);
        // Subnormal: 3 × 2^-24 is exact.
        let s = 3.0 / (1u32 << 24) as f32;
        assert_eq!(f16_to_f32(f32_to_f16(s)), s);
    }

    #[test]
    fn octahedral_directions_are_accurate() {
        let mut rng = Pcg32::new(3, 4);
        let mut worst = 0.0f32;
        for _ in 0..100_000 {
            let v = uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
            let w = oct_decode(oct_encode(v));
            // atan2 of |v×w| and v·w: acos near 1 is limited by f32 rounding (~3e-4).
            worst = worst.max(v.cross(w).length().atan2(v.dot(w)));
        }
        // Cell size 2/65535 in the octahedron; the map stretches by at most ~2.
        assert!(worst < 1e-4, "worst angular error {worst}");
        for axis in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
            assert!(oct_decode(oct_encode(axis)).dot(axis) > 0.999_999);
        }
    }

    /// The cosine test without normalisation decides as the decoded unit vector's cosine
    /// does, up to rounding at the threshold itself; and the side test as its sign.
    #[test]
    fn cosine_tests_agree_with_the_decoded_direction() {
        let mut rng = Pcg32::new(5, 6);
        let mut decided = [0usize; 2];
        for _ in 0..100_000 {
            let e = oct_encode(uniform_sphere(Vec2::new(rng.uniform(), rng.uniform())));
            let n = uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
            let c = oct_decode(e).dot(n);
            for cos in [0.0, 0.5, 0.7, 0.9] {
                for either_side in [false, true] {
                    let reference = if either_side { c.abs() } else { c };
                    if (reference - cos).abs() < 1e-6 {
                        continue;
                    }
                    let fast = oct_cos_exceeds(e, n, cos, either_side);
                    assert_eq!(fast, reference > cos, "cos {c} against {cos}");
                    decided[usize::from(fast)] += 1;
                }
            }
            let raw = RawPhoton {
                p: Vec3::ZERO,
                power: Rgb::WHITE,
                wi: oct_decode(e),
                n: Vec3::Z,
                bounces: 0,
                flags: 0,
            };
            let ph = Photon::encode(&raw, 1.0);
            if c.abs() > 1e-6 {
                assert_eq!(ph.arrives_from_side_of(n), c > 0.0);
            }
        }
        // Both answers occur often: the test is not vacuous.
        assert!(decided.iter().all(|&k| k > 100_000), "{decided:?}");
    }

    #[test]
    fn photon_record_round_trips_its_fields() {
        let raw = RawPhoton {
            p: Vec3::new(1.0, -2.0, 3.5),
            power: Rgb::new(0.5, 0.25, 0.125),
            wi: Vec3::new(0.0, 0.6, 0.8),
            n: Vec3::Y,
            bounces: 3,
            flags: CAUSTIC,
        };
        let ph = Photon::encode(&raw, 1.0 / 0.5);
        assert_eq!(ph.position(), raw.p);
        assert_eq!(ph.power(0.5), raw.power);
        assert!(ph.wi().dot(raw.wi) > 0.999_999);
        assert!(ph.normal().dot(raw.n) > 0.999_999);
        assert_eq!((ph.bounces, ph.flags), (3, CAUSTIC));
        assert_eq!(std::mem::size_of::<Photon>(), 28);
    }
}
