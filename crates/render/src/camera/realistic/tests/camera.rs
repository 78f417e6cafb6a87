//! Ray generation: radiometry against the reference, orientation, aperture handling.

use super::super::{CameraRaySample, RealisticCamera};
use super::{LENSES, lens, lens_record, num, reference};
use radiant_math::Vec2;

const RESOLUTION: (u32, u32) = (1000, 1000);
const STRATA: usize = 64;

fn camera(name: &str, aperture: f64, focus: f64) -> RealisticCamera {
    RealisticCamera::new(lens(name), aperture, focus, 35.0, RESOLUTION).unwrap()
}

/// Mean ray weight (blocked rays count as 0) at a raster point, over a stratified
/// STRATA × STRATA lens-sample grid: the film irradiance for unit radiance.
fn mean_weight(camera: &RealisticCamera, raster: Vec2) -> f64 {
    let mut sum = 0.0;
    for i in 0..STRATA {
        for j in 0..STRATA {
            let u = Vec2::new(
                (i as f32 + 0.5) / STRATA as f32,
                (j as f32 + 0.5) / STRATA as f32,
            );
            if let Some(s) = camera.generate_ray(raster, u) {
                sum += s.weight as f64;
            }
        }
    }
    sum / (STRATA * STRATA) as f64
}

/// Raster point at `film_radius` mm from the centre, towards the top-left corner (the film is
/// square, so the corner is at the 17.5 mm half diagonal).
fn raster_at_radius(film_radius: f64) -> Vec2 {
    let t = (film_radius / 17.5) as f32;
    let centre = Vec2::new(RESOLUTION.0 as f32, RESOLUTION.1 as f32) * 0.5;
    centre * (1.0 - t)
}

/// Relative illumination E(r)/E(0) at infinity focus against `relative_illumination_infinity_focus`,
/// within 2 % relative (the acceptance criterion) at every listed film radius, including the
/// fisheye's 8 % at 13.125 mm; where the reference has no light (fisheye corner) there must be
/// none. The reference integrates on a grid over the rear plane (~0.3 % error), our 64²
/// stratified estimate adds ~0.3 %: the observed differences are at most 0.8 % (wide.22mm at
/// 4.375 mm) and 0.2 % on the fisheye's rim.
#[test]
fn relative_illumination_matches_reference() {
    for name in LENSES {
        let camera = camera(name, 1e3, f64::INFINITY);
        let e0 = mean_weight(&camera, raster_at_radius(0.0));
        for entry in lens_record(name)["relative_illumination_infinity_focus"]
            .as_array()
            .unwrap()
        {
            let r = num(&entry["film_radius_mm"]);
            let expected = num(&entry["E_over_E0"]);
            let ratio = mean_weight(&camera, raster_at_radius(r)) / e0;
            if expected == 0.0 {
                assert_eq!(ratio, 0.0, "{name} r = {r}: light outside the image circle");
            } else {
                assert!(
                    ((ratio - expected) / expected).abs() < 0.02,
                    "{name} r = {r}: E/E0 = {ratio:.4} vs {expected:.4}"
                );
            }
        }
    }
}

/// The axial mean weight is pbrt's pixel value for a unit-radiance sky (`axial_E0_pbrt_weight_mean`,
/// 4 significant digits; full precision in `axial_irradiance_integral_E0`): within 1 % (the
/// reference's grid error ~0.3 % plus ours ~0.3 %).
#[test]
fn axial_weight_matches_pbrt_convention() {
    for name in LENSES {
        let camera = camera(name, 1e3, f64::INFINITY);
        let e0 = mean_weight(&camera, raster_at_radius(0.0));
        let summary = num(&reference()["summary"][name]["axial_E0_pbrt_weight_mean"]);
        let full = num(&lens_record(name)["axial_irradiance_integral_E0"]);
        assert!(((e0 - full) / full).abs() < 0.01, "{name}: {e0} vs {full}");
        assert!(
            ((e0 - summary) / summary).abs() < 0.01,
            "{name}: {e0} vs {summary}"
        );
    }
}

