//! The film: per-pixel sums of filtered radiance samples.
//!
//! Pixel filtering is done by filter importance sampling: each camera sample is
//! offset by a draw from the filter and counts, with the weight f/pdf, for the pixel it
//! was generated for only. Pixels are therefore independent, rows can be rendered in
//! parallel, and the sum in every pixel is taken in sample order — the same image at
//! any thread count.
//!
//! The sensor (pbrt-v4's `PixelSensor`) is applied here and nowhere else: integrators
//! accumulate scene radiance times the camera's weight, and every readout of the film
//! — the image, snapshots, partial images — scales by the sensor's imaging ratio.

use super::Image;
use radiant_math::color::Rgb;

/// Accumulated samples of one pixel (f64 sums: thousands of samples per pixel).
#[derive(Clone, Copy, Debug, Default)]
pub struct FilmPixel {
    pub sum: [f64; 3],
    pub weight: f64,
    /// Samples taken, including dropped non-finite ones.
    pub samples: u32,
}

impl FilmPixel {
    pub fn add(&mut self, l: Rgb, weight: f32) {
        self.sum[0] += (l.r * weight) as f64;
        self.sum[1] += (l.g * weight) as f64;
        self.sum[2] += (l.b * weight) as f64;
        self.weight += weight as f64;
        self.samples += 1;
    }

    /// A pixel holding an integrator's own estimate (SPPM's progressive statistics),
    /// made from `samples` samples.
    pub fn estimate(value: [f64; 3], samples: u32) -> FilmPixel {
        FilmPixel {
            sum: value,
            weight: 1.0,
            samples,
        }
    }

    /// The weighted mean of the samples, before the sensor.
    pub fn value(&self) -> Rgb {
        if self.weight == 0.0 {
            return Rgb::BLACK;
        }
        let inv = 1.0 / self.weight;
        Rgb::new(
            (self.sum[0] * inv) as f32,
            (self.sum[1] * inv) as f32,
            (self.sum[2] * inv) as f32,
        )
    }
}

/// Samples that were not finite, reported after the render (never written).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NonFinite {
    pub count: u64,
    /// The first pixel (in row-major order) that produced one.
    pub first_pixel: Option<(u32, u32)>,
}

impl NonFinite {
    pub fn merge(&mut self, other: NonFinite) {
        self.count += other.count;
        self.first_pixel = match (self.first_pixel, other.first_pixel) {
            (Some(a), Some(b)) => Some(if (a.1, a.0) <= (b.1, b.0) { a } else { b }),
            (a, b) => a.or(b),
        };
    }
}

/// The sensor's response: pbrt-v4's imaging ratio, exposure time × ISO / 100, which
/// turns scene radiance into the recorded value (1 at ISO 100 and a 1 s shutter).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensor {
    pub imaging_ratio: f32,
    /// Samples whose largest CIE XYZ component, as recorded, is above this are scaled
    /// down to it (pbrt-v4's `maxcomponentvalue`; infinite: no clamp).
    pub max_component: f32,
    /// White balance on the recorded linear sRGB, if any (see
    /// [`crate::white_balance`]).
    pub white_balance: Option<[[f32; 3]; 3]>,
}

impl Sensor {
    /// ISO 100 and a one-second exposure: pixels record radiance as it is.
    pub const UNIT: Sensor = Sensor {
        imaging_ratio: 1.0,
        max_component: f32::INFINITY,
        white_balance: None,
    };

    pub fn new(iso: f32, exposure_time: f32) -> Sensor {
        Sensor {
            imaging_ratio: exposure_time * iso / 100.0,
            ..Sensor::UNIT
        }
    }

    pub fn with_max_component(self, max_component: f32) -> Sensor {
        Sensor {
            max_component,
            ..self
        }
    }

    /// Balances the white of daylight at `kelvin` to D65 (`None`: no balance).
    pub fn with_white_balance(self, kelvin: Option<f32>) -> Sensor {
        Sensor {
            white_balance: kelvin.map(crate::white_balance::white_balance),
            ..self
        }
    }

    /// A radiance sample as it goes into a pixel: scaled down so that no XYZ
    /// component of what the sensor records exceeds `max_component` (its chromaticity
    /// kept). The identity without a clamp.
    pub fn clamp_sample(&self, l: Rgb) -> Rgb {
        if self.max_component == f32::INFINITY {
            return l;
        }
        let xyz = crate::white_balance::apply(&crate::white_balance::XYZ_FROM_RGB, [l.r, l.g, l.b]);
        let m = xyz[0].max(xyz[1]).max(xyz[2]) * self.imaging_ratio;
        if m > self.max_component {
            l * (self.max_component / m)
        } else {
            l
        }
    }

