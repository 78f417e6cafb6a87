//! Radiosity benchmarks: progressive refinement on a 10^4-patch box with on-the-fly
//! ray-cast factors, and full-matrix factors (ray casting, hemi-cube) with the
//! iterative solvers on about 2,000 patches.
//!
//! The Cornell-box benchmarks run the whole integrator path on the canonical scene
//! with its blocks (meshing excluded): shadow rays through the face BVH.
//!
//! Run: `cargo bench -p radiant-radiosity --bench radiosity` (`RAYON_NUM_THREADS=2` to
//! match the target machine); one case: `cargo bench -p radiant-radiosity --bench
//! radiosity -- cornell_progressive`.

use std::ops::ControlFlow;

use divan::Bencher;
use radiant_radiosity::mesh::meshed_scene::RadiosityScene;
use radiant_radiosity::mesh::procedural::cornell_like_box;
use radiant_radiosity::settings::{FormFactorMethod, RadiositySettings, SolverKind};
use radiant_radiosity::solve::solve;
use radiant_radiosity::visibility::bvh::FaceVisibility;
use radiant_radiosity::{
    AlwaysVisible, FormFactorMatrix, HemiCube, IterationSettings, PatchSet, ProgressiveSettings,
    RayCastSettings, RayCaster, ShootingFactors, solve_gauss_seidel, solve_jacobi,
    solve_progressive,
};
use radiant_render::world::World;
use radiant_scene::builtin::cornell_box;

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
            |_| ControlFlow::Continue(()),
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
    bencher.bench_local(|| hemicube.matrix(&set, &AlwaysVisible));
}

fn solver_input() -> (PatchSet, FormFactorMatrix<f64>) {
    let set = closed_box(MATRIX_DIVISIONS);
    let f = HemiCube::new(64)
        .expect("even resolution")
        .matrix(&set, &AlwaysVisible);
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

/// The canonical Cornell box (blocks included) meshed with patches of at most
/// `max_patch_area` mm^2.
fn cornell_scene(
    max_patch_area: f64,
    settings: RadiositySettings,
) -> (RadiosityScene, RadiositySettings) {
    let settings = RadiositySettings {
        max_patch_area: Some(max_patch_area),
        ..settings
    };
    let scene =
        RadiosityScene::from_desc(&cornell_box(), &settings).expect("canonical scene meshes");
    (scene, settings)
}

/// 10,082 patches.
const CORNELL_10K_AREA: f64 = 230.0;
/// 2,058 patches.
const CORNELL_2K_AREA: f64 = 1200.0;

/// Solves and checks convergence; returns (patches, shots or sweeps).
fn solve_cornell(scene: &RadiosityScene, settings: &RadiositySettings) -> (usize, usize) {
    let (world, _) = World::build(&cornell_box()).expect("canonical scene builds");
    let vis = FaceVisibility::new(scene);
    let solution = solve(
        scene,
        &world.lights,
        world.scene_sphere(),
        settings,
        &vis,
        |_| ControlFlow::Continue(()),
    )
    .expect("consistent inputs");
    assert!(solution.converged);
    (scene.patches.len(), solution.iterations)
}

/// Progressive refinement on the Cornell box with its blocks, 10^4 patches, to 1 %
/// unshot power: one-point contour factors at the receivers and one shadow ray each,
/// tested against the shot's shaft-culled occluders (the blocks and the light).
#[divan::bench(sample_count = 1, sample_size = 1)]
fn cornell_progressive_10k_patches_to_1_percent(bencher: Bencher) {
    let (scene, settings) = cornell_scene(
        CORNELL_10K_AREA,
        RadiositySettings {
            tolerance: 0.01,
            ..RadiositySettings::default()
        },
    );
    bencher.bench_local(|| solve_cornell(&scene, &settings));
}

/// The full-matrix path on 2,058 patches: ray-cast factors (2 x 2 points per receiver,
/// a shadow ray each), then Gauss-Seidel to 1e-6.
#[divan::bench(sample_count = 1, sample_size = 1)]
fn cornell_2k_raycast_matrix_gauss_seidel(bencher: Bencher) {
    let (scene, settings) = cornell_scene(
        CORNELL_2K_AREA,
        RadiositySettings {
            solver: SolverKind::GaussSeidel,
            tolerance: 1e-6,
            ..RadiositySettings::default()
        },
    );
    bencher.bench_local(|| solve_cornell(&scene, &settings));
}

/// The same with a 128-cell hemi-cube per patch (its depth buffer resolves occlusion).
#[divan::bench(sample_count = 1, sample_size = 1)]
fn cornell_2k_hemicube_matrix_gauss_seidel(bencher: Bencher) {
    let (scene, settings) = cornell_scene(
        CORNELL_2K_AREA,
        RadiositySettings {
            solver: SolverKind::GaussSeidel,
            form_factor: FormFactorMethod::HemiCube,
            hemicube_resolution: 128,
            tolerance: 1e-6,
            ..RadiositySettings::default()
        },
    );
    bencher.bench_local(|| solve_cornell(&scene, &settings));
}
