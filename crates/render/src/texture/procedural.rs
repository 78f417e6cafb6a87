//! The procedural classes: checkerboards, bilinear corners, dots and the noise-based
//! fBm, wrinkled, windy and marble.

use glam::{Vec2, Vec3};
use radiant_math::color::Rgb;

use super::mapping::{TexCoord2D, TexCoord3D};
use super::noise::{fbm, noise, turbulence};

/// ∫₀ˣ q(u) du for the square wave q = +1 on even unit intervals, −1 on odd ones: a
/// triangle wave of period 2.
fn square_wave_integral(x: f32) -> f32 {
    1.0 - ((x.rem_euclid(2.0)) - 1.0).abs()
}

/// The average of the square wave over [x − w, x + w]; the point value for w = 0.
fn square_wave_average(x: f32, w: f32) -> f32 {
    if w <= 1e-6 {
        return if x.floor().rem_euclid(2.0) == 0.0 {
            1.0
        } else {
            -1.0
        };
    }
    (square_wave_integral(x + w) - square_wave_integral(x - w)) / (2.0 * w)
}

/// How much of the second value a 2D checkerboard shows at `c`: 0 or 1 at a point, the
/// exact box-filtered fraction over the footprint's bounding box otherwise. With
/// q(s)q(t) = +1 on the first colour's squares and −1 on the second's, the box average
/// of the product is the product of averages, each closed-form.
pub fn checkerboard_2d_weight(c: &TexCoord2D) -> f32 {
    let ws = c.dsdx.abs().max(c.dsdy.abs());
    let wt = c.dtdx.abs().max(c.dtdy.abs());
    let q = square_wave_average(c.st.x, ws) * square_wave_average(c.st.y, wt);
    0.5 * (1.0 - q)
}

/// 0 on cubes with an even sum of integer coordinates, 1 on the others.
pub fn checkerboard_3d_weight(c: &TexCoord3D) -> f32 {
    let f = c.p.floor();
    if (f.x + f.y + f.z).rem_euclid(2.0) == 0.0 {
        0.0
    } else {
        1.0
    }
}

pub fn bilerp(st: Vec2, v00: Rgb, v01: Rgb, v10: Rgb, v11: Rgb) -> Rgb {
    let (s, t) = (st.x, st.y);
    v00 * ((1.0 - s) * (1.0 - t)) + v01 * ((1.0 - s) * t) + v10 * (s * (1.0 - t)) + v11 * (s * t)
}

/// Whether `st` is inside a polka dot: cells of unit size about integer points, a dot
/// in the cells where noise is positive, its centre shifted by noise within the cell.
pub fn inside_dot(st: Vec2) -> bool {
    let cell = (st + 0.5).floor();
    if noise(Vec3::new(cell.x + 0.5, cell.y + 0.5, 0.0)) <= 0.0 {
        return false;
    }
    const RADIUS: f32 = 0.35;
    let max_shift = 0.5 - RADIUS;
    let centre = cell
        + max_shift
            * Vec2::new(
                noise(Vec3::new(cell.x + 1.5, cell.y + 2.8, 0.0)),
                noise(Vec3::new(cell.x + 4.5, cell.y + 9.8, 0.0)),
            );
    (st - centre).length_squared() < RADIUS * RADIUS
}

pub fn fbm_value(c: &TexCoord3D, octaves: u32, roughness: f32) -> f32 {
    fbm(c.p, c.dpdx, c.dpdy, roughness, octaves)
}

pub fn wrinkled_value(c: &TexCoord3D, octaves: u32, roughness: f32) -> f32 {
    turbulence(c.p, c.dpdx, c.dpdy, roughness, octaves)
}

/// Waves whose height follows a slowly varying "wind strength" (Musgrave's windy
/// waves): turbulence at full scale times |fBm| at a tenth of it.
pub fn windy_value(c: &TexCoord3D) -> f32 {
    let strength = fbm(0.1 * c.p, 0.1 * c.dpdx, 0.1 * c.dpdy, 0.5, 3);
    let waves = turbulence(c.p, c.dpdx, c.dpdy, 0.5, 6);
    strength.abs() * waves
}

/// Marble (Perlin 1985): a sine of height perturbed by fBm, through a colour ramp of
/// pale stone with a few dark veins.
pub fn marble_value(
    c: &TexCoord3D,
    octaves: u32,
    roughness: f32,
    scale: f32,
    variation: f32,
) -> Rgb {
    let p = c.p * scale;
    let height = p.y + variation * fbm(p, c.dpdx * scale, c.dpdy * scale, roughness, octaves);
    let x = 0.5 + 0.5 * height.sin();
    marble_ramp(x)
}

/// Catmull–Rom through a fixed palette (an invented stone: greys with a blue-grey vein).
fn marble_ramp(x: f32) -> Rgb {
    const KNOTS: [[f32; 3]; 8] = [
        [0.62, 0.61, 0.60],
        [0.62, 0.61, 0.60],
        [0.55, 0.55, 0.56],
        [0.66, 0.64, 0.61],
        [0.60, 0.60, 0.62],
        [0.25, 0.26, 0.36],
        [0.60, 0.60, 0.62],
        [0.60, 0.60, 0.62],
    ];
    let segments = (KNOTS.len() - 3) as f32;
    let f = x.clamp(0.0, 1.0) * segments;
    let i = (f.floor() as usize).min(KNOTS.len() - 4);
    let t = f - i as f32;
    let k = |j: usize| Rgb::from_array(KNOTS[i + j]);
    let (p0, p1, p2, p3) = (k(0), k(1), k(2), k(3));
    let t2 = t * t;
    let t3 = t2 * t;
    let c = (p1 * 2.0
        + (p2 - p0) * t
        + (p0 * 2.0 - p1 * 5.0 + p2 * 4.0 - p3) * t2
        + (p1 * 3.0 - p0 - p2 * 3.0 + p3) * t3)
        * 0.5;
    c.clamp_min(0.0)
}
