//! Lenses built in the test against closed forms: the thick-lens lensmaker equation, a cemented
//! doublet by a hand-expanded y-nu trace, pupils by Gaussian imaging of the stop, and Snell's
//! law / total internal reflection at a single surface.

use super::super::{
    ApertureClipping, LensPrescription, LensRay, LensSurface, LensSystem, ParaxialData, ThickLens,
    TraceFailure,
};
use super::relative_error;
use radiant_math::DVec3;

fn surface(radius: f64, thickness: f64, index: f64, aperture_diameter: f64) -> LensSurface {
    LensSurface {
        radius,
        thickness,
        index,
        aperture_diameter,
    }
}

fn build(name: &str, surfaces: Vec<LensSurface>) -> LensSystem {
    let prescription = LensPrescription {
        name: name.into(),
        surfaces,
    };
    LensSystem::new(&prescription).unwrap()
}

/// Matrix products and closed forms agree to round-off (~1e-15); 1e-12 leaves margin.
const CLOSED_FORM_TOL: f64 = 1e-12;

fn assert_close(what: &str, value: f64, expected: f64) {
    let err = if expected == 0.0 {
        value.abs()
    } else {
        relative_error(value, expected)
    };
    assert!(err < CLOSED_FORM_TOL, "{what}: {value} vs {expected}");
}

/// Gaussian imaging from a principal plane: image distance for an object at distance s
/// (both positive in the direction of travel away from the lens).
fn image_distance(s: f64, f: f64) -> f64 {
    s * f / (s - f)
}

#[test]
fn biconvex_thick_lens_matches_lensmaker() {
    let (r1, r2, d, n) = (50.0, -40.0, 8.0, 1.6);
    let (stop_gap, stop_d) = (5.0, 16.0);
    let system = build(
        "biconvex",
        vec![
            surface(0.0, stop_gap, 1.0, stop_d),
            surface(r1, d, n, 20.0),
            surface(r2, 0.0, 1.0, 20.0),
        ],
    );
    let p = ParaxialData::new(&system).unwrap();

    // Lensmaker's equation for a thick lens (e.g. Hecht, "Optics", eq. 6.2).
    let power = (n - 1.0) * (1.0 / r1 - 1.0 / r2 + (n - 1.0) * d / (n * r1 * r2));
    let f = 1.0 / power;
    // Principal planes from the vertices (Hecht eqs. 6.3–6.4): + towards the film.
    let h1_from_first = -f * (n - 1.0) * d / (n * r2);
    let h2_from_last = -f * (n - 1.0) * d / (n * r1);
    assert_close("efl", p.efl, f);
    assert_close("bfd", p.bfd, f + h2_from_last);
    assert_close("ffd", p.ffd, f - h1_from_first - stop_gap);
    assert_close("H1", p.h1_z, stop_gap + h1_from_first);
    assert_close("H2", p.h2_z, stop_gap + d + h2_from_last);

    // The stop is in front of everything: it is its own entrance pupil.
    assert_close("entrance pupil z", p.entrance_pupil_z, 0.0);
    assert_close("entrance pupil diameter", p.entrance_pupil_diameter, stop_d);
    assert_close("f-number", p.f_number, f / stop_d);
    assert_eq!(p.axial_limiting_surface, 0);
    assert_close("limited f-number", p.f_number_limited, f / stop_d);

    // The exit pupil is the lens's image of the stop: object distance from H, image from H'.
    let s = stop_gap + h1_from_first;
    let s_image = image_distance(s, f);
    let exit_z = p.h2_z + s_image;
    assert_close(
        "exit pupil",
        p.exit_pupil_from_rear,
        exit_z - (stop_gap + d),
    );
    assert_close(
        "exit pupil diameter",
        p.exit_pupil_diameter,
        stop_d * (s_image / s).abs(),
    );
    assert_close("determinant", p.abcd.determinant(), 1.0);

    // Exact rays close to the axis converge on the paraxial cardinal points: the spherical
    // aberration of a zone at height h shifts them by O(h²) — 1e-3 mm gives ~1e-9 relative.
    let t = ThickLens::from_traced_rays(&system, 1e-3).unwrap();
    assert!(
        relative_error(t.focal_length(), f) < 1e-8,
        "{}",
        t.focal_length()
    );
    assert!(relative_error(t.image_focal, p.bfd) < 1e-8);
    assert!(relative_error(t.image_principal, h2_from_last) < 1e-6);
    assert!(relative_error(-t.object_principal, d - h1_from_first) < 1e-6);
}

