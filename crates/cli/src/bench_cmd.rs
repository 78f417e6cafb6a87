//! `radiant bench`: throughput figures (never part of the tests).

use std::path::{Path, PathBuf};

use clap::Args;
use radiant::image::{Crop, Image, compare, read_image};
use radiant::render::accel::{RayBenchConfig, ray_benchmark};
use radiant::render::bench::{environment_benchmark, render_benchmark, world_ray_benchmark};
use radiant::render::context::{Overrides, Progress};
use radiant::render::integrator::photon::bench::photon_benchmark;
use radiant::render::texture::bench::texture_lookup_benchmark;
use radiant::scene::builtin::cornell_box;
use radiant::scene::{ParamValue, SceneDesc};

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
    /// Instead of the throughput figures, the time-to-error rows: CPU seconds (user +
    /// system, the whole process) until each canonical task reaches its relMSE against
    /// the reference, from convergence runs whose power-of-two snapshots are compared
    /// with it.
    #[arg(long)]
    pub time_to_error: bool,
    /// Folder of the references (cornell-box-256-ref.exr, cornell-caustics-256-ref.exr).
    #[arg(long, default_value = "../shared/refs")]
    pub refs: PathBuf,
    /// Seeds of the convergence runs (each row prints every seed and the median).
    #[arg(long, default_value_t = 2)]
    pub seeds: u64,
}

pub fn run(args: BenchArgs) -> anyhow::Result<()> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()?;
    if args.time_to_error {
        return pool.install(|| time_to_error_rows(&args.refs, args.seeds));
    }
    pool.install(|| {
        let reps = if args.quick { 2 } else { 5 };
        let size = if args.quick { 256 } else { 1024 };
        out!("== rays through the world, cornell-box (36 triangles), {size}x{size} camera");
        out!("{}", world_ray_benchmark(&cornell_box(), size, reps));
        out!("== rays, displaced sphere of ~1M triangles inside the Cornell box");
        let config = RayBenchConfig {
            subdivision: if args.quick { 64 } else { 224 },
            image_size: if args.quick { 256 } else { 1024 },
            repetitions: reps,
            ..Default::default()
        };
        out!("{}", ray_benchmark(&config));
        out!(
            "== render cornell-box 256x256, {} spp, path tracer",
            args.spp
        );
        let (seconds, _) = render_benchmark(&cornell_box(), args.spp);
        out!(
            "{seconds:.2} s wall on {} threads",
            rayon::current_num_threads()
        );
        out!("== render bitterli/teapot at its resolution, 64 spp, path tracer");
        match teapot_scene() {
            Some(path) => match radiant::scene::parse_file(&path) {
                Ok(desc) => {
                    let (seconds, _) = render_benchmark(&desc, 64);
                    out!(
                        "{seconds:.2} s wall on {} threads",
                        rayon::current_num_threads()
                    );
                }
                Err(e) => out!("skipped: {e}"),
            },
            None => out!(
                "skipped: bitterli/teapot not found (set RADIANT_SHARED to the shared data folder)"
            ),
        }
        out!("== environment light sampling, sky with a small sun");
        out!(
            "{}",
            environment_benchmark(512, if args.quick { 200_000 } else { 2_000_000 })
        );
        out!("== photon mapping, cornell-caustics");
        out!("{}", photon_benchmark(args.quick));
        out!("== image texture lookups, 1024x1024 pyramid, anisotropic footprints");
        let lookups = if args.quick { 200_000 } else { 2_000_000 };
        out!("{}", texture_lookup_benchmark(lookups, reps));
    });
    Ok(())
}

/// CPU seconds (user + system) this process has used so far, from /proc/self/stat
/// (fields 14 and 15, in clock ticks of 1/100 s: USER_HZ is 100 on every Linux ABI).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // The command name (field 2) is in parentheses and may hold spaces.
    let after = stat.rsplit_once(')').map_or("", |(_, rest)| rest);
    let fields: Vec<&str> = after.split_whitespace().collect();
    let tick = |i: usize| {
        fields
            .get(i)
            .and_then(|f| f.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    // After the name: state is field 3, so utime (14) and stime (15) are at 11 and 12.
    (tick(11) + tick(12)) / 100.0
}

/// One canonical task: a scene and integrator, the error to reach and where.
struct Task {
    label: &'static str,
    scene: fn() -> SceneDesc,
    integrator: &'static str,
    reference: &'static str,
    crop: Option<Crop>,
    target: f64,
    /// Samples per pixel (SPPM: iterations) of the convergence run.
    max_spp: u32,
    /// Adaptive sampling: the run's last snapshot is its whole budget (`max_spp` on
    /// average), the earlier ones its uniform pilot.
    adaptive: bool,
}

impl Task {
    /// What the snapshots count: samples per pixel, or SPPM's iterations.
    fn unit(&self) -> &'static str {
        if self.integrator == "sppm" {
            "iterations"
        } else {
            "spp"
        }
    }
}

