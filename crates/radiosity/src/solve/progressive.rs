//! Progressive refinement (Cohen, Chen, Wallace & Greenberg, "A Progressive Refinement
//! Approach to Fast Radiosity Image Generation", SIGGRAPH 1988).
//!
//! Each step shoots the unshot radiosity `dB_i` of the patch with the most unshot power
//! `A_i dB_i` to every receiver: `dB_j += rho_j dB_i F_ij A_i / A_j = rho_j dB_i F_ji`
//! (reciprocity). Only the shooter's column of factors is needed, computed on the fly,
//! so memory is O(N). An ambient term estimates the light not yet shot, for display.
//!
//! Energy is booked per shot: the power `A_i dB_i` leaving the shooter is split into
//! what reaches receivers (`A_j F_ji dB_i`; a fraction `rho_j` of it becomes unshot
//! radiosity, the rest is absorbed) and what reaches no patch (escaped, through the
//! openings of an open scene). So `emitted = absorbed + escaped + unshot` holds at every
//! step, to rounding, whatever the factors.

use std::ops::ControlFlow;

use rayon::prelude::*;
use thiserror::Error;

use crate::formfactor::hemicube::{HemiCube, HemiCubeBuffers};
use crate::formfactor::matrix::FormFactorMatrix;
use crate::formfactor::ray_cast::RayCaster;
use crate::mesh::patch::PatchSet;
use crate::visibility::{InShot, ShotCull, Visibility};

#[derive(Debug, Error, PartialEq)]
pub enum ProgressiveError {
    #[error("band {0} does not exist (bands are 0, 1, 2)")]
    Band(usize),
    #[error("{patches} patches but a {matrix} x {matrix} form-factor matrix")]
    MatrixSize { patches: usize, matrix: usize },
    #[error("{patches} patches but a starting guess of {guess} radiosities")]
    GuessSize { patches: usize, guess: usize },
    #[error("{patches} patches but a saved state of {state} patches")]
    StateSize { patches: usize, state: usize },
}

/// Where a progressive solve starts.
#[derive(Clone, Copy, Debug, Default)]
pub enum Start<'a> {
    /// `B = dB = E`.
    #[default]
    Emission,
    /// A guess of the radiosities, primed as in [`solve_progressive_from`].
    Guess(&'a [[f64; 3]]),
    /// A state saved after some shots: the solve continues exactly as if it had never
    /// stopped, since the next shooter and every shot depend on the state alone.
    Resume(&'a ProgressiveState),
}

impl<'a> From<Option<&'a [[f64; 3]]>> for Start<'a> {
    fn from(guess: Option<&'a [[f64; 3]]>) -> Start<'a> {
        guess.map_or(Start::Emission, Start::Guess)
    }
}

/// How the next shooter is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShooterSelection {
    /// Largest `A_i sum_bands dB_i` (all bands shot together).
    TotalPower,
    /// Largest unshot power in one band (the classic one-band-at-a-time order).
    Band(usize),
}

