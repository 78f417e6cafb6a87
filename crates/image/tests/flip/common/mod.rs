//! Test inputs shared by the integration tests: a PFM reader and the image-pair recipes
//! of tools/flip_reference.py, rebuilt here bit for bit (float64 arithmetic, stored as
//! float32) so that no derived images are committed.

#![allow(dead_code)]

use radiant_math::hash::hash_u64s;
use std::path::Path;

/// The reference renders beside the repository.
pub fn refs() -> std::path::PathBuf {
    radiant_testkit::shared("refs")
}

/// An RGB image, row-major, row 0 at the top.
#[derive(Clone, Debug)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<[f32; 3]>,
}

/// Reads an image with radiant's own reader, as RGB triples.
pub fn read_pfm(path: &Path) -> Image {
    let img = radiant_image::read_image(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Image {
        width: img.width,
        height: img.height,
        pixels: img.pixels.iter().map(|p| p.to_array()).collect(),
    }
}

/// Uniform noise in [0, 1) with 24 bits: (hash_u64s([seed, x, y, c]) >> 40) / 2^24.
pub fn noise(seed: u64, x: usize, y: usize, c: usize) -> f64 {
    (hash_u64s(&[seed, x as u64, y as u64, c as u64]) >> 40) as f64 / (1u64 << 24) as f64
}

fn srgb_encode(v: f32) -> f32 {
    let c = (v as f64).clamp(0.0, 1.0);
    let e = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    e as f32
}

fn map_pixels(img: &Image, f: impl Fn(usize, usize, [f32; 3]) -> [f64; 3]) -> Image {
    let pixels = img
        .pixels
        .iter()
        .enumerate()
        .map(|(i, p)| f(i % img.width, i / img.width, *p).map(|v| v as f32))
        .collect();
    Image {
        pixels,
        ..img.clone()
    }
}

fn to_ldr(img: &Image) -> Image {
    Image {
        pixels: img.pixels.iter().map(|p| p.map(srgb_encode)).collect(),
        ..img.clone()
    }
}

fn box_blur(img: &Image) -> Image {
    let (w, h) = (img.width as isize, img.height as isize);
    map_pixels(img, |x, y, _| {
        let mut acc = [0.0f64; 3];
        for dy in -1..=1 {
            let sy = (y as isize + dy).clamp(0, h - 1);
            for dx in -1..=1 {
                let sx = (x as isize + dx).clamp(0, w - 1);
                let p = img.pixels[(sy * w + sx) as usize];
                for c in 0..3 {
                    acc[c] += p[c] as f64;
                }
            }
        }
        acc.map(|v| v / 9.0)
    })
}

/// One test pair in both dynamic ranges.
pub struct Pair {
    pub name: &'static str,
    pub hdr_reference: Image,
    pub hdr_test: Image,
    pub ldr_reference: Image,
    pub ldr_test: Image,
}

fn gradient_pair() -> Pair {
    let (w, h) = (200usize, 120usize);
    let coords = |i: usize| {
        (
            (i % w) as f64 / (w - 1) as f64,
            (i / w) as f64 / (h - 1) as f64,
        )
    };
    let image = |f: &dyn Fn(f64, f64) -> [f64; 3]| Image {
        width: w,
        height: h,
        pixels: (0..w * h)
            .map(|i| {
                let (s, t) = coords(i);
                f(s, t).map(|v| v as f32)
            })
            .collect(),
    };
    let hdr_reference = image(&|s, t| {
        let e = (8.0 * s - 4.0).exp2();
        [e * (0.25 + 0.75 * t), 0.5 * e, e * (1.0 - 0.75 * t)]
    });
    let hdr_test = map_pixels(&hdr_reference, |_, _, p| {
        p.map(|v| ((2.0 * (v as f64).log2()).round_ties_even() / 2.0).exp2())
    });
    let ldr_reference = image(&|s, t| [s, t, 1.0 - 0.5 * (s + t)]);
    let ldr_test =
        image(&|s, t| [s, t, 1.0 - 0.5 * (s + t)].map(|v| (7.0 * v).round_ties_even() / 7.0));
    Pair {
        name: "gradient_quantized",
        hdr_reference,
        hdr_test,
        ldr_reference,
        ldr_test,
    }
}

/// All pairs of tools/flip_reference.py, in its order.
pub fn pairs() -> Vec<Pair> {
    let refs = refs();
    let refs = refs.as_path();
    let mut out = Vec::new();
    let cornell = read_pfm(&refs.join("cornell-box-256-ref.pfm"));
    let hdr_pair = |name, reference: &Image, test: Image| Pair {
        name,
        ldr_reference: to_ldr(reference),
        ldr_test: to_ldr(&test),
        hdr_reference: reference.clone(),
        hdr_test: test,
    };
    let noisy = map_pixels(&cornell, |x, y, p| {
        [0, 1, 2].map(|c| p[c] as f64 * (0.7 + 0.6 * noise(1, x, y, c)))
    });
    out.push(hdr_pair("cornell_noise", &cornell, noisy));
    out.push(hdr_pair("cornell_blur", &cornell, box_blur(&cornell)));
    let brighter = map_pixels(&cornell, |_, _, p| p.map(|v| v as f64 * 1.5));
    out.push(hdr_pair("cornell_exposure", &cornell, brighter));

    let caustics = read_pfm(&refs.join("cornell-caustics-256-ref.pfm"));
    let fireflies = map_pixels(&caustics, |x, y, p| {
        let add = if noise(2, x, y, 0) < 0.01 {
            10.0 * noise(2, x, y, 1)
        } else {
            0.0
        };
        p.map(|v| v as f64 + add)
    });
    out.push(hdr_pair("caustics_fireflies", &caustics, fireflies));
    out.push(gradient_pair());
    out
}

/// The expected values written by tools/flip_reference.py.
pub fn expected() -> serde_json::Value {
    let path = radiant_testkit::repo_path("tests/data/flip_expected.json");
    let text = std::fs::read_to_string(&path).expect("tests/data/flip_expected.json");
    serde_json::from_str(&text).expect("valid flip_expected.json")
}