/// A convergence run: (spp, CPU seconds, relMSE) at every power-of-two snapshot.
fn convergence(task: &Task, reference: &Image, seed: u64) -> anyhow::Result<Vec<(u32, f64, f64)>> {
    let start = cpu_seconds();
    let overrides = Overrides {
        spp: Some(task.max_spp),
        seed: Some(seed),
        integrator: Some(task.integrator.to_string()),
        ..Default::default()
    };
    let mut session = radiant::Session::new(&(task.scene)(), &overrides)?;
    session.ctx.adaptive = task.adaptive;
    let mut snapshots: Vec<(u32, f64, Image)> = Vec::new();
    session.render_with_snapshots(&Progress::default(), &mut |n, film| {
        let t = cpu_seconds() - start;
        snapshots.push((n, t, film.image()));
    });
    snapshots
        .into_iter()
        .map(|(n, t, image)| Ok((n, t, compare(&image, reference, task.crop)?.relmse)))
        .collect()
}

/// Where a convergence run first reaches `target`: (CPU seconds, spp), interpolated
/// log-log between the snapshots around it (relMSE ∝ 1/spp for an unbiased estimator),
/// or extrapolated from the last snapshot the same way when it never gets there (the
/// flag says so).
fn reach(run: &[(u32, f64, f64)], target: f64) -> Option<(f64, f64, bool)> {
    let i = run.iter().position(|&(_, _, e)| e <= target);
    match i {
        Some(0) => run.first().map(|&(n, t, _)| (t, n as f64, false)),
        Some(i) => {
            let ((n0, t0, e0), (n1, t1, e1)) = (run[i - 1], run[i]);
            let f = (e0 / target).ln() / (e0 / e1).ln();
            let lerp = |a: f64, b: f64| (a.ln() + f * (b.ln() - a.ln())).exp();
            Some((lerp(t0, t1), lerp(n0 as f64, n1 as f64), false))
        }
        None => run
            .last()
            .map(|&(n, t, e)| (t * e / target, n as f64 * e / target, true)),
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// cornell-box with `"integer primarysplit" 8`: its noise is the indirect light, so
/// eight bounces per camera sample reach an error sooner (docs/speed.md).
fn cornell_box_split_8() -> SceneDesc {
    let mut desc = cornell_box();
    desc.integrator.params = desc
        .integrator
        .params
        .clone()
        .with("primarysplit", ParamValue::Int(vec![8]));
    desc
}

/// The canonical speed tasks, each as CPU seconds to its error (per seed and the
/// median), and the path tracer's CPU seconds per 256 samples per pixel.
fn time_to_error_rows(refs: &Path, seeds: u64) -> anyhow::Result<()> {
    use radiant::scene::builtin::{cornell_box, cornell_caustics};
    let caustic_crop = Crop {
        x0: 160,
        y0: 232,
        x1: 192,
        y1: 244,
    };
    let tasks = [
        Task {
            label: "cornell-box, path, to relMSE 6e-4",
            scene: cornell_box,
            integrator: "path",
            reference: "cornell-box-256-ref.exr",
            crop: None,
            target: 6e-4,
            max_spp: 512,
            adaptive: false,
        },
        Task {
            label: "cornell-box, path, adaptive (256 spp on average), to relMSE 6e-4",
            scene: cornell_box,
            integrator: "path",
            reference: "cornell-box-256-ref.exr",
            crop: None,
            target: 6e-4,
            max_spp: 256,
            adaptive: true,
        },
        Task {
            label: "cornell-box, path split 8 ways at the first vertex, to relMSE 6e-4",
            scene: cornell_box_split_8,
            integrator: "path",
            reference: "cornell-box-256-ref.exr",
            crop: None,
            target: 6e-4,
            max_spp: 64,
            adaptive: false,
        },
        Task {
            label: "cornell-caustics caustic crop (x 160..192, y 232..244), sppm, to 4e-3",
            scene: cornell_caustics,
            integrator: "sppm",
            reference: "cornell-caustics-256-ref.exr",
            crop: Some(caustic_crop),
            target: 4e-3,
            max_spp: 128,
            adaptive: false,
        },
        Task {
            label: "cornell-caustics whole image, sppm, to 7.5e-4",
            scene: cornell_caustics,
            integrator: "sppm",
            reference: "cornell-caustics-256-ref.exr",
            crop: None,
            target: 7.5e-4,
            max_spp: 128,
            adaptive: false,
        },
    ];
    out!(
        "== time to error: CPU seconds (user + system, whole process), {} threads, seeds 1..={seeds}",
        rayon::current_num_threads()
    );
    for task in &tasks {
        let path = refs.join(task.reference);
        let reference =
            read_image(&path).map_err(|e| anyhow::anyhow!("reference {}: {e}", path.display()))?;
        let (mut times, mut spps) = (Vec::new(), Vec::new());
        let mut cells = Vec::new();
        for seed in 1..=seeds {
            let run = convergence(task, &reference, seed)?;
            let Some((t, n, extrapolated)) = reach(&run, task.target) else {
                continue;
            };
            cells.push(format!(
                "seed {seed}: {t:.1} CPU-s at {n:.0} {}{}",
                task.unit(),
                if extrapolated { " (extrapolated)" } else { "" }
            ));
            times.push(t);
            spps.push(n);
        }
        out!(
            "{}: median {:.1} CPU-s, {:.0} {}  [{}]",
            task.label,
            median(times),
            median(spps),
            task.unit(),
            cells.join("; ")
        );
    }
    let mut per_256 = Vec::new();
    for seed in 1..=seeds {
        let start = cpu_seconds();
        let session = radiant::Session::new(
            &matched_roulette(cornell_box()),
            &Overrides {
                spp: Some(256),
                seed: Some(seed),
                integrator: Some("path".into()),
                ..Default::default()
            },
        )?;
        session.render(&Progress::default());
        per_256.push(cpu_seconds() - start);
    }
    out!(
        "cornell-box, path, 256 spp at Mitsuba 3's Russian roulette (rrdepth 4, rrthreshold 1): median {:.1} CPU-s  [{}]",
        median(per_256.clone()),
        per_256
            .iter()
            .map(|t| format!("{t:.1}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(())
}

/// `desc` with Mitsuba 3's Russian roulette (its `rr_depth` 5 counts the camera vertex;
/// survival by the throughput itself), so that the cost per sample compares at equal
/// path lengths.
fn matched_roulette(mut desc: SceneDesc) -> SceneDesc {
    desc.integrator.params = desc
        .integrator
        .params
        .with("rrdepth", ParamValue::Int(vec![4]))
        .with("rrthreshold", ParamValue::Float(vec![1.0]));
    desc
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reach_interpolates_log_log_and_extrapolates_past_the_run() {
        // relMSE 4e-3, 2e-3, 1e-3 at 16, 32, 64 spp taking 1, 2, 4 s.
        let run = [(16, 1.0, 4e-3), (32, 2.0, 2e-3), (64, 4.0, 1e-3)];
        let (t, n, x) = reach(&run, 1.4142135e-3).unwrap();
        assert!((t - 2.0 * 2f64.sqrt()).abs() < 1e-5 && (n - 32.0 * 2f64.sqrt()).abs() < 1e-4);
        assert!(!x);
        let (t, n, x) = reach(&run, 5e-4).unwrap();
        assert!((t - 8.0).abs() < 1e-9 && (n - 128.0).abs() < 1e-9 && x);
        assert_eq!(reach(&run, 1.0), Some((1.0, 16.0, false)));
        assert_eq!(reach(&[], 1.0), None);
    }

    #[test]
    fn the_cpu_clock_reads_and_advances() {
        // Spins until the clock has moved a tick (however busy the machine), giving up
        // after ten seconds of wall time.
        let t = std::time::Instant::now();
        let first = cpu_seconds();
        while cpu_seconds() <= first && t.elapsed().as_secs() < 10 {
            std::hint::black_box(0u64);
        }
        assert!(cpu_seconds() > first);
    }
}
