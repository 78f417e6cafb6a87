//! The test object: configuration, the histogram of a sampler, and the expected
//! histogram integrated from its pdf.

use crate::chi2::domain::{Domain, DomainPoint};
use crate::chi2::grid::Grid;
use crate::chi2::pearson::{MIN_EXPECTED, pearson};
use crate::chi2::quadrature::{CellIntegrator, GaussLegendre};
use crate::chi2::report::{ChiSquareReport, PdfMismatch, residual};
use glam::Vec2;
use radiant_math::hash::Pcg32;
use std::path::PathBuf;

/// Uniform random numbers handed to the sampler for one sample: a 1D number for
/// discrete choices (BSDF lobe, light selection) and two 2D numbers (direction; or
/// position and direction for emission; film and pupil for a camera). Drawn
/// independently from a seeded PCG32 stream, never stratified: Pearson's test
/// assumes independent samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleInput {
    pub u1: f32,
    pub u2: Vec2,
    pub u3: Vec2,
}

/// A chi-square goodness-of-fit test of one sampling routine against its pdf.
///
/// ```
/// use radiant_testkit::chi2::{ChiSquareTest, Domain};
/// use radiant_math::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};
///
/// ChiSquareTest::new("cosine_hemisphere", Domain::Hemisphere)
///     .samples(200_000)
///     .run(|u| Some(cosine_hemisphere(u.u2)), |w| cosine_hemisphere_pdf(w.z))
///     .assert_passes(0.01, 1);
/// ```
#[derive(Clone, Debug)]
pub struct ChiSquareTest {
    name: String,
    domain: Domain,
    resolution: [usize; 2],
    samples: u64,
    seed: u64,
    quadrature_nodes: usize,
    max_refinement: u32,
    integral_tolerance: f64,
    loss_tolerance: f64,
    pdf_tolerance: f64,
    output_dir: Option<PathBuf>,
}

/// Quadrature error allowed per cell, as a fraction of the cell's counting noise
/// sqrt(E): each cell then adds at most 0.05² = 0.0025 to a statistic whose standard
/// deviation is sqrt(2 dof) (~128 for 8k cells).
const QUADRATURE_NOISE_FRACTION: f64 = 0.05;

/// A cell is rechecked on a 2^4 x 2^4 split: 64 x 64 nodes at the default 4 per axis.
const RECHECK_SPLIT_LEVELS: u32 = 4;

/// Neighbours of rough cells are integrated again on a 2^2 x 2^2 split.
const NEIGHBOUR_SPLIT_LEVELS: u32 = 2;

/// At most this many cells are rechecked per run.
const RECHECK_LIMIT: usize = 128;

/// PCG32 stream for the sampler's random numbers (the seed varies, the stream not).
const SAMPLE_STREAM: u64 = 0x00c4_1259;

impl ChiSquareTest {
    pub const DEFAULT_SAMPLES: u64 = 1_000_000;
    /// Gauss–Legendre nodes per cell and axis: exact for polynomials of degree 7 in
    /// each parameter, far below the counting noise for smooth lobes (a cos^20 lobe
    /// spans ~10 cells); adaptive refinement takes care of the rest.
    pub const DEFAULT_QUADRATURE_NODES: usize = 4;
    /// Levels of 2 x 2 refinement allowed per cell where the pdf is not smooth: a
    /// jump is resolved to 1/256 of a cell.
    pub const DEFAULT_MAX_REFINEMENT: u32 = 8;
    pub const DEFAULT_INTEGRAL_TOLERANCE: f64 = 1e-3;
    /// See [`loss_tolerance`](Self::loss_tolerance).
    pub const DEFAULT_LOSS_TOLERANCE: f64 = 2e-4;
    pub const DEFAULT_PDF_TOLERANCE: f64 = 1e-3;

    /// A test with the domain's default resolution, 10^6 samples and seed 0.
    pub fn new(name: impl Into<String>, domain: Domain) -> ChiSquareTest {
        ChiSquareTest {
            name: name.into(),
            domain,
            resolution: domain.default_resolution(),
            samples: Self::DEFAULT_SAMPLES,
            seed: 0,
            quadrature_nodes: Self::DEFAULT_QUADRATURE_NODES,
            max_refinement: Self::DEFAULT_MAX_REFINEMENT,
            integral_tolerance: Self::DEFAULT_INTEGRAL_TOLERANCE,
            loss_tolerance: Self::DEFAULT_LOSS_TOLERANCE,
            pdf_tolerance: Self::DEFAULT_PDF_TOLERANCE,
            output_dir: None,
        }
    }

