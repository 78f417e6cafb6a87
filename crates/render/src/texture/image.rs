//! Image textures: files decoded to linear RGB and their MIP pyramids (Williams 1983),
//! each built once per (file, encoding) and shared through `Arc` by every texture that
//! reads it.
//!
//! 8- and 16-bit images (PNG, JPEG, TGA) are decoded by the `image` crate and turned
//! linear by their encoding (sRGB unless the scene says otherwise); Radiance HDR, EXR and
//! PFM hold linear floats already. Each pyramid level halves the one below with a 2×2
//! box; an odd side repeats its last row or column for the pair it lacks.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use radiant_math::color::Rgb;
use radiant_scene::{ColorEncoding, WrapMode};

/// One level of the pyramid, row 0 at the top of the image.
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    pub width: usize,
    pub height: usize,
    texels: Texels,
}

/// How a level holds its texels. An 8-bit image keeps its codes, a quarter of the
/// memory of linear floats, and decodes them through a 256-entry table on each read:
/// the floats read are those a decoded copy would hold, while a 1024² image takes 3 MB
/// instead of 12 and its bilinear reads, which are cache misses, meet fewer lines.
#[derive(Clone, Debug, PartialEq)]
enum Texels {
    Linear(Vec<Rgb>),
    Coded {
        codes: Vec<[u8; 3]>,
        decode: Box<[f32; 256]>,
    },
}

impl Level {
    pub fn new(width: usize, height: usize, texels: Vec<Rgb>) -> Level {
        assert_eq!(texels.len(), width * height, "texel count");
        Level {
            width,
            height,
            texels: Texels::Linear(texels),
        }
    }

    /// A level of 8-bit codes, each channel's linear value `decode[code]`.
    pub fn coded(width: usize, height: usize, codes: Vec<[u8; 3]>, decode: [f32; 256]) -> Level {
        assert_eq!(codes.len(), width * height, "texel count");
        Level {
            width,
            height,
            texels: Texels::Coded {
                codes,
                decode: Box::new(decode),
            },
        }
    }

    /// The texel at `i` in row-major order.
    #[inline(always)]
    pub fn at(&self, i: usize) -> Rgb {
        match &self.texels {
            Texels::Linear(t) => t[i],
            Texels::Coded { codes, decode } => {
                let [r, g, b] = codes[i];
                Rgb::new(decode[r as usize], decode[g as usize], decode[b as usize])
            }
        }
    }

    /// The texel at integer coordinates, outside the image as `wrap` says.
    pub fn texel(&self, x: i64, y: i64, wrap: WrapMode) -> Rgb {
        let (w, h) = (self.width as i64, self.height as i64);
        let (x, y) = match wrap {
            WrapMode::Repeat => (x.rem_euclid(w), y.rem_euclid(h)),
            WrapMode::Clamp => (x.clamp(0, w - 1), y.clamp(0, h - 1)),
            WrapMode::Black => {
                if x < 0 || x >= w || y < 0 || y >= h {
                    return Rgb::BLACK;
                }
                (x, y)
            }
            WrapMode::OctahedralSphere => octahedral_wrap(x, y, w, h),
        };
        self.at(y as usize * self.width + x as usize)
    }

    /// The 2 × 2 texels from (x, y) to (x + 1, y + 1) that bilinear interpolation reads,
    /// row by row, each as [`texel`](Self::texel) gives it. For the common wrap modes the
    /// second column and row follow from the first instead of being wrapped anew:
    /// repeating takes a remainder, which is a division, and four texels would take eight.
    pub fn quad(&self, x: i64, y: i64, wrap: WrapMode) -> [Rgb; 4] {
        let (w, h) = (self.width as i64, self.height as i64);
        let pair = |x: i64, n: i64| -> Option<(usize, usize)> {
            match wrap {
                WrapMode::Repeat => {
                    let a = x.rem_euclid(n);
                    Some((a as usize, if a + 1 == n { 0 } else { a as usize + 1 }))
                }
                WrapMode::Clamp => {
                    Some((x.clamp(0, n - 1) as usize, (x + 1).clamp(0, n - 1) as usize))
                }
                WrapMode::Black | WrapMode::OctahedralSphere => None,
            }
        };
        match (pair(x, w), pair(y, h)) {
            (Some((x0, x1)), Some((y0, y1))) => {
                let (r0, r1) = (y0 * self.width, y1 * self.width);
                [
                    self.at(r0 + x0),
                    self.at(r0 + x1),
                    self.at(r1 + x0),
                    self.at(r1 + x1),
                ]
            }
            _ => [
                self.texel(x, y, wrap),
                self.texel(x + 1, y, wrap),
                self.texel(x, y + 1, wrap),
                self.texel(x + 1, y + 1, wrap),
            ],
        }
    }