#[test]
fn cemented_doublet_matches_hand_expanded_y_nu_trace() {
    // A classic crown-flint achromat (BK7 / F2), stop 3 mm behind it.
    let (r1, r2, r3) = (61.47, -44.64, -129.94);
    let (d1, d2, air) = (6.0, 2.5, 3.0);
    let (n1, n2) = (1.5168, 1.6727);
    let stop_d = 18.0;
    let system = build(
        "doublet",
        vec![
            surface(r1, d1, n1, 25.0),
            surface(r2, d2, n2, 25.0),
            surface(r3, air, 1.0, 25.0),
            surface(0.0, 0.0, 1.0, stop_d),
        ],
    );
    let p = ParaxialData::new(&system).unwrap();

    let (phi1, phi2, phi3) = ((n1 - 1.0) / r1, (n2 - n1) / r2, (1.0 - n2) / r3);
    // Forward: y = 1, n·u = 0 from infinity.
    let y1 = 1.0;
    let nu1 = -y1 * phi1;
    let y2 = y1 + d1 * nu1 / n1;
    let nu2 = nu1 - y2 * phi2;
    let y3 = y2 + d2 * nu2 / n2;
    let nu3 = nu2 - y3 * phi3;
    let f = -1.0 / nu3;
    let bfd_from_r3 = -y3 / nu3;
    // Backward (surface powers are unchanged by reversing the lens).
    let b3 = 1.0;
    let mu3 = -b3 * phi3;
    let b2 = b3 + d2 * mu3 / n2;
    let mu2 = mu3 - b2 * phi2;
    let b1 = b2 + d1 * mu2 / n1;
    let mu1 = mu2 - b1 * phi1;
    let ffd = -b1 / mu1;

    assert_close("efl", p.efl, f);
    assert_close("efl (backward)", -1.0 / mu1, f);
    assert_close("bfd", p.bfd, bfd_from_r3 - air);
    assert_close("ffd", p.ffd, ffd);
    let lens_track = d1 + d2;
    assert_close("H1", p.h1_z, f - ffd);
    assert_close("H2", p.h2_z, lens_track + bfd_from_r3 - f);

    // The stop is the last element: it is its own exit pupil.
    assert_close("exit pupil", p.exit_pupil_from_rear, 0.0);
    assert_close("exit pupil diameter", p.exit_pupil_diameter, stop_d);
    // The entrance pupil is the doublet's image of the stop, looking in from the front:
    // object distance from H' (towards the film), image distance from H (towards the scene).
    let s = (lens_track + air) - p.h2_z;
    let s_image = image_distance(s, f);
    assert_close("entrance pupil z", p.entrance_pupil_z, p.h1_z - s_image);
    let epd = stop_d * (s_image / s).abs();
    assert_close("entrance pupil diameter", p.entrance_pupil_diameter, epd);
    assert_close("f-number", p.f_number, f / epd);
    assert_close("determinant", p.abcd.determinant(), 1.0);

    let t = ThickLens::from_traced_rays(&system, 1e-3).unwrap();
    assert!(relative_error(t.focal_length(), f) < 1e-8);
    assert!(relative_error(t.image_focal, p.bfd) < 1e-8);
}

/// A plano-convex block (front sphere R = 10 mm, flat rear at the stop, n = 1.5) traced from the
/// film side with rays parallel to the axis: at height h the incidence angle on the sphere is
/// asin(h/R). Below the critical angle asin(1/1.5) = 41.8° Snell's law holds exactly; above it
/// the ray is totally internally reflected; outside the aperture it is blocked.
#[test]
fn single_surface_snell_tir_and_clipping() {
    let (radius, n) = (10.0, 1.5);
    let system = build(
        "plano-convex",
        vec![surface(radius, 10.0, n, 19.0), surface(0.0, 0.0, 1.0, 19.0)],
    );
    let ray_at = |h: f64| LensRay {
        origin: DVec3::new(h, 0.0, -1.0),
        dir: DVec3::Z,
    };

    for h in [0.5, 2.0, 5.0, 6.6] {
        let out = system
            .trace_to_scene(ray_at(h), ApertureClipping::Clip)
            .unwrap();
        let center = DVec3::new(0.0, 0.0, system.interfaces()[0].center_z());
        let normal = (out.origin - center).normalize();
        let sin_in = h / radius;
        let sin_out = out.dir.cross(normal).length();
        assert!(
            (sin_out - n * sin_in).abs() < 1e-12,
            "h = {h}: sin θt = {sin_out}, n sin θi = {}",
            n * sin_in
        );
        assert_eq!(out.dir.y, 0.0, "refraction stays in the plane of incidence");
        assert!((out.origin.length_squared() - radius * radius).abs() < 1e-9 * radius);
    }

    // sin θi = 0.7 > 1/1.5: total internal reflection at the front surface (index 0).
    assert_eq!(
        system.trace_to_scene(ray_at(7.0), ApertureClipping::Clip),
        Err(TraceFailure::TotalInternalReflection { surface: 0 })
    );
    // Beyond the 9.5 mm aperture the flat rear stop (index 1) blocks first.
    assert_eq!(
        system.trace_to_scene(ray_at(9.7), ApertureClipping::Clip),
        Err(TraceFailure::Blocked { surface: 1 })
    );
}
