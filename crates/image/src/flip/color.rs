//! Colour-space conversions used by FLIP.
//!
//! FLIP (Andersson et al. 2020, Sec. 3) filters images in the linear opponent space
//! YCxCz (Johnson & Fairchild's variant of CIELAB without the cube root), then measures
//! colour differences in CIELAB after Hunt adjustment with the HyAB distance
//! (Abasi et al. 2020). All spaces here use the sRGB primaries and a D65 white; the
//! reference white is the XYZ of linear RGB (1, 1, 1), so white maps to L* = 100.

/// Linear sRGB → CIE XYZ (D65), IEC 61966-2-1 primaries. The published digits are
/// kept verbatim even where f32 cannot hold all of them.
#[allow(clippy::excessive_precision)]
const RGB_TO_XYZ: [[f32; 3]; 3] = [
    [0.412_456_4, 0.357_576_1, 0.180_437_5],
    [0.212_672_9, 0.715_152_2, 0.072_175_0],
    [0.019_333_9, 0.119_192_0, 0.950_304_1],
];

/// CIE XYZ (D65) → linear sRGB, the inverse of [`RGB_TO_XYZ`].
#[allow(clippy::excessive_precision)]
const XYZ_TO_RGB: [[f32; 3]; 3] = [
    [3.240_454_2, -1.537_138_5, -0.498_531_4],
    [-0.969_266_0, 1.876_010_8, 0.041_556_0],
    [0.055_643_4, -0.204_025_9, 1.057_225_2],
];

/// XYZ of linear RGB white (1, 1, 1): the reference white of YCxCz and CIELAB.
const WHITE: [f32; 3] = [
    RGB_TO_XYZ[0][0] + RGB_TO_XYZ[0][1] + RGB_TO_XYZ[0][2],
    RGB_TO_XYZ[1][0] + RGB_TO_XYZ[1][1] + RGB_TO_XYZ[1][2],
    RGB_TO_XYZ[2][0] + RGB_TO_XYZ[2][1] + RGB_TO_XYZ[2][2],
];

#[inline]
fn mat_mul(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// sRGB transfer function decode (IEC 61966-2-1) of one channel in [0, 1].
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// sRGB transfer function encode of one linear channel in [0, 1].
#[cfg(test)]
fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Relative luminance of linear sRGB (the Y row of [`RGB_TO_XYZ`], Rec. 709 weights).
#[inline]
pub fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// Linear sRGB → YCxCz. Y is 116·Y/Yn − 16 (the lightness scale of L* without the
/// cube root), Cx and Cz are the linear red–green and blue–yellow opponent channels.
#[inline]
pub fn linear_rgb_to_ycxcz(rgb: [f32; 3]) -> [f32; 3] {
    let xyz = mat_mul(&RGB_TO_XYZ, rgb);
    let x = xyz[0] / WHITE[0];
    let y = xyz[1] / WHITE[1];
    let z = xyz[2] / WHITE[2];
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

/// YCxCz → linear sRGB, the exact inverse of [`linear_rgb_to_ycxcz`].
#[inline]
pub fn ycxcz_to_linear_rgb(ycxcz: [f32; 3]) -> [f32; 3] {
    let y = (ycxcz[0] + 16.0) / 116.0;
    let x = ycxcz[1] / 500.0 + y;
    let z = y - ycxcz[2] / 200.0;
    mat_mul(&XYZ_TO_RGB, [x * WHITE[0], y * WHITE[1], z * WHITE[2]])
}

/// The CIELAB companding function f(t), linear below (6/29)³.
#[inline]
fn lab_f(t: f32) -> f32 {
    const DELTA: f32 = 6.0 / 29.0;
    if t > DELTA * DELTA * DELTA {
        t.cbrt()
    } else {
        t / (3.0 * DELTA * DELTA) + 4.0 / 29.0
    }
}

/// Linear sRGB → CIELAB (D65 white of the sRGB primaries).
#[inline]
pub fn linear_rgb_to_lab(rgb: [f32; 3]) -> [f32; 3] {
    let xyz = mat_mul(&RGB_TO_XYZ, rgb);
    let fx = lab_f(xyz[0] / WHITE[0]);
    let fy = lab_f(xyz[1] / WHITE[1]);
    let fz = lab_f(xyz[2] / WHITE[2]);
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// Hunt adjustment (FLIP Sec. 3.1): chroma shrinks with lightness, a* and b* are
/// scaled by L*/100, because colourfulness is perceived to drop as luminance drops.
#[inline]
pub fn hunt_adjust(lab: [f32; 3]) -> [f32; 3] {
    let s = 0.01 * lab[0];
    [lab[0], s * lab[1], s * lab[2]]
}

/// The HyAB distance (Abasi et al. 2020): city-block in lightness plus Euclidean in
/// chroma, which fits large colour differences better than ΔE*ab.
#[inline]
pub fn hyab(a: [f32; 3], b: [f32; 3]) -> f32 {
    let dl = a[0] - b[0];
    let da = a[1] - b[1];
    let db = a[2] - b[2];
    dl.abs() + (da * da + db * db).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_maps_to_lightness_100_and_neutral() {
        let lab = linear_rgb_to_lab([1.0, 1.0, 1.0]);
        assert!((lab[0] - 100.0).abs() < 1e-3, "{lab:?}");
        assert!(lab[1].abs() < 1e-3 && lab[2].abs() < 1e-3, "{lab:?}");
        let ycc = linear_rgb_to_ycxcz([1.0, 1.0, 1.0]);
        assert!((ycc[0] - 100.0).abs() < 1e-3 && ycc[1].abs() < 1e-3 && ycc[2].abs() < 1e-3);
    }

    #[test]
    fn ycxcz_round_trips() {
        for rgb in [
            [0.2, 0.5, 0.9],
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.7, 0.7, 0.1],
        ] {
            let back = ycxcz_to_linear_rgb(linear_rgb_to_ycxcz(rgb));
            for c in 0..3 {
                assert!((back[c] - rgb[c]).abs() < 1e-5, "{rgb:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn srgb_round_trips_and_is_continuous() {
        for i in 0..=100 {
            let v = i as f32 / 100.0;
            assert!((linear_to_srgb(srgb_to_linear(v)) - v).abs() < 1e-5);
        }
        let knee = 0.040_45_f32;
        assert!((srgb_to_linear(knee) - srgb_to_linear(knee + 1e-6)).abs() < 1e-5);
    }

    #[test]
    fn hyab_of_known_pair() {
        // |ΔL| = 3, chroma distance = 5 (3-4-5 triangle).
        assert!((hyab([50.0, 1.0, 1.0], [53.0, 4.0, 5.0]) - 8.0).abs() < 1e-5);
    }
}