    /// Half the size, by 2×2 box averages.
    fn downsample(&self) -> Level {
        let (w, h) = (
            self.width.div_ceil(2).max(1),
            self.height.div_ceil(2).max(1),
        );
        let at = |x: usize, y: usize| {
            self.at(y.min(self.height - 1) * self.width + x.min(self.width - 1))
        };
        let mut texels = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let (x0, y0) = (2 * x, 2 * y);
                texels.push(
                    (at(x0, y0) + at(x0 + 1, y0) + at(x0, y0 + 1) + at(x0 + 1, y0 + 1)) * 0.25,
                );
            }
        }
        Level::new(w, h, texels)
    }
}

/// The equal-area octahedral square is continuous across its edges when mirrored: a
/// step past one side comes back in at the mirrored position along it.
fn octahedral_wrap(mut x: i64, mut y: i64, w: i64, h: i64) -> (i64, i64) {
    if x < 0 {
        x = -x - 1;
        y = h - 1 - y;
    } else if x >= w {
        x = 2 * w - 1 - x;
        y = h - 1 - y;
    }
    if y < 0 {
        x = w - 1 - x;
        y = -y - 1;
    } else if y >= h {
        x = w - 1 - x;
        y = 2 * h - 1 - y;
    }
    (x.clamp(0, w - 1), y.clamp(0, h - 1))
}

/// A MIP pyramid: level 0 is the image, the last is 1×1.
#[derive(Clone, Debug, PartialEq)]
pub struct MipMap {
    pub levels: Vec<Level>,
}

impl MipMap {
    pub fn new(base: Level) -> MipMap {
        let mut levels = vec![base];
        loop {
            let last = levels.last().expect("at least the base");
            if last.width == 1 && last.height == 1 {
                break;
            }
            let next = last.downsample();
            levels.push(next);
        }
        MipMap { levels }
    }

    pub fn width(&self) -> usize {
        self.levels[0].width
    }

    pub fn height(&self) -> usize {
        self.levels[0].height
    }
}

/// Why an image could not be used.
#[derive(Debug, thiserror::Error)]
pub enum ImageTextureError {
    #[error("cannot read image '{path}': {message}")]
    Read { path: PathBuf, message: String },
    #[error("image '{path}' is empty")]
    Empty { path: PathBuf },
}

/// The linear value of an encoded one in [0, 1].
pub fn decode(encoding: ColorEncoding, v: f32) -> f32 {
    match encoding {
        ColorEncoding::Linear => v,
        ColorEncoding::Srgb => radiant_image::png::srgb_eotf(v),
        ColorEncoding::Gamma(g) => v.max(0.0).powf(g),
    }
}