/// Where a shot's factors come from.
#[derive(Clone, Copy, Debug)]
pub enum ShootingFactors<'a> {
    /// `F_ji` by contour integrals at points on each receiver (with shadow rays).
    RayCast(&'a RayCaster),
    /// `F_ij` from a hemi-cube at the shooter's centroid (its own depth buffer).
    HemiCube(&'a HemiCube),
    /// A stored matrix (for tests and small scenes).
    Matrix(&'a FormFactorMatrix<f64>),
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProgressiveSettings {
    /// Stop when the unshot power falls to this fraction of the emitted power (summed
    /// over bands, or in the selected band for [`ShooterSelection::Band`]).
    pub unshot_tolerance: f64,
    pub max_shots: usize,
    pub selection: ShooterSelection,
    /// Call the progress hook every this many shots (0: never).
    pub callback_every: usize,
}

impl Default for ProgressiveSettings {
    fn default() -> Self {
        ProgressiveSettings {
            unshot_tolerance: 0.01,
            max_shots: usize::MAX,
            selection: ShooterSelection::TotalPower,
            callback_every: 0,
        }
    }
}

/// The solution in progress.
#[derive(Clone, Debug, PartialEq)]
pub struct ProgressiveState {
    /// Radiosity gathered so far, per patch and band.
    pub radiosity: Vec<[f64; 3]>,
    /// Unshot radiosity `dB`, per patch and band.
    pub unshot: Vec<[f64; 3]>,
    /// Irradiance `H` gathered so far (power arriving per unit area), per patch and band.
    pub irradiance: Vec<[f64; 3]>,
    pub shots: usize,
    /// Power per band: emitted in total, absorbed by patches so far, escaped so far
    /// (reached no patch), and still unshot.
    pub emitted: [f64; 3],
    pub absorbed: [f64; 3],
    pub escaped: [f64; 3],
    pub unshot_power: [f64; 3],
    /// `sum_i A_i |dB_i|` per band: the unshot power, counting negative unshot
    /// radiosity (left by a starting guess that was too bright) as much as positive.
    pub unshot_magnitude: [f64; 3],
}

impl ProgressiveState {
    /// Start: `B = dB = E`.
    pub fn new(set: &PatchSet) -> ProgressiveState {
        let emission: Vec<[f64; 3]> = set.patches.iter().map(|p| p.emission).collect();
        let emitted = set.emitted_power();
        ProgressiveState {
            radiosity: emission.clone(),
            unshot: emission,
            irradiance: vec![[0.0; 3]; set.len()],
            shots: 0,
            emitted,
            absorbed: [0.0; 3],
            escaped: [0.0; 3],
            unshot_power: emitted,
            unshot_magnitude: emitted,
        }
    }

    /// Unshot power (its magnitude) over emitted power, summed over bands (0 for a
    /// dark scene).
    pub fn unshot_fraction(&self) -> f64 {
        let emitted: f64 = self.emitted.iter().sum();
        if emitted > 0.0 {
            self.unshot_magnitude.iter().sum::<f64>() / emitted
        } else {
            0.0
        }
    }

    /// Unshot over emitted power per band (0 where a band emits nothing).
    pub fn unshot_fraction_per_band(&self) -> [f64; 3] {
        std::array::from_fn(|b| {
            if self.emitted[b] > 0.0 {
                self.unshot_magnitude[b] / self.emitted[b]
            } else {
                0.0
            }
        })
    }

    /// The ambient term of Cohen et al. 1988: the unshot radiosity averaged over the
    /// area, times the overall interreflection factor `1 / (1 - rho_avg)` with
    /// `rho_avg` the area-weighted mean reflectance.
    pub fn ambient(&self, set: &PatchSet) -> [f64; 3] {
        let total_area = set.total_area();
        std::array::from_fn(|b| {
            let mean_reflectance = set
                .patches
                .iter()
                .map(|p| p.area * p.reflectance[b])
                .sum::<f64>()
                / total_area;
            let mean_unshot = self.unshot_power[b] / total_area;
            if mean_reflectance < 1.0 {
                mean_unshot / (1.0 - mean_reflectance)
            } else {
                0.0
            }
        })
    }

    /// Radiosity for display: `B_i + rho_i * ambient`.
    pub fn display_radiosity(&self, set: &PatchSet) -> Vec<[f64; 3]> {
        let ambient = self.ambient(set);
        self.radiosity
            .iter()
            .zip(&set.patches)
            .map(|(b, p)| std::array::from_fn(|k| b[k] + p.reflectance[k] * ambient[k]))
            .collect()
    }
}

/// The outcome of a progressive solve.
#[derive(Clone, Debug, PartialEq)]
pub struct ProgressiveReport {
    pub state: ProgressiveState,
    /// Unshot fraction after each shot (as [`ProgressiveState::unshot_fraction`]).
    pub unshot_fraction: Vec<f64>,
    /// The same per band.
    pub unshot_fraction_per_band: Vec<[f64; 3]>,
    pub converged: bool,
    /// The progress hook asked to stop before convergence.
    pub stopped: bool,
    /// Shots whose factors had to be scaled to closure.
    pub closure: ClosureReport,
}

/// Row sums of form factors up to this far above 1 are rounding or quadrature noise
/// (a closed enclosure's rows sum to 1 to rounding with the contour factors) and are
/// left alone.
pub const CLOSURE_SLACK: f64 = 1e-3;

/// Shooter rows whose factors summed to more than 1 and were scaled back to 1.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClosureReport {
    /// Shots whose row sum exceeded `1 + CLOSURE_SLACK`.
    pub scaled_rows: usize,
    /// The largest row sum seen (0 when none was scaled).
    pub largest_row_sum: f64,
    /// Shots with a non-finite factor (set to 0).
    pub non_finite: usize,
}

/// Receivers whose factors a shot computes between two stop checks: about 0.4 s of a
/// shot on a large mesh (25 s for 65k patches), a negligible pause on small ones.
const SHOT_BLOCK: usize = 1024;

/// Receivers per parallel work item. Fixed (not derived from the thread count) so that
/// the per-chunk partial sums, and thus every result, are the same on any machine.
const CHUNK: usize = 512;

/// Partial sums of one chunk of receivers in one shot.
#[derive(Clone, Copy, Default)]
struct ShotPartial {
    incident: [f64; 3],
    absorbed: [f64; 3],
    unshot_power: [f64; 3],
    unshot_magnitude: [f64; 3],
    best_score: f64,
    best: usize,
}

/// Shoots until the unshot fraction reaches the tolerance. `on_progress` sees the state
/// every `callback_every` shots (e.g. to write the classic image sequence) and may stop
/// the solve early by returning `ControlFlow::Break` (e.g. on Ctrl-C).
pub fn solve_progressive<V: Visibility>(
    set: &PatchSet,
    factors: ShootingFactors<'_>,
    vis: &V,
    settings: ProgressiveSettings,
    on_progress: impl FnMut(&ProgressiveState) -> ControlFlow<()>,
) -> Result<ProgressiveReport, ProgressiveError> {
    solve_progressive_from(set, factors, vis, settings, None, on_progress)
}

/// [`solve_progressive`] from a starting guess of the radiosities (e.g. the solution
/// of a coarser mesh). The guess `G` is treated as already shot: every patch first
/// shoots its `G_j` once, which makes `B = E + rho F G` exact for that shot state, and
/// its unshot radiosity becomes the residual `B - G`, positive or negative. Shooting
/// then proceeds as usual on the magnitudes; with a good guess the residual starts
/// near the tolerance, so the priming shots (one per patch) replace the many rounds a
/// cold start needs. The power balance holds throughout.
pub fn solve_progressive_from<V: Visibility>(
    set: &PatchSet,
    factors: ShootingFactors<'_>,
    vis: &V,
    settings: ProgressiveSettings,
    guess: Option<&[[f64; 3]]>,
    on_progress: impl FnMut(&ProgressiveState) -> ControlFlow<()>,
) -> Result<ProgressiveReport, ProgressiveError> {
    solve_progressive_start(set, factors, vis, settings, guess.into(), on_progress)
}

/// [`solve_progressive`] from the emission, a guess, or a saved state.
pub fn solve_progressive_start<V: Visibility>(
    set: &PatchSet,
    factors: ShootingFactors<'_>,
    vis: &V,
    settings: ProgressiveSettings,
    start: Start<'_>,
    on_progress: impl FnMut(&ProgressiveState) -> ControlFlow<()>,
) -> Result<ProgressiveReport, ProgressiveError> {
    solve_progressive_stoppable(set, factors, vis, settings, start, on_progress, |_, _| {
        ControlFlow::Continue(())
    })
}

/// [`solve_progressive_start`] that also asks `mid_shot(done, total)` between blocks of
/// a shot's factors whether to go on (e.g. on Ctrl-C: a shot of a large mesh takes
/// seconds). A shot stopped that way is not applied: the report's state is the one
/// after the last whole shot, and `stopped` is set.
pub fn solve_progressive_stoppable<V: Visibility>(
    set: &PatchSet,
    factors: ShootingFactors<'_>,
    vis: &V,
    settings: ProgressiveSettings,
    start: Start<'_>,
    mut on_progress: impl FnMut(&ProgressiveState) -> ControlFlow<()>,
    mut mid_shot: impl FnMut(usize, usize) -> ControlFlow<()>,
) -> Result<ProgressiveReport, ProgressiveError> {
    let n = set.len();
    let guess = match start {
        Start::Guess(g) => Some(g),
        _ => None,
    };
    if let Start::Resume(s) = start
        && [s.radiosity.len(), s.unshot.len(), s.irradiance.len()] != [n; 3]
    {
        return Err(ProgressiveError::StateSize {
            patches: n,
            state: s.radiosity.len(),
        });
    }
    if let ShooterSelection::Band(b) = settings.selection
        && b > 2
    {
        return Err(ProgressiveError::Band(b));
    }
    if let ShootingFactors::Matrix(m) = factors
        && m.len() != n
    {
        return Err(ProgressiveError::MatrixSize {
            patches: n,
            matrix: m.len(),
        });
    }
    if let Some(g) = guess
        && g.len() != n
    {
        return Err(ProgressiveError::GuessSize {
            patches: n,
            guess: g.len(),
        });
    }
    let mut state = match start {
        Start::Resume(s) => s.clone(),
        _ => ProgressiveState::new(set),
    };
    let mut fractions = Vec::new();
    let mut fractions_per_band = Vec::new();
    let mut shooting = Shooting {
        set,
        factors,
        vis,
        selection: settings.selection,
        hemicube_row: match factors {
            ShootingFactors::HemiCube(_) => vec![0.0; n],
            _ => Vec::new(),
        },
        hemicube_buffers: match factors {
            ShootingFactors::HemiCube(h) => Some(h.buffers()),
            _ => None,
        },
        shot_cull: ShotCull::default(),
        cull: matches!(factors, ShootingFactors::RayCast(_)) && !vis.always_visible(),
        coefficients: Vec::new(),
        closure: ClosureReport::default(),
    };
    let fraction = |state: &ProgressiveState| match settings.selection {
        ShooterSelection::TotalPower => state.unshot_fraction(),
        ShooterSelection::Band(b) => state.unshot_fraction_per_band()[b],
    };
    let mut shooter = best_shooter(set, &state.unshot, settings.selection);
    if let Some(g) = guess {
        for (j, shot) in g.iter().enumerate() {
            if *shot != [0.0; 3] {
                shooting.shoot(&mut state, j, *shot);
                state.shots += 1;
            }
        }
        let mut unshot_power = [0.0; 3];
        let mut unshot_magnitude = [0.0; 3];
        for ((db, b), (patch, shot)) in state
            .unshot
            .iter_mut()
            .zip(&state.radiosity)
            .zip(set.patches.iter().zip(g))
        {
            for band in 0..3 {
                db[band] = b[band] - shot[band];
                unshot_power[band] += patch.area * db[band];
                unshot_magnitude[band] += patch.area * db[band].abs();
            }
        }
        state.unshot_power = unshot_power;
        state.unshot_magnitude = unshot_magnitude;
        shooter = best_shooter(set, &state.unshot, settings.selection);
    }
    let mut converged = fraction(&state) <= settings.unshot_tolerance;
    let mut stopped = false;
    while !converged && !stopped && state.shots < settings.max_shots {
        let Some(i) = shooter else { break };
        let shot = state.unshot[i];
        state.unshot[i] = [0.0; 3];
        match shooting.shoot_checked(&mut state, i, shot, &mut mid_shot) {
            Some(next) => shooter = next,
            None => {
                // Stopped inside the shot: nothing of it was applied, so the state is
                // the one after the previous shot. The hook sees it once more, now that
                // the stop is known (e.g. to save it as a checkpoint).
                state.unshot[i] = shot;
                stopped = true;
                if settings.callback_every > 0 {
                    let _ = on_progress(&state);
                }
                break;
            }
        }
        state.shots += 1;
        fractions.push(state.unshot_fraction());
        fractions_per_band.push(state.unshot_fraction_per_band());
        converged = fraction(&state) <= settings.unshot_tolerance;
        if settings.callback_every > 0
            && state.shots.is_multiple_of(settings.callback_every)
            && on_progress(&state).is_break()
        {
            stopped = !converged;
        }
    }
    Ok(ProgressiveReport {
        state,
        unshot_fraction: fractions,
        unshot_fraction_per_band: fractions_per_band,
        converged,
        stopped,
        closure: shooting.closure,
    })
}

/// What one shot needs besides the state: factors, visibility and their scratch.
struct Shooting<'a, V: Visibility> {
    set: &'a PatchSet,
    factors: ShootingFactors<'a>,
    vis: &'a V,
    selection: ShooterSelection,
    hemicube_row: Vec<f64>,
    hemicube_buffers: Option<HemiCubeBuffers>,
    /// Occluders that matter per group of receivers for the current shooter.
    shot_cull: ShotCull,
    cull: bool,
    /// Scratch: the shot's gathering coefficients `F_ji`.
    coefficients: Vec<f64>,
    closure: ClosureReport,
}

impl<V: Visibility> Shooting<'_, V> {
    /// Shoots radiosity `shot` from patch `i` to every receiver, books the power, and
    /// returns the patch with the most unshot power afterwards.
    fn shoot(&mut self, state: &mut ProgressiveState, i: usize, shot: [f64; 3]) -> Option<usize> {
        self.shoot_checked(state, i, shot, &mut |_, _| ControlFlow::Continue(()))
            .expect("a shot that is never stopped completes")
    }

    /// [`Self::shoot`], asking `mid_shot(done, total)` between blocks of receivers'
    /// factors whether to go on. `None` when it answered `Break`: then nothing of the
    /// shot has been applied and `state` is as it was.
    fn shoot_checked(
        &mut self,
        state: &mut ProgressiveState,
        i: usize,
        shot: [f64; 3],
        mid_shot: &mut dyn FnMut(usize, usize) -> ControlFlow<()>,
    ) -> Option<Option<usize>> {
        let set = self.set;
        let factors = self.factors;
        let selection = self.selection;
        let area_i = set.patches[i].area;
        if let (ShootingFactors::HemiCube(h), Some(buffers)) =
            (factors, self.hemicube_buffers.as_mut())
        {
            h.row(set, i, self.vis, buffers, &mut self.hemicube_row);
        }
        if self.cull {
            let total = set.len();
            let mut go_on = || mid_shot(0, total).is_continue();
            if !self
                .vis
                .prepare_shot(set, i, &mut self.shot_cull, &mut go_on)
            {
                return None;
            }
        }
        let in_shot = InShot {
            vis: self.vis,
            shot: &self.shot_cull,
        };
        let hemicube_row = &self.hemicube_row;
        // Gathering coefficient F_ji of each receiver j for this shooter.
        let coefficient = |j: usize| -> f64 {
            match factors {
                ShootingFactors::RayCast(r) => r.factor(set, j, i, &in_shot),
                ShootingFactors::HemiCube(_) => hemicube_row[j] * area_i / set.patches[j].area,
                ShootingFactors::Matrix(m) => m.get(i, j) * area_i / set.patches[j].area,
            }
        };
        self.coefficients.resize(set.len(), 0.0);
        // The factors are most of a shot's work (seconds on large meshes), so they are
        // computed in blocks with a stop check between them, as the factor matrix is.
        let total = set.len();
        for (b, block) in self.coefficients.chunks_mut(SHOT_BLOCK).enumerate() {
            let first = b * SHOT_BLOCK;
            block
                .par_iter_mut()
                .enumerate()
                .with_min_len(64)
                .for_each(|(k, c)| *c = coefficient(first + k));
            let done = first + block.len();
            if done < total && mid_shot(done, total).is_break() {
                return None;
            }
        }
        // Closure of the shooter's row: by reciprocity `sum_j A_j F_ji = A_i sum_j F_ij`,
        // and the factors from one side of a patch cannot sum to more than 1 (Cohen &
        // Wallace, "Radiosity and Realistic Image Synthesis", sec. 4.1). Estimates that
        // do (e.g. rays that slip past a surface lying on the receiver) would hand out
        // more power than the shot carries and make the iteration diverge, so such a row
        // is scaled back to 1 and counted.
        let row_sum = self
            .coefficients
            .iter()
            .zip(&set.patches)
            .map(|(c, p)| c * p.area)
            .sum::<f64>()
            / area_i;
        if !row_sum.is_finite() {
            self.closure.non_finite += 1;
            self.coefficients.iter_mut().for_each(|c| {
                if !c.is_finite() {
                    *c = 0.0;
                }
            });
        } else if row_sum > 1.0 + CLOSURE_SLACK {
            self.closure.scaled_rows += 1;
            self.closure.largest_row_sum = self.closure.largest_row_sum.max(row_sum);
            let scale = 1.0 / row_sum;
            self.coefficients.iter_mut().for_each(|c| *c *= scale);
        }
        let coefficients = &self.coefficients;
        let coefficient = |j: usize| coefficients[j];
        let partials: Vec<ShotPartial> = state
            .radiosity
            .par_chunks_mut(CHUNK)
            .zip(state.unshot.par_chunks_mut(CHUNK))
            .zip(state.irradiance.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(chunk, ((radiosity, unshot), irradiance))| {
                let mut partial = ShotPartial::default();
                let first = chunk * CHUNK;
                let receivers = radiosity
                    .iter_mut()
                    .zip(unshot.iter_mut())
                    .zip(irradiance.iter_mut());
                for (k, ((b, db), h)) in receivers.enumerate() {
                    let j = first + k;
                    let patch = &set.patches[j];
                    let c = coefficient(j);
                    if c != 0.0 {
                        for band in 0..3 {
                            let arriving = c * shot[band];
                            let reflected = patch.reflectance[band] * arriving;
                            h[band] += arriving;
                            b[band] += reflected;
                            db[band] += reflected;
                            partial.incident[band] += patch.area * arriving;
                            partial.absorbed[band] += patch.area * (arriving - reflected);
                        }
                    }
                    add_scaled(&mut partial.unshot_power, db, patch.area);
                    add_scaled(&mut partial.unshot_magnitude, &db.map(f64::abs), patch.area);
                    let score = selection_score(patch.area, db, selection);
                    if score > partial.best_score {
                        partial.best_score = score;
                        partial.best = j;
                    }
                }
                partial
            })
            .collect();
        let mut best_score = 0.0;
        let mut shooter = None;
        let mut unshot_power = [0.0; 3];
        let mut unshot_magnitude = [0.0; 3];
        for p in &partials {
            add_scaled(&mut state.absorbed, &p.absorbed, 1.0);
            add_scaled(&mut state.escaped, &p.incident, -1.0);
            add_scaled(&mut unshot_power, &p.unshot_power, 1.0);
            add_scaled(&mut unshot_magnitude, &p.unshot_magnitude, 1.0);
            if p.best_score > best_score {
                best_score = p.best_score;
                shooter = Some(p.best);
            }
        }
        add_scaled(&mut state.escaped, &shot, area_i);
        state.unshot_power = unshot_power;
        state.unshot_magnitude = unshot_magnitude;
        Some(shooter)
    }
}

