//! Figures for `radiant bench`: image texture lookups per second by filter, on one
//! thread, over a synthetic 1024² pyramid with footprints of a plane seen at grazing
//! angles (anisotropic, widths from a tenth of a texel to a few dozen).

use std::fmt;
use std::time::Instant;

use glam::Vec2;
use radiant_math::color::Rgb;
use radiant_math::hash::Pcg32;
use radiant_scene::{ImageFilter, WrapMode};

use super::filter::{Footprint, lookup};
use super::image::{Level, MipMap};

#[derive(Clone, Copy, Debug)]
pub struct TextureLookupFigures {
    pub bilinear_m_per_s: f64,
    pub trilinear_m_per_s: f64,
    pub ewa_m_per_s: f64,
    pub lookups: usize,
}

impl fmt::Display for TextureLookupFigures {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "bilinear {:.1} / trilinear {:.1} / EWA {:.1} Mlookups/s ({} lookups each, 1 thread)",
            self.bilinear_m_per_s, self.trilinear_m_per_s, self.ewa_m_per_s, self.lookups
        )
    }
}

/// Times `lookups` lookups with each filter; the fastest of `repetitions`.
pub fn texture_lookup_benchmark(lookups: usize, repetitions: u32) -> TextureLookupFigures {
    let n = 1024;
    let mut rng = Pcg32::new(11, 3);
    let texels = (0..n * n)
        .map(|_| Rgb::new(rng.uniform(), rng.uniform(), rng.uniform()))
        .collect();
    let mip = MipMap::new(Level::new(n, n, texels));
    let queries: Vec<(Vec2, Footprint)> = (0..lookups)
        .map(|_| {
            let st = Vec2::new(rng.uniform(), rng.uniform());
            let width = (2.0f32).powf(rng.uniform() * 9.0 - 3.0) / n as f32;
            let angle = rng.uniform() * std::f32::consts::TAU;
            let (s, c) = angle.sin_cos();
            let stretch = 1.0 + 7.0 * rng.uniform();
            let fp = Footprint {
                dst0: Vec2::new(c, s) * width * stretch,
                dst1: Vec2::new(-s, c) * width,
            };
            (st, fp)
        })
        .collect();
    let time = |filter: ImageFilter| {
        let mut best = f64::INFINITY;
        for _ in 0..repetitions.max(1) {
            let start = Instant::now();
            let mut sum = Rgb::BLACK;
            for (st, fp) in &queries {
                sum += lookup(&mip, filter, *st, *fp, 8.0, WrapMode::Repeat);
            }
            std::hint::black_box(sum);
            best = best.min(start.elapsed().as_secs_f64());
        }
        lookups as f64 / best / 1e6
    };
    TextureLookupFigures {
        bilinear_m_per_s: time(ImageFilter::Bilinear),
        trilinear_m_per_s: time(ImageFilter::Trilinear),
        ewa_m_per_s: time(ImageFilter::Ewa),
        lookups,
    }
}
