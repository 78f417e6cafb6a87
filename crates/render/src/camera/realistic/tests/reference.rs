//! Paraxial data, thick lens, focusing and chief rays against lenses.json.

use super::super::{
    LensError, LensSystem, ParaxialData, ThickLens, chief_ray, film_distance_for_focus,
    image_circle,
};
use super::{LENSES, lens, lens_record, num, reference, relative_error};

fn system(name: &str) -> LensSystem {
    LensSystem::new(&lens(name)).unwrap()
}

/// The `paraxial` block of lenses.json is full f64 precision from an independent y-nu trace, so
/// agreement is limited only by round-off in differently ordered sums: ~1e-14 relative. 1e-9
/// leaves a wide margin while being 1000× tighter than the 1e-6 the acceptance asks for.
const PARAXIAL_REL_TOL: f64 = 1e-9;

#[test]
fn paraxial_data_matches_full_precision_reference() {
    for name in LENSES {
        let p = ParaxialData::new(&system(name)).unwrap();
        let r = &lens_record(name)["paraxial"];
        let checks = [
            ("efl", p.efl, num(&r["efl"])),
            ("bfd", p.bfd, num(&r["bfd"])),
            ("ffd", p.ffd, num(&r["ffd"])),
            ("H1", p.h1_z, num(&r["H1"])),
            ("H2", p.h2_z, num(&r["H2"])),
            ("total_track", p.total_track, num(&r["total_track"])),
            ("z_stop", p.stop_z, num(&r["z_stop"])),
            (
                "entrance_pupil_z",
                p.entrance_pupil_z,
                num(&r["entrance_pupil_z"]),
            ),
            (
                "entrance_pupil_diameter",
                p.entrance_pupil_diameter,
                num(&r["entrance_pupil_diameter"]),
            ),
            (
                "exit_pupil_from_rear_vertex",
                p.exit_pupil_from_rear,
                num(&r["exit_pupil_from_rear_vertex"]),
            ),
            (
                "exit_pupil_diameter",
                p.exit_pupil_diameter,
                num(&r["exit_pupil_diameter"]),
            ),
            (
                "f_number_paraxial_stop",
                p.f_number,
                num(&r["f_number_paraxial_stop"]),
            ),
            (
                "f_number_paraxial_limited",
                p.f_number_limited,
                num(&r["f_number_paraxial_limited"]),
            ),
            ("A", p.abcd.a, num(&r["abcd"][0])),
            ("B", p.abcd.b, num(&r["abcd"][1])),
            ("C", p.abcd.c, num(&r["abcd"][2])),
            ("D", p.abcd.d, num(&r["abcd"][3])),
        ];
        for (field, value, expected) in checks {
            assert!(
                relative_error(value, expected) < PARAXIAL_REL_TOL,
                "{name} {field}: {value} vs {expected}"
            );
        }
        assert_eq!(
            p.axial_limiting_surface as u64,
            r["axial_limiting_surface"].as_u64().unwrap(),
            "{name}"
        );
        assert_eq!(p.stop_index as u64, r["stop_index"].as_u64().unwrap());
    }
}

/// The summary block rounds to 4 decimals, so it can only confirm the field identities: each
/// value must agree within half a unit in the last place (5e-5) plus round-off.
#[test]
fn summary_fields_agree_within_their_rounding() {
    for name in LENSES {
        let p = ParaxialData::new(&system(name)).unwrap();
        let s = &reference()["summary"][name];
        for (field, value) in [
            ("efl_mm", p.efl),
            ("bfd_mm", p.bfd),
            ("ffd_mm", p.ffd),
            ("H1_z_mm", p.h1_z),
            ("H2_z_mm", p.h2_z),
            ("f_number_stop", p.f_number),
            ("f_number_limited", p.f_number_limited),
            ("entrance_pupil_diam_mm", p.entrance_pupil_diameter),
            ("exit_pupil_from_rear_mm", p.exit_pupil_from_rear),
        ] {
            let expected = num(&s[field]);
            assert!(
                (value - expected).abs() <= 5.0e-5 + 1e-12,
                "{name} {field}: {value} vs {expected}"
            );
        }
    }
}

