//! Tile-by-tile comparison of two images with bounds from measured noise.
//!
//! Whole-image figures (relMSE, mean) average a local bias away: a 3 % error on one wall
//! of a Cornell box moves the image mean by a fraction of a per cent. Means over small
//! tiles keep it visible while averaging enough pixels that each tile's noise is small
//! and, by the central limit theorem, close to normal.
//!
//! Noise is measured, not assumed. An image is made as the mean of K independent passes
//! (different seeds). Pixel noise is independent between pixels (every pixel's sample
//! stream is hashed from its own coordinates and the seed), so the variance of a tile
//! mean is `Σ_p Var(pixel p) / N²` over its N pixels, and each pixel's variance of the
//! K-pass mean is estimated without bias by the passes' sample variance divided by K:
//! `s²_p / K`, `s²_p = Σ_k (x_pk − x̄_p)² / (K − 1)`. The tile's estimate thus pools
//! N (K − 1) degrees of freedom — 768 for 16×16 tiles and 4 passes — so it scatters by
//! about 5 %, and `diff / SE` is close to a standard normal variate for an unbiased
//! render (Student's t with that many degrees of freedom). The spread of pixel values
//! inside a tile would be no measure at all: it mixes noise with the image's own
//! structure (edges, gradients).
//!
//! Two images with independent noise have `SE² = SE²_a + SE²_b`. A tile passes when
//! each channel's `|mean_a − mean_b| ≤ k · SE + rel_floor · |mean_b| + abs_floor`; the
//! floors absorb what is no noise (rounding of stored references, a deterministic
//! method's discretization, near-black tiles) and are chosen per comparison.

use radiant_math::color::Rgb;

use super::metrics::check_same_size;
use super::{Image, ImageError};

/// Per-tile channel means of an image and the variance of each mean (0 where unknown).
#[derive(Clone, Debug, PartialEq)]
pub struct TileStats {
    /// Tile edge in pixels (tiles on the right and bottom edges may be smaller).
    pub tile: usize,
    pub width: usize,
    pub height: usize,
    /// Tiles across and down.
    pub nx: usize,
    pub ny: usize,
    /// Row-major over tiles: mean of each channel.
    pub mean: Vec<[f64; 3]>,
    /// Row-major over tiles: variance of each channel's mean.
    pub var: Vec<[f64; 3]>,
}

impl TileStats {
    /// Tile means of one image taken as exact (no noise known).
    pub fn from_image(image: &Image, tile: usize) -> TileStats {
        let (nx, ny) = grid(image.width, image.height, tile);
        let mut mean = vec![[0.0; 3]; nx * ny];
        for y in 0..image.height {
            for x in 0..image.width {
                let p = image.get(x, y);
                let m = &mut mean[(y / tile) * nx + x / tile];
                for c in 0..3 {
                    m[c] += p[c] as f64;
                }
            }
        }
        let mut stats = TileStats {
            tile,
            width: image.width,
            height: image.height,
            nx,
            ny,
            mean,
            var: vec![[0.0; 3]; nx * ny],
        };
        for t in 0..nx * ny {
            let n = stats.pixel_count(t) as f64;
            for c in 0..3 {
                stats.mean[t][c] /= n;
            }
        }
        stats
    }

