//! The picture of an area light with an image (pbrt-v4's `DiffuseAreaLight` with
//! `filename`): the emitted radiance varies over the surface as the image does,
//! looked up at the surface's (u, 1 − v) — row 0 of the file at v = 1, as image
//! textures are — with bilinear interpolation between texel centres and the border
//! texels repeated outside them.

use glam::Vec2;
use radiant_math::color::Rgb;

#[derive(Clone, Debug, PartialEq)]
pub struct EmissionImage {
    width: usize,
    height: usize,
    /// Linear RGB, row by row from the top, each channel finite and ≥ 0.
    texels: Vec<Rgb>,
    /// The mean texel, which is the mean over the (u, v) square of the bilinear
    /// interpolant up to the half-texel border: what the light's power uses.
    mean: Rgb,
}

impl EmissionImage {
    /// The image of `width` × `height` texels (`texels.len()` must be their product,
    /// both at least 1).
    pub fn new(width: usize, height: usize, texels: Vec<Rgb>) -> EmissionImage {
        assert!(width > 0 && height > 0 && texels.len() == width * height);
        let mut sum = [0.0f64; 3];
        for t in &texels {
            sum[0] += t.r as f64;
            sum[1] += t.g as f64;
            sum[2] += t.b as f64;
        }
        let n = texels.len() as f64;
        let mean = Rgb::new(
            (sum[0] / n) as f32,
            (sum[1] / n) as f32,
            (sum[2] / n) as f32,
        );
        EmissionImage {
            width,
            height,
            texels,
            mean,
        }
    }

    pub fn mean(&self) -> Rgb {
        self.mean
    }

    fn texel(&self, x: i64, y: i64) -> Rgb {
        let x = x.clamp(0, self.width as i64 - 1) as usize;
        let y = y.clamp(0, self.height as i64 - 1) as usize;
        self.texels[y * self.width + x]
    }

    /// The image at surface parameters `uv`.
    pub fn lookup(&self, uv: Vec2) -> Rgb {
        let x = uv.x * self.width as f32 - 0.5;
        let y = (1.0 - uv.y) * self.height as f32 - 0.5;
        if !(x.is_finite() && y.is_finite()) {
            return Rgb::BLACK;
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (dx, dy) = (x - x0, y - y0);
        let (xi, yi) = (x0 as i64, y0 as i64);
        self.texel(xi, yi) * ((1.0 - dx) * (1.0 - dy))
            + self.texel(xi + 1, yi) * (dx * (1.0 - dy))
            + self.texel(xi, yi + 1) * ((1.0 - dx) * dy)
            + self.texel(xi + 1, yi + 1) * (dx * dy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texel_centres_are_exact_and_rows_run_down_from_v_one() {
        // 2 × 2: top row red, green; bottom row blue, white.
        let img = EmissionImage::new(
            2,
            2,
            vec![
                Rgb::new(1.0, 0.0, 0.0),
                Rgb::new(0.0, 1.0, 0.0),
                Rgb::new(0.0, 0.0, 1.0),
                Rgb::WHITE,
            ],
        );
        assert_eq!(img.lookup(Vec2::new(0.25, 0.75)), Rgb::new(1.0, 0.0, 0.0));
        assert_eq!(img.lookup(Vec2::new(0.75, 0.75)), Rgb::new(0.0, 1.0, 0.0));
        assert_eq!(img.lookup(Vec2::new(0.25, 0.25)), Rgb::new(0.0, 0.0, 1.0));
        assert_eq!(img.lookup(Vec2::new(0.75, 0.25)), Rgb::WHITE);
        // Halfway between the two top texels, and clamped past the border.
        assert_eq!(img.lookup(Vec2::new(0.5, 0.75)), Rgb::new(0.5, 0.5, 0.0));
        assert_eq!(img.lookup(Vec2::new(0.0, 1.0)), Rgb::new(1.0, 0.0, 0.0));
        assert_eq!(img.lookup(Vec2::new(-3.0, 7.0)), Rgb::new(1.0, 0.0, 0.0));
        assert_eq!(img.mean(), Rgb::new(0.5, 0.5, 0.5));
    }

    #[test]
    fn the_mean_is_the_average_of_the_interpolant_over_the_square() {
        // A ramp 0, 1, 2, 3 across: the interpolant is flat over the outer half texels,
        // linear between centres; its integral over [0,1] equals the texel mean.
        let img = EmissionImage::new(4, 1, (0..4).map(|i| Rgb::splat(i as f32)).collect());
        let n = 4000;
        let avg: f64 = (0..n)
            .map(|i| img.lookup(Vec2::new((i as f32 + 0.5) / n as f32, 0.5)).r as f64)
            .sum::<f64>()
            / n as f64;
        assert!((avg - 1.5).abs() < 1e-3, "{avg}");
        assert_eq!(img.mean().r, 1.5);
    }
}
