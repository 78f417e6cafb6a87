//! Pearson's statistic over a histogram, with the usual pooling of sparse cells.
//!
//! The chi-square approximation to Pearson's statistic needs every cell to expect at
//! least ~5 counts (Cochran 1954, "Some methods for strengthening the common χ² tests").
//! Cells expecting fewer are merged into one pooled cell; if even that expects fewer
//! than 5 it is merged into the sparsest regular cell. Counts in cells whose expected
//! value is exactly zero cannot come from the pdf at all and make the statistic
//! infinite.

use crate::chi2::gamma::chi_square_survival;

/// Cells expecting fewer counts than this are pooled.
pub const MIN_EXPECTED: f64 = 5.0;

/// Outcome of the goodness-of-fit computation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pearson {
    /// Σ (observed - expected)² / expected over the cells used.
    pub statistic: f64,
    /// Cells used after pooling, minus one (the total count is fixed).
    pub dof: usize,
    /// P(χ²(dof) ≥ statistic); NaN when fewer than two cells remain.
    pub p_value: f64,
    /// Cells entering the statistic after pooling (the pooled cell counts once).
    pub cells_used: usize,
    /// Cells with 0 < expected < MIN_EXPECTED that were pooled.
    pub pooled_cells: usize,
    /// Samples that fell into cells whose expected count is zero.
    pub samples_where_expected_is_zero: u64,
}

fn term(observed: f64, expected: f64) -> f64 {
    let d = observed - expected;
    d * d / expected
}

/// Computes the pooled Pearson statistic over (observed, expected) pairs.
pub fn pearson(cells: impl Iterator<Item = (u64, f64)> + Clone) -> Pearson {
    let mut statistic = 0.0;
    let mut cells_used = 0usize;
    let mut pooled_cells = 0usize;
    let mut pooled = (0.0f64, 0.0f64);
    let mut in_zero_cells = 0u64;
    // The sparsest cell that entered the statistic on its own, as (observed, expected).
    let mut sparsest: Option<(f64, f64)> = None;
    for (o, e) in cells {
        let o_f = o as f64;
        if e >= MIN_EXPECTED {
            statistic += term(o_f, e);
            cells_used += 1;
            if sparsest.is_none_or(|(_, se)| e < se) {
                sparsest = Some((o_f, e));
            }
        } else if e > 0.0 {
            pooled.0 += o_f;
            pooled.1 += e;
            pooled_cells += 1;
        } else if o > 0 {
            in_zero_cells += o;
        }
    }
    let (po, pe) = pooled;
    if pe >= MIN_EXPECTED {
        statistic += term(po, pe);
        cells_used += 1;
    } else if pe > 0.0 {
        match sparsest {
            Some((so, se)) => {
                statistic += term(so + po, se + pe) - term(so, se);
            }
            None => {
                statistic += term(po, pe);
                cells_used += 1;
            }
        }
    }
    if in_zero_cells > 0 {
        statistic = f64::INFINITY;
    }
    let dof = cells_used.saturating_sub(1);
    let p_value = if statistic.is_infinite() {
        0.0
    } else {
        chi_square_survival(statistic, dof)
    };
    Pearson {
        statistic,
        dof,
        p_value,
        cells_used,
        pooled_cells,
        samples_where_expected_is_zero: in_zero_cells,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_computed_statistic() {
        // (12-10)²/10 + (8-10)²/10 + (30-30)²/30 = 0.8 with 2 degrees of freedom.
        let cells = [(12u64, 10.0), (8, 10.0), (30, 30.0)];
        let r = pearson(cells.iter().copied());
        assert!((r.statistic - 0.8).abs() < 1e-12);
        assert_eq!((r.dof, r.cells_used, r.pooled_cells), (2, 3, 0));
        assert!((r.p_value - (-0.4f64).exp()).abs() < 1e-12);
    }

    #[test]
    fn sparse_cells_are_pooled() {
        // Three cells expecting 2 each pool into one expecting 6 with 9 observed.
        let cells = [(3u64, 2.0), (3, 2.0), (3, 2.0), (10, 10.0), (10, 10.0)];
        let r = pearson(cells.iter().copied());
        assert_eq!((r.cells_used, r.pooled_cells, r.dof), (3, 3, 2));
        assert!((r.statistic - 9.0 / 6.0).abs() < 1e-12);
    }

    #[test]
    fn a_small_pool_merges_into_the_sparsest_cell() {
        let cells = [(4u64, 1.0), (6, 6.0), (20, 20.0)];
        let r = pearson(cells.iter().copied());
        assert_eq!((r.cells_used, r.dof), (2, 1));
        assert!((r.statistic - 9.0 / 7.0).abs() < 1e-12);
    }

    #[test]
    fn counts_where_nothing_is_expected_are_fatal() {
        let cells = [(1u64, 0.0), (10, 10.0), (10, 10.0)];
        let r = pearson(cells.iter().copied());
        assert!(r.statistic.is_infinite());
        assert_eq!(r.p_value, 0.0);
        assert_eq!(r.samples_where_expected_is_zero, 1);
        // Empty cells that expect nothing are harmless.
        let cells = [(0u64, 0.0), (10, 10.0), (10, 10.0)];
        assert_eq!(pearson(cells.iter().copied()).statistic, 0.0);
    }

    #[test]
    fn a_single_cell_has_no_p_value() {
        let r = pearson([(10u64, 10.0)].into_iter());
        assert_eq!(r.dof, 0);
        assert!(r.p_value.is_nan());
    }
}