/// pbrt-v4's thick lens: exact rays at 0.001 × 35 mm. Both sides trace in f64; the focal point
/// divides by the outgoing slope (~1e-3), so round-off of 1e-15 mm grows to ~1e-12 mm: 1e-8 mm
/// is a safe bound that would still catch a different ray height (which moves fz0 by ≥ 1e-6 mm).
#[test]
fn thick_lens_matches_pbrt_reference() {
    let diagonal = num(&reference()["film_diagonal_mm"]);
    for name in LENSES {
        let t = ThickLens::from_traced_rays(&system(name), 0.001 * diagonal).unwrap();
        let r = &lens_record(name)["pbrt_thick_lens_mm"];
        for (field, value) in [
            ("pz0", t.image_principal),
            ("fz0", t.image_focal),
            ("pz1", t.object_principal),
            ("fz1", t.object_focal),
            ("f", t.focal_length()),
        ] {
            let expected = num(&r[field]);
            assert!(
                (value - expected).abs() < 1e-8,
                "{name} {field}: {value} vs {expected}"
            );
        }
    }
}

/// Film gaps for every focus distance in `pbrt_focus_film_gap_mm_by_focusdistance_m` (10 m and
/// 2 m among them). The acceptance asks for 1e-4 mm; the shared thick lens makes the gaps agree
/// to ~1e-12 mm except at 10⁶ m where the reference's own evaluation differs by ~3e-8 mm, so
/// 1e-6 mm is asserted. null entries are distances the lens cannot reach.
#[test]
fn film_gaps_match_pbrt_reference() {
    let diagonal = num(&reference()["film_diagonal_mm"]);
    for name in LENSES {
        let system = system(name);
        let table = lens_record(name)["pbrt_focus_film_gap_mm_by_focusdistance_m"]
            .as_object()
            .unwrap();
        assert!(table.contains_key("10") && table.contains_key("2"));
        for (distance, expected) in table {
            let focus: f64 = distance.parse().unwrap();
            let gap = film_distance_for_focus(&system, focus, diagonal);
            if expected.is_null() {
                assert!(
                    matches!(gap, Err(LensError::FocusTooClose { .. })),
                    "{name} at {focus} m: expected a refusal, got {gap:?}"
                );
            } else {
                let gap = gap.unwrap();
                let expected = num(expected);
                assert!(
                    (gap - expected).abs() < 1e-6,
                    "{name} at {focus} m: {gap} vs {expected}"
                );
            }
        }
        // Infinity focuses on the thick lens's focal point.
        let t = ThickLens::from_traced_rays(&system, 0.001 * diagonal).unwrap();
        let at_infinity = film_distance_for_focus(&system, f64::INFINITY, diagonal).unwrap();
        assert!((at_infinity - t.image_focal).abs() < 1e-12);
    }
}

#[test]
fn telephoto_refuses_to_focus_at_one_metre() {
    let err = film_distance_for_focus(&system("telephoto.250mm.dat"), 1.0, 35.0).unwrap_err();
    let message = err.to_string();
    assert!(
        message.contains("cannot focus at 1 m") && message.contains("closest focus"),
        "{message}"
    );
    // The closest distance named must itself be reachable, and a little less must not be.
    let LensError::FocusTooClose { closest_m, .. } = err else {
        panic!("wrong error kind")
    };
    assert!(closest_m > 1.0 && closest_m < 2.0);
    let system = system("telephoto.250mm.dat");
    assert!(film_distance_for_focus(&system, closest_m * (1.0 + 1e-9), 35.0).is_ok());
    assert!(film_distance_for_focus(&system, closest_m * (1.0 - 1e-9), 35.0).is_err());
}

/// The example: at 10⁶ m the textbook root (L − √(L² − 4fL))/2 in f32 cancels to
/// 62.5 mm; the conjugate form keeps dgauss.50mm at its focal point, 36.1 mm.
#[test]
fn focusing_far_away_is_numerically_stable() {
    let system = system("dgauss.50mm.dat");
    let expected =
        num(&lens_record("dgauss.50mm.dat")["pbrt_focus_film_gap_mm_by_focusdistance_m"]["1e+06"]);
    let gap = film_distance_for_focus(&system, 1e6, 35.0).unwrap();
    assert!((gap - expected).abs() < 1e-6, "{gap} vs {expected}");
    assert!((gap - 36.1059).abs() < 1e-4);

    // The failure mode being avoided, reproduced with the same thick lens in f32.
    let t = ThickLens::from_traced_rays(&system, 0.035).unwrap();
    let (f, hiatus) = (
        t.focal_length() as f32,
        (t.image_principal - t.object_principal) as f32,
    );
    let total = 1e9f32 - hiatus;
    let naive = t.image_principal as f32 + (total - (total * total - 4.0 * f * total).sqrt()) / 2.0;
    assert!(
        (naive - 36.1).abs() > 1.0,
        "the f32 textbook root happened to be fine: {naive}"
    );
}

