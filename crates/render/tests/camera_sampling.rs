//! The realistic camera's pupil sampling against its density, by Pearson's chi-square
//! test (`radiant_testkit::chi2`): for film points at the centre, in the field at odd
//! azimuths and in the corner, the points drawn on the rear vertex plane must be uniform
//! over the exit-pupil rectangle of the film point's radial bucket, turned to the film
//! point's azimuth, with the density 1 / area the sampler claims. The camera's ray weight
//! must be the film-irradiance factor cos⁴θ / (pdf Z²) of that same density (Kolb,
//! Mitchell & Hanrahan 1995, §4). Lens files from ../shared/data/lenses.

use radiant_math::{DVec2, Vec2};
use radiant_render::camera::realistic::{LensPrescription, RealisticCamera};
use radiant_testkit::chi2::{ChiSquareReport, ChiSquareTest, Domain};

const ALPHA: f64 = 0.01;
/// An upper bound on the chi-square tests in this file (film points whose bucket has no
/// light, as in the fisheye's corner, have no test; counting them is conservative).
const CHI2_TESTS: u32 = 20;
const SAMPLES: u64 = 200_000;
/// Samples per test whose camera ray weight is checked against the pupil's density.
const WEIGHT_CHECKS: usize = 20_000;
const RESOLUTION: (u32, u32) = (1000, 1000);

fn check(report: &ChiSquareReport) {
    report.check(ALPHA, CHI2_TESTS);
}

fn lens(name: &str) -> LensPrescription {
    let path = radiant_testkit::shared(&format!("data/lenses/{name}"));
    LensPrescription::from_file(path).expect("reference lens parses")
}

fn camera(name: &str, aperture_mm: f64, focus_m: f64) -> RealisticCamera {
    RealisticCamera::new(lens(name), aperture_mm, focus_m, 35.0, RESOLUTION)
        .expect("the camera builds")
}

/// The film centre, two field points at azimuths off the axes, and the corner.
const RASTERS: [[f32; 2]; 4] = [[500.0, 500.0], [700.0, 380.0], [130.0, 880.0], [999.5, 0.5]];

/// Pupil samples for the film point under `raster` against the uniform density over
/// the bucket's rectangle turned to the film point's azimuth, on a rectangle domain
/// bounding it; each claimed density must be 1 / area, and each ray the camera makes
/// from the same numbers must carry the weight cos⁴θ / (pdf Z²).
fn pupil_follows_uniform_density(name: &str, camera: &RealisticCamera, raster: Vec2, seed: u64) {
    let pupil = camera.exit_pupil();
    let film = camera.film_point(raster);
    let r = film.length();
    let Some(rect) = pupil.rect_for_radius(r) else {
        for i in 0..100 {
            let u = DVec2::new(i as f64 / 100.0, 0.37);
            assert!(
                pupil.sample(film, u).is_none(),
                "{name}: a sample without bounds"
            );
        }
        return;
    };
    // The film point's azimuth; a point on the axis takes the rectangle as it is.
    let (sin, cos) = if r > 0.0 {
        film.y.atan2(film.x).sin_cos()
    } else {
        (0.0, 1.0)
    };
    let area = (rect.x_max - rect.x_min) * 2.0 * rect.y_max;
    let corners = [
        DVec2::new(rect.x_min, -rect.y_max),
        DVec2::new(rect.x_min, rect.y_max),
        DVec2::new(rect.x_max, -rect.y_max),
        DVec2::new(rect.x_max, rect.y_max),
    ]
    .map(|c| DVec2::new(cos * c.x - sin * c.y, sin * c.x + cos * c.y));
    let lo = corners.iter().copied().reduce(DVec2::min).unwrap();
    let hi = corners.iter().copied().reduce(DVec2::max).unwrap();
    let pad = 1e-3 * (hi - lo).max_element();
    let domain = Domain::Rectangle {
        min: (lo - pad).as_vec2(),
        max: (hi + pad).as_vec2(),
    };
    let density = |p: Vec2| -> f64 {
        let p = p.as_dvec2();
        // Back into the frame of a film point on +x.
        let local = DVec2::new(cos * p.x + sin * p.y, -sin * p.x + cos * p.y);
        let inside = local.x >= rect.x_min && local.x <= rect.x_max && local.y.abs() <= rect.y_max;
        if inside { 1.0 / area } else { 0.0 }
    };
    let gap = camera.film_gap();
    let (mut weights_checked, mut bad_weights) = (0usize, Vec::new());
    let test_name = format!("{name}_pupil_{}_{}", raster.x, raster.y);
    let report = ChiSquareTest::new(&test_name, domain)
        .samples(SAMPLES)
        .seed(seed)
        .max_refinement(6)
        .run_with_pdf(
            |u| {
                let (p, pdf) = pupil.sample(film, u.u2.as_dvec2())?;
                if weights_checked < WEIGHT_CHECKS {
                    weights_checked += 1;
                    if let Some(ray) = camera.generate_ray(raster, u.u2) {
                        let d = (p - film).extend(gap).normalize();
                        let expected = d.z.powi(4) / (pdf * gap * gap);
                        if ((ray.weight as f64) - expected).abs() > 1e-5 * expected {
                            bad_weights.push((p, ray.weight, expected));
                        }
                    }
                }
                Some((p.as_vec2(), pdf))
            },
            density,
        );
    check(&report);
    assert!(
        bad_weights.is_empty(),
        "{test_name}: {} ray weights differ from cos^4 / (pdf Z^2), e.g. {:?}",
        bad_weights.len(),
        bad_weights[0]
    );
    // The sampler never fails inside its bounds, so the density integrates to 1.
    assert_eq!(report.no_sample, 0, "{test_name}");
    assert!((report.pdf_integral - 1.0).abs() < 1e-3, "{test_name}");
}

#[test]
fn pupil_sampling_is_uniform_over_the_bounds_of_every_lens() {
    let lenses = [
        "dgauss.50mm.dat",
        "wide.22mm.dat",
        "fisheye.10mm.dat",
        "telephoto.250mm.dat",
    ];
    let mut seed = 1;
    for name in lenses {
        // Wide open (the aperture is clamped to the file's stop), focused at infinity.
        let camera = camera(name, 1e3, f64::INFINITY);
        for [x, y] in RASTERS {
            pupil_follows_uniform_density(name, &camera, Vec2::new(x, y), seed);
            seed += 1;
        }
    }
}

#[test]
fn pupil_sampling_is_uniform_when_stopped_down_and_focused_close() {
    // f/8 and focus at 0.5 m move and shrink the pupil bounds.
    let stopped = camera("dgauss.50mm.dat", 50.0 / 8.0, f64::INFINITY);
    let close = camera("dgauss.50mm.dat", 1e3, 0.5);
    for (k, [x, y]) in [RASTERS[1], RASTERS[2]].into_iter().enumerate() {
        let raster = Vec2::new(x, y);
        pupil_follows_uniform_density("dgauss_f8", &stopped, raster, 100 + k as u64);
        pupil_follows_uniform_density("dgauss_close", &close, raster, 200 + k as u64);
    }
}
