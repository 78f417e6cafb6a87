//! Solving a meshed scene: the first shot of point, spot, distant and infinite lights, form
//! factors by the chosen method, the chosen solver, and the power balance.
//!
//! Lights that are not area lights (delta lights and environments) have no patches. Their direct irradiance `H0_j` (with shadow rays) is
//! added as a source term: the solver sees `E'_j = E_j + rho_j H0_j`, the radiosity of
//! the light's first reflection, which is exact for `B = E + rho (H0 + F B)`. The power
//! they send is booked separately: what reaches patches is absorbed or reflected there,
//! the rest of `Light::power` escapes.
//!
//! The solvers it chooses from, and what checks them:
//! - [`matrix_solvers`]: Jacobi and Gauss-Seidel on a stored factor matrix.
//! - [`progressive`]: progressive refinement (shooting), factors on the fly, O(N)
//!   memory.
//! - [`adaptive`]: solve, split neighbours whose radiosities differ, solve again.
//! - [`diagnostics`]: reciprocity, closure, irradiance and energy balance.

pub mod adaptive;
pub mod diagnostics;
pub mod matrix_solvers;
pub mod progressive;

use std::ops::ControlFlow;
use std::time::Instant;

use glam::Vec2;
use rayon::prelude::*;
use thiserror::Error;

use self::matrix_solvers::{IterationSettings, SolveError, solve_gauss_seidel, solve_jacobi};
use self::progressive::{
    ProgressiveError, ProgressiveSettings, ProgressiveState, ShooterSelection, ShootingFactors,
    Start, solve_progressive_start,
};
use crate::formfactor::hemicube::{HemiCube, HemiCubeError};
use crate::formfactor::matrix::FormFactorMatrix;
use crate::formfactor::quadrature::{PatchRule, Rule1D};
use crate::formfactor::ray_cast::{Quadrature, RayCastSettings, RayCaster};
use crate::mesh::meshed_scene::RadiosityScene;
use crate::mesh::patch::PatchSet;
use crate::settings::{FormFactorMethod, RadiositySettings, SolverKind};
use crate::visibility::Visibility;
use crate::visibility::bvh::NO_PATCH;
use radiant_math::hash::Pcg32;
use radiant_render::light::{Light, LightSampleContext, SceneSphere};

#[derive(Debug, Error)]
pub enum RadiosityError {
    #[error(transparent)]
    Progressive(#[from] ProgressiveError),
    #[error(transparent)]
    Solve(#[from] SolveError),
    #[error(transparent)]
    HemiCube(#[from] HemiCubeError),
}

/// Power per band (W, or the scene's units of power): what the lights send, where it
/// went, and what the solver had not yet distributed when it stopped.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PowerBalance {
    pub emitted: [f64; 3],
    /// Arrived at a patch and was not reflected.
    pub absorbed: [f64; 3],
    /// Left the scene without reaching a patch.
    pub escaped: [f64; 3],
    /// Reflected power not yet shot (progressive refinement only).
    pub unshot: [f64; 3],
}

impl PowerBalance {
    /// `emitted - absorbed - escaped - unshot` per band: zero up to rounding for
    /// progressive refinement, the solver residual and the factors' reciprocity error
    /// for the matrix solvers.
    pub fn imbalance(&self) -> [f64; 3] {
        std::array::from_fn(|b| {
            self.emitted[b] - self.absorbed[b] - self.escaped[b] - self.unshot[b]
        })
    }

    /// The balance as one line of text.
    pub fn summary(&self) -> String {
        let f = |v: [f64; 3]| format!("({:.6e}, {:.6e}, {:.6e})", v[0], v[1], v[2]);
        let relative: [f64; 3] = std::array::from_fn(|b| {
            self.imbalance()[b] / self.emitted[b].abs().max(f64::MIN_POSITIVE)
        });
        format!(
            "energy balance (RGB): emitted {} = absorbed {} + escaped {} + unshot {}; imbalance {:.2e} {:.2e} {:.2e} of emitted",
            f(self.emitted),
            f(self.absorbed),
            f(self.escaped),
            f(self.unshot),
            relative[0],
            relative[1],
            relative[2]
        )
    }
}

/// What the radiosity integrator reports with its image.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RadiosityStats {
    pub patches: usize,
    /// Shots (progressive) or sweeps (matrix solvers).
    pub iterations: usize,
    pub converged: bool,
    pub solve_seconds: f64,
    pub balance: PowerBalance,
}

impl std::fmt::Display for RadiosityStats {
    /// Info lines for the command line.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "radiosity: {} patches, {} iterations ({}), solved in {:.2} s",
            self.patches,
            self.iterations,
            if self.converged {
                "converged"
            } else {
                "not converged"
            },
            self.solve_seconds
        )?;
        writeln!(f, "radiosity: {}", self.balance.summary())
    }
}

