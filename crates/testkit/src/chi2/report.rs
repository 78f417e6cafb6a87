//! The outcome of one test: the statistic and every sanity check, the verdict under a
//! multiple-testing correction, and a failure message naming the files written.

use crate::chi2::domain::Domain;
use crate::chi2::output::{HistogramFiles, default_failure_dir};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Šidák's correction (Šidák 1967, "Rectangular confidence regions for the means of
/// multivariate normal distributions"): the per-test significance at which `test_count`
/// independent tests together reject a correct sampler with probability `alpha`,
/// 1 - (1 - alpha)^(1/test_count). Evaluated through ln1p/expm1 so that it keeps its
/// precision when alpha / test_count is tiny.
pub fn sidak_significance(alpha: f64, test_count: u32) -> f64 {
    assert!(
        (0.0..1.0).contains(&alpha) && test_count > 0,
        "alpha must be in [0, 1) and test_count positive, got {alpha} and {test_count}"
    );
    -((-alpha).ln_1p() / test_count as f64).exp_m1()
}

/// The sampled point where the sampler's own pdf and the pdf closure disagree most.
#[derive(Clone, Debug, PartialEq)]
pub struct PdfMismatch {
    pub point: String,
    /// The pdf the sampler returned with the sample.
    pub sampled: f64,
    /// The pdf closure at the same point.
    pub evaluated: f64,
    /// |sampled - evaluated| / max(sampled, evaluated); infinite when `sampled` is not
    /// a positive finite number.
    pub relative_error: f64,
}

/// Everything one run of a [`ChiSquareTest`](crate::chi2::ChiSquareTest) measured. Histograms
/// are row-major (`row * columns + column`), rows along cos θ / r² / y.
#[derive(Clone, Debug)]
pub struct ChiSquareReport {
    pub name: String,
    pub domain: Domain,
    /// (columns, rows).
    pub resolution: [usize; 2],
    pub samples: u64,
    pub seed: u64,
    /// Pearson's statistic after pooling; infinite when samples fell where the pdf is 0.
    pub statistic: f64,
    pub dof: usize,
    /// NaN when fewer than two cells expect at least 5 counts.
    pub p_value: f64,
    pub cells_used: usize,
    pub pooled_cells: usize,
    /// Samples in cells whose integrated pdf is exactly zero.
    pub samples_where_pdf_is_zero: u64,
    /// ∫ pdf over the domain; below 1 for routines that may yield no sample.
    pub pdf_integral: f64,
    pub integral_tolerance: f64,
    /// Trials on which the sampler returned None.
    pub no_sample: u64,
    /// samples · (1 - pdf_integral), what `no_sample` should be near.
    pub expected_no_sample: f64,
    /// Samples off the domain (non-unit or below-horizon directions, non-finite points).
    pub outside_domain: u64,
    pub first_outside: Option<String>,
    /// Negative or non-finite pdf closure values (at quadrature nodes or samples).
    pub invalid_pdf_values: u64,
    pub first_invalid_pdf: Option<String>,
    /// Samples whose own pdf was compared with the pdf closure (0 for `run`).
    pub pdf_checks: u64,
    pub pdf_mismatches: u64,
    pub pdf_tolerance: f64,
    pub worst_pdf_mismatch: Option<PdfMismatch>,
    pub(crate) observed: Vec<u64>,
    pub(crate) expected: Vec<f64>,
    pub(crate) output_dir: Option<PathBuf>,
}

impl ChiSquareReport {
    /// Observed counts per cell.
    pub fn observed(&self) -> &[u64] {
        &self.observed
    }

    /// Expected counts per cell (samples × integral of the pdf over the cell).
    pub fn expected(&self) -> &[f64] {
        &self.expected
    }

