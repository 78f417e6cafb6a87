//! Ray throughput on the displaced-sphere Cornell scene (see `radiant::render::accel::ray_benchmark`).
//! `cargo bench --bench rays [-- <subdivision> <image size> <repetitions>]`.

use radiant::render::accel::{RayBenchConfig, ray_benchmark};

fn main() {
    let args: Vec<u32> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let d = RayBenchConfig::default();
    let config = RayBenchConfig {
        subdivision: args.first().copied().unwrap_or(d.subdivision),
        image_size: args.get(1).copied().unwrap_or(d.image_size),
        repetitions: args.get(2).copied().unwrap_or(d.repetitions),
        ..d
    };
    println!("{}", ray_benchmark(&config));
}