    /// Tile means of the mean of `passes` (independent renders of the same image) and
    /// their variance from the passes' per-pixel spread (see the module comment). Also
    /// returns the mean image. Needs at least two passes of the same size.
    pub fn from_passes(passes: &[Image], tile: usize) -> Result<(TileStats, Image), ImageError> {
        let first = passes.first().ok_or(ImageError::TooFewPasses { got: 0 })?;
        if passes.len() < 2 {
            return Err(ImageError::TooFewPasses { got: passes.len() });
        }
        for p in passes {
            check_same_size(p, first)?;
        }
        let k = passes.len() as f64;
        let (w, h) = (first.width, first.height);
        let mut mean_image = Image::new(w, h);
        let mut stats = TileStats::from_image(first, tile);
        stats.var.iter_mut().for_each(|v| *v = [0.0; 3]);
        stats.mean.iter_mut().for_each(|m| *m = [0.0; 3]);
        for y in 0..h {
            for x in 0..w {
                let t = (y / tile) * stats.nx + x / tile;
                let mut px = [0.0f32; 3];
                for (c, out) in px.iter_mut().enumerate() {
                    let m = passes.iter().map(|p| p.get(x, y)[c] as f64).sum::<f64>() / k;
                    let s2 = passes
                        .iter()
                        .map(|p| (p.get(x, y)[c] as f64 - m).powi(2))
                        .sum::<f64>()
                        / (k - 1.0);
                    stats.mean[t][c] += m;
                    stats.var[t][c] += s2 / k;
                    *out = m as f32;
                }
                mean_image.set(x, y, Rgb::from_array(px));
            }
        }
        for t in 0..stats.mean.len() {
            let n = stats.pixel_count(t) as f64;
            for c in 0..3 {
                stats.mean[t][c] /= n;
                stats.var[t][c] /= n * n;
            }
        }
        Ok((stats, mean_image))
    }

    /// The same means with every variance multiplied by `factor`.
    pub fn scaled_variance(&self, factor: f64) -> TileStats {
        let mut s = self.clone();
        s.var
            .iter_mut()
            .for_each(|v| v.iter_mut().for_each(|x| *x *= factor));
        s
    }

    /// The same means with the variances of `other` (same grid).
    pub fn with_variance_of(&self, other: &TileStats) -> TileStats {
        assert_eq!((self.nx, self.ny), (other.nx, other.ny));
        TileStats {
            var: other.var.clone(),
            ..self.clone()
        }
    }

    /// Pixels in tile `t` (row-major index).
    pub fn pixel_count(&self, t: usize) -> usize {
        let (tx, ty) = (t % self.nx, t / self.nx);
        let w = (self.width - tx * self.tile).min(self.tile);
        let h = (self.height - ty * self.tile).min(self.tile);
        w * h
    }
}

fn grid(width: usize, height: usize, tile: usize) -> (usize, usize) {
    assert!(tile > 0, "tile size 0");
    (width.div_ceil(tile), height.div_ceil(tile))
}

/// When a tile passes: `|diff| ≤ k · SE + rel_floor · |reference mean| + abs_floor` per
/// channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileCriterion {
    pub k: f64,
    pub rel_floor: f64,
    pub abs_floor: f64,
}

/// One tile's figures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileResult {
    /// Tile column and row.
    pub tx: usize,
    pub ty: usize,
    pub test: [f64; 3],
    pub reference: [f64; 3],
    /// Standard error of the difference (both images' noise).
    pub se: [f64; 3],
    /// `(test − reference) / se` per channel (±inf where se is 0 and they differ).
    pub z: [f64; 3],
    /// Left out of the test (and of the failures).
    pub masked: bool,
    /// The largest channel's `|diff|` over its bound: above 1 fails.
    pub excess: f64,
}

impl TileResult {
    pub fn failed(&self) -> bool {
        !self.masked && self.excess > 1.0
    }

    /// The channel with the largest excess and its relative difference.
    pub fn worst_channel(&self) -> (usize, f64) {
        let c = (0..3)
            .max_by(|&a, &b| self.z[a].abs().total_cmp(&self.z[b].abs()))
            .unwrap_or(0);
        let rel = (self.test[c] - self.reference[c]) / self.reference[c].abs().max(1e-12);
        (c, rel)
    }
}

/// Every tile of a comparison.
#[derive(Clone, Debug)]
pub struct TileComparison {
    pub tile: usize,
    pub width: usize,
    pub height: usize,
    pub nx: usize,
    pub ny: usize,
    pub criterion: TileCriterion,
    pub tiles: Vec<TileResult>,
}