    /// Why the routine fails at family-wise significance `alpha` over `test_count`
    /// tests; empty when it passes.
    pub fn failures(&self, alpha: f64, test_count: u32) -> Vec<String> {
        let significance = sidak_significance(alpha, test_count);
        let mut reasons = Vec::new();
        if self.samples_where_pdf_is_zero > 0 {
            reasons.push(format!(
                "{} samples fell into cells where the pdf integrates to zero \
                 (or the pdf has features finer than the quadrature nodes)",
                self.samples_where_pdf_is_zero
            ));
        }
        if self.p_value.is_nan() {
            reasons.push(format!(
                "only {} cell(s) expect at least 5 samples: raise the sample count or lower the resolution",
                self.cells_used
            ));
        } else if self.p_value < significance {
            let mut reason = format!(
                "distribution mismatch: statistic {:.2}, dof {}, p-value {:.3e} < significance {:.3e} \
                 (alpha {alpha} over {test_count} tests)",
                self.statistic, self.dof, self.p_value, significance
            );
            // Losing samples the pdf does not account for is a common bug; name it.
            let lost = self.no_sample as f64;
            if (lost - self.expected_no_sample).abs()
                > 3.0 * self.expected_no_sample.max(1.0).sqrt()
            {
                let _ = write!(
                    reason,
                    "; the sampler returned no sample {} times where the pdf predicts {:.1}",
                    self.no_sample, self.expected_no_sample
                );
            }
            reasons.push(reason);
        }
        if self.pdf_integral > 1.0 + self.integral_tolerance {
            reasons.push(format!(
                "pdf integrates to {:.6} over the domain (more than 1 + {})",
                self.pdf_integral, self.integral_tolerance
            ));
        }
        if self.outside_domain > 0 {
            reasons.push(format!(
                "{} samples outside the domain, first {}",
                self.outside_domain,
                self.first_outside.as_deref().unwrap_or("?")
            ));
        }
        if self.invalid_pdf_values > 0 {
            reasons.push(format!(
                "{} negative or non-finite pdf values, first {}",
                self.invalid_pdf_values,
                self.first_invalid_pdf.as_deref().unwrap_or("?")
            ));
        }
        if let Some(w) = &self.worst_pdf_mismatch {
            reasons.push(format!(
                "{} of {} sampled pdfs differ from the pdf closure by more than {} relative; \
                 worst at {}: sampled {:e}, closure {:e}",
                self.pdf_mismatches,
                self.pdf_checks,
                self.pdf_tolerance,
                w.point,
                w.sampled,
                w.evaluated
            ));
        }
        reasons
    }

    pub fn passes(&self, alpha: f64, test_count: u32) -> bool {
        self.failures(alpha, test_count).is_empty()
    }

    /// One line for the test log: statistic, degrees of freedom, p-value, the pdf's
    /// integral over the domain and the count of failed samples.
    pub fn one_line(&self) -> String {
        format!(
            "{}: statistic {:.1}, dof {}, p-value {:.3e}, integral {:.6}, no sample {}",
            self.name, self.statistic, self.dof, self.p_value, self.pdf_integral, self.no_sample
        )
    }

    /// Prints [`one_line`](Self::one_line), then [`assert_passes`](Self::assert_passes).
    pub fn check(&self, alpha: f64, test_count: u32) {
        println!("{}", self.one_line());
        self.assert_passes(alpha, test_count);
    }

    /// Panics unless the routine passes at family-wise significance `alpha` over
    /// `test_count` tests. Before panicking it writes the observed, expected and
    /// residual histograms and a summary into [`failure_dir`](Self::failure_dir);
    /// the message names them.
    pub fn assert_passes(&self, alpha: f64, test_count: u32) {
        let reasons = self.failures(alpha, test_count);
        if reasons.is_empty() {
            return;
        }
        let mut message = format!("chi2 test '{}' failed:\n", self.name);
        for r in &reasons {
            let _ = writeln!(message, "  - {r}");
        }
        let _ = writeln!(
            message,
            "  statistic {:.2}, dof {}, p-value {:.3e}",
            self.statistic, self.dof, self.p_value
        );
        let dir = self.failure_dir();
        match self.write_files(&dir, &reasons) {
            Ok(files) => {
                let _ = write!(message, "{files}");
            }
            Err(e) => {
                let _ = write!(message, "  (could not write histograms: {e})");
            }
        }
        panic!("{message}");
    }

    /// Where [`assert_passes`](Self::assert_passes) writes on failure:
    /// `<output_dir>/<name>/` if the test set one, else `$RADIANT_CHI2_DIR/<name>/`, else
    /// `<cargo target dir>/chi2-failures/<name>/`.
    pub fn failure_dir(&self) -> PathBuf {
        let base = match &self.output_dir {
            Some(dir) => dir.clone(),
            None => default_failure_dir(),
        };
        base.join(sanitize(&self.name))
    }

