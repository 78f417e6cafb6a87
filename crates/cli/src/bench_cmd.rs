//! `radiant bench`: throughput figures (never part of the tests).

use clap::Args;
use radiant::render::accel::{RayBenchConfig, ray_benchmark};
use radiant::render::bench::{environment_benchmark, render_benchmark, world_ray_benchmark};
use radiant::render::integrator::photon::bench::photon_benchmark;
use radiant::render::texture::bench::texture_lookup_benchmark;
use radiant::scene::builtin::cornell_box;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Smaller workloads, for a quick look (the figures are then less stable).
    #[arg(long)]
    pub quick: bool,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Samples per pixel of the timed cornell-box render.
    #[arg(long, default_value_t = 256)]
    pub spp: u32,
}

pub fn run(args: BenchArgs) -> anyhow::Result<()> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()?;
    pool.install(|| {
        let reps = if args.quick { 2 } else { 5 };
        let size = if args.quick { 256 } else { 1024 };
        println!("== rays through the world, cornell-box (36 triangles), {size}x{size} camera");
        println!("{}", world_ray_benchmark(&cornell_box(), size, reps));
        println!("== rays, displaced sphere of ~1M triangles inside the Cornell box");
        let config = RayBenchConfig {
            subdivision: if args.quick { 64 } else { 224 },
            image_size: if args.quick { 256 } else { 1024 },
            repetitions: reps,
            ..Default::default()
        };
        println!("{}", ray_benchmark(&config));
        println!(
            "== render cornell-box 256x256, {} spp, path tracer",
            args.spp
        );
        let (seconds, _) = render_benchmark(&cornell_box(), args.spp);
        println!(
            "{seconds:.2} s wall on {} threads",
            rayon::current_num_threads()
        );
        println!("== render bitterli/teapot at its resolution, 64 spp, path tracer");
        match teapot_scene() {
            Some(path) => match radiant::scene::parse_file(&path) {
                Ok(desc) => {
                    let (seconds, _) = render_benchmark(&desc, 64);
                    println!(
                        "{seconds:.2} s wall on {} threads",
                        rayon::current_num_threads()
                    );
                }
                Err(e) => println!("skipped: {e}"),
            },
            None => println!(
                "skipped: bitterli/teapot not found (set RADIANT_SHARED to the shared data folder)"
            ),
        }
        println!("== environment light sampling, sky with a small sun");
        println!(
            "{}",
            environment_benchmark(512, if args.quick { 200_000 } else { 2_000_000 })
        );
        println!("== photon mapping, cornell-caustics");
        println!("{}", photon_benchmark(args.quick));
        println!("== image texture lookups, 1024x1024 pyramid, anisotropic footprints");
        let lookups = if args.quick { 200_000 } else { 2_000_000 };
        println!("{}", texture_lookup_benchmark(lookups, reps));
    });
    Ok(())
}

/// `data/scenes/bitterli/teapot/scene-v4.pbrt` under the shared data folder:
/// `$RADIANT_SHARED`, else `../shared` beside the working folder or beside the
/// repository the binary was built from.
fn teapot_scene() -> Option<std::path::PathBuf> {
    const REL: &str = "data/scenes/bitterli/teapot/scene-v4.pbrt";
    let repo = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    std::env::var_os("RADIANT_SHARED")
        .map(std::path::PathBuf::from)
        .into_iter()
        .chain([
            std::path::PathBuf::from("../shared"),
            std::path::PathBuf::from("shared"),
            repo.join("../shared"),
        ])
        .map(|root| root.join(REL))
        .find(|p| p.exists())
}
