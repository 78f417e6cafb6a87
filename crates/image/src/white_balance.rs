//! White balance for the film: the von Kries adaptation, in the Bradford cone space
//! (Lam 1985; Süsstrunk, Holm & Finlayson 2001), that takes the white of a CIE
//! daylight illuminant of a given colour temperature to the output's D65 white, as a
//! matrix on linear sRGB (Rec. 709 primaries).

/// Linear sRGB to CIE XYZ (IEC 61966-2-1, D65).
pub const XYZ_FROM_RGB: [[f32; 3]; 3] = [
    [0.412_456_4, 0.357_576_1, 0.180_437_5],
    [0.212_672_9, 0.715_152_2, 0.072_175_0],
    [0.019_333_9, 0.119_192, 0.950_304_1],
];

const RGB_FROM_XYZ: [[f32; 3]; 3] = [
    [3.240_454_2, -1.537_138_5, -0.498_531_4],
    [-0.969_266, 1.876_010_8, 0.041_556_0],
    [0.055_643_4, -0.204_025_9, 1.057_225_2],
];

/// Bradford's sharpened cone responses from XYZ, and back.
const LMS_FROM_XYZ: [[f32; 3]; 3] = [
    [0.895_1, 0.266_4, -0.161_4],
    [-0.750_2, 1.713_5, 0.036_7],
    [0.038_9, -0.068_5, 1.029_6],
];
const XYZ_FROM_LMS: [[f32; 3]; 3] = [
    [0.986_992_9, -0.147_054_3, 0.159_962_7],
    [0.432_305_3, 0.518_360_3, 0.049_291_2],
    [-0.008_528_7, 0.040_042_8, 0.968_486_7],
];

/// The D65 white point (xy).
pub const D65: [f32; 2] = [0.3127, 0.3290];

pub fn mul(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3]) -> [[f32; 3]; 3] {
    let mut out = [[0.0f32; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    out
}

pub fn apply(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    [0, 1, 2].map(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

/// Chromaticity of the CIE daylight illuminant of correlated colour temperature
/// `kelvin` (CIE 15:2004, the daylight locus; defined for 4000–25000 K, and
/// clamped to that range).
pub fn daylight_xy(kelvin: f32) -> [f32; 2] {
    let t = kelvin.clamp(4000.0, 25000.0) as f64;
    let x = if t <= 7000.0 {
        -4.6070e9 / t.powi(3) + 2.9678e6 / t.powi(2) + 0.09911e3 / t + 0.244063
    } else {
        -2.0064e9 / t.powi(3) + 1.9018e6 / t.powi(2) + 0.24748e3 / t + 0.237040
    };
    let y = -3.0 * x * x + 2.870 * x - 0.275;
    [x as f32, y as f32]
}

fn xyz_of_white(xy: [f32; 2]) -> [f32; 3] {
    [xy[0] / xy[1], 1.0, (1.0 - xy[0] - xy[1]) / xy[1]]
}

/// The linear-sRGB matrix that maps the white `from` (xy) to the white `to`.
pub fn adaptation(from: [f32; 2], to: [f32; 2]) -> [[f32; 3]; 3] {
    let src = apply(&LMS_FROM_XYZ, xyz_of_white(from));
    let dst = apply(&LMS_FROM_XYZ, xyz_of_white(to));
    let mut scale = [[0.0f32; 3]; 3];
    for i in 0..3 {
        scale[i][i] = dst[i] / src[i];
    }
    let xyz = mul(&XYZ_FROM_LMS, &mul(&scale, &LMS_FROM_XYZ));
    mul(&RGB_FROM_XYZ, &mul(&xyz, &XYZ_FROM_RGB))
}

/// pbrt-v4's `whitebalance`: daylight of `kelvin` becomes D65 white.
pub fn white_balance(kelvin: f32) -> [[f32; 3]; 3] {
    adaptation(daylight_xy(kelvin), D65)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn daylight_locus_passes_through_d65_and_d50() {
        // D65 and D50 sit at 6504 K and 5003 K on the locus (CIE 15:2004, table T.3).
        let d65 = daylight_xy(6504.0);
        assert!(
            (d65[0] - 0.3127).abs() < 2e-4 && (d65[1] - 0.3290).abs() < 2e-4,
            "{d65:?}"
        );
        let d50 = daylight_xy(5003.0);
        assert!(
            (d50[0] - 0.3457).abs() < 2e-4 && (d50[1] - 0.3585).abs() < 2e-4,
            "{d50:?}"
        );
    }

    #[test]
    fn adaptation_takes_the_source_white_to_the_target_and_d65_to_itself() {
        let m = white_balance(4000.0);
        // The RGB of the 4000 K daylight white (Y = 1) becomes neutral: equal channels.
        let src = xyz_of_white(daylight_xy(4000.0));
        let rgb = apply(&RGB_FROM_XYZ, src);
        let out = apply(&m, rgb);
        let mean = (out[0] + out[1] + out[2]) / 3.0;
        for c in out {
            assert!((c - mean).abs() < 2e-3 * mean, "{out:?}");
        }
        // Adapting D65 to D65 is the identity.
        let id = adaptation(D65, D65);
        for (i, row) in id.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((v - want).abs() < 1e-4, "{id:?}");
            }
        }
    }
}
