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
    CLOSURE_SLACK, ClosureReport, ProgressiveError, ProgressiveSettings, ProgressiveState,
    ShooterSelection, ShootingFactors, Start, solve_progressive_stoppable,
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
    #[error("{0}")]
    Diverged(String),
}

/// Power per band (W, or the scene's units of power): what the lights send, where it
/// went, and what the solver had not yet distributed when it stopped.
/// What a scene's escaping power says about it (see [`PowerBalance::escape_warning`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EscapeContext {
    /// Patches were meshed on both sides of surfaces.
    pub two_sided: bool,
    /// An infinite or distant light shines in from outside the scene.
    pub lit_from_outside: bool,
}

impl EscapeContext {
    pub fn of(settings: &RadiositySettings, lights: &[Light]) -> EscapeContext {
        EscapeContext {
            two_sided: settings.two_sided,
            lit_from_outside: lights
                .iter()
                .any(|l| matches!(l, Light::Infinite { .. } | Light::Distant { .. })),
        }
    }
}

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

    /// Why the balance shows a failed solve, if it does: a non-finite figure, or more
    /// power absorbed, escaped or left unshot than was emitted (the iteration grew
    /// instead of converging). Such a solution must not be shown as an image.
    pub fn failure(&self) -> Option<String> {
        let figures = [self.emitted, self.absorbed, self.escaped, self.unshot];
        if figures.iter().flatten().any(|v| !v.is_finite()) {
            return Some(format!(
                "the radiosity solve diverged (non-finite power); {}",
                self.summary()
            ));
        }
        // Each of absorbed, escaped and unshot is a share of the emitted power, up to
        // the matrix solvers' residual and reciprocity error (a few per cent at most).
        let exploded = (0..3).any(|b| {
            let limit = 1.5 * self.emitted[b].abs() + f64::MIN_POSITIVE;
            [self.absorbed[b], self.escaped[b], self.unshot[b]]
                .iter()
                .any(|v| v.abs() > limit)
        });
        exploded.then(|| {
            format!(
                "the radiosity solve diverged (power grew beyond the emitted power); {}",
                self.summary()
            )
        })
    }

    /// A warning when more than half of the emitted power (summed over bands) left the
    /// scene without reaching a patch: usually surfaces facing away from the light
    /// (one-sided patches of a scene wound the other way) rather than an open scene.
    /// None for scenes lit from outside, whose lights' power is their flux through a
    /// disk covering the whole scene, most of which misses its surfaces by design.
    pub fn escape_warning(&self, scene: EscapeContext) -> Option<String> {
        let emitted: f64 = self.emitted.iter().sum();
        let escaped: f64 = self.escaped.iter().sum();
        let share = 100.0 * escaped / emitted;
        if scene.lit_from_outside || !(emitted > 0.0 && escaped > 0.5 * emitted) {
            return None;
        }
        Some(if scene.two_sided {
            format!(
                "radiosity: {share:.0} % of the emitted power escaped without reaching a patch: the scene is open where its lights shine"
            )
        } else {
            format!(
                "radiosity: {share:.0} % of the emitted power escaped without reaching a patch; if the scene is closed, its surfaces may face away from the light (try \"bool twosided\" true)"
            )
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
    /// What the balance's escaping power means for this scene.
    pub escape: EscapeContext,
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
    /// Rows of form factors that summed to more than 1 and were scaled to closure.
    pub closure: ClosureReport,
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
    /// Receivers of the current progressive shot whose factors are done (between
    /// blocks of a shot, so that a stop is honoured within a shot).
    ShotFactors { done: usize, total: usize },
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
            // Both hooks report to `on_event`, one after each shot, one within shots.
            let on_event_cell = std::cell::RefCell::new(&mut on_event);
            let report = solve_progressive_stoppable(
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
                    (on_event_cell.borrow_mut())(SolveEvent::Shot {
                        scene,
                        state,
                        fraction_done,
                    })
                },
                |done, total| (on_event_cell.borrow_mut())(SolveEvent::ShotFactors { done, total }),
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
                closure: report.closure,
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
                    closure: ClosureReport::default(),
                });
            };
            let (f, closure) = f;
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
                closure,
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
    // Bad results never pass silently: a solve that blew up is an error, not an
    // all-black image.
    let finite = solution
        .radiosity
        .iter()
        .chain(&solution.irradiance)
        .flatten()
        .all(|v| v.is_finite());
    if !finite {
        return Err(RadiosityError::Diverged(format!(
            "the radiosity solve diverged (non-finite radiosity); {}",
            solution.balance.summary()
        )));
    }
    if let Some(failure) = solution.balance.failure() {
        return Err(RadiosityError::Diverged(failure));
    }
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
) -> Result<Option<(FormFactorMatrix<f64>, ClosureReport)>, RadiosityError> {
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
                    |buffers, (k, row)| h.row(set, first + k, vis, buffers, row),
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
    let closure = enforce_closure(n, &mut values);
    Ok(Some((
        FormFactorMatrix::from_row_major(n, values).expect("n x n values"),
        closure,
    )))
}