    /// Writes `observed.pfm`, `expected.pfm`, `residual.pfm` ((O - E)/√E per cell) and
    /// `summary.txt` into `dir`, creating it.
    pub fn write_histograms(&self, dir: &Path) -> Result<HistogramFiles, crate::chi2::Chi2Error> {
        self.write_files(dir, &[])
    }

    fn write_files(
        &self,
        dir: &Path,
        reasons: &[String],
    ) -> Result<HistogramFiles, crate::chi2::Chi2Error> {
        let mut summary = String::new();
        if !reasons.is_empty() {
            summary.push_str("FAILED:\n");
            for r in reasons {
                let _ = writeln!(summary, "  - {r}");
            }
            summary.push('\n');
        }
        summary.push_str(&self.summary());
        crate::chi2::output::write_all(self, dir, &summary)
    }

    /// A human-readable account of the run, with the cells that deviate most.
    pub fn summary(&self) -> String {
        let [columns, rows] = self.resolution;
        let [col_axis, row_axis] = self.domain.axis_names();
        let mut s = String::new();
        let _ = writeln!(s, "chi2 test '{}' on {:?}", self.name, self.domain);
        let _ = writeln!(
            s,
            "grid: {columns} columns ({col_axis}) x {rows} rows ({row_axis}), {} samples, seed {}",
            self.samples, self.seed
        );
        let _ = writeln!(
            s,
            "statistic {:.3}, dof {}, p-value {:.4e}; {} cells used, {} pooled",
            self.statistic, self.dof, self.p_value, self.cells_used, self.pooled_cells
        );
        let _ = writeln!(
            s,
            "pdf integral {:.6}; no sample {} (expected {:.1}); outside domain {}; \
             invalid pdf values {}; pdf checks {} with {} mismatches",
            self.pdf_integral,
            self.no_sample,
            self.expected_no_sample,
            self.outside_domain,
            self.invalid_pdf_values,
            self.pdf_checks,
            self.pdf_mismatches
        );
        let _ = writeln!(
            s,
            "largest deviations (column, row: observed vs expected, (O-E)/sqrt(E)):"
        );
        for (i, score) in self.worst_cells(12) {
            let _ = writeln!(
                s,
                "  {:>4}, {:>4}: {:>8} vs {:>10.2}  {:+.2}",
                i % columns,
                i / columns,
                self.observed[i],
                self.expected[i],
                score
            );
        }
        s
    }

    /// Indices of the `count` cells with the largest |O - E| / √E (counts in cells
    /// expecting nothing rank first), with that score.
    fn worst_cells(&self, count: usize) -> Vec<(usize, f64)> {
        let mut scored: Vec<(usize, f64)> = (0..self.observed.len())
            .map(|i| (i, residual(self.observed[i], self.expected[i])))
            .collect();
        scored.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
        scored.truncate(count);
        scored
    }
}

/// (O - E)/√E; infinite for counts where nothing is expected, 0 for an empty cell
/// expecting nothing.
pub(crate) fn residual(observed: u64, expected: f64) -> f64 {
    let o = observed as f64;
    if expected > 0.0 {
        (o - expected) / expected.sqrt()
    } else if observed > 0 {
        f64::INFINITY
    } else {
        0.0
    }
}

/// A test name as a single path component.
fn sanitize(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() || s.chars().all(|c| c == '.') {
        "unnamed".to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sidak_matches_its_definition_and_limits() {
        assert!((sidak_significance(0.01, 1) - 0.01).abs() < 1e-15);
        let s = sidak_significance(0.01, 100);
        assert!((s - (1.0 - 0.99f64.powf(0.01))).abs() < 1e-15);
        // Slightly above Bonferroni's alpha / n, and n tests at s reproduce alpha.
        assert!(s > 0.01 / 100.0 && s < 0.01 / 100.0 * 1.01);
        assert!((1.0 - (1.0 - s).powi(100) - 0.01).abs() < 1e-12);
        assert!(sidak_significance(1e-12, 1000) > 0.0);
    }

    #[test]
    fn names_become_single_path_components() {
        assert_eq!(sanitize("bsdf/diffuse θ=30"), "bsdf_diffuse___30");
        assert_eq!(sanitize(".."), "unnamed");
        assert_eq!(sanitize("ok-name_1.2"), "ok-name_1.2");
    }
}
