//! Images and files: the film that integrators accumulate into, pixel filters, the
//! EXR / PFM / PNG writers and readers, and the error metrics used to compare renders.

pub mod film;
pub mod filter;

use crate::color::Rgb;

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
}

/// Facts about how an image was made, written into file headers where the format has room
/// (EXR attributes `samplesPerPixel`, `renderTimeSeconds`, `software`).
#[derive(Clone, Debug, Default)]
pub struct ImageMeta {
    pub samples_per_pixel: Option<u32>,
    pub render_time_seconds: Option<f64>,
    pub software: String,
}
