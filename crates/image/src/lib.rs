//! Images and files: the film that integrators accumulate into, pixel filters, the
//! EXR / PFM / PNG writers and readers, and the error metrics used to compare renders.

#![forbid(unsafe_code)]

pub mod atomic;
pub mod error;
pub mod exr;
pub mod falsecolor;
pub mod film;
pub mod filter;
pub mod flip;
pub mod metrics;
pub mod pfm;
pub mod png;
#[cfg(test)]
mod reference_tests;
pub mod tiles;
pub mod white_balance;

use std::path::Path;

use radiant_math::color::Rgb;

pub use error::ImageError;

/// The most samples (pixels × channels, all layers together) an image file may declare:
/// 2^30, 4 GiB of f32 — far beyond any render, texture or environment map radiant
/// reads. Readers check headers against it before allocating.
pub const MAX_READ_SAMPLES: u64 = 1 << 30;
pub use film::{Film, FilmPixel, NonFinite, Sensor};
pub use filter::{Filter, FilterSample};
pub use metrics::{Metrics, compare};
pub use tiles::{TileComparison, TileCriterion, TileStats, compare_tiles};

/// A linear RGB image, row-major, row 0 at the top (pixel (0,0) is top-left).
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<Rgb>,
}

impl Image {
    pub fn new(width: usize, height: usize) -> Image {
        Image {
            width,
            height,
            pixels: vec![Rgb::BLACK; width * height],
        }
    }

    pub fn get(&self, x: usize, y: usize) -> Rgb {
        self.pixels[y * self.width + x]
    }

    pub fn set(&mut self, x: usize, y: usize, c: Rgb) {
        self.pixels[y * self.width + x] = c;
    }

    /// Mean over all pixels and channels.
    pub fn mean(&self) -> f64 {
        let s: f64 = self
            .pixels
            .iter()
            .map(|p| p.r as f64 + p.g as f64 + p.b as f64)
            .sum();
        s / (3 * self.pixels.len()).max(1) as f64
    }

    /// Mean over the pixels inside `crop` and all channels (sums in f64).
    pub fn mean_in(&self, crop: Crop) -> Result<f64, ImageError> {
        crop.check(self.width, self.height)?;
        let mut s = 0.0f64;
        for y in crop.y0..crop.y1 {
            for p in &self.pixels[y * self.width + crop.x0..y * self.width + crop.x1] {
                s += p.r as f64 + p.g as f64 + p.b as f64;
            }
        }
        Ok(s / (3 * crop.width() * crop.height()) as f64)
    }

    /// A copy of the pixels inside `crop`.
    pub fn crop(&self, crop: Crop) -> Result<Image, ImageError> {
        crop.check(self.width, self.height)?;
        let mut pixels = Vec::with_capacity(crop.width() * crop.height());
        for y in crop.y0..crop.y1 {
            pixels.extend_from_slice(
                &self.pixels[y * self.width + crop.x0..y * self.width + crop.x1],
            );
        }
        Ok(Image {
            width: crop.width(),
            height: crop.height(),
            pixels,
        })
    }

    /// Checks that the image is non-empty and its buffer matches its size; `path` is only
    /// used in the message.
    pub fn validate(&self, path: &Path) -> Result<(), ImageError> {
        let invalid = |message: String| ImageError::InvalidImage {
            path: path.to_path_buf(),
            message,
        };
        if self.width == 0 || self.height == 0 {
            return Err(invalid(format!("size {}x{}", self.width, self.height)));
        }
        if self.width.checked_mul(self.height) != Some(self.pixels.len()) {
            return Err(invalid(format!(
                "{} pixels for a {}x{} image",
                self.pixels.len(),
                self.width,
                self.height
            )));
        }
        Ok(())
    }
}

/// Facts about how an image was made, written into file headers where the format has room
/// (EXR attributes `samplesPerPixel`, `renderTimeSeconds`, `software`).
#[derive(Clone, Debug, Default)]
pub struct ImageMeta {
    pub samples_per_pixel: Option<u32>,
    pub render_time_seconds: Option<f64>,
    pub software: String,
}

/// A half-open pixel rectangle `x0 <= x < x1`, `y0 <= y < y1` (y down, row 0 at the top).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

impl Crop {
    /// The rectangle covering a whole `width` x `height` image.
    pub fn full(width: usize, height: usize) -> Crop {
        Crop {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    pub fn width(&self) -> usize {
        self.x1.saturating_sub(self.x0)
    }

    pub fn height(&self) -> usize {
        self.y1.saturating_sub(self.y0)
    }

    /// Errors if the rectangle is empty or sticks out of a `width` x `height` image.
    pub fn check(&self, width: usize, height: usize) -> Result<(), ImageError> {
        if self.x0 < self.x1 && self.y0 < self.y1 && self.x1 <= width && self.y1 <= height {
            Ok(())
        } else {
            Err(ImageError::BadCrop {
                x0: self.x0,
                y0: self.y0,
                x1: self.x1,
                y1: self.y1,
                width,
                height,
            })
        }
    }
}

impl std::str::FromStr for Crop {
    type Err = String;

    /// Parses `x0,y0,x1,y1`.
    fn from_str(s: &str) -> Result<Crop, String> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        let [x0, y0, x1, y1] = parts.as_slice() else {
            return Err(format!("expected x0,y0,x1,y1, got `{s}`"));
        };
        let num = |t: &str| {
            t.parse::<usize>()
                .map_err(|_| format!("`{t}` is not a pixel coordinate in `{s}`"))
        };
        Ok(Crop {
            x0: num(x0)?,
            y0: num(y0)?,
            x1: num(x1)?,
            y1: num(y1)?,
        })
    }
}

/// The image file formats radiant reads and writes, chosen from the file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Exr,
    Pfm,
    Png,
}

