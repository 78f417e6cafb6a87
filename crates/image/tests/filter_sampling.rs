//! Filter importance sampling (Ernst, Stamminger & Greiner 2006) against the filters,
//! by Pearson's chi-square test (`radiant_testkit::chi2`): every filter's offsets must
//! follow |f| / ∫|f| over the rectangle of its support, and the weights must be right —
//! f / (pdf ∫f) per sample (so the density they imply is the sampler's), with mean
//! one. Filters with negative lobes (Mitchell, Lanczos) are sampled by |f| and carry
//! the sign in their weights.

use radiant_image::Filter;
use radiant_math::Vec2;
use radiant_testkit::chi2::{ChiSquareReport, ChiSquareTest, Domain};

const ALPHA: f64 = 0.01;
/// Every chi-square test in this file.
const CHI2_TESTS: u32 = 11;
const SAMPLES: u64 = 1_000_000;

fn check(report: &ChiSquareReport) {
    report.check(ALPHA, CHI2_TESTS);
}

/// The filters the renderer offers, with square and elongated supports.
fn filters() -> Vec<(&'static str, Filter)> {
    vec![
        ("box_pixel", Filter::box_filter(Vec2::splat(0.5))),
        ("box_wide", Filter::box_filter(Vec2::new(1.5, 0.75))),
        ("triangle", Filter::triangle(Vec2::splat(1.0))),
        ("triangle_wide", Filter::triangle(Vec2::new(2.0, 1.25))),
        ("gaussian_default", Filter::default()),
        ("gaussian_wide", Filter::gaussian(Vec2::new(2.0, 1.0), 0.8)),
        ("gaussian_narrow", Filter::gaussian(Vec2::splat(1.0), 0.25)),
    ]
}

/// The chi-square test of `SAMPLES` offsets over a filter's support.
fn over_support(name: &str, radius: Vec2) -> ChiSquareTest {
    ChiSquareTest::new(
        name,
        Domain::Rectangle {
            min: -radius,
            max: radius,
        },
    )
    .samples(SAMPLES)
}

/// The mean of `n` weights (their sum and sum of squares) is 1, E[f / (pdf ∫f)], within
/// four standard errors.
fn assert_mean_weight_is_one(name: &str, n: u64, sum: f64, sum2: f64) {
    let mean = sum / n as f64;
    let sd = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
    assert!(
        (mean - 1.0).abs() <= 4.0 * sd + 1e-6,
        "{name}: mean weight {mean} ± {sd}, expected 1"
    );
}

/// How far the density a Gaussian weight implies, f / (weight ∫f), may be from f / ∫f:
/// the sampler inverts a piecewise-linear interpolant of each axis, whose relative error
/// is largest in the last segment before the radius (measured weights per axis within
/// 1.4e-3 of 1; the product of both axes within 3e-3).
const GAUSSIAN_PDF_TOLERANCE: f64 = 3e-3;

/// Offsets over the filter's support against f / ∫f; each sample's weight gives the
/// density it claims, f / (weight ∫f), which must be f / ∫f too (exactly for box and
/// tent, whose weights are 1). The mean weight must be ∫f / ∫|f| = 1 within its
/// standard error, and ∫f the harness's integral of f over the cells.
#[test]
fn filter_offsets_follow_the_normalised_filter() {
    for (seed, (name, filter)) in filters().into_iter().enumerate() {
        let radius = filter.radius();
        let integral = filter.integral() as f64;
        assert!(integral > 0.0, "{name}");
        let gaussian = matches!(filter, Filter::Gaussian { .. });
        let (mut n, mut sum, mut sum2) = (0u64, 0.0f64, 0.0f64);
        let report = over_support(name, radius)
            .seed(seed as u64 + 1)
            .pdf_tolerance(if gaussian {
                GAUSSIAN_PDF_TOLERANCE
            } else {
                1e-6
            })
            .run_with_pdf(
                |u| {
                    let s = filter.sample(u.u2);
                    let w = s.weight as f64;
                    n += 1;
                    sum += w;
                    sum2 += w * w;
                    assert!(w.is_finite() && w > 0.0, "{name}: weight {w}");
                    if !gaussian {
                        assert_eq!(s.weight, 1.0, "{name}: {s:?}");
                    }
                    // An offset on the support's rim (u = 0) has f = 0 and weight no
                    // density; it counts as no sample.
                    let f = filter.eval(s.offset) as f64;
                    (f > 0.0).then_some((s.offset, f / (w * integral)))
                },
                |p| filter.eval(p).abs() as f64 / integral,
            );
        check(&report);
        // The harness integrates f / ∫f over the cells: ∫f must be the filter's integral.
        assert!(
            (report.pdf_integral - 1.0).abs() < 1e-3,
            "{name}: the filter's integral {integral} is off by {}",
            report.pdf_integral - 1.0
        );
        // Samples with f = 0 lie on the support's rim, a set of measure zero.
        assert!(
            report.no_sample <= 5,
            "{name}: {} offsets on the rim",
            report.no_sample
        );
        assert_mean_weight_is_one(name, n, sum, sum2);
    }
}