/// A solved scene.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Radiosity `B` per patch and band (emission included).
    pub radiosity: Vec<[f64; 3]>,
    /// Irradiance `H` per patch and band (delta lights included).
    pub irradiance: Vec<[f64; 3]>,
    /// Progressive refinement's estimate of the light not yet shot (zero otherwise);
    /// display adds `rho * ambient`.
    pub ambient: [f64; 3],
    pub balance: PowerBalance,
    /// Shots or sweeps.
    pub iterations: usize,
    pub converged: bool,
    /// Stopped by the progress hook (Ctrl-C).
    pub interrupted: bool,
    /// Seconds spent on the factor matrix (matrix solvers) and in total.
    pub factor_seconds: f64,
    pub seconds: f64,
}

impl Solution {
    /// Radiosity for display: `B + rho * ambient`.
    pub fn display_radiosity(&self, set: &PatchSet) -> Vec<[f64; 3]> {
        self.radiosity
            .iter()
            .zip(&set.patches)
            .map(|(b, p)| std::array::from_fn(|k| b[k] + p.reflectance[k] * self.ambient[k]))
            .collect()
    }
}

/// What a solve reports while it runs; the hook answers `Break` to stop early.
pub enum SolveEvent<'a> {
    /// Rows of the factor matrix done.
    Factors { done: usize, total: usize },
    /// A matrix-solver sweep finished.
    Sweep { sweep: usize, residual: f64 },
    /// A progressive shot finished; `fraction_done` runs from 0 to 1 on a log scale of
    /// the unshot power. `scene` is the mesh the state belongs to (it changes between
    /// the passes of an adaptive solve).
    Shot {
        scene: &'a RadiosityScene,
        state: &'a ProgressiveState,
        fraction_done: f64,
    },
}

/// Light samples per Gauss point for lights at infinity that are not delta lights
/// (environments): a 4 x 4 stratified grid, jittered by a generator seeded per patch.
const ENVIRONMENT_STRATA: u32 = 4;