/// Stopped down to 2 mm, dgauss.50mm works in the paraxial regime, where the irradiance from a
/// unit-radiance sky at infinity focus is π sin²θ' = π / (4N² + 1) with N the paraxial f-number
/// (Kolb et al. 1995, eq. 9 and its small-aperture form). The remaining differences, pupil
/// aberration and the cos⁴ variation across a 1.6° cone, are ~1e-3: 0.5 % is asserted.
#[test]
fn small_aperture_irradiance_is_paraxial() {
    let camera = camera("dgauss.50mm.dat", 2.0, f64::INFINITY);
    let n = camera.paraxial().f_number;
    let expected = std::f64::consts::PI / (4.0 * n * n + 1.0);
    let e0 = mean_weight(&camera, raster_at_radius(0.0));
    assert!(
        ((e0 - expected) / expected).abs() < 0.005,
        "{e0} vs {expected} (f/{n:.2})"
    );
    assert!(camera.warnings().is_empty());
}

#[test]
fn aperture_wider_than_the_stop_is_clamped_with_a_warning() {
    let camera = camera("dgauss.50mm.dat", 40.0, 10.0);
    assert_eq!(camera.system().stop_diameter(), 17.1);
    assert_eq!(camera.warnings().len(), 1);
    assert!(camera.warnings()[0].contains("clamped"));
    assert!(RealisticCamera::new(lens("dgauss.50mm.dat"), 0.0, 10.0, 35.0, RESOLUTION).is_err());
}

/// Like the pinhole camera: a scene direction with +x, +y must land right of and above the
/// centre, i.e. a raster point right of and above the centre must send rays towards +x, +y.
/// The mean direction of the bundle is the chief direction; its slope must match the
/// distortion-free estimate film offset / f within the lens's distortion (< 2 % here).
#[test]
fn image_orientation_matches_pinhole() {
    let camera =
        RealisticCamera::new(lens("dgauss.50mm.dat"), 17.1, 10.0, 35.0, (200, 100)).unwrap();
    let size = camera.film_size();
    let raster = Vec2::new(150.0, 25.0);
    let mut sum = radiant_math::DVec3::ZERO;
    for i in 0..16 {
        for j in 0..16 {
            let u = Vec2::new((i as f32 + 0.5) / 16.0, (j as f32 + 0.5) / 16.0);
            if let Some(CameraRaySample { dir, .. }) = camera.generate_ray(raster, u) {
                sum += dir.as_dvec3();
            }
        }
    }
    let d = sum.normalize();
    assert!(d.x > 0.0 && d.y > 0.0 && d.z > 0.0, "{d}");
    let f = camera.paraxial().efl;
    let film_x = 0.25 * size.x; // 150 of 200 pixels: a quarter width right of centre
    let film_y = 0.25 * size.y; // 25 of 100 pixels: a quarter height above centre
    let (slope_x, slope_y) = (d.x / d.z, d.y / d.z);
    assert!(
        ((slope_x - film_x / f) / (film_x / f)).abs() < 0.02,
        "{slope_x}"
    );
    assert!(
        ((slope_y - film_y / f) / (film_y / f)).abs() < 0.02,
        "{slope_y}"
    );
}

#[test]
fn rays_are_well_formed() {
    for name in LENSES {
        let camera = camera(name, 1e3, 10.0);
        let front_z = ((camera.film_gap() + camera.system().total_track()) / 1000.0) as f32;
        let mut passed = 0;
        for k in 0..400u32 {
            let raster = Vec2::new((k * 37 % 1000) as f32 + 0.5, (k * 91 % 1000) as f32 + 0.5);
            let u = Vec2::new(((k * 13) % 97) as f32 / 97.0, ((k * 29) % 89) as f32 / 89.0);
            if let Some(s) = camera.generate_ray(raster, u) {
                passed += 1;
                assert!((s.dir.length() - 1.0).abs() < 1e-5);
                assert!(s.dir.z > 0.0, "{name}: rays leave forwards");
                assert!(s.weight > 0.0 && s.weight.is_finite());
                // Origins lie on the front element, at most its sag behind the front vertex.
                assert!(
                    s.origin.z <= front_z + 1e-6 && s.origin.z > 0.0,
                    "{name}: {}",
                    s.origin
                );
            }
        }
        assert!(passed > 50, "{name}: only {passed} of 400 rays passed");
    }
}
