//! Timing of HDR-ꟻLIP, printed and never asserted. Run with
//! `cargo test --release --test bench -- --ignored --nocapture`.

use crate::common::{Image, noise, read_pfm};
use radiant_image::flip::{DEFAULT_PIXELS_PER_DEGREE, flip_hdr};
use std::time::Instant;

/// Nearest-neighbour upscale by `factor`, so the 1024² case has the same content.
fn upscale(img: &Image, factor: usize) -> Image {
    let (w, h) = (img.width * factor, img.height * factor);
    let pixels = (0..w * h)
        .map(|i| img.pixels[(i / w / factor) * img.width + (i % w) / factor])
        .collect();
    Image {
        width: w,
        height: h,
        pixels,
    }
}

fn with_noise(img: &Image) -> Vec<[f32; 3]> {
    img.pixels
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (x, y) = (i % img.width, i / img.width);
            [0, 1, 2].map(|c| (p[c] as f64 * (0.7 + 0.6 * noise(1, x, y, c))) as f32)
        })
        .collect()
}

#[test]
#[ignore = "benchmark; prints timings"]
fn bench_hdr_flip() {
    let base = read_pfm(&crate::common::refs().join("cornell-box-256-ref.pfm"));
    for factor in [1, 4] {
        let r = upscale(&base, factor);
        let t = with_noise(&r);
        let runs = if factor == 1 { 5 } else { 2 };
        let mut best = f64::INFINITY;
        let mut exposures = 0;
        for _ in 0..runs {
            let start = Instant::now();
            let map = flip_hdr(
                &t,
                &r.pixels,
                r.width,
                r.height,
                DEFAULT_PIXELS_PER_DEGREE,
                None,
            )
            .unwrap();
            best = best.min(start.elapsed().as_secs_f64());
            exposures = map.exposures.len();
        }
        println!(
            "HDR-FLIP {}x{}: {:.3} s best of {runs} ({exposures} exposures, {} rayon threads)",
            r.width,
            r.height,
            best,
            rayon::current_num_threads()
        );
    }
}