/// Compares `test` with `reference` tile by tile. `mask(tx, ty)` true leaves a tile out.
pub fn compare_tiles(
    test: &TileStats,
    reference: &TileStats,
    criterion: TileCriterion,
    mask: &dyn Fn(usize, usize) -> bool,
) -> Result<TileComparison, ImageError> {
    if test.tile != reference.tile {
        return Err(ImageError::TileMismatch {
            a: test.tile,
            b: reference.tile,
        });
    }
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err(ImageError::SizeMismatch {
            test_w: test.width,
            test_h: test.height,
            ref_w: reference.width,
            ref_h: reference.height,
        });
    }
    let tiles = (0..test.mean.len())
        .map(|t| {
            let (tx, ty) = (t % test.nx, t / test.nx);
            let (a, b) = (test.mean[t], reference.mean[t]);
            let mut se = [0.0; 3];
            let mut z = [0.0; 3];
            let mut excess = 0.0f64;
            for c in 0..3 {
                se[c] = (test.var[t][c] + reference.var[t][c]).sqrt();
                let d = a[c] - b[c];
                z[c] = if d == 0.0 { 0.0 } else { d / se[c] };
                let bound =
                    criterion.k * se[c] + criterion.rel_floor * b[c].abs() + criterion.abs_floor;
                let e = if d == 0.0 { 0.0 } else { d.abs() / bound };
                excess = excess.max(if e.is_nan() { f64::INFINITY } else { e });
            }
            TileResult {
                tx,
                ty,
                test: a,
                reference: b,
                se,
                z,
                masked: mask(tx, ty),
                excess,
            }
        })
        .collect();
    Ok(TileComparison {
        tile: test.tile,
        width: test.width,
        height: test.height,
        nx: test.nx,
        ny: test.ny,
        criterion,
        tiles,
    })
}

impl TileComparison {
    pub fn failures(&self) -> Vec<&TileResult> {
        self.tiles.iter().filter(|t| t.failed()).collect()
    }

    /// The `n` unmasked tiles with the largest excess, largest first.
    pub fn worst(&self, n: usize) -> Vec<&TileResult> {
        let mut v: Vec<_> = self.tiles.iter().filter(|t| !t.masked).collect();
        v.sort_by(|a, b| b.excess.total_cmp(&a.excess));
        v.truncate(n);
        v
    }

    /// The largest `|z|` over unmasked tiles and channels.
    pub fn max_abs_z(&self) -> f64 {
        self.tiles
            .iter()
            .filter(|t| !t.masked)
            .flat_map(|t| t.z.map(f64::abs))
            .fold(0.0, f64::max)
    }

    /// A table of the `n` worst tiles: pixel rectangle, channel, means, relative
    /// difference, z and excess.
    pub fn report(&self, n: usize) -> String {
        let mut s = format!(
            "{} of {} tiles fail (k = {}, floor {:.2} % + {:.1e}, {} masked), max |z| {:.2}\n",
            self.failures().len(),
            self.tiles.len(),
            self.criterion.k,
            100.0 * self.criterion.rel_floor,
            self.criterion.abs_floor,
            self.tiles.iter().filter(|t| t.masked).count(),
            self.max_abs_z()
        );
        s += "  tile (x0,y0)-(x1,y1)   ch       test  reference    diff %       z  excess\n";
        for t in self.worst(n) {
            let (c, rel) = t.worst_channel();
            let x0 = t.tx * self.tile;
            let y0 = t.ty * self.tile;
            s += &format!(
                "  ({:3},{:3})-({:3},{:3})  {}  {:9.6}  {:9.6}  {:+7.3}  {:+7.2}  {:6.2}{}\n",
                x0,
                y0,
                (x0 + self.tile).min(self.width),
                (y0 + self.tile).min(self.height),
                ['r', 'g', 'b'][c],
                t.test[c],
                t.reference[c],
                100.0 * rel,
                t.z[c],
                t.excess,
                if t.failed() { "  FAIL" } else { "" }
            );
        }
        s
    }