/// Filters with negative lobes, square and elongated.
fn signed_filters() -> Vec<(&'static str, Filter)> {
    vec![
        (
            "mitchell_default",
            Filter::mitchell(Vec2::splat(2.0), 1.0 / 3.0, 1.0 / 3.0),
        ),
        (
            "mitchell_sharp",
            Filter::mitchell(Vec2::new(2.5, 1.5), 0.0, 0.5),
        ),
        (
            "lanczos_default",
            Filter::lanczos_sinc(Vec2::splat(4.0), 3.0),
        ),
        // Truncated between the sinc's zeros: the density is not 0 at the rim.
        (
            "lanczos_truncated",
            Filter::lanczos_sinc(Vec2::new(2.5, 1.7), 2.0),
        ),
    ]
}

/// Offsets of filters with negative lobes follow |f| / ∫|f|; their weights carry f's
/// sign, are about ±∫|f| / ∫f away from the lobes' zeros, and average 1 (the film's
/// weighted mean is then unbiased in the limit).
#[test]
fn signed_filters_sample_their_magnitude_and_weights_average_one() {
    for (seed, (name, filter)) in signed_filters().into_iter().enumerate() {
        let radius = filter.radius();
        let abs_integral = filter.abs_integral() as f64;
        let integral = filter.integral() as f64;
        assert!(
            integral > 0.0 && abs_integral > integral,
            "{name}: {integral} {abs_integral}"
        );
        let (mut n, mut sum, mut sum2, mut negative) = (0u64, 0.0f64, 0.0f64, 0u64);
        let report = over_support(name, radius).seed(seed as u64 + 101).run(
            |u| {
                let s = filter.sample(u.u2);
                let w = s.weight as f64;
                assert!(w.is_finite(), "{name}: weight {w}");
                let f = filter.eval(s.offset) as f64;
                assert!(f * w >= 0.0, "{name}: weight {w} against f {f}");
                n += 1;
                sum += w;
                sum2 += w * w;
                negative += u64::from(w < 0.0);
                Some(s.offset)
            },
            |p| filter.eval(p).abs() as f64 / abs_integral,
        );
        check(&report);
        assert!(
            (report.pdf_integral - 1.0).abs() < 1e-3,
            "{name}: ∫|f| {abs_integral} is off by {}",
            report.pdf_integral - 1.0
        );
        assert!(negative > 0, "{name}: no sample in a negative lobe");
        assert_mean_weight_is_one(name, n, sum, sum2);
    }
}

/// pbrt-v4's Mitchell filter at its defaults: 8/9 at the centre of each axis
/// ((6 − 2b) / 6 with b = 1/3), 0 at the radius, negative between 1 and 2 scaled units;
/// the windowed sinc is 1 at the centre and 0 at whole numbers.
#[test]
fn mitchell_and_lanczos_have_their_closed_forms() {
    let m = Filter::mitchell(Vec2::splat(2.0), 1.0 / 3.0, 1.0 / 3.0);
    let g0 = 8.0 / 9.0;
    assert!((m.eval(Vec2::ZERO) - g0 * g0).abs() < 1e-6);
    assert_eq!(m.eval(Vec2::new(2.0, 0.0)), 0.0);
    assert!(m.eval(Vec2::new(1.5, 0.0)) < 0.0);
    // The cubic integrates to 1 over its support [-2, 2] for any b and c; stretched
    // over the radius r it integrates to r / 2 per axis, 1 at r = 2.
    assert!((m.integral() - 1.0).abs() < 1e-4, "{}", m.integral());
    let l = Filter::lanczos_sinc(Vec2::splat(4.0), 3.0);
    assert!((l.eval(Vec2::ZERO) - 1.0).abs() < 1e-6);
    assert!(l.eval(Vec2::new(1.0, 0.0)).abs() < 1e-6);
    assert!(l.eval(Vec2::new(1.5, 0.0)) < 0.0);
}
