//! Deliberately wrong samplers are rejected with the default sample count, at the
//! per-test significance of a 100-test suite.

use crate::common::*;
use glam::Vec3;
use radiant_math::sampling::{
    UNIFORM_HEMISPHERE_PDF, UNIFORM_SPHERE_PDF, concentric_disk, cosine_hemisphere, uniform_sphere,
};
use radiant_testkit::chi2::{ChiSquareTest, Domain};
use std::f32::consts::FRAC_1_PI;

#[test]
fn cosine_samples_against_a_uniform_pdf_fail() {
    let report = ChiSquareTest::new("cosine_vs_uniform", Domain::Hemisphere).run(
        |u| Some(cosine_hemisphere(u.u2)),
        |_| UNIFORM_HEMISPHERE_PDF,
    );
    print_report(&report);
    assert!(!report.passes(ALPHA, SUITE_TESTS));
    assert!(report.p_value < 1e-100);
}

#[test]
fn a_quadrant_ten_percent_too_dense_fails() {
    // Uniform disk samples; the pdf claims 1.1x the density in the first quadrant,
    // renormalized so that it still integrates to one.
    let norm = (1.1 + 3.0) / 4.0;
    let report = ChiSquareTest::new("quadrant_bias", Domain::Disk).run(
        |u| Some(concentric_disk(u.u2)),
        |p| {
            let w = if p.x > 0.0 && p.y > 0.0 { 1.1 } else { 1.0 };
            FRAC_1_PI * w / norm
        },
    );
    print_report(&report);
    assert!((report.pdf_integral - 1.0).abs() < 1e-6);
    assert!(!report.passes(ALPHA, SUITE_TESTS));
    let failures = report.failures(ALPHA, SUITE_TESTS);
    assert_eq!(failures.len(), 1);
    assert!(
        failures[0].contains("distribution mismatch"),
        "{failures:?}"
    );
}

#[test]
fn a_lobe_exponent_off_by_ten_percent_fails() {
    let axis = Vec3::new(0.6, -0.3, 0.4);
    let sampled = PhongLobe::new(axis, 22.0);
    let claimed = PhongLobe::new(axis, 20.0);
    let report = ChiSquareTest::new("phong_exponent_off", Domain::Sphere)
        .run(|u| Some(sampled.sample(u.u2)), |w| claimed.pdf(w));
    print_report(&report);
    assert!(!report.passes(ALPHA, SUITE_TESTS));
}

#[test]
fn dropping_three_percent_of_samples_fails() {
    let report = ChiSquareTest::new("drops_three_percent", Domain::Sphere).run(
        |u| (u.u1 >= 0.03).then(|| uniform_sphere(u.u2)),
        |_| UNIFORM_SPHERE_PDF,
    );
    print_report(&report);
    assert!((report.no_sample as f64 / 1e6 - 0.03).abs() < 1e-3);
    let failures = report.failures(ALPHA, SUITE_TESTS);
    assert_eq!(failures.len(), 1, "{failures:?}");
    assert!(failures[0].contains("returned no sample"), "{failures:?}");
    assert_eq!(report.samples_where_pdf_is_zero, 0);
    // The same sampler is correct once its pdf admits the loss.
    let honest = ChiSquareTest::new("drops_three_percent_declared", Domain::Sphere).run(
        |u| (u.u1 >= 0.03).then(|| uniform_sphere(u.u2)),
        |_| 0.97 * UNIFORM_SPHERE_PDF,
    );
    print_report(&honest);
    honest.assert_passes(ALPHA, SUITE_TESTS);
}