/// Scales every row of the row-major `n x n` factors that sums to more than
/// `1 + CLOSURE_SLACK` back to 1, and zeroes non-finite factors. The factors leaving
/// one side of a patch cannot sum to more than 1 (Cohen & Wallace, "Radiosity and
/// Realistic Image Synthesis", sec. 4.1); a row that does makes `rho F` expand energy,
/// and with reflectances near 1 the Jacobi and Gauss-Seidel iterations diverge.
pub fn enforce_closure(n: usize, values: &mut [f64]) -> ClosureReport {
    let mut report = ClosureReport::default();
    if n == 0 {
        return report;
    }
    for row in values.chunks_mut(n) {
        if row.iter().any(|f| !f.is_finite()) {
            report.non_finite += 1;
            row.iter_mut()
                .filter(|f| !f.is_finite())
                .for_each(|f| *f = 0.0);
        }
        let sum: f64 = row.iter().sum();
        if sum > 1.0 + CLOSURE_SLACK {
            report.scaled_rows += 1;
            report.largest_row_sum = report.largest_row_sum.max(sum);
            row.iter_mut().for_each(|f| *f /= sum);
        }
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::visibility::bvh::FaceVisibility;
    use glam::{DVec3, Vec3};
    use radiant_scene::builtin::cornell_box;
    use radiant_scene::{FileLoc, ShapeDesc};

    /// The Cornell box with a 100-unit white cube whose bottom face lies on the floor
    /// (back to back with it), meshed two-sided.
    fn box_with_a_cube_on_the_floor() -> RadiosityScene {
        let mut desc = cornell_box();
        let material = desc.shapes[0].material;
        let (x0, x1, z0, z1, h) = (380.0, 480.0, 60.0, 160.0, 100.0);
        let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        let faces = [
            [
                p(x0, 0.0, z0),
                p(x1, 0.0, z0),
                p(x1, 0.0, z1),
                p(x0, 0.0, z1),
            ],
            [p(x0, h, z0), p(x0, h, z1), p(x1, h, z1), p(x1, h, z0)],
            [p(x0, 0.0, z0), p(x0, h, z0), p(x1, h, z0), p(x1, 0.0, z0)],
            [p(x0, 0.0, z1), p(x1, 0.0, z1), p(x1, h, z1), p(x0, h, z1)],
            [p(x0, 0.0, z0), p(x0, 0.0, z1), p(x0, h, z1), p(x0, h, z0)],
            [p(x1, 0.0, z0), p(x1, h, z0), p(x1, h, z1), p(x1, 0.0, z1)],
        ];
        desc.shapes
            .push(ShapeDesc::quads(&faces, material, FileLoc::builtin("test")));
        let settings = RadiositySettings {
            max_patch_area: Some(2500.0),
            two_sided: true,
            ..RadiositySettings::default()
        };
        RadiosityScene::from_desc(&desc, &settings).unwrap()
    }

    /// Area-weighted mean radiosity (first band) of the patches facing into the room
    /// from the walls, floor and ceiling.
    fn room_mean(scene: &RadiosityScene, radiosity: &[[f64; 3]]) -> f64 {
        let (mut sum, mut area) = (0.0, 0.0);
        for (patch, b) in scene.patches.patches.iter().zip(radiosity) {
            let towards_centre = (DVec3::splat(278.0) - patch.centroid).dot(patch.normal) > 0.0;
            if towards_centre && patch.emission == [0.0; 3] {
                sum += patch.area * b[0];
                area += patch.area;
            }
        }
        sum / area
    }

    #[test]
    fn a_two_sided_box_with_a_cube_on_the_floor_stays_finite_and_closed() {
        let scene = box_with_a_cube_on_the_floor();
        let vis = FaceVisibility::new(&scene);
        // The floor under the cube and the cube's bottom cover each other.
        assert!(vis.covered_patches() > 0);
        let sphere = SceneSphere {
            center: Vec3::splat(278.0),
            radius: 500.0,
        };
        let mut means = Vec::new();
        for (form_factor, solver) in [
            (FormFactorMethod::RayCast, SolverKind::Progressive),
            (FormFactorMethod::HemiCube, SolverKind::Progressive),
            (FormFactorMethod::HemiCube, SolverKind::GaussSeidel),
        ] {
            let case = format!("{form_factor:?} {solver:?}");
            let settings = RadiositySettings {
                max_patch_area: Some(2500.0),
                two_sided: true,
                tolerance: 1e-3,
                form_factor,
                solver,
                ..RadiositySettings::default()
            };
            let solution = solve(&scene, &[], sphere, &settings, &vis, |_| {
                ControlFlow::Continue(())
            })
            .unwrap();
            assert!(solution.converged, "{case}");
            let balance = solution.balance;
            assert!(balance.failure().is_none(), "{case}: {}", balance.summary());
            // Energy balance: emitted = absorbed + escaped + unshot, every share between 0
            // and the emitted power. Shooting books every shot exactly; gathering with
            // factors from patch centroids is only as reciprocal as they are.
            let slack = match solver {
                SolverKind::Progressive => 1e-9,
                _ => 1e-2,
            };
            for b in 0..3 {
                let imbalance = balance.imbalance()[b] / balance.emitted[b];
                assert!(imbalance.abs() < slack, "{case}: {}", balance.summary());
                for share in [balance.absorbed[b], balance.escaped[b], balance.unshot[b]] {
                    assert!(
                        (-1e-9..=1.0).contains(&(share / balance.emitted[b])),
                        "{case}"
                    );
                }
            }
            // Closure: no row of factors came out above 1 by more than the centroid
            // estimate's error next to small neighbours (a patch coupled to its own
            // back side, or one seeing through a face lying on it, sums to about 2).
            assert!(
                solution.closure.largest_row_sum < 1.5,
                "{case}: {:?}",
                solution.closure
            );
            // No light reaches the inside of the closed cube, nor the floor under it:
            // a patch's back twin, in its plane up to rounding, sees none of its front.
            let lit = solution.radiosity.iter().map(|b| b[0]).fold(0.0, f64::max);
            for (patch, b) in scene.patches.patches.iter().zip(&solution.radiosity) {
                let c = patch.centroid;
                let inside =
                    (380.5..479.5).contains(&c.x) && (60.5..159.5).contains(&c.z) && c.y < 99.5;
                if inside {
                    assert!(
                        b[0] < 1e-9 * lit,
                        "{case}: {c:?} {:?} {lit}: {b:?}",
                        patch.normal
                    );
                }
            }
            means.push((case, room_mean(&scene, &solution.radiosity)));
        }
        // The methods agree on the room's light (they differ by their discretisation:
        // 0.1 % here; a hemi-cube that saw the back twins lost 5 %).
        let (_, reference) = &means[0];
        for (case, mean) in &means {
            assert!(
                (mean / reference - 1.0).abs() < 0.01,
                "{case}: {mean} against ray-cast {reference}"
            );
        }
    }

    #[test]
    fn rows_above_one_are_scaled_to_closure() {
        let mut values = vec![0.5, 0.9, 0.0, 0.2, 0.3, 0.1, f64::NAN, 0.4, 0.0];
        let report = enforce_closure(3, &mut values);
        assert_eq!(report.scaled_rows, 1);
        assert_eq!(report.non_finite, 1);
        assert!((report.largest_row_sum - 1.4).abs() < 1e-12);
        for row in values.chunks(3) {
            let sum: f64 = row.iter().sum();
            assert!(sum.is_finite() && sum <= 1.0 + 1e-12, "{row:?}");
        }
        assert_eq!(&values[3..6], &[0.2, 0.3, 0.1]);
    }

    #[test]
    fn a_diverged_balance_is_a_failure() {
        let ok = PowerBalance {
            emitted: [1.0; 3],
            absorbed: [0.6; 3],
            escaped: [0.4; 3],
            unshot: [0.0; 3],
        };
        assert!(ok.failure().is_none());
        let inside = EscapeContext::default();
        assert!(ok.escape_warning(inside).is_none());
        let nan = PowerBalance {
            absorbed: [f64::NAN, 0.6, 0.6],
            ..ok
        };
        assert!(nan.failure().is_some());
        let exploded = PowerBalance {
            absorbed: [8.6e73, 0.6, 0.6],
            escaped: [-1.5e74, 0.4, 0.4],
            ..ok
        };
        assert!(exploded.failure().is_some());
        let open = PowerBalance {
            absorbed: [0.12; 3],
            escaped: [0.88; 3],
            ..ok
        };
        let warning = open.escape_warning(inside).unwrap();
        assert!(
            warning.contains("88 %") && warning.contains("twosided"),
            "{warning}"
        );
        let two_sided = EscapeContext {
            two_sided: true,
            ..inside
        };
        let warning = open.escape_warning(two_sided).unwrap();
        assert!(
            warning.contains("88 %") && !warning.contains("twosided"),
            "{warning}"
        );
        // An environment's power is its flux through a disk covering the scene.
        let outside = EscapeContext {
            lit_from_outside: true,
            ..two_sided
        };
        assert!(open.escape_warning(outside).is_none());
    }
}