    /// A false-colour map at the image's size: each tile filled by its signed worst-
    /// channel z (blue below the reference, red above, full colour at ±2k, grey 0),
    /// failing tiles framed in yellow, masked tiles dark hatched.
    pub fn z_map(&self) -> Image {
        let mut img = Image::new(self.width, self.height);
        let k = self.criterion.k;
        for t in &self.tiles {
            let (c, _) = t.worst_channel();
            let fill = if t.masked {
                None
            } else {
                Some(diverging(t.z[c] / (2.0 * k)))
            };
            let x0 = t.tx * self.tile;
            let y0 = t.ty * self.tile;
            let x1 = (x0 + self.tile).min(self.width);
            let y1 = (y0 + self.tile).min(self.height);
            for y in y0..y1 {
                for x in x0..x1 {
                    let edge = x == x0 || y == y0 || x + 1 == x1 || y + 1 == y1;
                    let colour = match fill {
                        None if (x + y) % 4 == 0 => Rgb::splat(0.2),
                        None => Rgb::splat(0.02),
                        Some(_) if edge && t.failed() => Rgb::new(1.0, 0.85, 0.0),
                        Some(f) => f,
                    };
                    img.set(x, y, colour);
                }
            }
        }
        img
    }
}

/// Grey at 0 to blue (−1) or red (+1); values beyond ±1 saturate, NaN is magenta.
fn diverging(t: f64) -> Rgb {
    if t.is_nan() {
        return Rgb::new(1.0, 0.0, 1.0);
    }
    let t = t.clamp(-1.0, 1.0) as f32;
    let grey = Rgb::splat(0.18);
    let end = if t < 0.0 {
        Rgb::new(0.02, 0.1, 1.0)
    } else {
        Rgb::new(1.0, 0.05, 0.02)
    };
    grey * (1.0 - t.abs()) + end * t.abs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_math::hash::{hash_u64s, u32_to_unit_f32};

    /// A smooth image with structure (a gradient and a step), plus independent uniform
    /// noise of standard deviation `sigma` per pixel and channel.
    fn noisy(
        w: usize,
        h: usize,
        sigma: f64,
        seed: u64,
        bias: &dyn Fn(usize, usize) -> f64,
    ) -> Image {
        let mut img = Image::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let base = 0.2 + 0.3 * x as f64 / w as f64 + if y > h / 2 { 0.5 } else { 0.0 };
                let mut px = [0.0f32; 3];
                for (c, v) in px.iter_mut().enumerate() {
                    let u = u32_to_unit_f32(hash_u64s(&[x as u64, y as u64, c as u64, seed]) as u32)
                        as f64;
                    // Uniform on [-√3 σ, √3 σ] has standard deviation σ.
                    let n = (2.0 * u - 1.0) * 3f64.sqrt() * sigma;
                    *v = (base * (1.0 + bias(x, y)) + n) as f32;
                }
                img.set(x, y, Rgb::from_array(px));
            }
        }
        img
    }

    #[test]
    fn tile_means_and_partial_tiles() {
        let mut img = Image::new(5, 3);
        img.set(4, 2, Rgb::new(6.0, 0.0, 3.0));
        let s = TileStats::from_image(&img, 4);
        assert_eq!((s.nx, s.ny), (2, 1));
        assert_eq!(s.pixel_count(1), 3);
        assert_eq!(s.mean[1], [2.0, 0.0, 1.0]);
        assert_eq!(s.mean[0], [0.0; 3]);
    }

    #[test]
    fn pass_variance_is_the_variance_of_the_tile_mean() {
        // Passes with independent noise σ: each pixel's K-pass mean has variance σ²/K,
        // a tile mean of N pixels σ²/(K N).
        let (sigma, k, tile) = (0.1, 4usize, 16usize);
        let passes: Vec<_> = (0..k)
            .map(|s| noisy(64, 64, sigma, s as u64, &|_, _| 0.0))
            .collect();
        let (stats, mean) = TileStats::from_passes(&passes, tile).unwrap();
        let expected = sigma * sigma / (k * tile * tile) as f64;
        let avg: f64 = stats.var.iter().flatten().sum::<f64>() / (3 * stats.var.len()) as f64;
        // 16 tiles × 3 channels × 768 degrees of freedom: the average is within 2 %.
        assert!((avg / expected - 1.0).abs() < 0.02, "{avg} vs {expected}");
        let direct = TileStats::from_image(&mean, tile);
        for (a, b) in stats.mean.iter().zip(&direct.mean) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() < 1e-6);
            }
        }
        assert!(TileStats::from_passes(&passes[..1], tile).is_err());
    }

    #[test]
    fn unbiased_images_pass_and_a_local_bias_fails() {
        let criterion = TileCriterion {
            k: 4.0,
            rel_floor: 0.0,
            abs_floor: 0.0,
        };
        let passes = |seed: u64, bias: &dyn Fn(usize, usize) -> f64| {
            (0..4)
                .map(|s| noisy(128, 128, 0.05, seed * 10 + s, bias))
                .collect::<Vec<_>>()
        };
        let (a, _) = TileStats::from_passes(&passes(1, &|_, _| 0.0), 16).unwrap();
        let (b, _) = TileStats::from_passes(&passes(2, &|_, _| 0.0), 16).unwrap();
        let same = compare_tiles(&a, &b, criterion, &|_, _| false).unwrap();
        assert!(same.failures().is_empty(), "{}", same.report(5));
        // z over 64 tiles × 3 channels is close to standard normal: its RMS near 1.
        let rms = (same
            .tiles
            .iter()
            .flat_map(|t| t.z)
            .map(|z| z * z)
            .sum::<f64>()
            / (3 * same.tiles.len()) as f64)
            .sqrt();
        assert!((0.8..1.2).contains(&rms), "rms z {rms}");

        // 3 % too dark in one 20×20 patch: its tiles fail, the others do not.
        let patch = |x: usize, y: usize| (40..60).contains(&x) && (70..90).contains(&y);
        let (c, _) = TileStats::from_passes(
            &passes(3, &|x, y| if patch(x, y) { -0.03 } else { 0.0 }),
            16,
        )
        .unwrap();
        let cmp = compare_tiles(&c, &b, criterion, &|_, _| false).unwrap();
        let failed: Vec<_> = cmp.failures().iter().map(|t| (t.tx, t.ty)).collect();
        assert!(!failed.is_empty(), "{}", cmp.report(5));
        assert!(
            failed
                .iter()
                .all(|&(tx, ty)| (2..=3).contains(&tx) && (4..=5).contains(&ty)),
            "{failed:?}"
        );
        assert!(cmp.report(3).contains("FAIL"));
        // Masking those tiles, or a floor above the bias, makes it pass.
        let masked =
            compare_tiles(&c, &b, criterion, &|tx, ty| failed.contains(&(tx, ty))).unwrap();
        assert!(masked.failures().is_empty());
        let floored = compare_tiles(
            &c,
            &b,
            TileCriterion {
                k: 4.0,
                rel_floor: 0.04,
                abs_floor: 0.0,
            },
            &|_, _| false,
        )
        .unwrap();
        assert!(floored.failures().is_empty());

        let map = cmp.z_map();
        assert_eq!((map.width, map.height), (128, 128));
        // A failing tile's frame is yellow, an unmasked tile's inside is not.
        let (tx, ty) = failed[0];
        assert_eq!(map.get(tx * 16, ty * 16 + 5), Rgb::new(1.0, 0.85, 0.0));
        assert_ne!(map.get(tx * 16 + 5, ty * 16 + 5), Rgb::new(1.0, 0.85, 0.0));
    }
}