impl Format {
    /// The format named by `path`'s extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Format, ImageError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("exr") => Ok(Format::Exr),
            Some("pfm") => Ok(Format::Pfm),
            Some("png") => Ok(Format::Png),
            _ => Err(ImageError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }
}

/// Writes `image` in the format named by the extension of `path`. `meta` goes into EXR
/// headers; `exposure_stops` only affects PNG (the HDR formats store linear radiance).
pub fn write_image(
    path: impl AsRef<Path>,
    image: &Image,
    meta: &ImageMeta,
    exposure_stops: f32,
) -> Result<(), ImageError> {
    let path = path.as_ref();
    match Format::from_path(path)? {
        Format::Exr => exr::write_exr(path, image, meta),
        Format::Pfm => pfm::write_pfm(path, image),
        Format::Png => png::write_png(path, image, exposure_stops),
    }
}

/// Writes `path` all or nothing through [`atomic::AtomicFile`]: `write` fills a temporary
/// file beside it, which replaces `path` only once complete and synced.
pub(crate) fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<(), ImageError>,
) -> Result<(), ImageError> {
    let mut file = atomic::AtomicFile::create(path).map_err(|e| ImageError::io(path, e))?;
    write(file.writer())?;
    file.commit().map_err(|e| ImageError::io(path, e))
}

/// Checks before rendering that `path` names a known image format and can be created
/// (its folder exists and is writable); returns the format.
pub fn check_output(path: impl AsRef<Path>) -> Result<Format, ImageError> {
    let path = path.as_ref();
    let format = Format::from_path(path)?;
    atomic::check_writable(path).map_err(|e| ImageError::io(path, e))?;
    Ok(format)
}

/// Reads an image in the format named by the extension of `path`, as linear RGB.
pub fn read_image(path: impl AsRef<Path>) -> Result<Image, ImageError> {
    let path = path.as_ref();
    match Format::from_path(path)? {
        Format::Exr => exr::read_exr(path),
        Format::Pfm => pfm::read_pfm(path),
        Format::Png => png::read_png(path),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dispatch_by_extension_is_case_insensitive() {
        let dir = std::env::temp_dir().join(format!("radiant-dispatch-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut img = Image::new(3, 2);
        img.set(2, 1, Rgb::new(0.5, 2.0, 1e-3));
        for name in ["a.EXR", "b.Pfm", "c.exr", "d.pfm"] {
            let path = dir.join(name);
            write_image(&path, &img, &ImageMeta::default(), 0.0).unwrap();
            assert_eq!(read_image(&path).unwrap(), img, "{name}");
            std::fs::remove_file(&path).ok();
        }
        // PNG clips 2.0 to white and quantises: check the format was really PNG.
        let path = dir.join("e.PNG");
        write_image(&path, &img, &ImageMeta::default(), 0.0).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::remove_file(&path).ok();
        assert_eq!(&bytes[1..4], b"PNG");

        for bad in ["f.jpg", "noextension"] {
            let err = write_image(dir.join(bad), &img, &ImageMeta::default(), 0.0)
                .unwrap_err()
                .to_string();
            assert!(
                err.contains(bad) && err.contains("unknown image format"),
                "{err}"
            );
            let err = read_image(dir.join(bad)).unwrap_err().to_string();
            assert!(err.contains(bad), "{err}");
        }
    }

    #[test]
    fn crop_parses_and_checks() {
        let c: Crop = "1, 2,30,40".parse().unwrap();
        assert_eq!((c.x0, c.y0, c.x1, c.y1), (1, 2, 30, 40));
        assert!("1,2,3".parse::<Crop>().is_err());
        assert!("1,2,3,-4".parse::<Crop>().is_err());
        assert!(c.check(30, 40).is_ok());
        assert!(c.check(29, 40).is_err());
        let empty = Crop { x1: 1, ..c };
        assert!(empty.check(30, 40).is_err());
    }

    #[test]
    fn writers_reject_empty_images() {
        let path = std::env::temp_dir().join("radiant-empty.pfm");
        let err = write_image(&path, &Image::new(0, 4), &ImageMeta::default(), 0.0).unwrap_err();
        assert!(matches!(err, ImageError::InvalidImage { .. }), "{err}");
    }
}
