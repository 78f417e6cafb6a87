//! Sampler throughput: numbers drawn per second by each pixel sampler, one thread.
//!
//! `cargo bench --bench sampler`; divan prints items/s. One item is one path vertex's
//! worth of draws as the path tracer makes them (a 1D and a 2D number for the light, a
//! 1D and a 2D number for the BSDF), over 64 vertices of 64 samples of one pixel, so
//! the figures include starting each pixel sample (its hash) as a render pays it.

use divan::Bencher;
use divan::counter::ItemsCount;
use radiant::render::sampler::PixelSample;
use radiant::scene::{DigitRandomization, SamplerKind};

fn main() {
    divan::main();
}

const SAMPLES: u32 = 64;
const VERTICES: usize = 64;

const KINDS: [&str; 5] = [
    "sobol",
    "halton_owen",
    "halton_permuted",
    "stratified",
    "independent",
];

fn kind(name: &str) -> SamplerKind {
    match name {
        "sobol" => SamplerKind::Sobol,
        "halton_owen" => SamplerKind::Halton {
            randomization: DigitRandomization::Owen,
        },
        "halton_permuted" => SamplerKind::Halton {
            randomization: DigitRandomization::PermuteDigits,
        },
        "stratified" => SamplerKind::Stratified {
            x: 8,
            y: 8,
            jitter: true,
        },
        "independent" => SamplerKind::Independent,
        other => panic!("unknown sampler {other}"),
    }
}

#[divan::bench(args = KINDS, sample_count = 20)]
fn vertex_draws(bencher: Bencher, name: &str) {
    let kind = kind(name);
    bencher
        .counter(ItemsCount::new(SAMPLES as usize * VERTICES))
        .bench(|| {
            let mut acc = 0.0f32;
            for index in 0..SAMPLES {
                let mut s = PixelSample::new(kind, 1, divan::black_box(17), 23, index);
                for _ in 0..VERTICES {
                    let (a, b) = (s.get_1d(), s.get_2d());
                    let (c, d) = (s.get_1d(), s.get_2d());
                    acc += a + b.x + b.y + c + d.x * d.y;
                }
            }
            acc
        });
}
