//! Realistic-camera benchmarks: exit-pupil precomputation per lens and camera-ray throughput.
//! Run with `cargo bench --bench lens`. The lens files are read from ../shared/data/lenses.

use radiant::math::Vec2;
use radiant::math::hash::{hash_u64s, u32_to_unit_f32};
use radiant::render::camera::realistic::{
    ExitPupilBounds, LensPrescription, LensSystem, RealisticCamera, film_distance_for_focus,
};

const LENSES: [&str; 4] = [
    "dgauss.50mm.dat",
    "wide.22mm.dat",
    "fisheye.10mm.dat",
    "telephoto.250mm.dat",
];
const FILM_DIAGONAL: f64 = 35.0;
const RAYS_PER_ITERATION: u64 = 1000;

fn main() {
    divan::main();
}

fn prescription(name: &str) -> LensPrescription {
    let dir = radiant_testkit::shared_root().join("data/lenses");
    LensPrescription::from_file(dir.join(name)).expect("lens file")
}

/// The exit-pupil bounds of one lens focused at 10 m (64 radial buckets), using all threads.
#[divan::bench(args = LENSES, sample_count = 5)]
fn exit_pupil_bounds(bencher: divan::Bencher, name: &str) {
    let system = LensSystem::new(&prescription(name)).unwrap();
    let gap = film_distance_for_focus(&system, 10.0, FILM_DIAGONAL).unwrap();
    bencher.bench(|| {
        ExitPupilBounds::compute(
            &system,
            gap,
            0.5 * FILM_DIAGONAL,
            ExitPupilBounds::DEFAULT_BUCKETS,
        )
        .unwrap()
    });
}

/// 1000 camera rays at hashed film positions and lens samples (one thread); divan reports the
/// time per 1000 rays and the throughput.
#[divan::bench(args = LENSES)]
fn generate_rays(bencher: divan::Bencher, name: &str) {
    let camera =
        RealisticCamera::new(prescription(name), 1e3, 10.0, FILM_DIAGONAL, (1000, 1000)).unwrap();
    let samples: Vec<(Vec2, Vec2)> = (0..RAYS_PER_ITERATION)
        .map(|i| {
            let a = hash_u64s(&[i, 0]);
            let b = hash_u64s(&[i, 1]);
            (
                Vec2::new(
                    u32_to_unit_f32(a as u32) * 1000.0,
                    u32_to_unit_f32((a >> 32) as u32) * 1000.0,
                ),
                Vec2::new(u32_to_unit_f32(b as u32), u32_to_unit_f32((b >> 32) as u32)),
            )
        })
        .collect();
    bencher
        .counter(divan::counter::ItemsCount::new(RAYS_PER_ITERATION as usize))
        .bench(|| {
            let mut passed = 0u32;
            for (raster, u) in &samples {
                passed += camera.generate_ray(*raster, *u).is_some() as u32;
            }
            passed
        });
}