/// Direct irradiance of the point, spot, distant and infinite lights on every patch
/// (3 x 3 Gauss points per patch; a shadow ray each for delta lights, 16 importance
/// samples of the environment, each with a shadow ray, for infinite ones), and their
/// total power. An environment's power is its flux through the disk covering the scene
/// (`Light::power`); what no patch receives escapes.
pub fn delta_light_irradiance<V: Visibility>(
    set: &PatchSet,
    lights: &[Light],
    sphere: SceneSphere,
    vis: &V,
) -> (Vec<[f64; 3]>, [f64; 3]) {
    let first_shot: Vec<&Light> = lights
        .iter()
        .filter(|l| {
            matches!(
                l,
                Light::Point { .. }
                    | Light::Spot { .. }
                    | Light::Distant { .. }
                    | Light::Infinite { .. }
                    | Light::Goniometric(_)
                    | Light::Projection(_)
            )
        })
        .collect();
    let mut power = [0.0; 3];
    for l in &first_shot {
        let p = l.power(sphere).to_array();
        for b in 0..3 {
            power[b] += p[b] as f64;
        }
    }
    if first_shot.is_empty() {
        return (vec![[0.0; 3]; set.len()], power);
    }
    let rule = PatchRule::Tensor(Rule1D::gauss_legendre(3));
    let strata = ENVIRONMENT_STRATA;
    let irradiance = (0..set.len())
        .into_par_iter()
        .map(|j| {
            let patch = &set.patches[j];
            let mut sum = [0.0; 3];
            let mut rng = Pcg32::new(0, 0);
            let mut jitter = Pcg32::new(j as u64, 0x0e4f);
            rule.for_each_point(set.polygon(j).as_slice(), &mut rng, |x, w| {
                let ctx = LightSampleContext::on_surface(x.as_vec3(), patch.normal.as_vec3());
                for light in &first_shot {
                    let (count, scale) = if light.is_delta() {
                        (1, 1.0)
                    } else {
                        (strata * strata, 1.0 / (strata * strata) as f64)
                    };
                    for k in 0..count {
                        let u = if light.is_delta() {
                            Vec2::ZERO
                        } else {
                            Vec2::new(
                                ((k % strata) as f32 + jitter.uniform()) / strata as f32,
                                ((k / strata) as f32 + jitter.uniform()) / strata as f32,
                            )
                            .min(Vec2::splat(radiant_math::ONE_MINUS_EPSILON))
                        };
                        let Some(s) = light.sample_li(&ctx, u, sphere) else {
                            continue;
                        };
                        let cos = patch.normal.dot(s.wi.as_dvec3());
                        if cos <= 0.0 || !vis.visible(x, s.p_light.p.as_dvec3(), j, NO_PATCH) {
                            continue;
                        }
                        // Delta lights report pdf 1.
                        let weight = w * cos * scale / s.pdf as f64;
                        let li = s.li.to_array();
                        for b in 0..3 {
                            sum[b] += weight * li[b] as f64;
                        }
                    }
                }
            });
            sum.map(|s| s / patch.area)
        })
        .collect();
    (irradiance, power)
}

/// The ray-cast settings of the full-matrix path: 2 x 2 Gauss points on the receiving
/// patch, one shadow ray from each to the other patch's centroid, exact contour
/// factors everywhere (the matrix is computed once, so it can afford them).
pub fn matrix_ray_cast_settings() -> RayCastSettings {
    RayCastSettings {
        quadrature: Quadrature::Gauss {
            order: 2,
            grading_levels: 0,
        },
        shadow_rays_per_side: 1,
        far_field_ratio: None,
        seed: 0,
    }
}