    pub fn samples(mut self, samples: u64) -> ChiSquareTest {
        self.samples = samples;
        self
    }

    pub fn seed(mut self, seed: u64) -> ChiSquareTest {
        self.seed = seed;
        self
    }

    /// Grid size: columns along the first parameter (φ, or x), rows along the second
    /// (cos θ, r², or y). An `Interval` has exactly one row.
    pub fn resolution(mut self, columns: usize, rows: usize) -> ChiSquareTest {
        self.resolution = [columns, rows];
        self
    }

    /// Gauss–Legendre nodes per cell and axis for the expected counts.
    pub fn quadrature_nodes(mut self, nodes: usize) -> ChiSquareTest {
        self.quadrature_nodes = nodes;
        self
    }

    /// Levels of adaptive 2 x 2 refinement per cell (0: the fixed rule only).
    pub fn max_refinement(mut self, levels: u32) -> ChiSquareTest {
        self.max_refinement = levels;
        self
    }

    /// How far above 1 the integral of the pdf over the domain may be.
    pub fn integral_tolerance(mut self, tolerance: f64) -> ChiSquareTest {
        self.integral_tolerance = tolerance;
        self
    }

    /// Slack, as a fraction of the sample count, on the number of trials without a
    /// sample. Its expectation samples · (1 - ∫ pdf) sums the quadrature error of all
    /// cells (a sharp rim grazing cells between their nodes is always missed the same
    /// way) and the f32 round-off of the pdf, so it cannot be exact; the expectation
    /// is moved toward the observed count by up to this slack before it enters the
    /// statistic (slightly conservative). Losses beyond it are detected. The slack
    /// is never below 5 trials.
    pub fn loss_tolerance(mut self, fraction: f64) -> ChiSquareTest {
        self.loss_tolerance = fraction;
        self
    }

    /// Relative tolerance between a sampler's own pdf and the pdf closure.
    pub fn pdf_tolerance(mut self, tolerance: f64) -> ChiSquareTest {
        self.pdf_tolerance = tolerance;
        self
    }

