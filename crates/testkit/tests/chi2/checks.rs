//! The harness's own checks: determinism, calibration, failure output, and the sanity
//! checks beside the statistic.

use crate::common::*;
use glam::{Vec2, Vec3};
use radiant_math::sampling::{
    UNIFORM_HEMISPHERE_PDF, UNIFORM_SPHERE_PDF, cosine_hemisphere, cosine_hemisphere_pdf,
    uniform_hemisphere, uniform_sphere,
};
use radiant_testkit::chi2::{ChiSquareTest, Domain, chi_square_survival};
use std::path::PathBuf;

fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radiant-chi2-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn same_seed_gives_identical_counts_and_other_seeds_differ() {
    let run = |seed| {
        ChiSquareTest::new("determinism", Domain::Sphere)
            .samples(100_000)
            .seed(seed)
            .run(|u| Some(uniform_sphere(u.u2)), |_| UNIFORM_SPHERE_PDF)
    };
    let (a, b, c) = (run(3), run(3), run(4));
    assert_eq!(a.observed(), b.observed());
    assert_eq!(a.statistic.to_bits(), b.statistic.to_bits());
    assert_ne!(a.observed(), c.observed());
}

/// Under the null hypothesis p-values are uniform on [0, 1]. Over 60 seeds of a small
/// test, the Kolmogorov–Smirnov distance to the uniform CDF stays below 0.25, the
/// 0.1 % critical value for n = 60 (1.95 / √n); a harness whose statistic, pooling or
/// tail function were off (e.g. dof miscounted by a few percent) would exceed it.
#[test]
fn p_values_of_a_correct_sampler_are_uniform() {
    let mut p: Vec<f64> = (0..60)
        .map(|seed| {
            ChiSquareTest::new("calibration", Domain::Hemisphere)
                .resolution(24, 12)
                .samples(20_000)
                .seed(1000 + seed)
                .run(
                    |u| Some(cosine_hemisphere(u.u2)),
                    |w| cosine_hemisphere_pdf(w.z),
                )
                .p_value
        })
        .collect();
    p.sort_by(f64::total_cmp);
    let n = p.len() as f64;
    let ks = p
        .iter()
        .enumerate()
        .map(|(i, &x)| (x - i as f64 / n).abs().max(((i + 1) as f64 / n - x).abs()))
        .fold(0.0, f64::max);
    let mean = p.iter().sum::<f64>() / n;
    println!("KS distance {ks:.3}, mean p {mean:.3}");
    assert!(ks < 0.25, "KS distance {ks}");
}