/// Solves `scene` (patch emission plus the delta lights among `lights`) with the
/// method and solver of `settings`. `on_event` sees the progress and may stop the solve.
pub fn solve<V: Visibility>(
    scene: &RadiosityScene,
    lights: &[Light],
    sphere: SceneSphere,
    settings: &RadiositySettings,
    vis: &V,
    on_event: impl FnMut(SolveEvent<'_>) -> ControlFlow<()>,
) -> Result<Solution, RadiosityError> {
    solve_from(scene, lights, sphere, settings, vis, None, on_event)
}

/// [`solve`] from a starting guess of every patch's radiosity (progressive refinement
/// only, see [`progressive::solve_progressive_from`]; the matrix solvers start
/// from the emission as always).
pub fn solve_from<V: Visibility>(
    scene: &RadiosityScene,
    lights: &[Light],
    sphere: SceneSphere,
    settings: &RadiositySettings,
    vis: &V,
    guess: Option<&[[f64; 3]]>,
    on_event: impl FnMut(SolveEvent<'_>) -> ControlFlow<()>,
) -> Result<Solution, RadiosityError> {
    solve_start(scene, lights, sphere, settings, vis, guess.into(), on_event)
}

/// [`solve`] from the emission, a guess or a saved progressive state (progressive
/// refinement only; the matrix solvers start from the emission as always).
pub fn solve_start<V: Visibility>(
    scene: &RadiosityScene,
    lights: &[Light],
    sphere: SceneSphere,
    settings: &RadiositySettings,
    vis: &V,
    start_from: Start<'_>,
    mut on_event: impl FnMut(SolveEvent<'_>) -> ControlFlow<()>,
) -> Result<Solution, RadiosityError> {
    let start = Instant::now();
    let (direct, delta_power) = delta_light_irradiance(&scene.patches, lights, sphere, vis);
    let has_delta = direct.iter().any(|h| h.iter().any(|&v| v > 0.0));
    // The solver's patch set: emission plus the delta lights' first reflection.
    let solver_set_owned;
    let set = if has_delta {
        let mut s = scene.patches.clone();
        for (p, h) in s.patches.iter_mut().zip(&direct) {
            for ((e, r), h) in p.emission.iter_mut().zip(&p.reflectance).zip(h) {
                *e += r * h;
            }
        }
        solver_set_owned = s;
        &solver_set_owned
    } else {
        &scene.patches
    };
    let n = set.len();
    let mut solution = match settings.solver {
        SolverKind::Progressive => {
            let caster = RayCaster::new(RayCastSettings::fast());
            let hemicube;
            let factors = match settings.form_factor {
                FormFactorMethod::RayCast => ShootingFactors::RayCast(&caster),
                FormFactorMethod::HemiCube => {
                    hemicube = HemiCube::new(settings.hemicube_resolution)?;
                    ShootingFactors::HemiCube(&hemicube)
                }
            };
            let log_tolerance = settings.tolerance.ln();
            let report = solve_progressive_start(
                set,
                factors,
                vis,
                ProgressiveSettings {
                    unshot_tolerance: settings.tolerance,
                    max_shots: settings.max_iterations,
                    selection: ShooterSelection::TotalPower,
                    callback_every: 1,
                },
                start_from,
                |state| {
                    let fraction = state.unshot_fraction().max(f64::MIN_POSITIVE);
                    let fraction_done = (fraction.ln() / log_tolerance).clamp(0.0, 1.0);
                    on_event(SolveEvent::Shot {
                        scene,
                        state,
                        fraction_done,
                    })
                },
            )?;
            let state = report.state;
            let ambient = state.ambient(set);
            Solution {
                balance: PowerBalance {
                    emitted: state.emitted,
                    absorbed: state.absorbed,
                    escaped: state.escaped,
                    unshot: state.unshot_power,
                },
                radiosity: state.radiosity,
                irradiance: state.irradiance,
                ambient,
                iterations: state.shots,
                converged: report.converged,
                interrupted: report.stopped,
                factor_seconds: 0.0,
                seconds: 0.0,
            }
        }
        SolverKind::GaussSeidel | SolverKind::Jacobi => {
            let factor_start = Instant::now();
            let Some(f) = factor_matrix(set, settings, vis, &mut on_event)? else {
                // Stopped while computing factors: nothing solved beyond emission.
                return Ok(Solution {
                    radiosity: set.patches.iter().map(|p| p.emission).collect(),
                    irradiance: vec![[0.0; 3]; n],
                    ambient: [0.0; 3],
                    balance: PowerBalance {
                        emitted: set.emitted_power(),
                        unshot: set.emitted_power(),
                        ..PowerBalance::default()
                    },
                    iterations: 0,
                    converged: false,
                    interrupted: true,
                    factor_seconds: factor_start.elapsed().as_secs_f64(),
                    seconds: start.elapsed().as_secs_f64(),
                });
            };
            let factor_seconds = factor_start.elapsed().as_secs_f64();
            let iteration = IterationSettings {
                tolerance: settings.tolerance,
                max_iterations: settings.max_iterations,
            };
            let on_sweep = |sweep, residual| {
                // Sweeps are short; stopping is honoured between phases, not here.
                let _ = on_event(SolveEvent::Sweep { sweep, residual });
            };
            let report = if settings.solver == SolverKind::GaussSeidel {
                solve_gauss_seidel(set, &f, iteration, on_sweep)?
            } else {
                solve_jacobi(set, &f, iteration, on_sweep)?
            };
            let balance = diagnostics::energy_balance(set, &f, &report.radiosity);
            Solution {
                irradiance: diagnostics::irradiance(&f, &report.radiosity),
                radiosity: report.radiosity,
                ambient: [0.0; 3],
                balance: PowerBalance {
                    emitted: balance.emitted,
                    absorbed: balance.absorbed,
                    escaped: balance.escaped,
                    unshot: [0.0; 3],
                },
                iterations: report.residuals.len(),
                converged: report.converged,
                interrupted: false,
                factor_seconds,
                seconds: 0.0,
            }
        }
    };
    if has_delta {
        // Book the delta lights: their power replaces the first reflection the solver
        // saw as emission; what reached patches and was not reflected is absorbed,
        // what reached no patch escaped.
        let mut reflected = [0.0; 3];
        let mut absorbed = [0.0; 3];
        let mut arrived = [0.0; 3];
        for ((p, h), total) in scene
            .patches
            .patches
            .iter()
            .zip(&direct)
            .zip(&mut solution.irradiance)
        {
            for b in 0..3 {
                reflected[b] += p.area * p.reflectance[b] * h[b];
                absorbed[b] += p.area * (1.0 - p.reflectance[b]) * h[b];
                arrived[b] += p.area * h[b];
                total[b] += h[b];
            }
        }
        for b in 0..3 {
            solution.balance.emitted[b] += delta_power[b] - reflected[b];
            solution.balance.absorbed[b] += absorbed[b];
            solution.balance.escaped[b] += (delta_power[b] - arrived[b]).max(0.0);
        }
    }
    solution.seconds = start.elapsed().as_secs_f64();
    Ok(solution)
}

/// Patch-to-patch factor evaluations per thread in a block of factor-matrix rows.
const FACTOR_BLOCK_WORK: usize = 1 << 18;

/// The full factor matrix in blocks of rows (parallel within a block), reporting after
/// each block. `None` when the hook asked to stop.
fn factor_matrix<V: Visibility>(
    set: &PatchSet,
    settings: &RadiositySettings,
    vis: &V,
    on_event: &mut impl FnMut(SolveEvent<'_>) -> ControlFlow<()>,
) -> Result<Option<FormFactorMatrix<f64>>, RadiosityError> {
    let n = set.len();
    let mut values = vec![0.0; n * n];
    // A row costs about n patch projections (hemi-cube) or ray casts, so a block of
    // FACTOR_BLOCK_WORK / n rows is a similar amount of work at any n (tens of
    // milliseconds per thread); the hook, which checks for cancellation, runs between
    // blocks. At least a row per thread keeps every thread busy.
    let threads = rayon::current_num_threads();
    let block = (FACTOR_BLOCK_WORK * threads / n.max(1)).clamp(threads, 1024);
    let caster = RayCaster::new(matrix_ray_cast_settings());
    let hemicube = match settings.form_factor {
        FormFactorMethod::HemiCube => Some(HemiCube::new(settings.hemicube_resolution)?),
        FormFactorMethod::RayCast => None,
    };
    if n > 0 {
        for (b, rows) in values.chunks_mut(block * n).enumerate() {
            let first = b * block;
            match &hemicube {
                Some(h) => rows.par_chunks_mut(n).enumerate().for_each_init(
                    || h.buffers(),
                    |buffers, (k, row)| h.row(set, first + k, buffers, row),
                ),
                None => rows
                    .par_chunks_mut(n)
                    .enumerate()
                    .for_each(|(k, row)| caster.row(set, first + k, vis, row)),
            }
            let done = (first + block).min(n);
            if on_event(SolveEvent::Factors { done, total: n }).is_break() {
                return Ok(None);
            }
        }
    }
    Ok(Some(
        FormFactorMatrix::from_row_major(n, values).expect("n x n values"),
    ))
}