/// Chief-ray field angles at the film radii of `field_at_infinity_focus_diag35mm`, film at the
/// paraxial BFD. The reference solves the same stop-centre condition in f64, so the angles agree
/// to ~1e-9 degrees; 1e-6 degrees is asserted. Film radii without a chief ray are null there.
#[test]
fn chief_ray_angles_match_reference() {
    for name in LENSES {
        let system = system(name);
        let record = lens_record(name);
        let gap = num(&record["paraxial"]["bfd"]);
        for field in record["field_at_infinity_focus_diag35mm"]
            .as_array()
            .unwrap()
        {
            let radius = num(&field["film_radius_mm"]);
            let chief = chief_ray(&system, gap, radius);
            if field.get("chief_ray").is_some_and(|c| c.is_null()) {
                assert!(chief.is_none(), "{name} r={radius}: expected no chief ray");
                continue;
            }
            let chief = chief.unwrap_or_else(|| panic!("{name} r={radius}: no chief ray"));
            let expected = num(&field["theta_deg"]);
            let angle = chief.field_angle.to_degrees();
            assert!(
                (angle - expected).abs() < 1e-6,
                "{name} r={radius}: {angle} vs {expected} deg"
            );
            assert_eq!(
                chief.vignetted,
                field["vignetted_by_rims"].as_bool().unwrap(),
                "{name} r={radius}"
            );
        }
        // The summary's corner half field of view (4 decimals, or null outside the image circle).
        let half_fov = &reference()["summary"][name]["half_fov_corner_deg_35mm_diag"];
        let corner = chief_ray(&system, gap, 17.5);
        match half_fov.as_f64() {
            Some(expected) => {
                let angle = corner.unwrap().field_angle.to_degrees();
                assert!((angle - expected).abs() < 5e-3 + 1e-9, "{name}: {angle}");
            }
            None => assert!(corner.is_none()),
        }
    }
}

/// The fisheye's image circle (`image_circle_infinity_focus`): the reference steps the film
/// radius by 0.125 mm and reports 13.0 mm, the last radius whose chief ray clears every rim
/// (at 13.125 mm it is clipped); our bisected radius must fall in that step, and at 13.0 mm the
/// chief-ray angle must match to 1e-6 degrees.
#[test]
fn fisheye_image_circle_matches_reference() {
    let system = system("fisheye.10mm.dat");
    let record = &lens_record("fisheye.10mm.dat")["image_circle_infinity_focus"];
    let gap = num(&lens_record("fisheye.10mm.dat")["paraxial"]["bfd"]);
    let circle = image_circle(&system, gap, 17.5).unwrap();
    let expected = num(&record["film_radius_mm"]);
    assert!(
        circle.film_radius >= expected && circle.film_radius < expected + 0.125,
        "{}",
        circle.film_radius
    );
    let at_reference = chief_ray(&system, gap, expected).unwrap();
    let angle = at_reference.field_angle.to_degrees();
    assert!((angle - num(&record["theta_deg"])).abs() < 1e-6, "{angle}");
    // Lenses whose corners are clear report the corner itself.
    let dgauss = self::system("dgauss.50mm.dat");
    let corner = image_circle(&dgauss, 36.1, 17.5).unwrap();
    assert_eq!(corner.film_radius, 17.5);
}

/// The fisheye is an equidistant (f-θ) design: image height r = f·θ within 1 % up to 70°
/// (the reference shows deviations of 0.03–0.5 %). Film radii 0.5 mm apart up to where θ
/// passes 70°.
#[test]
fn fisheye_image_height_follows_f_theta() {
    let system = system("fisheye.10mm.dat");
    let p = ParaxialData::new(&system).unwrap();
    let mut checked = 0;
    let mut radius: f64 = 0.5;
    loop {
        let chief = chief_ray(&system, p.bfd, radius).expect("inside the image circle");
        let theta = chief.field_angle;
        if theta.to_degrees() > 70.0 {
            break;
        }
        let ideal = p.efl * theta;
        assert!(
            relative_error(radius, ideal) < 0.01,
            "r = {radius} mm, θ = {:.3}°, f·θ = {ideal}",
            theta.to_degrees()
        );
        checked += 1;
        radius += 0.5;
    }
    // 70° at f ≈ 10 mm is r ≈ 12.2 mm: 24 film radii.
    assert!(checked >= 24, "only {checked} radii below 70°");
}