/// Reads an image as linear RGB. `encoding` applies to integer images (default sRGB)
/// and is ignored for float ones.
pub fn read_linear(
    path: &Path,
    encoding: Option<ColorEncoding>,
) -> Result<Level, ImageTextureError> {
    let err = |message: String| ImageTextureError::Read {
        path: path.to_path_buf(),
        message,
    };
    let finish = |level: Level| {
        if level.width == 0 || level.height == 0 {
            return Err(ImageTextureError::Empty {
                path: path.to_path_buf(),
            });
        }
        Ok(level)
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let level = match ext.as_str() {
        "exr" | "pfm" => {
            let img = if ext == "exr" {
                radiant_image::exr::read_exr(path)
            } else {
                radiant_image::pfm::read_pfm(path)
            }
            .map_err(|e| err(e.to_string()))?;
            let (w, h) = (img.width, img.height);
            let texels = (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| img.get(x, y))
                .collect();
            Level::new(w, h, texels)
        }
        _ => {
            let reader = image::ImageReader::open(path)
                .map_err(|e| err(e.to_string()))?
                .with_guessed_format()
                .map_err(|e| err(e.to_string()))?;
            let img = reader.decode().map_err(|e| err(e.to_string()))?;
            let (w, h) = (img.width() as usize, img.height() as usize);
            let enc = encoding.unwrap_or(ColorEncoding::Srgb);
            use image::DynamicImage as D;
            let texels: Vec<Rgb> = match &img {
                D::ImageRgb32F(_) | D::ImageRgba32F(_) => img
                    .to_rgb32f()
                    .pixels()
                    .map(|p| Rgb::new(p[0], p[1], p[2]))
                    .collect(),
                D::ImageLuma16(_) | D::ImageLumaA16(_) | D::ImageRgb16(_) | D::ImageRgba16(_) => {
                    img.to_rgb16()
                        .pixels()
                        .map(|p| {
                            Rgb::from_array([0, 1, 2].map(|c| decode(enc, p[c] as f32 / 65535.0)))
                        })
                        .collect()
                }
                _ => {
                    // 256 entries: each 8-bit code decoded once, and read through the
                    // table at every lookup.
                    let table: [f32; 256] = std::array::from_fn(|c| decode(enc, c as f32 / 255.0));
                    let codes = img.to_rgb8().pixels().map(|p| p.0).collect();
                    return finish(Level::coded(w, h, codes, table));
                }
            };
            Level::new(w, h, texels)
        }
    };
    finish(level)
}

/// Pyramids by file and encoding, so that a file read by several textures is read and
/// filtered once.
#[derive(Default)]
pub struct ImageCache {
    maps: HashMap<(PathBuf, String), Arc<MipMap>>,
}

impl ImageCache {
    pub fn get(
        &mut self,
        path: &Path,
        encoding: Option<ColorEncoding>,
    ) -> Result<Arc<MipMap>, ImageTextureError> {
        let key = (path.to_path_buf(), format!("{encoding:?}"));
        if let Some(m) = self.maps.get(&key) {
            return Ok(m.clone());
        }
        let map = Arc::new(MipMap::new(read_linear(path, encoding)?));
        self.maps.insert(key, map.clone());
        Ok(map)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An 8-bit level reads, wraps and filters into its pyramid exactly as the level of
    /// its decoded floats does.
    #[test]
    fn a_coded_level_reads_as_its_decoded_floats() {
        let table: [f32; 256] =
            std::array::from_fn(|c| decode(ColorEncoding::Srgb, c as f32 / 255.0));
        let (w, h) = (7, 5);
        let codes: Vec<[u8; 3]> = (0..w * h)
            .map(|i| {
                [
                    (i * 37 % 256) as u8,
                    (i * 101 % 256) as u8,
                    (255 - i * 11 % 256) as u8,
                ]
            })
            .collect();
        let floats = codes
            .iter()
            .map(|c| {
                Rgb::new(
                    table[c[0] as usize],
                    table[c[1] as usize],
                    table[c[2] as usize],
                )
            })
            .collect();
        let (coded, linear) = (Level::coded(w, h, codes, table), Level::new(w, h, floats));
        for wrap in [WrapMode::Repeat, WrapMode::Clamp, WrapMode::Black] {
            for x in -9..16 {
                for y in -9..16 {
                    assert_eq!(coded.texel(x, y, wrap), linear.texel(x, y, wrap));
                    assert_eq!(coded.quad(x, y, wrap), linear.quad(x, y, wrap));
                }
            }
        }
        let (a, b) = (MipMap::new(coded), MipMap::new(linear));
        assert_eq!(a.levels.len(), b.levels.len());
        for (la, lb) in a.levels.iter().zip(&b.levels).skip(1) {
            assert_eq!(la, lb, "the levels above the image are the same floats");
        }
    }

    /// The 2 × 2 block equals four single reads, in every wrap mode, for images down to
    /// one texel wide or high and coordinates inside, beside and far outside them.
    #[test]
    fn a_quad_is_four_texels() {
        for (w, h) in [(1, 1), (1, 5), (4, 1), (2, 2), (7, 3), (16, 16)] {
            let texels = (0..w * h)
                .map(|i| Rgb::new(i as f32, (i * 7 % 5) as f32, 0.5))
                .collect();
            let level = Level::new(w, h, texels);
            for wrap in [
                WrapMode::Repeat,
                WrapMode::Clamp,
                WrapMode::Black,
                WrapMode::OctahedralSphere,
            ] {
                if wrap == WrapMode::OctahedralSphere && w != h {
                    continue;
                }
                let coords = (-40i64..40).chain([i64::from(i32::MAX), -i64::from(i32::MAX)]);
                for x in coords.clone() {
                    for y in coords.clone().step_by(3) {
                        let single = [
                            level.texel(x, y, wrap),
                            level.texel(x + 1, y, wrap),
                            level.texel(x, y + 1, wrap),
                            level.texel(x + 1, y + 1, wrap),
                        ];
                        assert_eq!(
                            level.quad(x, y, wrap),
                            single,
                            "{w}x{h} {wrap:?} ({x}, {y})"
                        );
                    }
                }
            }
        }
    }
}