    /// Folder under which failure output goes (`<dir>/<test name>/`); without it,
    /// `$RADIANT_CHI2_DIR/<test name>/`, else `<cargo target dir>/chi2-failures/<test name>/`.
    pub fn output_dir(mut self, dir: impl Into<PathBuf>) -> ChiSquareTest {
        self.output_dir = Some(dir.into());
        self
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    pub fn domain(&self) -> Domain {
        self.domain
    }

    /// Runs the test. `sample` maps uniform numbers to a point of the domain, or None
    /// when the routine yields no sample (legal: a BSDF may absorb); `pdf` is the
    /// density the samples should follow, w.r.t. the domain's measure, per trial —
    /// so a routine that fails 3 % of the time has a pdf integrating to 0.97.
    ///
    /// Panics on a misconfigured test (invalid domain, empty grid, point type not
    /// matching the domain), never on a bad sampler: those go into the report.
    pub fn run<P, R>(
        &self,
        mut sample: impl FnMut(SampleInput) -> Option<P>,
        pdf: impl FnMut(P) -> R,
    ) -> ChiSquareReport
    where
        P: DomainPoint,
        R: Into<f64>,
    {
        self.run_inner(|u| sample(u).map(|p| (p, None)), pdf)
    }

    /// Like [`run`](Self::run) for routines that return their own pdf with each
    /// sample (BSDF `sample`, light `sample_li`); that value is also compared with
    /// `pdf` at the sampled point.
    pub fn run_with_pdf<P, Q, R>(
        &self,
        mut sample: impl FnMut(SampleInput) -> Option<(P, Q)>,
        pdf: impl FnMut(P) -> R,
    ) -> ChiSquareReport
    where
        P: DomainPoint,
        Q: Into<f64>,
        R: Into<f64>,
    {
        self.run_inner(|u| sample(u).map(|(p, q)| (p, Some(q.into()))), pdf)
    }

    fn check_configuration<P: DomainPoint>(&self) {
        let name = &self.name;
        if let Err(e) = self.domain.validate() {
            panic!("chi2 test '{name}': {e}");
        }
        assert!(
            P::KIND == self.domain.point_kind(),
            "chi2 test '{name}': domain {:?} takes {:?} points, the sampler returns {:?}",
            self.domain,
            self.domain.point_kind(),
            P::KIND
        );
        let [columns, rows] = self.resolution;
        assert!(
            columns > 0 && rows > 0,
            "chi2 test '{name}': empty grid {columns} x {rows}"
        );
        assert!(
            self.domain.has_rows() || rows == 1,
            "chi2 test '{name}': an interval has one row, got {rows}"
        );
        assert!(
            self.quadrature_nodes > 0,
            "chi2 test '{name}': no quadrature nodes"
        );
        assert!(self.samples > 0, "chi2 test '{name}': no samples");
    }

    fn run_inner<P, R>(
        &self,
        sample: impl FnMut(SampleInput) -> Option<(P, Option<f64>)>,
        pdf: impl FnMut(P) -> R,
    ) -> ChiSquareReport
    where
        P: DomainPoint,
        R: Into<f64>,
    {
        self.check_configuration::<P>();
        let mut pdf = CheckedPdf {
            pdf,
            invalid: 0,
            first_invalid: None,
        };
        let grid = Grid::new(self.domain, self.resolution);
        let mut expected = self.expected_counts(&grid, &mut pdf);
        let seen = self.observed_counts(&grid, sample, &mut pdf);
        self.recheck_deviating_cells(&grid, &mut pdf, &seen.observed, &mut expected);
        let pdf_integral = expected.iter().sum::<f64>() / self.samples as f64;

        // The "no sample" outcome is one more cell: it expects the probability mass
        // the pdf does not cover, so a routine that silently drops samples fails.
        let expected_no_sample = (self.samples as f64 * (1.0 - pdf_integral)).max(0.0);
        // At least MIN_EXPECTED trials of slack, so that an excess of losses always
        // leaves the cell expecting enough to stand on its own instead of being
        // diluted by pooling.
        let slack = (self.loss_tolerance * self.samples as f64).max(MIN_EXPECTED);
        let lost = seen.no_sample as f64;
        let no_sample_cell = (
            seen.no_sample,
            lost.clamp(expected_no_sample - slack, expected_no_sample + slack)
                .max(0.0),
        );
        let cells = seen
            .observed
            .iter()
            .copied()
            .zip(expected.iter().copied())
            .chain(std::iter::once(no_sample_cell));
        let stats = pearson(cells);
        ChiSquareReport {
            name: self.name.clone(),
            domain: self.domain,
            resolution: self.resolution,
            samples: self.samples,
            seed: self.seed,
            statistic: stats.statistic,
            dof: stats.dof,
            p_value: stats.p_value,
            cells_used: stats.cells_used,
            pooled_cells: stats.pooled_cells,
            // The slack keeps the "no sample" cell's expectation positive whenever
            // it has counts, so these are all samples inside the domain.
            samples_where_pdf_is_zero: stats.samples_where_expected_is_zero,
            pdf_integral,
            integral_tolerance: self.integral_tolerance,
            no_sample: seen.no_sample,
            expected_no_sample,
            outside_domain: seen.outside_domain,
            first_outside: seen.first_outside,
            invalid_pdf_values: pdf.invalid,
            first_invalid_pdf: pdf.first_invalid,
            pdf_checks: seen.pdf_checks,
            pdf_mismatches: seen.pdf_mismatches,
            pdf_tolerance: self.pdf_tolerance,
            worst_pdf_mismatch: seen.worst_pdf_mismatch,
            observed: seen.observed,
            expected,
            output_dir: self.output_dir.clone(),
        }
    }

    fn integrator(&self) -> CellIntegrator {
        let has_rows = self.domain.has_rows();
        CellIntegrator {
            col_rule: GaussLegendre::new(self.quadrature_nodes),
            row_rule: GaussLegendre::new(if has_rows { self.quadrature_nodes } else { 1 }),
            split_rows: has_rows,
            max_depth: self.max_refinement,
        }
    }

    /// ∫ pdf over one cell by adaptive tensor-product Gauss–Legendre, refined until
    /// its error estimate is a small fraction of the cell's counting noise sqrt(E), so
    /// that quadrature error cannot move the statistic noticeably.
    fn cell_integral<P, F, R>(
        &self,
        grid: &Grid,
        integrator: &CellIntegrator,
        pdf: &mut CheckedPdf<F>,
        cell: usize,
        split_levels: u32,
    ) -> (f64, bool)
    where
        P: DomainPoint,
        F: FnMut(P) -> R,
        R: Into<f64>,
    {
        let domain = grid.domain;
        let to_counts = self.samples as f64 * domain.jacobian();
        let tolerance = |integral: f64| {
            QUADRATURE_NOISE_FRACTION * (integral * to_counts).max(1.0).sqrt() / to_counts
        };
        let (row, col) = (cell / grid.columns, cell % grid.columns);
        let r0 = grid.row_range[0] + row as f64 * grid.row_width;
        let c0 = grid.col_range[0] + col as f64 * grid.col_width;
        let cols = [c0, c0 + grid.col_width];
        let rows = [r0, r0 + grid.row_width];
        let mut f = |p: [f64; 2]| pdf.eval(P::at_parameters(&domain, p));
        let (integral, rough) = integrator.integrate(&mut f, cols, rows, &tolerance, split_levels);
        (integral * domain.jacobian(), rough)
    }

    /// samples × ∫ pdf per cell. Cells next to a rough cell (one where refinement
    /// found a jump) are integrated again on a 4 x 4 split: a jump that crosses one
    /// cell often grazes its neighbours inside the band along their edges that their
    /// Gauss nodes do not see.
    fn expected_counts<P, F, R>(&self, grid: &Grid, pdf: &mut CheckedPdf<F>) -> Vec<f64>
    where
        P: DomainPoint,
        F: FnMut(P) -> R,
        R: Into<f64>,
    {
        let integrator = self.integrator();
        let n = self.samples as f64;
        let cells = grid.columns * grid.rows;
        let mut rough = vec![false; cells];
        let mut expected = vec![0.0f64; cells];
        for cell in 0..cells {
            let (integral, is_rough) = self.cell_integral(grid, &integrator, pdf, cell, 0);
            expected[cell] = n * integral;
            rough[cell] = is_rough;
        }
        for (cell, e) in expected.iter_mut().enumerate() {
            if grid.neighborhood(cell).any(|c| rough[c]) {
                *e = n * self
                    .cell_integral(grid, &integrator, pdf, cell, NEIGHBOUR_SPLIT_LEVELS)
                    .0;
            }
        }
        expected
    }

    /// Integrates again, on a 16 x 16 split of the cell, where the counts disagree
    /// with the expectation: samples in a cell expecting almost nothing (a pdf feature
    /// may hide between the quadrature nodes) or a residual beyond 3.5 sigma (a jump
    /// the error estimate misjudged). Choosing cells from the data does not bias the
    /// test: it only makes their expected counts more accurate, and true zeros stay.
    /// A correct sampler has a handful of such cells; a wrong one has many, of which
    /// only the worst `RECHECK_LIMIT` are redone.
    fn recheck_deviating_cells<P, F, R>(
        &self,
        grid: &Grid,
        pdf: &mut CheckedPdf<F>,
        observed: &[u64],
        expected: &mut [f64],
    ) where
        P: DomainPoint,
        F: FnMut(P) -> R,
        R: Into<f64>,
    {
        let mut suspicious: Vec<(usize, f64)> = observed
            .iter()
            .zip(expected.iter())
            .enumerate()
            .filter_map(|(cell, (&o, &e))| {
                let score = residual(o, e).abs();
                ((o > 0 && e < MIN_EXPECTED) || score > 3.5).then_some((cell, score))
            })
            .collect();
        suspicious.sort_by(|a, b| b.1.total_cmp(&a.1));
        suspicious.truncate(RECHECK_LIMIT);
        let integrator = self.integrator();
        let n = self.samples as f64;
        for (cell, _) in suspicious {
            expected[cell] = n * self
                .cell_integral(grid, &integrator, pdf, cell, RECHECK_SPLIT_LEVELS)
                .0;
        }
    }

    /// Draws the samples and bins them; compares returned pdfs with the closure.
    fn observed_counts<P, F, R>(
        &self,
        grid: &Grid,
        mut sample: impl FnMut(SampleInput) -> Option<(P, Option<f64>)>,
        pdf: &mut CheckedPdf<F>,
    ) -> Observation
    where
        P: DomainPoint,
        F: FnMut(P) -> R,
        R: Into<f64>,
    {
        let mut seen = Observation {
            observed: vec![0u64; grid.columns * grid.rows],
            no_sample: 0,
            outside_domain: 0,
            first_outside: None,
            pdf_checks: 0,
            pdf_mismatches: 0,
            worst_pdf_mismatch: None,
        };
        let mut rng = Pcg32::new(self.seed, SAMPLE_STREAM);
        for _ in 0..self.samples {
            let u = SampleInput {
                u1: rng.uniform(),
                u2: Vec2::new(rng.uniform(), rng.uniform()),
                u3: Vec2::new(rng.uniform(), rng.uniform()),
            };
            let Some((point, own_pdf)) = sample(u) else {
                seen.no_sample += 1;
                continue;
            };
            let Some(cell) = grid.cell_of(point) else {
                seen.outside_domain += 1;
                if seen.first_outside.is_none() {
                    seen.first_outside = Some(format!("{point:?}"));
                }
                continue;
            };
            seen.observed[cell] += 1;
            let Some(sampled) = own_pdf else {
                continue;
            };
            seen.pdf_checks += 1;
            let evaluated = pdf.eval(point);
            let error = relative_pdf_error(sampled, evaluated);
            if error > self.pdf_tolerance {
                seen.pdf_mismatches += 1;
                let worst = &seen.worst_pdf_mismatch;
                if worst.as_ref().is_none_or(|w| error > w.relative_error) {
                    seen.worst_pdf_mismatch = Some(PdfMismatch {
                        point: format!("{point:?}"),
                        sampled,
                        evaluated,
                        relative_error: error,
                    });
                }
            }
        }
        seen
    }
}

/// The pdf closure, with negative or non-finite values counted and replaced by 0.
struct CheckedPdf<F> {
    pdf: F,
    invalid: u64,
    first_invalid: Option<String>,
}

impl<F> CheckedPdf<F> {
    fn eval<P: DomainPoint, R: Into<f64>>(&mut self, p: P) -> f64
    where
        F: FnMut(P) -> R,
    {
        let v: f64 = (self.pdf)(p).into();
        if v.is_finite() && v >= 0.0 {
            return v;
        }
        self.invalid += 1;
        if self.first_invalid.is_none() {
            self.first_invalid = Some(format!("pdf({p:?}) = {v}"));
        }
        0.0
    }
}

/// What the sampling pass saw.
struct Observation {
    observed: Vec<u64>,
    no_sample: u64,
    outside_domain: u64,
    first_outside: Option<String>,
    pdf_checks: u64,
    pdf_mismatches: u64,
    worst_pdf_mismatch: Option<PdfMismatch>,
}

/// |a - b| / max(a, b); infinite when the sampler's own pdf is not a positive finite
/// number (a returned sample with pdf 0 would divide by zero in an estimator).
fn relative_pdf_error(sampled: f64, evaluated: f64) -> f64 {
    if !(sampled.is_finite() && sampled > 0.0) {
        return f64::INFINITY;
    }
    (sampled - evaluated).abs() / sampled.max(evaluated)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_pdf_error_is_symmetric_and_flags_bad_values() {
        assert!((relative_pdf_error(1.0, 1.1) - relative_pdf_error(1.1, 1.0)).abs() < 1e-15);
        assert!((relative_pdf_error(2.0, 1.0) - 0.5).abs() < 1e-15);
        assert!(relative_pdf_error(0.0, 0.0).is_infinite());
        assert!(relative_pdf_error(f64::NAN, 1.0).is_infinite());
        assert_eq!(relative_pdf_error(0.3, 0.3), 0.0);
    }
}
