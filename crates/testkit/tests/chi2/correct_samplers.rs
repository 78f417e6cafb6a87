//! Correct samplers pass with the default sample count, at the per-test significance a
//! 100-test suite uses.

use crate::common::*;
use glam::{Vec2, Vec3};
use radiant_math::sampling::{
    UNIFORM_SPHERE_PDF, concentric_disk, cosine_hemisphere, cosine_hemisphere_pdf, uniform_sphere,
};
use radiant_testkit::chi2::{ChiSquareTest, Domain};
use std::f32::consts::FRAC_1_PI;

#[test]
fn uniform_sphere_passes() {
    let report = ChiSquareTest::new("uniform_sphere", Domain::Sphere)
        .run(|u| Some(uniform_sphere(u.u2)), |_| UNIFORM_SPHERE_PDF);
    print_report(&report);
    assert!((report.pdf_integral - 1.0).abs() < 1e-6);
    assert_eq!(report.resolution, [128, 64]);
    report.assert_passes(ALPHA, SUITE_TESTS);
}

#[test]
fn cosine_hemisphere_passes_with_its_own_pdf_consistent() {
    let report = ChiSquareTest::new("cosine_hemisphere", Domain::Hemisphere).run_with_pdf(
        |u| {
            let w = cosine_hemisphere(u.u2);
            Some((w, cosine_hemisphere_pdf(w.z)))
        },
        |w| cosine_hemisphere_pdf(w.z),
    );
    print_report(&report);
    assert_eq!(report.pdf_checks, 1_000_000);
    assert_eq!(report.pdf_mismatches, 0);
    assert!((report.pdf_integral - 1.0).abs() < 1e-6);
    report.assert_passes(ALPHA, SUITE_TESTS);
}

#[test]
fn concentric_disk_passes() {
    let report = ChiSquareTest::new("concentric_disk", Domain::Disk)
        .run(|u| Some(concentric_disk(u.u2)), |_| FRAC_1_PI);
    print_report(&report);
    assert!((report.pdf_integral - 1.0).abs() < 1e-6);
    report.assert_passes(ALPHA, SUITE_TESTS);
}

#[test]
fn truncated_gaussian_on_a_rectangle_passes_and_its_losses_match() {
    let (sigma, radius) = (0.5, 1.5);
    let domain = Domain::Rectangle {
        min: Vec2::splat(-radius),
        max: Vec2::splat(radius),
    };
    let report = ChiSquareTest::new("truncated_gaussian", domain).run(
        |u| gaussian_offset(u.u2, sigma, radius),
        |p| gaussian_pdf(p, sigma),
    );
    print_report(&report);
    // erf(1.5 / (0.5 sqrt 2))^2 = erf(2.12132)^2 = 0.994608.
    assert!(
        (report.pdf_integral - 0.994_608).abs() < 1e-5,
        "{}",
        report.pdf_integral
    );
    let lost = report.no_sample as f64;
    assert!((lost - report.expected_no_sample).abs() < 4.0 * report.expected_no_sample.sqrt());
    report.assert_passes(ALPHA, SUITE_TESTS);
}

#[test]
fn tilted_phong_lobe_passes() {
    let lobe = PhongLobe::new(Vec3::new(0.6, -0.3, 0.4), 20.0);
    let report = ChiSquareTest::new("phong_lobe_20", Domain::Sphere).run_with_pdf(
        |u| {
            let w = lobe.sample(u.u2);
            Some((w, lobe.pdf(w)))
        },
        |w| lobe.pdf(w),
    );
    print_report(&report);
    assert!(
        (report.pdf_integral - 1.0).abs() < 1e-5,
        "{}",
        report.pdf_integral
    );
    assert!(
        report.pooled_cells > 1000,
        "the lobe leaves most cells sparse"
    );
    report.assert_passes(ALPHA, SUITE_TESTS);
}

#[test]
fn tent_on_an_interval_passes() {
    let domain = Domain::Interval {
        min: -1.0,
        max: 1.0,
    };
    let report = ChiSquareTest::new("tent", domain).run(|u| Some(tent(u.u1)), tent_pdf);
    print_report(&report);
    assert!((report.pdf_integral - 1.0).abs() < 1e-9);
    assert_eq!(report.resolution, [512, 1]);
    report.assert_passes(ALPHA, SUITE_TESTS);
}

/// A sphere light seen from a point, as `sample_li` samples it: uniform in a narrow
/// cone about a tilted axis. The cone's rim cuts through cells at arbitrary places,
/// where the pdf jumps from 0 to ~10^4 samples per cell; only adaptive refinement of
/// those cells keeps the quadrature error below the counting noise.
#[test]
fn narrow_cone_with_a_sharp_rim_passes() {
    use radiant_math::sampling::{uniform_cone, uniform_cone_pdf};
    let frame = radiant_math::Frame::from_normal(Vec3::new(-0.3, 0.5, 0.2).normalize());
    let cos_max = 10f32.to_radians().cos();
    let pdf = uniform_cone_pdf(cos_max);
    let report = ChiSquareTest::new("cone_10_degrees", Domain::Sphere).run_with_pdf(
        |u| Some((frame.to_world(uniform_cone(u.u2, cos_max)), pdf)),
        |w| if w.dot(frame.n) >= cos_max { pdf } else { 0.0 },
    );
    print_report(&report);
    assert!(
        (report.pdf_integral - 1.0).abs() < 1e-3,
        "{}",
        report.pdf_integral
    );
    report.assert_passes(ALPHA, SUITE_TESTS);
}

/// A jump exactly on a cell edge (the horizon, cos θ = 0, between rows 31 and 32):
/// Gauss nodes never sit on edges, so this costs no refinement and no error.
#[test]
fn hemisphere_inside_the_sphere_domain_passes() {
    use radiant_math::sampling::{UNIFORM_HEMISPHERE_PDF, uniform_hemisphere};
    let report = ChiSquareTest::new("hemisphere_on_sphere", Domain::Sphere).run(
        |u| Some(uniform_hemisphere(u.u2)),
        |w: Vec3| {
            if w.z >= 0.0 {
                UNIFORM_HEMISPHERE_PDF
            } else {
                0.0
            }
        },
    );
    print_report(&report);
    assert!((report.pdf_integral - 1.0).abs() < 1e-6);
    assert_eq!(report.samples_where_pdf_is_zero, 0);
    report.assert_passes(ALPHA, SUITE_TESTS);
}
