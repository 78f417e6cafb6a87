//! Diagnostics of a form-factor matrix and a solution: reciprocity
//! (`A_i F_ij = A_j F_ji`), closure (`sum_j F_ij = 1` in a closed scene), irradiance and
//! the energy balance (emitted = absorbed + escaped).

use crate::formfactor::matrix::FormFactorMatrix;
use crate::mesh::patch::PatchSet;

/// The worst violation of reciprocity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reciprocity {
    /// `max_ij |A_i F_ij - A_j F_ji|` (area units).
    pub max_abs: f64,
    /// The same difference over `max(A_i F_ij, A_j F_ji)`, maximised over pairs where
    /// that exceeds `1e-12` of the largest `A_i F_ij`.
    pub max_relative: f64,
    /// The pair with the largest absolute violation.
    pub worst_pair: (usize, usize),
}

/// Reciprocity error of a matrix for the areas of `set`.
pub fn reciprocity<T: Copy + Into<f64>>(set: &PatchSet, f: &FormFactorMatrix<T>) -> Reciprocity {
    let n = f.len();
    let mut largest = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            largest = largest.max(set.patches[i].area * f.get(i, j));
        }
    }
    let mut report = Reciprocity {
        max_abs: 0.0,
        max_relative: 0.0,
        worst_pair: (0, 0),
    };
    for i in 0..n {
        for j in i + 1..n {
            let forward = set.patches[i].area * f.get(i, j);
            let backward = set.patches[j].area * f.get(j, i);
            let difference = (forward - backward).abs();
            if difference > report.max_abs {
                report.max_abs = difference;
                report.worst_pair = (i, j);
            }
            let scale = forward.max(backward);
            if scale > 1e-12 * largest {
                report.max_relative = report.max_relative.max(difference / scale);
            }
        }
    }
    report
}

/// Row sums `sum_j F_ij` (1 for every patch of a closed scene).
pub fn closure<T: Copy + Into<f64>>(f: &FormFactorMatrix<T>) -> Vec<f64> {
    (0..f.len())
        .map(|i| f.row(i).iter().map(|&v| v.into()).sum())
        .collect()
}

/// `max_i |1 - sum_j F_ij|`.
pub fn closure_error<T: Copy + Into<f64>>(f: &FormFactorMatrix<T>) -> f64 {
    closure(f)
        .iter()
        .map(|s| (1.0 - s).abs())
        .fold(0.0, f64::max)
}

/// Irradiance `H_i = sum_j F_ij B_j` per patch and band.
pub fn irradiance<T: Copy + Into<f64>>(
    f: &FormFactorMatrix<T>,
    radiosity: &[[f64; 3]],
) -> Vec<[f64; 3]> {
    (0..f.len())
        .map(|i| super::matrix_solvers::gather(f.row(i), radiosity))
        .collect()
}

/// Power per band.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyBalance {
    /// `sum A_i E_i`.
    pub emitted: [f64; 3],
    /// `sum A_i (1 - rho_i) H_i`: arrives at a patch and is not reflected.
    pub absorbed: [f64; 3],
    /// `sum A_i B_i (1 - sum_j F_ij)`: leaves a patch and reaches no patch (through the
    /// openings of an open scene; zero when rows sum to 1).
    pub escaped: [f64; 3],
}

impl EnergyBalance {
    /// `emitted - absorbed - escaped` per band. Zero for an exact solution with
    /// reciprocal factors: summing `A_i B_i = A_i E_i + rho_i A_i H_i` over patches and
    /// using `sum_i A_i H_i = sum_j A_j B_j sum_i F_ji` (reciprocity) leaves exactly
    /// `emitted = absorbed + escaped`. Non-zero values measure the solver residual and
    /// the reciprocity error of the factors.
    pub fn imbalance(&self) -> [f64; 3] {
        std::array::from_fn(|b| self.emitted[b] - self.absorbed[b] - self.escaped[b])
    }
}

/// The energy balance of a solution `radiosity` under factors `f`.
pub fn energy_balance<T: Copy + Into<f64>>(
    set: &PatchSet,
    f: &FormFactorMatrix<T>,
    radiosity: &[[f64; 3]],
) -> EnergyBalance {
    let h = irradiance(f, radiosity);
    let sums = closure(f);
    let mut balance = EnergyBalance {
        emitted: set.emitted_power(),
        absorbed: [0.0; 3],
        escaped: [0.0; 3],
    };
    for (i, patch) in set.patches.iter().enumerate() {
        for b in 0..3 {
            balance.absorbed[b] += patch.area * (1.0 - patch.reflectance[b]) * h[i][b];
            balance.escaped[b] += patch.area * radiosity[i][b] * (1.0 - sums[i]);
        }
    }
    balance
}
