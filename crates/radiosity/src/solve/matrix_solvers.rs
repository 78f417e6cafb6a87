//! Full-matrix iterative solvers for `B_i = E_i + rho_i sum_j F_ij B_j`, all three bands
//! at once with the factors stored once.
//!
//! The system matrix `I - diag(rho) F` is strictly diagonally dominant by rows when
//! every `rho_i < 1` and rows of `F` sum to at most 1, so Jacobi and Gauss-Seidel both
//! converge (Cohen & Greenberg 1985; Cohen & Wallace, "Radiosity and Realistic Image
//! Synthesis", 1993, ch. 5). The error shrinks per sweep by about the largest `rho`
//! (Jacobi) and faster for Gauss-Seidel, which uses each new `B_j` at once.

use rayon::prelude::*;
use thiserror::Error;

use crate::formfactor::matrix::FormFactorMatrix;
use crate::mesh::patch::PatchSet;

#[derive(Debug, Error, PartialEq)]
pub enum SolveError {
    #[error("{patches} patches but a {matrix} x {matrix} form-factor matrix")]
    Size { patches: usize, matrix: usize },
}

fn check_size<T: Copy + Into<f64>>(
    set: &PatchSet,
    factors: &FormFactorMatrix<T>,
) -> Result<(), SolveError> {
    if set.len() == factors.len() {
        Ok(())
    } else {
        Err(SolveError::Size {
            patches: set.len(),
            matrix: factors.len(),
        })
    }
}

/// When to stop iterating.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterationSettings {
    /// Stop when the residual (see [`SolveReport::residuals`]) falls below this.
    pub tolerance: f64,
    pub max_iterations: usize,
}

impl Default for IterationSettings {
    fn default() -> Self {
        IterationSettings {
            tolerance: 1e-6,
            max_iterations: 1000,
        }
    }
}

/// The outcome of an iterative solve.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveReport {
    /// Radiosity `B` per patch and band.
    pub radiosity: Vec<[f64; 3]>,
    /// Per sweep: the largest change of any `B` over the largest `B`,
    /// `max |B_new - B_old| / max |B_new|` (scale-free; zero for a dark scene).
    pub residuals: Vec<f64>,
    pub converged: bool,
}

impl SolveReport {
    /// Number of sweeps performed.
    pub fn iterations(&self) -> usize {
        self.residuals.len()
    }
}

/// Jacobi iteration from `B = E`. Rows are updated in parallel (each row a fixed-order
/// sum, so the result does not depend on the thread count). `on_sweep(k, residual)` is
/// called after each sweep (e.g. to print progress).
pub fn solve_jacobi<T>(
    set: &PatchSet,
    factors: &FormFactorMatrix<T>,
    settings: IterationSettings,
    mut on_sweep: impl FnMut(usize, f64),
) -> Result<SolveReport, SolveError>
where
    T: Copy + Into<f64> + Sync,
{
    check_size(set, factors)?;
    let mut b: Vec<[f64; 3]> = set.patches.iter().map(|p| p.emission).collect();
    let mut next = b.clone();
    let mut residuals = Vec::new();
    let mut converged = false;
    for sweep in 0..settings.max_iterations {
        next.par_iter_mut()
            .enumerate()
            .with_min_len(16)
            .for_each(|(i, out)| {
                let patch = &set.patches[i];
                let gathered = gather(factors.row(i), &b);
                for band in 0..3 {
                    out[band] = patch.emission[band] + patch.reflectance[band] * gathered[band];
                }
            });
        let residual = relative_change(&b, &next);
        std::mem::swap(&mut b, &mut next);
        residuals.push(residual);
        on_sweep(sweep + 1, residual);
        if residual < settings.tolerance {
            converged = true;
            break;
        }
    }
    Ok(SolveReport {
        radiosity: b,
        residuals,
        converged,
    })
}

/// Gauss-Seidel iteration from `B = E`, in place and in patch order (sequential).
pub fn solve_gauss_seidel<T>(
    set: &PatchSet,
    factors: &FormFactorMatrix<T>,
    settings: IterationSettings,
    mut on_sweep: impl FnMut(usize, f64),
) -> Result<SolveReport, SolveError>
where
    T: Copy + Into<f64>,
{
    check_size(set, factors)?;
    let mut b: Vec<[f64; 3]> = set.patches.iter().map(|p| p.emission).collect();
    let mut residuals = Vec::new();
    let mut converged = false;
    for sweep in 0..settings.max_iterations {
        let mut largest_change = 0.0f64;
        let mut largest_value = 0.0f64;
        for i in 0..b.len() {
            let patch = &set.patches[i];
            let gathered = gather(factors.row(i), &b);
            for band in 0..3 {
                let value = patch.emission[band] + patch.reflectance[band] * gathered[band];
                largest_change = largest_change.max((value - b[i][band]).abs());
                largest_value = largest_value.max(value.abs());
                b[i][band] = value;
            }
        }
        let residual = if largest_value > 0.0 {
            largest_change / largest_value
        } else {
            0.0
        };
        residuals.push(residual);
        on_sweep(sweep + 1, residual);
        if residual < settings.tolerance {
            converged = true;
            break;
        }
    }
    Ok(SolveReport {
        radiosity: b,
        residuals,
        converged,
    })
}

/// `sum_j F_ij B_j` per band: the irradiance of patch `i`.
#[inline]
pub(crate) fn gather<T: Copy + Into<f64>>(row: &[T], b: &[[f64; 3]]) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for (f, bj) in row.iter().zip(b) {
        let f: f64 = (*f).into();
        sum[0] += f * bj[0];
        sum[1] += f * bj[1];
        sum[2] += f * bj[2];
    }
    sum
}

fn relative_change(old: &[[f64; 3]], new: &[[f64; 3]]) -> f64 {
    let mut largest_change = 0.0f64;
    let mut largest_value = 0.0f64;
    for (o, n) in old.iter().zip(new) {
        for band in 0..3 {
            largest_change = largest_change.max((n[band] - o[band]).abs());
            largest_value = largest_value.max(n[band].abs());
        }
    }
    if largest_value > 0.0 {
        largest_change / largest_value
    } else {
        0.0
    }
}
