//! Radiosity benchmarks: progressive refinement on a 10^4-patch box with on-the-fly
//! ray-cast factors, and full-matrix factors (ray casting, hemi-cube) with the
//! iterative solvers on about 2,000 patches.
//!
//! Run: `cargo bench --bench radiosity` (`RAYON_NUM_THREADS=2` to match the target
//! machine).

use divan::Bencher;
use radiant::radiosity::shapes::cornell_like_box;
use radiant::radiosity::{
    AlwaysVisible, FormFactorMatrix, HemiCube, IterationSettings, PatchSet, ProgressiveSettings,
    RayCastSettings, RayCaster, ShootingFactors, solve_gauss_seidel, solve_jacobi,
    solve_progressive,
};

fn main() {
    divan::main();
}

/// The closed Cornell-like box with `divisions^2` patches per wall (6 walls) and a light
/// of about a quarter of the ceiling's width.
fn closed_box(divisions: usize) -> PatchSet {
    cornell_like_box(divisions, false, 0.12).expect("valid box")
}

/// 10,086 patches, shooting until 1 % of the emitted power is unshot, with one-point
/// contour factors at the receivers (far-field disk beyond 8 patch sizes). The box is
/// convex, so visibility is exact without rays.
#[divan::bench(sample_count = 1, sample_size = 1)]
fn progressive_10k_patches_to_1_percent(bencher: Bencher) {
    let set = closed_box(41);
    let caster = RayCaster::new(RayCastSettings::fast());
    bencher.bench_local(|| {
        let report = solve_progressive(
            &set,
            ShootingFactors::RayCast(&caster),
            &AlwaysVisible,
            ProgressiveSettings::default(),
            |_| {},
        )
        .expect("valid settings");
        assert!(report.converged);
        report.state.shots
    });
}

/// 1,944 patches (18 x 18 per wall).
const MATRIX_DIVISIONS: usize = 18;

#[divan::bench(sample_count = 1, sample_size = 1)]
fn ray_cast_matrix_1944_patches(bencher: Bencher) {
    let set = closed_box(MATRIX_DIVISIONS);
    let caster = RayCaster::new(RayCastSettings::default());
    bencher.bench_local(|| caster.matrix(&set, &AlwaysVisible));
}

#[divan::bench(sample_count = 1, sample_size = 1, args = [64, 128])]
fn hemicube_matrix_1944_patches(bencher: Bencher, resolution: usize) {
    let set = closed_box(MATRIX_DIVISIONS);
    let hemicube = HemiCube::new(resolution).expect("even resolution");
    bencher.bench_local(|| hemicube.matrix(&set));
}

fn solver_input() -> (PatchSet, FormFactorMatrix<f64>) {
    let set = closed_box(MATRIX_DIVISIONS);
    let f = HemiCube::new(64).expect("even resolution").matrix(&set);
    (set, f)
}

const SOLVE_TO_1E6: IterationSettings = IterationSettings {
    tolerance: 1e-6,
    max_iterations: 10_000,
};

#[divan::bench(sample_count = 3, sample_size = 1)]
fn gauss_seidel_1944_patches(bencher: Bencher) {
    let (set, f) = solver_input();
    bencher.bench_local(|| solve_gauss_seidel(&set, &f, SOLVE_TO_1E6, |_, _| {}));
}

#[divan::bench(sample_count = 3, sample_size = 1)]
fn jacobi_1944_patches(bencher: Bencher) {
    let (set, f) = solver_input();
    bencher.bench_local(|| solve_jacobi(&set, &f, SOLVE_TO_1E6, |_, _| {}));
}