/// `sum += scale * value`, per band.
#[inline]
fn add_scaled(sum: &mut [f64; 3], value: &[f64; 3], scale: f64) {
    for (s, v) in sum.iter_mut().zip(value) {
        *s += scale * v;
    }
}

#[inline]
fn selection_score(area: f64, unshot: &[f64; 3], selection: ShooterSelection) -> f64 {
    match selection {
        ShooterSelection::TotalPower => {
            area * (unshot[0].abs() + unshot[1].abs() + unshot[2].abs())
        }
        ShooterSelection::Band(b) => area * unshot[b].abs(),
    }
}

/// The patch with the largest unshot power (lowest index on ties), if any has some.
fn best_shooter(set: &PatchSet, unshot: &[[f64; 3]], selection: ShooterSelection) -> Option<usize> {
    let mut best = None;
    let mut best_score = 0.0;
    for (j, (patch, db)) in set.patches.iter().zip(unshot).enumerate() {
        let score = selection_score(patch.area, db, selection);
        if score > best_score {
            best_score = score;
            best = Some(j);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formfactor::ray_cast::RayCastSettings;
    use crate::visibility::AlwaysVisible;
    use glam::DVec3;

    /// Two facing 40 x 40 grids of unit squares one unit apart (3200 patches, more
    /// than two blocks of a shot); one patch of the upper grid emits.
    fn facing_grids() -> PatchSet {
        let mut set = PatchSet::new();
        for (z, up) in [(0.0, true), (1.0, false)] {
            for i in 0..40 {
                for j in 0..40 {
                    let (x, y) = (i as f64 - 20.0, j as f64 - 20.0);
                    let mut square = [
                        DVec3::new(x, y, z),
                        DVec3::new(x + 1.0, y, z),
                        DVec3::new(x + 1.0, y + 1.0, z),
                        DVec3::new(x, y + 1.0, z),
                    ];
                    if !up {
                        square.reverse();
                    }
                    let emission = if !up && i == 20 && j == 20 {
                        [1.0; 3]
                    } else {
                        [0.0; 3]
                    };
                    set.add_polygon(&square, emission, [0.5; 3]).unwrap();
                }
            }
        }
        set
    }

    #[test]
    fn a_stop_within_a_shot_leaves_the_state_of_the_last_whole_shot() {
        let set = facing_grids();
        let caster = RayCaster::new(RayCastSettings::fast());
        let settings = ProgressiveSettings {
            unshot_tolerance: 1e-9,
            max_shots: 10,
            callback_every: 1,
            ..ProgressiveSettings::default()
        };
        let run = |max_shots| {
            solve_progressive(
                &set,
                ShootingFactors::RayCast(&caster),
                &AlwaysVisible,
                ProgressiveSettings {
                    max_shots,
                    ..settings
                },
                |_| ControlFlow::Continue(()),
            )
            .unwrap()
        };
        let blocks_per_shot = set.len().div_ceil(SHOT_BLOCK) - 1;
        assert!(blocks_per_shot >= 2);
        // Stop at the second check of the third shot.
        let mut checks = 0;
        let mut seen = Vec::new();
        let stopped = solve_progressive_stoppable(
            &set,
            ShootingFactors::RayCast(&caster),
            &AlwaysVisible,
            settings,
            Start::Emission,
            |state| {
                seen.push(state.shots);
                ControlFlow::Continue(())
            },
            |done, total| {
                assert!(done < total);
                checks += 1;
                if checks == 2 * blocks_per_shot + 2 {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            },
        )
        .unwrap();
        assert!(stopped.stopped && !stopped.converged);
        let two = run(2);
        assert_eq!(stopped.state, two.state);
        // The hook saw each whole shot, then the state it stopped in once more.
        assert_eq!(seen, vec![1, 2, 2]);
        let s = &stopped.state;
        for b in 0..3 {
            let balance = s.emitted[b] - s.absorbed[b] - s.escaped[b] - s.unshot_power[b];
            assert!(balance.abs() < 1e-12 * s.emitted[b]);
        }
    }
}