#[test]
fn failure_writes_named_histograms() {
    let dir = scratch_dir("failure");
    let report = ChiSquareTest::new("cosine vs uniform/1", Domain::Hemisphere)
        .samples(200_000)
        .output_dir(&dir)
        .run(
            |u| Some(cosine_hemisphere(u.u2)),
            |_| UNIFORM_HEMISPHERE_PDF,
        );
    let message = std::panic::catch_unwind(|| report.assert_passes(ALPHA, SUITE_TESTS))
        .expect_err("a wrong sampler must fail")
        .downcast::<String>()
        .expect("panic message");
    println!("{message}");
    let folder = dir.join("cosine_vs_uniform_1");
    assert_eq!(report.failure_dir(), folder);
    for file in [
        "observed.pfm",
        "expected.pfm",
        "residual.pfm",
        "summary.txt",
    ] {
        let path = folder.join(file);
        assert!(path.is_file(), "{} missing", path.display());
        assert!(message.contains(&path.display().to_string()), "{message}");
    }
    assert!(message.contains("statistic") && message.contains("dof 8191"));
    assert!(message.contains("p-value"));
    let pfm = std::fs::read(folder.join("observed.pfm")).unwrap();
    let header = b"Pf\n128 64\n-1.0\n";
    assert_eq!(&pfm[..header.len()], header);
    assert_eq!(pfm.len(), header.len() + 128 * 64 * 4);
    // Bottom row is cos θ near 0; with cosine sampling it holds few samples.
    let first = f32::from_le_bytes(pfm[header.len()..header.len() + 4].try_into().unwrap());
    let total: u64 = report.observed().iter().sum();
    assert_eq!(first as u64, report.observed()[0]);
    assert_eq!(total, 200_000);
    let summary = std::fs::read_to_string(folder.join("summary.txt")).unwrap();
    assert!(summary.starts_with("FAILED:") && summary.contains("largest deviations"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn default_failure_dir_is_in_the_target_folder() {
    let report = ChiSquareTest::new("where", Domain::Sphere)
        .samples(1000)
        .run(|u| Some(uniform_sphere(u.u2)), |_| UNIFORM_SPHERE_PDF);
    let dir = report.failure_dir();
    if std::env::var_os("RADIANT_CHI2_DIR").is_none() {
        assert!(dir.ends_with("chi2-failures/where"), "{}", dir.display());
    } else {
        assert!(dir.ends_with("where"), "{}", dir.display());
    }
}

#[test]
fn samples_outside_the_domain_are_reported() {
    // Every 100th direction points below the horizon.
    let report = ChiSquareTest::new("below_horizon", Domain::Hemisphere)
        .samples(100_000)
        .run(
            |u| {
                let w = uniform_hemisphere(u.u2);
                Some(if u.u1 < 0.01 { -w } else { w })
            },
            |_| UNIFORM_HEMISPHERE_PDF,
        );
    assert!((report.outside_domain as f64 - 1000.0).abs() < 150.0);
    let failures = report.failures(ALPHA, SUITE_TESTS);
    assert!(
        failures.iter().any(|f| f.contains("outside the domain")),
        "{failures:?}"
    );
    // A non-normalized direction is outside too.
    let report = ChiSquareTest::new("not_unit", Domain::Sphere)
        .samples(10_000)
        .run(
            |u| Some(uniform_sphere(u.u2) * 1.01),
            |_| UNIFORM_SPHERE_PDF,
        );
    assert_eq!(report.outside_domain, 10_000);
}

#[test]
fn negative_and_non_finite_pdf_values_are_reported() {
    let report = ChiSquareTest::new("nan_pdf", Domain::Sphere)
        .samples(100_000)
        .run(
            |u| Some(uniform_sphere(u.u2)),
            |w: Vec3| {
                if w.z > 0.99 {
                    f32::NAN
                } else {
                    UNIFORM_SPHERE_PDF
                }
            },
        );
    assert!(report.invalid_pdf_values > 0);
    assert!(report.first_invalid_pdf.as_deref().unwrap().contains("NaN"));
    assert!(!report.passes(ALPHA, SUITE_TESTS));
    let report = ChiSquareTest::new("negative_pdf", Domain::Interval { min: 0.0, max: 1.0 })
        .samples(100_000)
        .run(|u| Some(u.u1), |x: f32| if x < 0.01 { -1.0 } else { 1.0 });
    assert!(report.invalid_pdf_values > 0);
    assert!(!report.passes(ALPHA, SUITE_TESTS));
}

#[test]
fn inconsistent_returned_pdfs_are_reported() {
    // The sampler's own pdf is 2x too large in a small polar cap.
    let report = ChiSquareTest::new("pdf_mismatch", Domain::Hemisphere)
        .samples(100_000)
        .run_with_pdf(
            |u| {
                let w = cosine_hemisphere(u.u2);
                let pdf = cosine_hemisphere_pdf(w.z);
                Some((w, if w.z > 0.95 { 2.0 * pdf } else { pdf }))
            },
            |w| cosine_hemisphere_pdf(w.z),
        );
    // P(cos θ > 0.95) = 1 - 0.95² = 0.0975 under cosine sampling.
    let fraction = report.pdf_mismatches as f64 / report.pdf_checks as f64;
    assert!((fraction - 0.0975).abs() < 0.005, "{fraction}");
    let worst = report.worst_pdf_mismatch.as_ref().unwrap();
    assert!((worst.relative_error - 0.5).abs() < 1e-6);
    let failures = report.failures(ALPHA, SUITE_TESTS);
    assert_eq!(failures.len(), 1, "{failures:?}");
    // A zero pdf returned with a sample is a mismatch as well.
    let report = ChiSquareTest::new("zero_pdf", Domain::Sphere)
        .samples(1000)
        .run_with_pdf(
            |u| Some((uniform_sphere(u.u2), 0.0f32)),
            |_| UNIFORM_SPHERE_PDF,
        );
    assert_eq!(report.pdf_mismatches, 1000);
}

#[test]
fn a_pdf_integrating_above_one_is_reported() {
    let report = ChiSquareTest::new("too_much_mass", Domain::Sphere)
        .samples(100_000)
        .run(
            |u| Some(uniform_sphere(u.u2)),
            |_| 1.01 * UNIFORM_SPHERE_PDF,
        );
    assert!((report.pdf_integral - 1.01).abs() < 1e-6);
    let failures = report.failures(ALPHA, SUITE_TESTS);
    assert!(
        failures.iter().any(|f| f.contains("integrates to 1.01")),
        "{failures:?}"
    );
    let loose = ChiSquareTest::new("too_much_mass", Domain::Sphere)
        .samples(100_000)
        .integral_tolerance(0.02)
        .run(
            |u| Some(uniform_sphere(u.u2)),
            |_| 1.01 * UNIFORM_SPHERE_PDF,
        );
    assert!(
        !loose
            .failures(ALPHA, SUITE_TESTS)
            .iter()
            .any(|f| f.contains("integrates"))
    );
}

#[test]
fn samples_where_the_pdf_vanishes_are_fatal() {
    // Uniform on the whole sphere, but the pdf claims the upper hemisphere only.
    let report = ChiSquareTest::new("zero_region", Domain::Sphere)
        .samples(10_000)
        .run(
            |u| Some(uniform_sphere(u.u2)),
            |w: Vec3| {
                if w.z >= 0.0 {
                    UNIFORM_HEMISPHERE_PDF
                } else {
                    0.0
                }
            },
        );
    assert!((report.samples_where_pdf_is_zero as f64 - 5000.0).abs() < 300.0);
    assert!(report.statistic.is_infinite() && report.p_value == 0.0);
    assert!(!report.passes(ALPHA, SUITE_TESTS));
}

#[test]
fn too_few_samples_is_a_failure_not_a_pass() {
    let report = ChiSquareTest::new("starved", Domain::Sphere)
        .samples(20)
        .run(|u| Some(uniform_sphere(u.u2)), |_| UNIFORM_SPHERE_PDF);
    assert!(report.p_value.is_nan());
    let failures = report.failures(ALPHA, SUITE_TESTS);
    assert!(
        failures
            .iter()
            .any(|f| f.contains("raise the sample count")),
        "{failures:?}"
    );
}

#[test]
#[should_panic(expected = "takes Direction points")]
fn a_point_type_not_matching_the_domain_panics() {
    ChiSquareTest::new("mismatch", Domain::Sphere)
        .samples(10)
        .run(|u| Some(u.u2), |_: Vec2| 1.0f32);
}

#[test]
fn the_p_value_is_the_chi_square_tail_of_the_statistic() {
    let report = ChiSquareTest::new("tail", Domain::Disk)
        .samples(50_000)
        .resolution(32, 16)
        .run(
            |u| Some(radiant_math::sampling::concentric_disk(u.u2)),
            |_| std::f32::consts::FRAC_1_PI,
        );
    assert_eq!(report.cells_used, 512);
    assert_eq!(report.dof, 511);
    let p = chi_square_survival(report.statistic, report.dof);
    assert_eq!(p, report.p_value);
    // Statistic recomputed from the histograms (no pooling at ~98 per cell).
    let direct: f64 = report
        .observed()
        .iter()
        .zip(report.expected())
        .map(|(&o, &e)| (o as f64 - e).powi(2) / e)
        .sum();
    // The f32 pdf 1/π integrates to 1 - 4e-8, so the "no sample" cell expects ~0.002
    // and is merged into the sparsest cell; that shifts the statistic by ~1e-6.
    assert!(
        (direct - report.statistic).abs() < 1e-5 * direct,
        "{direct} vs {}",
        report.statistic
    );
}

/// The "no sample" cell resolves losses down to the loss tolerance (2e-4 of the
/// samples by default): 0.1 % unaccounted losses fail, 0.01 % are absorbed, and
/// 0.03 % pass by default but fail without tolerance.
#[test]
fn small_unaccounted_losses_are_resolved_down_to_the_loss_tolerance() {
    let run = |loss: f32, tolerance: f64| {
        ChiSquareTest::new("small_loss", Domain::Sphere)
            .loss_tolerance(tolerance)
            .run(
                |u| (u.u1 >= loss).then(|| uniform_sphere(u.u2)),
                |_| UNIFORM_SPHERE_PDF,
            )
    };
    let default = ChiSquareTest::DEFAULT_LOSS_TOLERANCE;
    assert!(!run(1e-3, default).passes(ALPHA, SUITE_TESTS));
    assert!(run(1e-4, default).passes(ALPHA, SUITE_TESTS));
    assert!(run(3e-4, default).passes(ALPHA, SUITE_TESTS));
    assert!(!run(3e-4, 0.0).passes(ALPHA, SUITE_TESTS));
}