    /// A pixel's accumulated radiance as the sensor records it.
    pub fn record(&self, l: Rgb) -> Rgb {
        let v = l * self.imaging_ratio;
        match &self.white_balance {
            None => v,
            Some(m) => {
                let [r, g, b] = crate::white_balance::apply(m, [v.r, v.g, v.b]);
                Rgb::new(r, g, b)
            }
        }
    }
}

impl Default for Sensor {
    fn default() -> Self {
        Sensor::UNIT
    }
}

#[derive(Clone, Debug)]
pub struct Film {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<FilmPixel>,
    pub nonfinite: NonFinite,
    pub sensor: Sensor,
    /// Per-pixel filter-weighted sums of squared samples (w·L² per channel), kept when
    /// a variance channel is asked for; not part of checkpoints.
    pub moments: Option<Vec<[f64; 3]>>,
}

impl Film {
    pub fn new(width: usize, height: usize, sensor: Sensor) -> Film {
        Film {
            width,
            height,
            pixels: vec![FilmPixel::default(); width * height],
            nonfinite: NonFinite::default(),
            sensor,
            moments: None,
        }
    }

    /// The same film keeping second moments for [`Film::variance`].
    pub fn with_moments(mut self) -> Film {
        self.moments = Some(vec![[0.0; 3]; self.pixels.len()]);
        self
    }

    /// Per pixel and channel, the filter-weighted variance of the samples as the sensor
    /// records them (E_w[L²] − E_w[L]²), when the film keeps moments.
    pub fn variance(&self) -> Option<[Vec<f32>; 3]> {
        let moments = self.moments.as_ref()?;
        let r2 = (self.sensor.imaging_ratio as f64).powi(2);
        let mut out: [Vec<f32>; 3] = Default::default();
        for (p, m) in self.pixels.iter().zip(moments) {
            for c in 0..3 {
                let v = if p.weight == 0.0 {
                    0.0
                } else {
                    let mean = p.sum[c] / p.weight;
                    ((m[c] / p.weight - mean * mean).max(0.0) * r2) as f32
                };
                out[c].push(v);
            }
        }
        Some(out)
    }

    /// The current estimate: each pixel's weighted mean, as the sensor records it.
    pub fn image(&self) -> Image {
        Image {
            width: self.width,
            height: self.height,
            pixels: self
                .pixels
                .iter()
                .map(|p| self.sensor.record(p.value()))
                .collect(),
        }
    }

    /// Samples taken in the pixel with the fewest (the image's guaranteed spp).
    pub fn min_samples(&self) -> u32 {
        self.pixels.iter().map(|p| p.samples).min().unwrap_or(0)
    }

    /// Samples taken in the pixel with the most.
    pub fn max_samples(&self) -> u32 {
        self.pixels.iter().map(|p| p.samples).max().unwrap_or(0)
    }

    /// Samples per pixel on average (an adaptive render's spp).
    pub fn mean_samples(&self) -> f64 {
        let taken: u64 = self.pixels.iter().map(|p| p.samples as u64).sum();
        taken as f64 / self.pixels.len().max(1) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_value_is_the_weighted_mean() {
        let mut p = FilmPixel::default();
        p.add(Rgb::splat(1.0), 1.0);
        p.add(Rgb::splat(4.0), 3.0);
        assert_eq!(p.value(), Rgb::splat(13.0 / 4.0));
        assert_eq!(FilmPixel::default().value(), Rgb::BLACK);
    }

    #[test]
    fn max_component_scales_bright_samples_down_keeping_their_colour() {
        let s = Sensor::new(200.0, 1.0).with_max_component(10.0);
        // Recorded at twice the radiance: Y of white 8 records 16, scaled to 10.
        let white = s.clamp_sample(Rgb::splat(8.0));
        let xyz = crate::white_balance::apply(
            &crate::white_balance::XYZ_FROM_RGB,
            [white.r, white.g, white.b],
        );
        let m = xyz[0].max(xyz[1]).max(xyz[2]) * 2.0;
        assert!((m - 10.0).abs() < 1e-4, "{m}");
        assert!((white.r - white.g).abs() < 1e-6 && (white.g - white.b).abs() < 1e-6);
        // Dim samples and unclamped sensors pass unchanged.
        assert_eq!(s.clamp_sample(Rgb::splat(1.0)), Rgb::splat(1.0));
        assert_eq!(Sensor::UNIT.clamp_sample(Rgb::splat(1e9)), Rgb::splat(1e9));
    }

    #[test]
    fn first_nonfinite_pixel_is_the_earliest_in_row_order() {
        let mut a = NonFinite {
            count: 1,
            first_pixel: Some((5, 2)),
        };
        a.merge(NonFinite {
            count: 2,
            first_pixel: Some((9, 1)),
        });
        assert_eq!(
            a,
            NonFinite {
                count: 3,
                first_pixel: Some((9, 1))
            }
        );
    }
}
