//! Chi-square goodness-of-fit tests for sampling routines: BSDF sampling, light
//! `sample_li` and emission sampling, pixel-filter sampling, the realistic camera's
//! pupil sampling — anything that maps uniform random numbers to points of a sphere,
//! hemisphere, disk, rectangle or interval and claims a density for them.
//!
//! The idea (as in Mitsuba 3's shared chi-square test) is to histogram many samples
//! over a grid of cells of known measure, integrate the claimed pdf over the same
//! cells, and compare with Pearson's statistic (Pearson 1900). Sparse cells are pooled
//! so the chi-square approximation holds; the "no sample" outcome is a cell of its own,
//! so routines that silently lose samples are caught; a suite of many tests uses
//! Šidák's correction so that correct code fails with probability `alpha` overall.
//!
//! ```
//! use radiant_testkit::chi2::{ChiSquareTest, Domain};
//! use radiant_math::sampling::{UNIFORM_SPHERE_PDF, uniform_sphere};
//!
//! let report = ChiSquareTest::new("uniform_sphere", Domain::Sphere)
//!     .samples(100_000)
//!     .seed(7)
//!     .run(|u| Some(uniform_sphere(u.u2)), |_| UNIFORM_SPHERE_PDF);
//! report.assert_passes(0.01, 1);
//! assert!((report.pdf_integral - 1.0).abs() < 1e-6);
//! ```
//!
//! Random numbers come from a seeded PCG32 stream, independent and never stratified
//! (Pearson's test assumes independent samples), so every run is reproducible.
//!
//! Expected counts must be accurate to a fraction of their own noise √E, or 10^6
//! samples would flag the quadrature instead of the sampler. Each cell is integrated
//! with tensor Gauss–Legendre (4 x 4 nodes), refined adaptively where a 2 x 2 split
//! disagrees; cells next to such rough cells are integrated again on a finer split
//! (a cone's rim may graze them between their nodes); after sampling, cells whose
//! counts deviate by more than 3.5σ, or that hold samples while expecting almost
//! none, are integrated once more on a 16 x 16 split. That last step looks at the
//! data, but only to make expectations more accurate; true zeros stay zero.
//!
//! Sanity checks beside the statistic: samples outside the domain, negative or
//! non-finite pdf values, ∫ pdf > 1 + tolerance, and (with
//! [`ChiSquareTest::run_with_pdf`]) the sampler's own pdf against the pdf closure.

mod domain;
mod gamma;
mod grid;
mod harness;
mod output;
mod pearson;
mod quadrature;
mod report;

pub use domain::{Domain, DomainPoint, PointKind};
pub use gamma::{chi_square_survival, ln_gamma, regularized_gamma_q};
pub use harness::{ChiSquareTest, SampleInput};
pub use output::{Chi2Error, HistogramFiles, encode_pfm};
pub use pearson::MIN_EXPECTED;
pub use quadrature::GaussLegendre;
pub use report::{ChiSquareReport, PdfMismatch, sidak_significance};
